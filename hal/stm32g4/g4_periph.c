/* GPIO, USART2, IWDG (g4_periph.h). */
#include "g4_periph.h"

#include "g4_core.h"
#include "g4_regs.h"

uintptr_t g4_gpio_base(uint32_t port)
{
    switch (port) {
    case 0u:
        return G4_GPIOA;
    case 1u:
        return G4_GPIOB;
    default:
        return G4_GPIOC;
    }
}

void g4_gpio_config(g4_pin_t p, g4_pin_mode_t mode, uint32_t pull)
{
    const uintptr_t b = g4_gpio_base(p.port);
    g4_set(G4_RCC + G4_RCC_AHB2ENR, G4_BIT(p.port)); /* GPIOxEN = bit x */
    const uint32_t sh2 = 2u * p.pin;
    if (mode == G4_PIN_AF) {
        const uintptr_t afr = b + (p.pin < 8u ? G4_GPIO_AFRL : G4_GPIO_AFRH);
        const uint32_t sh4 = 4u * (p.pin % 8u);
        g4_mod(afr, 0xFu << sh4, (uint32_t)p.af << sh4);
    }
    if (mode == G4_PIN_OUTPUT || mode == G4_PIN_AF) {
        g4_clr(b + G4_GPIO_OTYPER, G4_BIT(p.pin));
        /* PC13..PC15 sit in the backup power domain: low speed only
         * (datasheet DS12589, pin notes: <= 2 MHz, 30 pF, no current source). */
        const uint32_t speed = (p.port == 2u && p.pin >= 13u) ? 0u : 3u;
        g4_mod(b + G4_GPIO_OSPEEDR, 3u << sh2, speed << sh2);
    }
    g4_mod(b + G4_GPIO_PUPDR, 3u << sh2, (pull & 3u) << sh2);
    g4_mod(b + G4_GPIO_MODER, 3u << sh2, (uint32_t)mode << sh2);
}

void g4_gpio_write(g4_pin_t p, bool high)
{
    g4_wr(g4_gpio_base(p.port) + G4_GPIO_BSRR, high ? G4_BIT(p.pin) : G4_BIT(p.pin + 16u));
}

void g4_usart2_init(uint32_t brr)
{
    g4_set(G4_RCC + G4_RCC_APB1ENR1, G4_RCC_APB1ENR1_USART2EN);
    g4_mod(G4_RCC + G4_RCC_CCIPR, G4_RCC_CCIPR_USART2SEL_MASK, 0u); /* PCLK1 */
    g4_wr(G4_USART2 + G4_USART_CR1, 0u);
    g4_wr(G4_USART2 + G4_USART_BRR, brr);
    /* FIFO mode, programmed while UE = 0 (RM0440 USART_CR1.FIFOEN): the
     * RXFIFO keeps 8 characters while the core stalls on a flash page
     * erase, where RDR alone keeps 1 (RXNEIE is then RXFNEIE: an interrupt
     * while the RXFIFO is not empty). */
    const uint32_t cr1 =
        G4_USART_CR1_FIFOEN | G4_USART_CR1_RE | G4_USART_CR1_TE | G4_USART_CR1_RXNEIE;
    g4_wr(G4_USART2 + G4_USART_CR1, cr1);
    g4_wr(G4_USART2 + G4_USART_CR1, cr1 | G4_USART_CR1_UE);
}

int g4_iwdg_start(uint32_t pr, uint32_t rlr, uint32_t f_cpu_hz)
{
    g4_wr(G4_IWDG + G4_IWDG_KR, G4_IWDG_KR_START);
    g4_wr(G4_IWDG + G4_IWDG_KR, G4_IWDG_KR_UNLOCK);
    g4_wr(G4_IWDG + G4_IWDG_PR, pr);
    g4_wr(G4_IWDG + G4_IWDG_RLR, rlr);
    /* The registers update in the LSI domain: up to a few LSI periods. */
    if (!g4_wait_bits(G4_IWDG + G4_IWDG_SR, 0x7u, 0u, 10u * (f_cpu_hz / 1000u))) {
        return G4_E_LSI;
    }
    g4_wr(G4_IWDG + G4_IWDG_KR, G4_IWDG_KR_REFRESH);
    /* Debugger halts freeze the watchdog (else a breakpoint resets). */
    g4_set(G4_DBGMCU + G4_DBGMCU_APB1FZR1, G4_DBGMCU_APB1FZR1_IWDG_STOP);
    return G4_OK;
}

void g4_iwdg_refresh(void)
{
    g4_wr(G4_IWDG + G4_IWDG_KR, G4_IWDG_KR_REFRESH);
}
