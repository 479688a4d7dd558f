/*
 * Board support for the QEMU `mps2-an386` machine (Cortex-M4F, 25 MHz):
 * start-up, CMSDK UART0 output, ARM semihosting (console and exit status),
 * CMSDK Timer0 periodic interrupt and Timer1 as a free-running counter.
 * Register map: ARM's "Application Note AN386" (MPS2+ Cortex-M4 FPGA image)
 * and the CMSDK peripherals' Technical Reference Manual; QEMU's model of the
 * board (hw/arm/mps2.c) is what runs; docs/architecture.md, "QEMU".
 *
 * The start-up code (startup.c) enables the FPU, copies .data, zeroes .bss,
 * calls board_init(), runs the C/C++ constructors and calls exit(main()): main's return value is
 * the exit status of QEMU (through SYS_EXIT_EXTENDED). printf() works (newlib
 * syscalls in syscalls.c write to UART0).
 *
 * Run an image with tools/qemu-run app.elf (deterministic -icount timing).
 */
#ifndef HAL_QEMU_MPS2_H
#define HAL_QEMU_MPS2_H

#include <stdbool.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define QEMU_MPS2_SYSCLK_HZ 25000000u /* system clock and timer clock */
#define QEMU_MPS2_TIMER0_HZ_DEFAULT 20000u

/* UART0 on, Timer1 counting from 0. Already called by the reset handler before
 * main(); calling it again restarts Timer1. */
void board_init(void);

/* UART0 (blocking; the QEMU model never stays full). '\n' is sent as is. */
void uart_putc(char c);
void uart_puts(const char *s);
void uart_put_u32(uint32_t v); /* decimal */

/* Semihosting: a string to QEMU's console (stderr, or the muxed chardev). */
void semihost_write0(const char *s);
/* Ends the emulation; QEMU exits with code & 0xFF. */
void semihost_exit(int code) __attribute__((noreturn));

/*
 * Timer0 periodic interrupt at `hz` (RELOAD = 25 MHz / hz - 1, so the actual
 * rate is 25 MHz / (RELOAD + 1); exact for divisors of 25 MHz such as 20 kHz).
 * `callback` runs in the interrupt. Returns 0, or -1 when hz is 0, above
 * 1 MHz, or callback is NULL (nothing is started then).
 */
typedef void (*timer0_callback_t)(void);
int timer0_start(uint32_t hz, timer0_callback_t callback);
void timer0_stop(void);
/* Called with interrupts masked: when a tick came while they were (its
 * interrupt pending), its period restarts now, so that the late interrupt has
 * a whole period, as every other, before the next tick. */
void timer0_realign(void);
/* Timer0 period in 25 MHz ticks (RELOAD + 1) while running, else 0. */
uint32_t timer0_period_ticks(void);

/* Timer1: free-running up-counter at 25 MHz, wraps modulo 2^32 (~171.8 s).
 * Differences of two readings (unsigned subtraction) are elapsed ticks. */
uint32_t timer1_read(void);
/* Timer1 ticks of 1000 emulated instructions (measured: a run of 1000 nops
 * less an empty call), at least 1; 200 at -icount shift=3. */
uint32_t timer1_ticks_per_kinstr(void);

/* PendSV, the lowest-priority exception (ARMv7-M ARM B3.2.4 ICSR.PENDSVSET,
 * B3.2.12 SHPR3): board_pendsv_set gives it the lowest priority and the
 * callback it runs; board_pendsv_pend pends it (it runs once no handler of
 * higher priority is active: after the Timer0 interrupt that pended it). */
typedef void (*pendsv_callback_t)(void);
void board_pendsv_set(pendsv_callback_t callback);
void board_pendsv_pend(void);

/* Interrupt masking (PRIMASK). */
void board_irq_disable(void);
void board_irq_enable(void);
/* Timer0's interrupt alone (NVIC ICER/ISER): masked, returning whether it
 * was enabled; enabled again. */
bool board_timer0_irq_mask(void);
void board_timer0_irq_unmask(void);

/* One pass of the idle loop: a busy-wait instruction, never `wfi` (under QEMU's
 * -icount sleep=off, wfi loses timer interrupts: QEMU.md). */
void board_idle(void);

#ifdef __cplusplus
}
#endif

#endif /* HAL_QEMU_MPS2_H */
