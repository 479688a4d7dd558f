/*
 * What the start-up code of every STM32 image here shares: the C run-time
 * set-up of the reset handler, and the fault path's name the library glue
 * calls (stm32_syscalls.c). Each chip's start-up (hal/stm32g4/g4_startup.c,
 * hal/stm32f4/f4_startup.c) has its own vector table and its own gates-off
 * fault handler: the advanced timer's address differs.
 */
#ifndef HAL_STM32_STM32_STARTUP_H
#define HAL_STM32_STM32_STARTUP_H

/* Gates off, then wait for the independent watchdog; never returns. The
 * chip's start-up defines it. */
void stm32_fault_halt(void) __attribute__((noreturn));

#endif /* HAL_STM32_STM32_STARTUP_H */
