/*
 * Start-up and fault handling of an STM32G431 image (g4_startup.c).
 */
#ifndef HAL_STM32G4_G4_STARTUP_H
#define HAL_STM32G4_G4_STARTUP_H

#include <stdint.h>

typedef void (*g4_vector_t)(void);

/* The vector table (flash, 0x0800_0000). */
extern const g4_vector_t g4_vectors[];

/* Called by every fault handler after the gates are off (TIM1 software break
 * and MOE cleared): the board may force its PWM pins inactive as well. Must
 * not rely on the stack being usable for much. Weak default: nothing. */
void g4_board_fault_hook(void);

/* Gates off (software break), then wait for the watchdog; never returns. */
void g4_fault_halt(void) __attribute__((noreturn));

#endif /* HAL_STM32G4_G4_STARTUP_H */
