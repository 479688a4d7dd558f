/* USART2 byte rings (esc1_uart.h). */
#include "esc1_uart.h"

#include <stdatomic.h>
#include <string.h>

#include "board_esc1.h"
#include "g4_core.h"
#include "g4_periph.h"
#include "g4_regs.h"

int esc1_uart_init(esc1_uart_t *u, uint32_t f_pclk_hz, uint32_t baud)
{
    memset(u, 0, sizeof *u);
    uint32_t brr;
    if (g4_usart_brr(f_pclk_hz, baud, &brr) != G4_OK) {
        return G4_E_CONFIG;
    }
    /* A full ring drains in TX_SIZE x 10 bits / baud; wait at most that. */
    u->tx_wait_cycles = (uint32_t)((uint64_t)f_pclk_hz * 10u * ESC1_UART_TX_SIZE / baud);
    u->byte_cycles = (uint32_t)((uint64_t)f_pclk_hz * 10u / baud);
    u->lost_idle_cycles = f_pclk_hz / 1000u * ESC1_UART_LOST_IDLE_MS; /* PCLK1 = the core's */
    g4_gpio_config(g4_board_esc1.uart_tx, G4_PIN_AF, 0u);
    g4_gpio_config(g4_board_esc1.uart_rx, G4_PIN_AF, 1u);
    g4_usart2_init(brr);
    return G4_OK;
}

int esc1_uart_getc(esc1_uart_t *u)
{
    const uint32_t t = u->rx_tail;
    if (t == u->rx_head) {
        return -1;
    }
    atomic_signal_fence(memory_order_acquire);         /* the byte after its count */
    const int c = u->rx[t & (ESC1_UART_RX_SIZE - 1u)]; /* with its losses (bits 8..11) */
    atomic_signal_fence(memory_order_release);         /* read before its slot is handed back */
    u->rx_tail = t + 1u;
    return c;
}

void esc1_uart_write(esc1_uart_t *u, const uint8_t *bytes, size_t len)
{
    for (size_t i = 0; i < len; i++) {
        if (u->tx_head - u->tx_tail >= ESC1_UART_TX_SIZE) {
            const uint32_t t0 = g4_cycles();
            while (u->tx_head - u->tx_tail >= ESC1_UART_TX_SIZE) {
                if (u->idle != NULL) {
                    u->idle(u->idle_ctx);
                }
                if (g4_cycles() - t0 > u->tx_wait_cycles) {
                    u->tx_dropped += (uint32_t)(len - i);
                    return;
                }
            }
        }
        atomic_signal_fence(memory_order_acquire); /* the slot freed before it is written */
        u->tx[u->tx_head & (ESC1_UART_TX_SIZE - 1u)] = bytes[i];
        atomic_signal_fence(memory_order_release); /* the byte before its count */
        u->tx_head++;
        /* The interrupt sends while bytes are queued. */
        g4_set(G4_USART2 + G4_USART_CR1, G4_USART_CR1_TXEIE);
    }
}

void esc1_uart_puts(esc1_uart_t *u, const char *s)
{
    esc1_uart_write(u, (const uint8_t *)s, strlen(s));
}

void esc1_uart_puts_polled(esc1_uart_t *u, const char *s)
{
    for (; *s != '\0'; s++) {
        if (!g4_wait_bits(G4_USART2 + G4_USART_ISR, G4_USART_ISR_TXE, G4_USART_ISR_TXE,
                          4u * u->byte_cycles)) {
            u->tx_dropped++;
            return;
        }
        g4_wr(G4_USART2 + G4_USART_TDR, (uint8_t)*s);
    }
}

/* Not inlined: the main loop's inlined copy took 48 B more of the image. */
__attribute__((noinline)) int esc1_uart_lost_idle(esc1_uart_t *u)
{
    /* Why only these: an overrun (or the ring full) loses bytes only of a
     * sender that streams them (9 characters within one flash erase, 256
     * behind a busy main loop), and such a sender's line goes on within a
     * character time of the core running again; a line idle for
     * lost_idle_cycles after the loss ended inside it. A framing or noise
     * error hits one character of any sender, a typist's too, whose pauses
     * say nothing: its line ends at the next end of line received. */
    int lost = -1;
    const uint32_t pm = g4_irq_lock();
    const uint32_t pending = u->rx_lost;
    if ((pending & (G4_USART_ISR_ORE | ESC1_UART_LOST_FULL)) != 0u && u->rx_head == u->rx_tail &&
        (g4_rd(G4_USART2 + G4_USART_ISR) & G4_USART_ISR_RXNE) == 0u &&
        g4_cycles() - u->rx_lost_at >= u->lost_idle_cycles) {
        u->rx_lost = 0u; /* the next byte starts a line of its own */
        lost = (int)(pending << 8 | '\r');
    }
    g4_irq_unlock(pm);
    return lost;
}

const char *esc1_uart_lost_why(int c)
{
    const uint32_t lost = (uint32_t)c >> 8;
    return (lost & G4_USART_ISR_ORE) != 0u  ? "overrun (ORE)"
           : (lost & G4_USART_ISR_FE) != 0u ? "framing (FE)"
           : (lost & G4_USART_ISR_NE) != 0u ? "noise (NE)"
                                            : "ring full";
}

void esc1_uart_irq(esc1_uart_t *u)
{
    /* The RXFIFO (RM0440 USART, FIFO mode), oldest first, at most its depth:
     * an overrun sets ORE only while the RXFIFO is full (RM0440 USART_ISR.ORE)
     * and only this loop reads it, so the characters an overrun lost came
     * after every one drained here, and ORE is looked at after them. */
    for (uint32_t n = 0; n < G4_USART_FIFO_DEPTH; n++) {
        const uint32_t isr = g4_rd(G4_USART2 + G4_USART_ISR);
        if ((isr & G4_USART_ISR_RXNE) == 0u) {
            break;
        }
        /* FE and NE are the character's in RDR: cleared before it is read,
         * as ST's HAL does, so that the next character's stay. */
        const uint32_t bad = isr & (G4_USART_ISR_FE | G4_USART_ISR_NE);
        if (bad != 0u) {
            g4_wr(G4_USART2 + G4_USART_ICR, G4_USART_ICR_FECF | G4_USART_ICR_NECF);
        }
        const uint32_t c = g4_rd(G4_USART2 + G4_USART_RDR) & 0xFFu; /* pops the RXFIFO */
        if (bad != 0u) {
            u->rx_errors++;
            u->rx_lost |= bad; /* a damaged character is a lost one */
            /* and one received: a sender still streaming, so an overrun's
             * pending loss waits its idle bound from here */
            u->rx_lost_at = g4_cycles();
        } else if (u->rx_head - u->rx_tail < ESC1_UART_RX_SIZE) {
            atomic_signal_fence(memory_order_acquire);
            u->rx[u->rx_head & (ESC1_UART_RX_SIZE - 1u)] = (uint16_t)(c | u->rx_lost << 8);
            atomic_signal_fence(memory_order_release); /* the byte before its count */
            u->rx_head++;
            u->rx_lost = 0u;
        } else {
            u->rx_dropped++;
            u->rx_lost |= ESC1_UART_LOST_FULL;
            u->rx_lost_at = g4_cycles();
        }
    }
    const uint32_t isr = g4_rd(G4_USART2 + G4_USART_ISR);
    if ((isr & G4_USART_ISR_ORE) != 0u) {
        g4_wr(G4_USART2 + G4_USART_ICR, G4_USART_ICR_ORECF);
        u->rx_errors++;
        u->rx_lost |= G4_USART_ISR_ORE;
        u->rx_lost_at = g4_cycles(); /* the core runs again: the loss ends here */
    }
    if ((isr & G4_USART_ISR_TXE) != 0u &&
        (g4_rd(G4_USART2 + G4_USART_CR1) & G4_USART_CR1_TXEIE) != 0u) {
        if (u->tx_tail != u->tx_head) {
            atomic_signal_fence(memory_order_acquire); /* the byte after its count */
            g4_wr(G4_USART2 + G4_USART_TDR, u->tx[u->tx_tail & (ESC1_UART_TX_SIZE - 1u)]);
            atomic_signal_fence(memory_order_release);
            u->tx_tail++;
        } else {
            g4_clr(G4_USART2 + G4_USART_CR1, G4_USART_CR1_TXEIE);
        }
    }
}
