/* Console byte rings (board_uart.h). */
#include "board_uart.h"

#include <stdatomic.h>
#include <string.h>

void board_uart_init(board_uart_t *u, const board_uart_port_t *port, uint32_t ticks_hz,
                     uint32_t f_cpu_hz, uint32_t baud)
{
    memset(u, 0, sizeof *u);
    u->port = port;
    /* A full ring drains in TX_SIZE x 10 bits / baud; wait at most that. */
    u->tx_wait_ticks = (uint32_t)((uint64_t)ticks_hz * 10u * BOARD_UART_TX_SIZE / baud);
    u->byte_ticks = (uint32_t)((uint64_t)ticks_hz * 10u / baud) + 1u;
    u->poll_cycles = (uint32_t)((uint64_t)f_cpu_hz * 10u / baud);
    u->lost_idle_ticks = ticks_hz / 1000u * BOARD_UART_LOST_IDLE_MS;
}

int board_uart_getc(board_uart_t *u)
{
    const uint32_t t = u->rx_tail;
    if (t == u->rx_head) {
        return -1;
    }
    atomic_signal_fence(memory_order_acquire);          /* the byte after its count */
    const int c = u->rx[t & (BOARD_UART_RX_SIZE - 1u)]; /* with its losses (bits 8..11) */
    atomic_signal_fence(memory_order_release);          /* read before its slot is handed back */
    u->rx_tail = t + 1u;
    return c;
}

int board_uart_lost_idle(board_uart_t *u, bool rx_waiting)
{
    /* Why only these: an overrun (or the ring full) loses bytes only of a
     * sender that streams them (2 characters within a flash sector erase,
     * 256 behind a busy main loop), and such a sender's line goes on within
     * a character time of the core running again; a line idle for
     * lost_idle_ticks after the loss ended inside it. A framing or noise
     * error hits one character of any sender, a typist's too, whose pauses
     * say nothing: its line ends at the next end of line received. */
    const uint32_t pending = u->rx_lost;
    if ((pending & (BOARD_UART_LOST_OVERRUN | BOARD_UART_LOST_FULL)) == 0u ||
        u->rx_head != u->rx_tail || rx_waiting ||
        u->port->ticks() - u->rx_lost_at < u->lost_idle_ticks) {
        return -1;
    }
    u->rx_lost = 0u; /* the next byte starts a line of its own */
    return (int)(pending << 8 | '\r');
}

const char *board_uart_lost_why(int c)
{
    const uint32_t lost = (uint32_t)c >> 8;
    return (lost & BOARD_UART_LOST_OVERRUN) != 0u   ? "overrun (ORE)"
           : (lost & BOARD_UART_LOST_FRAMING) != 0u ? "framing (FE)"
           : (lost & BOARD_UART_LOST_NOISE) != 0u   ? "noise (NF)"
                                                    : "ring full";
}

/* A byte by polling, calling idle between the characters (the writer's
 * wait, as with the ring). */
static void board_uart_put_direct(board_uart_t *u, uint8_t c)
{
    if (u->idle != NULL) {
        u->idle(u->idle_ctx);
    }
    if (!u->port->put_polled(c, 4u * u->poll_cycles)) {
        u->tx_dropped++;
    }
}

bool board_uart_check_tx(board_uart_t *u, const uint8_t *probe, size_t n)
{
    board_uart_write(u, probe, n);
    const uint32_t t0 = u->port->ticks();
    while (u->tx_tail == 0u && u->port->ticks() - t0 <= 8u * u->byte_ticks) {
    }
    if (u->tx_tail != 0u) {
        return true;
    }
    u->polled = true;
    /* the interrupt never sent: its enable off, the queued bytes by polling */
    u->port->tx_irq_off();
    while (u->tx_tail != u->tx_head) {
        board_uart_put_direct(u, u->tx[u->tx_tail & (BOARD_UART_TX_SIZE - 1u)]);
        u->tx_tail++;
    }
    return false;
}

void board_uart_write(board_uart_t *u, const uint8_t *bytes, size_t len)
{
    if (u->polled) {
        for (size_t i = 0; i < len; i++) {
            board_uart_put_direct(u, bytes[i]);
        }
        return;
    }
    for (size_t i = 0; i < len; i++) {
        if (u->tx_head - u->tx_tail >= BOARD_UART_TX_SIZE) {
            const uint32_t t0 = u->port->ticks();
            while (u->tx_head - u->tx_tail >= BOARD_UART_TX_SIZE) {
                if (u->idle != NULL) {
                    u->idle(u->idle_ctx);
                }
                if (u->port->ticks() - t0 > u->tx_wait_ticks) {
                    u->tx_dropped += (uint32_t)(len - i);
                    return;
                }
            }
        }
        atomic_signal_fence(memory_order_acquire); /* the slot freed before it is written */
        u->tx[u->tx_head & (BOARD_UART_TX_SIZE - 1u)] = bytes[i];
        atomic_signal_fence(memory_order_release); /* the byte before its count */
        u->tx_head++;
        u->port->tx_irq_on();
    }
}

void board_uart_puts(board_uart_t *u, const char *s)
{
    board_uart_write(u, (const uint8_t *)s, strlen(s));
}

void board_uart_puts_polled(board_uart_t *u, const char *s)
{
    for (; *s != '\0'; s++) {
        if (!u->port->put_polled((uint8_t)*s, 4u * u->poll_cycles)) {
            u->tx_dropped++;
            return;
        }
    }
}

void board_uart_rx(board_uart_t *u, uint8_t c)
{
    if (u->rx_head - u->rx_tail < BOARD_UART_RX_SIZE) {
        atomic_signal_fence(memory_order_acquire); /* the slot freed before it is written */
        u->rx[u->rx_head & (BOARD_UART_RX_SIZE - 1u)] = (uint16_t)(c | u->rx_lost << 8);
        atomic_signal_fence(memory_order_release); /* the byte before its count */
        u->rx_head++;
        u->rx_lost = 0u;
    } else {
        u->rx_dropped++;
        u->rx_lost |= BOARD_UART_LOST_FULL;
        u->rx_lost_at = u->port->ticks();
    }
}

void board_uart_rx_lost(board_uart_t *u, uint32_t lost)
{
    u->rx_errors++;
    u->rx_lost |= lost;
    /* An overrun: the core runs again, the loss ends here. A damaged
     * character: one received, a sender still streaming, so an overrun's
     * pending loss waits its idle bound from here. */
    u->rx_lost_at = u->port->ticks();
}

bool board_uart_tx_next(board_uart_t *u, uint8_t *c)
{
    if (u->tx_tail == u->tx_head) {
        return false;
    }
    atomic_signal_fence(memory_order_acquire); /* the byte after its count */
    *c = u->tx[u->tx_tail & (BOARD_UART_TX_SIZE - 1u)];
    atomic_signal_fence(memory_order_release); /* read before its slot is handed back */
    u->tx_tail++;
    return true;
}
