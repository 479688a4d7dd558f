/*
 * Start-up and fault handling of an STM32F405/407 image (f4_startup.c).
 */
#ifndef HAL_STM32F4_F4_STARTUP_H
#define HAL_STM32F4_F4_STARTUP_H

#include <stdbool.h>
#include <stdint.h>

#include "stm32_fault.h"

typedef void (*f4_vector_t)(void);

/* The vector table (flash sector 0, 0x0800_0000). */
extern const f4_vector_t f4_vectors[];

/* Called by every fault handler after the gates are off (TIM1 software break
 * and MOE cleared): the board forces EN_GATE low and its PWM pins inactive
 * as well. Must not rely on the stack being usable for much. Weak default:
 * nothing. */
void f4_board_fault_hook(void);

/* Gates off (software break), the stop recorded, then wait for the
 * watchdog (a system reset if it does not come); never returns. */
void f4_fault_halt(void) __attribute__((noreturn));

/* The fault the previous run ended with, if it left one (true, *out
 * filled); the record is cleared either way. Call once at start-up. */
bool f4_fault_take(stm32_fault_rec_t *out);

#endif /* HAL_STM32F4_F4_STARTUP_H */
