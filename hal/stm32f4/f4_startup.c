/*
 * Start-up of an STM32F405/407 image: the vector table at the start of flash
 * (0x0800_0000, RM0090 sec. 2.4 "Boot configuration": main flash boot with
 * BOOT0 low), the reset handler and the fault handlers.
 *
 * Every fault and unexpected interrupt first turns the gates off: a store of
 * TIM1_EGR.BG (software break: the hardware clears MOE and drives the outputs
 * to their idle, inactive level), written as the handler's first
 * instructions without touching the stack (a fault may come from a broken
 * stack); then MOE is cleared, the board's hook drives EN_GATE low (the
 * DRV8301 then holds every gate low), the fault is recorded for the next
 * start-up's report (hal/stm32/stm32_fault.h: exception, stacked PC, LR and
 * xPSR, CFSR, HFSR, fault addresses) and the core waits for the independent
 * watchdog, then resets the chip itself if the watchdog did not.
 *
 * The application provides the handlers it uses with their CMSIS names
 * (ADC_IRQHandler, EXTI9_5_IRQHandler, USART3_IRQHandler, ...); every other
 * vector is the gates-off fault handler. The NMI (the clock security
 * system's HSE failure) takes the fault path too.
 */
#include <stdint.h>

#include "f4_core.h"
#include "f4_periph.h"
#include "f4_regs.h"
#include "f4_startup.h"
#include "stm32_calc.h"
#include "stm32_fault.h"
#include "stm32_startup.h"

extern uint32_t __stack_top__;

int main(void);
void Reset_Handler(void);
void f4_fault_handler(void);

#define F4_WEAK_FAULT __attribute__((weak, alias("f4_fault_handler")))
void NMI_Handler(void) F4_WEAK_FAULT;
void HardFault_Handler(void) F4_WEAK_FAULT;
void MemManage_Handler(void) F4_WEAK_FAULT;
void BusFault_Handler(void) F4_WEAK_FAULT;
void UsageFault_Handler(void) F4_WEAK_FAULT;
void SVC_Handler(void) F4_WEAK_FAULT;
void DebugMon_Handler(void) F4_WEAK_FAULT;
void PendSV_Handler(void) F4_WEAK_FAULT;
void SysTick_Handler(void) F4_WEAK_FAULT;
void EXTI0_IRQHandler(void) F4_WEAK_FAULT;         /* 6 */
void EXTI1_IRQHandler(void) F4_WEAK_FAULT;         /* 7 */
void EXTI2_IRQHandler(void) F4_WEAK_FAULT;         /* 8 */
void EXTI3_IRQHandler(void) F4_WEAK_FAULT;         /* 9 */
void EXTI4_IRQHandler(void) F4_WEAK_FAULT;         /* 10 */
void ADC_IRQHandler(void) F4_WEAK_FAULT;           /* 18 */
void EXTI9_5_IRQHandler(void) F4_WEAK_FAULT;       /* 23 */
void TIM1_BRK_TIM9_IRQHandler(void) F4_WEAK_FAULT; /* 24 */
void USART1_IRQHandler(void) F4_WEAK_FAULT;        /* 37 */
void USART2_IRQHandler(void) F4_WEAK_FAULT;        /* 38 */
void USART3_IRQHandler(void) F4_WEAK_FAULT;        /* 39 */
void EXTI15_10_IRQHandler(void) F4_WEAK_FAULT;     /* 40 */
void UART4_IRQHandler(void) F4_WEAK_FAULT;         /* 52 */
void USART6_IRQHandler(void) F4_WEAK_FAULT;        /* 71 */

/* Repeats of the fault handler for the vectors nothing else uses. */
#define F1 f4_fault_handler
#define F2 F1, F1
#define F4 F2, F2
#define F8 F4, F4
#define F16 F8, F8

/* Referenced with -Wl,--undefined=f4_vectors; KEEP(*(.isr_vector)).
 * IRQ numbers: RM0090 table 61 (stm32f405xx.h IRQn_Type). */
__attribute__((section(".isr_vector"), used)) const f4_vector_t f4_vectors[16u + F4_NUM_IRQ] = {
    (f4_vector_t)(uintptr_t)&__stack_top__,
    Reset_Handler,
    NMI_Handler,
    HardFault_Handler,
    MemManage_Handler,
    BusFault_Handler,
    UsageFault_Handler,
    F4, /* reserved 7..10 */
    SVC_Handler,
    DebugMon_Handler,
    F1, /* reserved 13 */
    PendSV_Handler,
    SysTick_Handler,
    F4,
    F2,               /* IRQ 0..5 */
    EXTI0_IRQHandler, /* 6 */
    EXTI1_IRQHandler, /* 7 */
    EXTI2_IRQHandler, /* 8 */
    EXTI3_IRQHandler, /* 9 */
    EXTI4_IRQHandler, /* 10 */
    F4,
    F2,
    F1,                       /* 11..17 */
    ADC_IRQHandler,           /* 18 */
    F4,                       /* 19..22 */
    EXTI9_5_IRQHandler,       /* 23 */
    TIM1_BRK_TIM9_IRQHandler, /* 24 */
    F8,
    F4,                   /* 25..36 */
    USART1_IRQHandler,    /* 37 */
    USART2_IRQHandler,    /* 38 */
    USART3_IRQHandler,    /* 39 */
    EXTI15_10_IRQHandler, /* 40 */
    F8,
    F2,
    F1,               /* 41..51 */
    UART4_IRQHandler, /* 52 */
    F16,
    F2,                /* 53..70 */
    USART6_IRQHandler, /* 71 */
    F8,
    F2, /* 72..81 */
};
_Static_assert(sizeof f4_vectors / sizeof f4_vectors[0] == 16u + F4_NUM_IRQ, "vector count");

/* Gates off without the stack: TIM1_EGR = BG (RM0090 sec. 17.4.6), then the
 * C part with the exception frame (the stack the fault used, from
 * EXC_RETURN bit 2: ARMv7-M ARM B1.5.8) and EXC_RETURN. Address 0x40010014
 * = TIM1 base + EGR offset. */
__attribute__((naked)) void f4_fault_handler(void)
{
    __asm__ volatile("ldr r2, =0x40010014\n\t"
                     "movs r3, #0x80\n\t"
                     "str r3, [r2]\n\t"
                     "tst lr, #4\n\t"
                     "ite eq\n\t"
                     "mrseq r0, msp\n\t"
                     "mrsne r0, psp\n\t"
                     "b f4_fault_stop\n\t"
                     ".ltorg");
}

/* The record the next start-up reports (f4_fault_take): in .noinit, which
 * the C run-time neither copies nor clears. */
__attribute__((section(".noinit"))) static stm32_fault_rec_t f4_fault_rec;

extern uint32_t __data_start__;

/* After the gates are off: wait for the independent watchdog's reset, as
 * long as the longest window it may have been given (its PR and RLR read
 * back, at the slowest LSI) and 10 ms more; should it not come (a watchdog
 * that never started, or an emulator without one: QEMU), a system reset
 * (AIRCR.SYSRESETREQ, B3.2.6). The loop takes at least 4 cycles per turn,
 * counted at 168 MHz: longer at a slower clock, never shorter. */
static void __attribute__((noreturn)) f4_fault_reset(void)
{
    const uint32_t pr = f4_rd(F4_IWDG + F4_IWDG_PR) & 7u;
    const uint32_t rlr = f4_rd(F4_IWDG + F4_IWDG_RLR) & 0xFFFu;
    const uint32_t ms = stm32_iwdg_timeout_ms(pr, rlr, F4_LSI_MIN_HZ) + 10u;
    for (volatile uint32_t n = ms * (168000u / 4u); n != 0u; n--) {
        /* the independent watchdog resets the chip (gates off from reset) */
    }
    __asm__ volatile("dsb" ::: "memory");
    f4_wr(F4_SCB + F4_SCB_AIRCR, F4_SCB_AIRCR_VECTKEY | F4_SCB_AIRCR_SYSRESETREQ);
    __asm__ volatile("dsb" ::: "memory");
    for (;;) {
    }
}

static void f4_gates_off(void)
{
    f4_clr(F4_TIM1 + F4_TIM_BDTR, F4_TIM_BDTR_MOE);
    f4_board_fault_hook();
}

__attribute__((used, noreturn)) void f4_fault_stop(const uint32_t *frame);
__attribute__((used, noreturn)) void f4_fault_stop(const uint32_t *frame)
{
    f4_gates_off();
    uint32_t ipsr;
    __asm__ volatile("mrs %0, ipsr" : "=r"(ipsr));
    stm32_fault_fill(&f4_fault_rec, ipsr & 0x1FFu, frame, (uintptr_t)&__data_start__,
                     (uintptr_t)&__stack_top__, f4_rd(F4_SCB + F4_SCB_CFSR),
                     f4_rd(F4_SCB + F4_SCB_HFSR), f4_rd(F4_SCB + F4_SCB_MMFAR),
                     f4_rd(F4_SCB + F4_SCB_BFAR));
    f4_fault_reset();
}

/* The program stopped itself (abort, exit: stm32_syscalls.c): recorded as
 * exception 0. */
__attribute__((used)) void f4_fault_halt(void)
{
    f4_gates_off();
    stm32_fault_fill(&f4_fault_rec, 0u, NULL, 0u, 0u, 0u, 0u, 0u, 0u);
    f4_fault_reset();
}

bool f4_fault_take(stm32_fault_rec_t *out)
{
    return stm32_fault_take(&f4_fault_rec, out);
}

/* The fault path under the name the shared library glue calls
 * (hal/stm32/stm32_syscalls.c: _exit). */
void stm32_fault_halt(void) __attribute__((noreturn, alias("f4_fault_halt")));

/* Default hook: nothing more to do. */
__attribute__((weak)) void f4_board_fault_hook(void)
{
}

void Reset_Handler(void)
{
    stm32_crt_init();
    (void)main();
    f4_fault_halt();
}
