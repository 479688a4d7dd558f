/* GPIO, USART, EXTI, IWDG (f4_periph.h). */
#include "f4_periph.h"

#include "f4_core.h"
#include "f4_regs.h"

uintptr_t f4_gpio_base(uint32_t port)
{
    switch (port) {
    case 0u:
        return F4_GPIOA;
    case 1u:
        return F4_GPIOB;
    case 2u:
        return F4_GPIOC;
    default:
        return F4_GPIOD;
    }
}

void f4_gpio_config(f4_pin_t p, f4_pin_mode_t mode, uint32_t pull)
{
    if (!f4_pin_used(p)) {
        return;
    }
    const uintptr_t b = f4_gpio_base(p.port);
    f4_rcc_enable(F4_RCC_AHB1ENR, F4_BIT(p.port)); /* GPIOxEN = bit x */
    const uint32_t sh2 = 2u * p.pin;
    if (mode == F4_PIN_AF) {
        const uintptr_t afr = b + (p.pin < 8u ? F4_GPIO_AFRL : F4_GPIO_AFRH);
        const uint32_t sh4 = 4u * (p.pin % 8u);
        f4_mod(afr, 0xFu << sh4, (uint32_t)p.af << sh4);
    }
    if (mode == F4_PIN_OUTPUT || mode == F4_PIN_AF) {
        f4_clr(b + F4_GPIO_OTYPER, F4_BIT(p.pin));
        const uint32_t speed = (p.port == 2u && p.pin >= 13u) ? 0u : 3u;
        f4_mod(b + F4_GPIO_OSPEEDR, 3u << sh2, speed << sh2);
    }
    f4_mod(b + F4_GPIO_PUPDR, 3u << sh2, (pull & 3u) << sh2);
    f4_mod(b + F4_GPIO_MODER, 3u << sh2, (uint32_t)mode << sh2);
}

void f4_gpio_output(f4_pin_t p, bool high, uint32_t pull)
{
    if (!f4_pin_used(p)) {
        return;
    }
    /* The port's clock before the level: with it off the BSRR write is
     * lost, and the pin would drive ODR's reset value (0) once an output. */
    f4_rcc_enable(F4_RCC_AHB1ENR, F4_BIT(p.port));
    f4_gpio_write(p, high);
    f4_gpio_config(p, F4_PIN_OUTPUT, pull);
}

void f4_gpio_write(f4_pin_t p, bool high)
{
    if (f4_pin_used(p)) {
        f4_wr(f4_gpio_base(p.port) + F4_GPIO_BSRR, high ? F4_BIT(p.pin) : F4_BIT(p.pin + 16u));
    }
}

bool f4_gpio_read(f4_pin_t p)
{
    return f4_pin_used(p) && (f4_rd(f4_gpio_base(p.port) + F4_GPIO_IDR) & F4_BIT(p.pin)) != 0u;
}

int f4_usart_find(uint32_t n, f4_usart_t *u)
{
    switch (n) {
    case 1u:
        *u = (f4_usart_t){F4_USART1, F4_IRQ_USART1, 2u, F4_RCC_APB2ENR_USART1EN};
        return F4_OK;
    case 2u:
        *u = (f4_usart_t){F4_USART2, F4_IRQ_USART2, 1u, F4_RCC_APB1ENR_USART2EN};
        return F4_OK;
    case 3u:
        *u = (f4_usart_t){F4_USART3, F4_IRQ_USART3, 1u, F4_RCC_APB1ENR_USART3EN};
        return F4_OK;
    case 4u:
        *u = (f4_usart_t){F4_UART4, F4_IRQ_UART4, 1u, F4_RCC_APB1ENR_UART4EN};
        return F4_OK;
    case 6u:
        *u = (f4_usart_t){F4_USART6, F4_IRQ_USART6, 2u, F4_RCC_APB2ENR_USART6EN};
        return F4_OK;
    default:
        return F4_E_CONFIG;
    }
}

void f4_usart_init(const f4_usart_t *u, uint32_t brr)
{
    f4_rcc_enable(u->apb == 2u ? F4_RCC_APB2ENR : F4_RCC_APB1ENR, u->en);
    f4_wr(u->base + F4_USART_CR1, 0u);
    f4_wr(u->base + F4_USART_BRR, brr);
    f4_wr(u->base + F4_USART_CR1,
          F4_USART_CR1_UE | F4_USART_CR1_RE | F4_USART_CR1_TE | F4_USART_CR1_RXNEIE);
}

uint32_t f4_exti_irq(uint32_t line)
{
    if (line <= 4u) {
        return F4_IRQ_EXTI0 + line;
    }
    return line <= 9u ? F4_IRQ_EXTI9_5 : F4_IRQ_EXTI15_10;
}

uint32_t f4_exti_falling(f4_pin_t p)
{
    const uint32_t line = p.pin;
    f4_rcc_enable(F4_RCC_APB2ENR, F4_RCC_APB2ENR_SYSCFGEN);
    f4_mod(F4_SYSCFG + F4_SYSCFG_EXTICR(line), 0xFu << F4_SYSCFG_EXTICR_SHIFT(line),
           (uint32_t)p.port << F4_SYSCFG_EXTICR_SHIFT(line));
    f4_clr(F4_EXTI + F4_EXTI_RTSR, F4_BIT(line));
    f4_set(F4_EXTI + F4_EXTI_FTSR, F4_BIT(line));
    f4_wr(F4_EXTI + F4_EXTI_PR, F4_BIT(line));
    f4_set(F4_EXTI + F4_EXTI_IMR, F4_BIT(line));
    return f4_exti_irq(line);
}

bool f4_exti_pending(uint32_t line)
{
    return (f4_rd(F4_EXTI + F4_EXTI_PR) & F4_BIT(line)) != 0u;
}

void f4_exti_clear(uint32_t line)
{
    f4_wr(F4_EXTI + F4_EXTI_PR, F4_BIT(line));
}

void f4_iwdg_window(uint32_t pr, uint32_t rlr, uint32_t *min_ms, uint32_t *max_ms)
{
    *min_ms = stm32_iwdg_timeout_ms(pr, rlr, F4_LSI_MAX_HZ);
    *max_ms = stm32_iwdg_timeout_ms(pr, rlr, F4_LSI_MIN_HZ);
}

uint32_t f4_iwdg_update_ms(uint32_t pr)
{
    const uint32_t div = 4u << (pr < 6u ? pr : 6u);
    return (F4_IWDG_UPDATE_PERIODS * div * 1000u + F4_LSI_MIN_HZ - 1u) / F4_LSI_MIN_HZ + 1u;
}

int f4_iwdg_start(uint32_t pr, uint32_t rlr, uint32_t f_cpu_hz)
{
    /* LSION as well: the start key forces the LSI on (sec. 21.3.2), LSION
     * makes LSIRDY below the oscillator's own flag whoever started it
     * (RCC_CSR's reset flags are read-only: the read-modify-write keeps
     * them, RMVF reads 0). */
    f4_set(F4_RCC + F4_RCC_CSR, F4_RCC_CSR_LSION);
    f4_wr(F4_IWDG + F4_IWDG_KR, F4_IWDG_KR_START);
    f4_wr(F4_IWDG + F4_IWDG_KR, F4_IWDG_KR_UNLOCK);
    f4_wr(F4_IWDG + F4_IWDG_PR, pr);
    f4_wr(F4_IWDG + F4_IWDG_RLR, rlr);
    /* PVU and RVU clear once the values have crossed into the LSI domain
     * (f4_iwdg_update_ms: the prescaled LSI's periods). */
    if (!f4_wait_bits(F4_IWDG + F4_IWDG_SR, 0x3u, 0u, f4_iwdg_update_ms(pr) * (f_cpu_hz / 1000u))) {
        return F4_E_LSI;
    }
    /* The start key forces the LSI on (sec. 21.3.2); it is ready within
     * t_SU(LSI) = 40 us at most (DS8626, LSI oscillator characteristics):
     * without LSIRDY the watchdog does not count. 1 ms. */
    if (!f4_wait_bits(F4_RCC + F4_RCC_CSR, F4_RCC_CSR_LSIRDY, F4_RCC_CSR_LSIRDY,
                      f_cpu_hz / 1000u)) {
        return F4_E_LSI;
    }
    f4_wr(F4_IWDG + F4_IWDG_KR, F4_IWDG_KR_REFRESH);
    /* Debugger halts freeze the watchdog (else a breakpoint resets). */
    f4_set(F4_DBGMCU + F4_DBGMCU_APB1_FZ, F4_DBGMCU_APB1_FZ_IWDG_STOP);
    return F4_OK;
}

void f4_iwdg_refresh(void)
{
    f4_wr(F4_IWDG + F4_IWDG_KR, F4_IWDG_KR_REFRESH);
}
