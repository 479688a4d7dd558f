/*
 * What the start-up code of every STM32 image here shares: the C run-time
 * set-up of the reset handler, and the fault path's name the library glue
 * calls (stm32_syscalls.c). Each chip's start-up (hal/stm32g4/g4_startup.c,
 * hal/stm32f4/f4_startup.c) has its own vector table and its own gates-off
 * fault handler: the advanced timer's address differs.
 */
#ifndef HAL_STM32_STM32_STARTUP_H
#define HAL_STM32_STM32_STARTUP_H

#include <stdint.h>

/* The C run-time set-up, the reset handler's first call: the FPU (CP10,
 * CP11) enabled before any floating-point instruction (ARMv7-M ARM B3.2.20,
 * CPACR), .data copied from flash, .bss zeroed (the linker script's
 * __data_start__/__data_end__/__data_load__, __bss_start__/__bss_end__),
 * MemManage, BusFault and UsageFault taken by their own handlers (SHCSR),
 * the static constructors run (__libc_init_array). */
void stm32_crt_init(void);

/* Gates off, then wait for the independent watchdog; never returns. The
 * chip's start-up defines it. */
void stm32_fault_halt(void) __attribute__((noreturn));

/* The stack pointer now (the main stack in thread mode): where main's
 * painting of the stack below its own frame ends (firmware/link/fw_stack.h). */
static inline uint32_t *stm32_sp(void)
{
#if defined(__arm__)
    uint32_t *sp;
    __asm__ volatile("mov %0, sp" : "=r"(sp));
    return sp;
#else
    return (uint32_t *)0; /* a host build (the register models) has no such stack */
#endif
}

#endif /* HAL_STM32_STM32_STARTUP_H */
