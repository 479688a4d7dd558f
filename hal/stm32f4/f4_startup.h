/*
 * Start-up and fault handling of an STM32F405/407 image (f4_startup.c).
 */
#ifndef HAL_STM32F4_F4_STARTUP_H
#define HAL_STM32F4_F4_STARTUP_H

#include <stdint.h>

typedef void (*f4_vector_t)(void);

/* The vector table (flash sector 0, 0x0800_0000). */
extern const f4_vector_t f4_vectors[];

/* Called by every fault handler after the gates are off (TIM1 software break
 * and MOE cleared): the board forces EN_GATE low and its PWM pins inactive
 * as well. Must not rely on the stack being usable for much. Weak default:
 * nothing. */
void f4_board_fault_hook(void);

/* Gates off (software break), then wait for the watchdog; never returns. */
void f4_fault_halt(void) __attribute__((noreturn));

#endif /* HAL_STM32F4_F4_STARTUP_H */
