/* The console on the board's USART (f405_app.h): the F4's USART registers
 * (RM0090 sec. 30.6) under the shared byte rings (board_uart.h). */
#include <stddef.h>

#include "f405_app.h"
#include "f4_core.h"
#include "f4_regs.h"
#include "stm32_calc.h"
#include F405_BOARD_HEADER

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

int f405_uart_init(f405_t *s, uint32_t baud)
{
    const f4_board_t *b = s->board;
    if (f4_usart_find(b->uart, &s->usart) != F4_OK) {
        return F4_E_CONFIG;
    }
    const uint32_t f_ck = s->usart.apb == 2u ? s->clk.pclk2_hz : s->clk.pclk1_hz;
    uint32_t brr;
    if (stm32_usart_brr(f_ck, baud, &brr) != STM32_OK) {
        return F4_E_CONFIG;
    }
    f405_uart_base = s->usart.base;
    board_uart_init(&s->app.uart, &f405_uart_port, 1000000u, s->clk.sysclk_hz, baud);
    f4_gpio_config(b->uart_tx, F4_PIN_AF, 0u);
    f4_gpio_config(b->uart_rx, F4_PIN_AF, 1u); /* pulled up: an open line reads idle */
    f4_usart_init(&s->usart, brr);
    return F4_OK;
}

void f405_uart_irq(f405_t *s)
{
    const uintptr_t u = s->usart.base;
    const uint32_t sr = f4_rd(u + F4_USART_SR);
    if ((sr & (F4_USART_SR_ORE | F4_USART_SR_FE | F4_USART_SR_NF)) != 0u) {
        s->app.uart.rx_errors++; /* cleared by this SR read and the DR read below */
    }
    if ((sr & (F4_USART_SR_RXNE | F4_USART_SR_ORE)) != 0u) {
        board_uart_rx(&s->app.uart, (uint8_t)f4_rd(u + F4_USART_DR));
    }
    if ((sr & F4_USART_SR_TXE) != 0u && (f4_rd(u + F4_USART_CR1) & F4_USART_CR1_TXEIE) != 0u) {
        uint8_t c;
        if (board_uart_tx_next(&s->app.uart, &c)) {
            f4_wr(u + F4_USART_DR, c);
        } else {
            f4_clr(u + F4_USART_CR1, F4_USART_CR1_TXEIE);
        }
    }
}
