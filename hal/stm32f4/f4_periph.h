/*
 * GPIO, USART, EXTI and independent watchdog of the STM32F405/407 (RM0090
 * GPIO sec. 8, USART sec. 30, EXTI sec. 12, IWDG sec. 21).
 */
#ifndef HAL_STM32F4_F4_PERIPH_H
#define HAL_STM32F4_F4_PERIPH_H

#include <stdbool.h>
#include <stdint.h>

#include "stm32_calc.h"

/* A pin: port 0 = A .. 3 = D; pin 0..15; alternate function 0..15.
 * F4_PORT_NONE: no pin (a signal the board does not wire). */
typedef struct {
    uint8_t port, pin, af;
} f4_pin_t;
#define F4_PORT_NONE 0xFFu

typedef enum {
    F4_PIN_INPUT = 0,
    F4_PIN_OUTPUT = 1,
    F4_PIN_AF = 2,
    F4_PIN_ANALOG = 3
} f4_pin_mode_t;

static inline bool f4_pin_used(f4_pin_t p)
{
    return p.port != F4_PORT_NONE;
}
uintptr_t f4_gpio_base(uint32_t port);
/* Clock of the port on (RCC_AHB1ENR.GPIOxEN); pin mode; for AF its function;
 * push-pull; very high speed for outputs and AF (2 MHz for PC13..PC15, which
 * the backup domain's switch supplies: DS8626 pin notes); pull-up (pull = 1),
 * pull-down (2) or none (0). A pin not used: nothing. */
void f4_gpio_config(f4_pin_t p, f4_pin_mode_t mode, uint32_t pull);
/* A push-pull output that drives `high` from its first instant: the port's
 * clock on, the level written (BSRR), then the mode (a pin already an
 * output changes level once at most). */
void f4_gpio_output(f4_pin_t p, bool high, uint32_t pull);
/* Output level (BSRR: atomic; the port's clock must be on). */
void f4_gpio_write(f4_pin_t p, bool high);
/* Input level (IDR). */
bool f4_gpio_read(f4_pin_t p);

/* The USART instances: USART1/6 on APB2, USART2/3, UART4 on APB1. */
typedef struct {
    uintptr_t base;
    uint32_t irq;
    uint32_t apb; /* 1 or 2: the bus whose clock drives it */
    uint32_t en;  /* its enable bit in RCC_APB1ENR / RCC_APB2ENR */
} f4_usart_t;
/* n = 1, 2, 3, 4 (UART4) or 6. F4_OK or F4_E_CONFIG. */
int f4_usart_find(uint32_t n, f4_usart_t *u);
/* 8N1, oversampling 16, BRR from the bus clock (stm32_usart_brr), RX
 * interrupt on (the TX interrupt is switched by the driver). */
void f4_usart_init(const f4_usart_t *u, uint32_t brr);

/* EXTI line `pin` from port `port` on the falling edge (SYSCFG_EXTICRx,
 * EXTI_FTSR, EXTI_IMR). Returns the NVIC interrupt of the line. */
uint32_t f4_exti_falling(f4_pin_t p);
/* The line's pending bit; clearing it (rc_w1). */
bool f4_exti_pending(uint32_t line);
void f4_exti_clear(uint32_t line);
/* The interrupt of EXTI line 0..15 (EXTI0..4: 6..10, 9_5: 23, 15_10: 40). */
uint32_t f4_exti_irq(uint32_t line);

/* IWDG: the LSI's frequency spread (DS8626 "LSI oscillator characteristics":
 * 17 kHz min, 32 kHz typical, 47 kHz max) makes its time-out uncertain by a
 * factor of about 2.8: f4_iwdg_window gives the shortest and longest
 * time-outs of PR, RLR. */
#define F4_LSI_MIN_HZ 17000u
#define F4_LSI_TYP_HZ 32000u
#define F4_LSI_MAX_HZ 47000u
void f4_iwdg_window(uint32_t pr, uint32_t rlr, uint32_t *min_ms, uint32_t *max_ms);
/* How long IWDG_SR's PVU / RVU may stay set after PR / RLR are written, ms:
 * 5 periods of the prescaled LSI (ST's STM32F4 HAL, stm32f4xx_hal_iwdg.c:
 * "5 RC LSI divided by prescaler clock"; it waits 6), 6 here, at the slowest
 * LSI, + 1 ms for the LSI's start-up: 3 ms at /4 .. 92 ms at /256. */
#define F4_IWDG_UPDATE_PERIODS 6u
uint32_t f4_iwdg_update_ms(uint32_t pr);
/* Start (0xCCCC: it also turns the LSI on), unlock (0x5555), PR, RLR, wait
 * until SR = 0 (the values reached the LSI domain: f4_iwdg_update_ms), refresh. It cannot be
 * stopped afterwards. Also changes PR and RLR of a running watchdog (the
 * start key then has no further effect). f_cpu_hz for the wait. */
int f4_iwdg_start(uint32_t pr, uint32_t rlr, uint32_t f_cpu_hz);
void f4_iwdg_refresh(void);

#endif /* HAL_STM32F4_F4_PERIPH_H */
