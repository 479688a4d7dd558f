/*
 * USART2 of the B-G431B-ESC1 (ST-LINK virtual COM port): interrupt-driven
 * byte rings between the USART interrupt and the main loop. The main loop
 * owns the transmit side (whole lines and frames, PROTOCOL.md), the interrupt
 * moves bytes. Each count has one writer; a byte is stored before its count
 * behind a release signal fence and read after the other side's count behind
 * an acquire fence (docs/architecture.md, "State shared between the
 * contexts").
 */
#ifndef FIRMWARE_APPS_ESC1_ESC1_UART_H
#define FIRMWARE_APPS_ESC1_ESC1_UART_H

#include <stddef.h>
#include <stdint.h>

#define ESC1_UART_RX_SIZE 256u /* powers of two */
#define ESC1_UART_TX_SIZE 1024u

/* What the receiver lost right before a received byte (bits of its ring
 * entry above the byte): USART_ISR's error flags at their own positions
 * (RM0440 USART_ISR: FE bit 1, NE bit 2, ORE bit 3), and bit 0 (PE's place:
 * no parity on this link) for the receive ring found full. */
#define ESC1_UART_LOST_FULL 0x1u
#define ESC1_UART_LOST_MASK 0xFu
/* A line whose end an overrun (or the ring full) may have lost: idle this
 * long after the loss with nothing received, it is taken as ended inside
 * the loss (esc1_uart_lost_idle). 20 ms: 230 character times at 115 200
 * baud, far beyond any gap inside a line a program sends in one write, and
 * well inside a console's wait for the answer. */
#define ESC1_UART_LOST_IDLE_MS 20u

typedef struct {
    /* byte | (ESC1_UART_LOST_* of the bytes lost right before it) << 8 */
    uint16_t rx[ESC1_UART_RX_SIZE];
    uint8_t tx[ESC1_UART_TX_SIZE];
    volatile uint32_t rx_head, rx_tail; /* head: interrupt, tail: main loop */
    volatile uint32_t tx_head, tx_tail; /* head: main loop, tail: interrupt */
    volatile uint32_t rx_dropped, rx_errors;
    /* Losses since the last byte stored (the interrupt's; the main loop
     * takes them under g4_irq_lock: esc1_uart_lost_idle) and when the last
     * was noted (core cycles). */
    volatile uint32_t rx_lost, rx_lost_at;
    uint32_t lost_idle_cycles; /* ESC1_UART_LOST_IDLE_MS in core cycles */
    uint32_t tx_dropped;
    uint32_t tx_wait_cycles; /* longest wait for transmit space before dropping */
    uint32_t byte_cycles;    /* one character on the line, core cycles */
    /* Called while the writer waits for space (NULL: none): the main loop's
     * watchdog service, so that a long reply does not starve the watchdog. */
    void (*idle)(void *ctx);
    void *idle_ctx;
} esc1_uart_t;

/* Pins, USART2 8N1 at `baud` from PCLK1 = f_pclk_hz. Returns G4_OK or
 * G4_E_CONFIG. */
int esc1_uart_init(esc1_uart_t *u, uint32_t f_pclk_hz, uint32_t baud);
/* Next received byte, or -1; bits 8..11 (ESC1_UART_LOST_* << 8) say that
 * bytes were lost right before it (esc1_uart_lost_why names it). */
int esc1_uart_getc(esc1_uart_t *u);
/* A line that ended inside a loss: an overrun or the ring full not yet
 * marked on a byte, the ring and the RXFIFO empty, ESC1_UART_LOST_IDLE_MS
 * since the loss. Returns an end of line carrying the losses as getc's
 * bits 8..11 (forgotten here, so the next byte starts a line of its own),
 * else -1. Main loop. */
int esc1_uart_lost_idle(esc1_uart_t *u);
/* What a getc's bits 8..11 say was lost, for "err 13 lost <why>". */
const char *esc1_uart_lost_why(int c);
/* Queues bytes; when the ring is full it waits for the interrupt to drain
 * it, up to tx_wait_cycles per byte, calling idle meanwhile, then drops the
 * rest (counted). */
void esc1_uart_write(esc1_uart_t *u, const uint8_t *bytes, size_t len);
void esc1_uart_puts(esc1_uart_t *u, const char *s);
/* Sends a string by polling TXE, bypassing the ring (start-up, before the
 * interrupt is enabled, and the halt loop). Gives up on a character after
 * four character times without TXE (counted in tx_dropped). */
void esc1_uart_puts_polled(esc1_uart_t *u, const char *s);
/* USART2 interrupt: the RXFIFO drained into the receive ring, each loss
 * (an overrun, a framing or noise error, the ring full) marked on the next
 * byte stored; a byte to send when the TXFIFO has room. */
void esc1_uart_irq(esc1_uart_t *u);

#endif /* FIRMWARE_APPS_ESC1_ESC1_UART_H */
