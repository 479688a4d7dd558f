/*
 * The console on an STM32F405 board's USART (f405_uart.c): the F4's USART
 * registers under the shared byte rings (firmware/apps/board/board_uart.h).
 * Used by the drive image (f405_app.h) and the PIL image (apps/f405_pil),
 * which has no hal.h back-end of its own: hence a header apart.
 */
#ifndef FIRMWARE_APPS_F405_F405_UART_H
#define FIRMWARE_APPS_F405_F405_UART_H

#include <stdint.h>

#include "board_uart.h"
#include "f4_board.h"
#include "f4_clock.h"
#include "f4_periph.h"

/* Pins, BRR from the USART's bus clock at clk, the byte rings (their
 * clock: the board's tick timer, f4_ticks); F4_OK or F4_E_CONFIG. */
int f405_uart_init(board_uart_t *ring, f4_usart_t *usart, const f4_board_t *b,
                   const f4_clocks_t *clk, uint32_t baud);
/* The next received byte as board_uart_getc gives it (bits 8..11: bytes
 * lost before it), or a line that ended inside a loss taken as ended
 * (board_uart_lost_idle), or -1. Main loop. */
int f405_uart_next(board_uart_t *ring);
/* The USART interrupt's body: the received character into the ring, each
 * loss (an overrun, a framing error, noise, the ring full) marked on the
 * next byte stored; a byte to send when TXE and the ring has one. */
void f405_uart_irq(board_uart_t *ring, const f4_usart_t *usart);

#endif /* FIRMWARE_APPS_F405_F405_UART_H */
