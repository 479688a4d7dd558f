/*
 * The serial console of a board image: interrupt-driven byte rings between
 * the USART's interrupt and the main loop, independent of the chip. The
 * main loop owns the transmit side (whole lines and frames, PROTOCOL.md),
 * the interrupt moves bytes; the chip's part (its USART registers) is a
 * handful of calls the application gives (board_uart_port_t) and the
 * interrupt handler it writes around board_uart_rx / board_uart_tx_next.
 */
#ifndef FIRMWARE_APPS_BOARD_BOARD_UART_H
#define FIRMWARE_APPS_BOARD_BOARD_UART_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define BOARD_UART_RX_SIZE 256u /* powers of two */
#define BOARD_UART_TX_SIZE 1024u

/* What the receiver lost right before a received byte (bits of its ring
 * entry above the byte): at the F4 USART_SR's error flags' positions
 * (RM0090 sec. 30.6.1: FE bit 1, NF bit 2, ORE bit 3; ST's stm32f405xx.h
 * USART_SR_FE/NE/ORE), and bit 0 (PE's place: no parity on this link) for
 * the receive ring found full. */
#define BOARD_UART_LOST_FULL 0x1u
#define BOARD_UART_LOST_FRAMING 0x2u
#define BOARD_UART_LOST_NOISE 0x4u
#define BOARD_UART_LOST_OVERRUN 0x8u
/* A line whose end an overrun (or the ring full) may have lost: idle this
 * long after the loss with nothing received, it is taken as ended inside
 * the loss (board_uart_lost_idle). 20 ms: 230 character times at 115 200
 * baud, far beyond any gap inside a line a program sends in one write, and
 * well inside a console's wait for the answer (the B-G431B-ESC1's bound). */
#define BOARD_UART_LOST_IDLE_MS 20u

typedef struct {
    /* the transmit interrupt on (it sends while bytes are queued), off */
    void (*tx_irq_on)(void);
    void (*tx_irq_off)(void);
    /* one byte by polling, giving up after timeout_cycles: false then */
    bool (*put_polled)(uint8_t c, uint32_t timeout_cycles);
    uint32_t (*ticks)(void); /* a free-running clock of the rate given to board_uart_init */
} board_uart_port_t;

typedef struct {
    /* byte | (BOARD_UART_LOST_* of the bytes lost right before it) << 8 */
    uint16_t rx[BOARD_UART_RX_SIZE];
    uint8_t tx[BOARD_UART_TX_SIZE];
    volatile uint32_t rx_head, rx_tail; /* head: interrupt, tail: main loop */
    volatile uint32_t tx_head, tx_tail; /* head: main loop, tail: interrupt */
    volatile uint32_t rx_dropped, rx_errors;
    /* Losses since the last byte stored (the interrupt's; the main loop
     * takes them with the USART's interrupt masked: board_uart_lost_idle)
     * and when the last loss was noted (port ticks). */
    volatile uint32_t rx_lost, rx_lost_at;
    uint32_t lost_idle_ticks; /* BOARD_UART_LOST_IDLE_MS in port ticks */
    uint32_t tx_dropped;
    uint32_t tx_wait_ticks; /* longest wait for transmit space before dropping */
    uint32_t byte_ticks;    /* one character on the line */
    uint32_t poll_cycles;   /* one character on the line, core cycles (polled output) */
    const board_uart_port_t *port;
    /* Every byte sent by polling (board_uart_check_tx found the transmit
     * interrupt silent); the interrupt then never sends. */
    bool polled;
    /* Called while the writer waits for space (NULL: none): the main loop's
     * watchdog service, so that a long reply does not starve the watchdog. */
    void (*idle)(void *ctx);
    void *idle_ctx;
} board_uart_t;

/* Rings empty, the waits sized for `baud` with the port's ticks at
 * ticks_hz and the core at f_cpu_hz. */
void board_uart_init(board_uart_t *u, const board_uart_port_t *port, uint32_t ticks_hz,
                     uint32_t f_cpu_hz, uint32_t baud);
/* After the USART's interrupt is enabled: queues the n >= 1 bytes of
 * `probe` and waits up to eight character times for the transmit interrupt
 * to take the first.
 * When it does not (QEMU 7.2's STM32F405 USART models no transmit
 * interrupt), every later byte is sent by polling (u->polled) and the
 * probe's bytes too. Returns true when the interrupt works. */
bool board_uart_check_tx(board_uart_t *u, const uint8_t *probe, size_t n);
/* Next received byte, or -1; bits 8..11 (BOARD_UART_LOST_* << 8) say that
 * bytes were lost right before it (board_uart_lost_why names it). */
int board_uart_getc(board_uart_t *u);
/* A line that ended inside a loss: an overrun or the ring full not yet
 * marked on a byte, the ring empty and rx_waiting false (no character in
 * the USART), BOARD_UART_LOST_IDLE_MS since the loss. Returns an end of
 * line carrying the losses as getc's bits 8..11 (forgotten here, so the
 * next byte starts a line of its own), else -1. Main loop, with the USART's
 * interrupt masked. */
int board_uart_lost_idle(board_uart_t *u, bool rx_waiting);
/* What a getc's bits 8..11 say was lost, for "err 13 lost <why>". */
const char *board_uart_lost_why(int c);
/* Queues bytes; when the ring is full it waits for the interrupt to drain
 * it, up to tx_wait_ticks per byte, calling idle meanwhile, then drops the
 * rest (counted). */
void board_uart_write(board_uart_t *u, const uint8_t *bytes, size_t len);
void board_uart_puts(board_uart_t *u, const char *s);
/* A string by polling, bypassing the ring (start-up, before the interrupt
 * is enabled, and the halt paths); gives up on a character after four
 * character times (counted in tx_dropped). */
void board_uart_puts_polled(board_uart_t *u, const char *s);

/* From the chip's USART interrupt: a received byte, marked with the losses
 * since the last one stored (dropped, counted and itself a loss when the
 * ring is full); bytes the USART lost (BOARD_UART_LOST_*: counted in
 * rx_errors, marked on the next byte stored); the next byte to send, false
 * when the ring is empty (the handler then switches the transmit interrupt
 * off). */
void board_uart_rx(board_uart_t *u, uint8_t c);
void board_uart_rx_lost(board_uart_t *u, uint32_t lost);
bool board_uart_tx_next(board_uart_t *u, uint8_t *c);

#endif /* FIRMWARE_APPS_BOARD_BOARD_UART_H */
