/*
 * GPIO, USART and independent watchdog of the STM32G4 (RM0440 GPIO, USART
 * and IWDG chapters).
 */
#ifndef HAL_STM32G4_G4_PERIPH_H
#define HAL_STM32G4_G4_PERIPH_H

#include <stdbool.h>
#include <stdint.h>

#include "stm32_calc.h"

/* A pin: port 0 = A, 1 = B, 2 = C; pin 0..15; alternate function 0..15. */
typedef struct {
    uint8_t port, pin, af;
} g4_pin_t;

typedef enum {
    G4_PIN_INPUT = 0,
    G4_PIN_OUTPUT = 1,
    G4_PIN_AF = 2,
    G4_PIN_ANALOG = 3
} g4_pin_mode_t;

uintptr_t g4_gpio_base(uint32_t port);
/* Clock of the port on; pin mode; for AF its function; push-pull; very-high
 * speed for outputs and AF; pull-up (pull = 1), pull-down (2) or none (0). */
void g4_gpio_config(g4_pin_t p, g4_pin_mode_t mode, uint32_t pull);
/* Output level (BSRR: atomic). */
void g4_gpio_write(g4_pin_t p, bool high);

/* USART baud-rate register, oversampling by 16 (hal/stm32/stm32_calc.h). */
static inline int g4_usart_brr(uint32_t f_ck_hz, uint32_t baud, uint32_t *brr)
{
    return stm32_usart_brr(f_ck_hz, baud, brr);
}
/* USART2 8N1, RX interrupt on (TX interrupt switched by the driver). */
void g4_usart2_init(uint32_t brr);

/* IWDG (RM0440 IWDG chapter): LSI f_LSI (32 kHz nominal; the datasheet
 * gives 29.5 .. 34 kHz), divider 4 x 2^PR (PR 0..6), down-counter from RLR
 * (12 bits): time-out = (RLR + 1) x divider / f_LSI (stm32_calc.h). */
static inline int g4_iwdg_config(uint32_t timeout_ms, uint32_t f_lsi_hz, uint32_t *pr,
                                 uint32_t *rlr)
{
    return stm32_iwdg_config(timeout_ms, f_lsi_hz, pr, rlr);
}
/* Start (0xCCCC), unlock (0x5555), PR, RLR, wait for SR = 0, refresh. The
 * IWDG cannot be stopped afterwards. */
int g4_iwdg_start(uint32_t pr, uint32_t rlr, uint32_t f_cpu_hz);
void g4_iwdg_refresh(void);

#endif /* HAL_STM32G4_G4_PERIPH_H */
