/* The console on the board's USART (f405_uart.h): the F4's USART registers
 * (RM0090 sec. 30.6) under the shared byte rings (board_uart.h). */
#include <stdbool.h>
#include <stddef.h>

#include "f405_uart.h"
#include "f4_core.h"
#include "f4_regs.h"
#include "f4_tim.h"
#include "stm32_calc.h"
#include F405_BOARD_HEADER

/* The losses board_uart marks are USART_SR's error flags where they stand. */
_Static_assert(F4_USART_SR_FE == BOARD_UART_LOST_FRAMING &&
                   F4_USART_SR_NF == BOARD_UART_LOST_NOISE &&
                   F4_USART_SR_ORE == BOARD_UART_LOST_OVERRUN,
               "BOARD_UART_LOST_* are RM0090 USART_SR's FE, NF, ORE");

/* The one console of the image (the port's callbacks take no argument). */
static uintptr_t f405_uart_base;

static void f405_uart_tx_irq_on(void)
{
    f4_set(f405_uart_base + F4_USART_CR1, F4_USART_CR1_TXEIE);
}

static void f405_uart_tx_irq_off(void)
{
    f4_clr(f405_uart_base + F4_USART_CR1, F4_USART_CR1_TXEIE);
}

static bool f405_uart_put_polled(uint8_t c, uint32_t timeout_cycles)
{
    if (!f4_wait_bits(f405_uart_base + F4_USART_SR, F4_USART_SR_TXE, F4_USART_SR_TXE,
                      timeout_cycles)) {
        return false;
    }
    f4_wr(f405_uart_base + F4_USART_DR, c);
    return true;
}

static uint32_t f405_uart_ticks(void)
{
    return f4_ticks(F405_BOARD.tick_tim);
}

static const board_uart_port_t f405_uart_port = {
    f405_uart_tx_irq_on,
    f405_uart_tx_irq_off,
    f405_uart_put_polled,
    f405_uart_ticks,
};

int f405_uart_init(board_uart_t *ring, f4_usart_t *usart, const f4_board_t *b,
                   const f4_clocks_t *clk, uint32_t baud)
{
    if (f4_usart_find(b->uart, usart) != F4_OK) {
        return F4_E_CONFIG;
    }
    const uint32_t f_ck = usart->apb == 2u ? clk->pclk2_hz : clk->pclk1_hz;
    uint32_t brr;
    if (stm32_usart_brr(f_ck, baud, &brr) != STM32_OK) {
        return F4_E_CONFIG;
    }
    f405_uart_base = usart->base;
    board_uart_init(ring, &f405_uart_port, 1000000u, clk->sysclk_hz, baud);
    f4_gpio_config(b->uart_tx, F4_PIN_AF, 0u);
    f4_gpio_config(b->uart_rx, F4_PIN_AF, 1u); /* pulled up: an open line reads idle */
    f4_usart_init(usart, brr);
    return F4_OK;
}

int f405_uart_next(board_uart_t *ring)
{
    const int c = board_uart_getc(ring);
    if (c >= 0) {
        return c;
    }
    /* all read: a line that ended inside a loss ends now (under the lock:
     * the interrupt neither notes a loss nor stores a byte meanwhile) */
    const uint32_t pm = f4_irq_lock();
    const bool waiting = (f4_rd(f405_uart_base + F4_USART_SR) & F4_USART_SR_RXNE) != 0u;
    const int lost = board_uart_lost_idle(ring, waiting);
    f4_irq_unlock(pm);
    return lost;
}

void f405_uart_irq(board_uart_t *ring, const f4_usart_t *usart)
{
    const uintptr_t u = usart->base;
    /* RM0090 sec. 30.6.1 USART_SR: ORE, FE and NF are cleared by a read of
     * SR followed by a read of DR, the sequence below. FE and NF belong to
     * the character in DR: a damaged character is a lost one. An overrun
     * keeps DR's character (received before the lost ones) and overwrites
     * the shift register: the loss comes after DR's character, so it is
     * noted after that character is stored. ORE can be set with RXNE clear
     * (the character read while the next arrived, or one arriving inside
     * the sequence): DR is then read only to clear it. */
    const uint32_t sr = f4_rd(u + F4_USART_SR);
    if ((sr & (F4_USART_SR_RXNE | F4_USART_SR_ORE)) != 0u) {
        const uint8_t c = (uint8_t)f4_rd(u + F4_USART_DR);
        const uint32_t bad = sr & (F4_USART_SR_FE | F4_USART_SR_NF);
        if (bad != 0u) {
            board_uart_rx_lost(ring, bad); /* BOARD_UART_LOST_* at SR's positions */
        } else if ((sr & F4_USART_SR_RXNE) != 0u) {
            board_uart_rx(ring, c);
        }
        if ((sr & F4_USART_SR_ORE) != 0u) {
            board_uart_rx_lost(ring, BOARD_UART_LOST_OVERRUN);
        }
    }
    if ((sr & F4_USART_SR_TXE) != 0u && (f4_rd(u + F4_USART_CR1) & F4_USART_CR1_TXEIE) != 0u) {
        uint8_t c;
        if (board_uart_tx_next(ring, &c)) {
            f4_wr(u + F4_USART_DR, c);
        } else {
            f4_clr(u + F4_USART_CR1, F4_USART_CR1_TXEIE);
        }
    }
}
