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

typedef struct {
    /* the transmit interrupt on (it sends while bytes are queued), off */
    void (*tx_irq_on)(void);
    void (*tx_irq_off)(void);
    /* one byte by polling, giving up after timeout_cycles: false then */
    bool (*put_polled)(uint8_t c, uint32_t timeout_cycles);
    uint32_t (*ticks)(void); /* a free-running clock of the rate given to board_uart_init */
} board_uart_port_t;

typedef struct {
    uint8_t rx[BOARD_UART_RX_SIZE];
    uint8_t tx[BOARD_UART_TX_SIZE];
    volatile uint32_t rx_head, rx_tail; /* head: interrupt, tail: main loop */
    volatile uint32_t tx_head, tx_tail; /* head: main loop, tail: interrupt */
    volatile uint32_t rx_dropped, rx_errors;
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
/* Next received byte, or -1. */
int board_uart_getc(board_uart_t *u);
/* Queues bytes; when the ring is full it waits for the interrupt to drain
 * it, up to tx_wait_ticks per byte, calling idle meanwhile, then drops the
 * rest (counted). */
void board_uart_write(board_uart_t *u, const uint8_t *bytes, size_t len);
void board_uart_puts(board_uart_t *u, const char *s);
/* A string by polling, bypassing the ring (start-up, before the interrupt
 * is enabled, and the halt paths); gives up on a character after four
 * character times (counted in tx_dropped). */
void board_uart_puts_polled(board_uart_t *u, const char *s);

/* From the chip's USART interrupt: a received byte (dropped and counted when
 * the ring is full); the next byte to send, false when the ring is empty
 * (the handler then switches the transmit interrupt off). */
void board_uart_rx(board_uart_t *u, uint8_t c);
bool board_uart_tx_next(board_uart_t *u, uint8_t *c);

#endif /* FIRMWARE_APPS_BOARD_BOARD_UART_H */
