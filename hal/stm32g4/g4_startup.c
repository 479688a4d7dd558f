/*
 * Start-up of an STM32G431 image: the vector table at the start of flash
 * (0x0800_0000, RM0440 "Boot configuration": main flash boot), the reset
 * handler and the fault handlers.
 *
 * Every fault and unexpected interrupt first turns the gates off: a store of
 * TIMx_EGR.BG (software break: the hardware clears MOE and drives the outputs
 * to their idle, inactive level), written as the handler's first instructions
 * without touching the stack (a fault may come from a broken stack); then MOE
 * is cleared and the core waits for the independent watchdog, which the reset
 * handler starts as its first instruction (so a fault before the application
 * is up is a reset, not a silent halt). If the handler
 * itself faults, the core locks up, and SYSCFG_CFGR2.CLL (set by the
 * application) routes the lockup to the TIM1 system break as well.
 *
 * The application provides the handlers it uses with their CMSIS names
 * (ADC1_2_IRQHandler, TIM1_BRK_TIM15_IRQHandler, USART2_IRQHandler, ...);
 * every other vector is the gates-off fault handler.
 */
#include <stdint.h>
#include <string.h>

#include "g4_regs.h"
#include "g4_startup.h"
#include "stm32_startup.h"

extern uint32_t __stack_top__;
extern uint32_t __data_start__, __data_end__, __data_load__;
extern uint32_t __bss_start__, __bss_end__;

int main(void);
void __libc_init_array(void);
void Reset_Handler(void);
void g4_fault_handler(void);

#define G4_WEAK_FAULT __attribute__((weak, alias("g4_fault_handler")))
void NMI_Handler(void) G4_WEAK_FAULT;
void HardFault_Handler(void) G4_WEAK_FAULT;
void MemManage_Handler(void) G4_WEAK_FAULT;
void BusFault_Handler(void) G4_WEAK_FAULT;
void UsageFault_Handler(void) G4_WEAK_FAULT;
void SVC_Handler(void) G4_WEAK_FAULT;
void DebugMon_Handler(void) G4_WEAK_FAULT;
void PendSV_Handler(void) G4_WEAK_FAULT;
void SysTick_Handler(void) G4_WEAK_FAULT;
void ADC1_2_IRQHandler(void) G4_WEAK_FAULT;         /* 18 */
void TIM1_BRK_TIM15_IRQHandler(void) G4_WEAK_FAULT; /* 24 */
void TIM1_UP_TIM16_IRQHandler(void) G4_WEAK_FAULT;  /* 25 */
void TIM4_IRQHandler(void) G4_WEAK_FAULT;           /* 30 */
void USART2_IRQHandler(void) G4_WEAK_FAULT;         /* 38 */

/* Repeats of the fault handler for the vectors nothing else uses. */
#define F1 g4_fault_handler
#define F2 F1, F1
#define F4 F2, F2
#define F8 F4, F4
#define F16 F8, F8
#define F32 F16, F16

/* Referenced with -Wl,--undefined=g4_vectors; KEEP(*(.isr_vector)).
 * IRQ numbers: RM0440 vector table (stm32g431xx.h IRQn_Type). */
__attribute__((section(".isr_vector"), used)) const g4_vector_t g4_vectors[16u + G4_NUM_IRQ] = {
    (g4_vector_t)(uintptr_t)&__stack_top__,
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
    F16,
    F2,                /* IRQ 0..17 */
    ADC1_2_IRQHandler, /* 18 */
    F4,
    F1,                        /* 19..23 */
    TIM1_BRK_TIM15_IRQHandler, /* 24 */
    TIM1_UP_TIM16_IRQHandler,  /* 25 */
    F4,                        /* 26..29 */
    TIM4_IRQHandler,           /* 30 */
    F4,
    F2,
    F1,                /* 31..37 */
    USART2_IRQHandler, /* 38 */
    F32,
    F16,
    F8,
    F4,
    F2,
    F1, /* 39..101 */
};
_Static_assert(sizeof g4_vectors / sizeof g4_vectors[0] == 16u + G4_NUM_IRQ, "vector count");

/* Gates off without the stack: TIM1_EGR = BG (RM0440 chapter 29, TIMx_EGR),
 * then the C part. Address 0x40012C14 = TIM1 base + EGR offset. */
__attribute__((naked)) void g4_fault_handler(void)
{
    __asm__ volatile("ldr r0, =0x40012C14\n\t"
                     "movs r1, #0x80\n\t"
                     "str r1, [r0]\n\t"
                     "b g4_fault_halt\n\t"
                     ".ltorg");
}

__attribute__((used)) void g4_fault_halt(void)
{
    g4_clr(G4_TIM1 + G4_TIM_BDTR, G4_TIM_BDTR_MOE);
    g4_board_fault_hook();
    for (;;) {
        /* The independent watchdog, running since the reset handler's first
         * instruction (and not stoppable), resets the chip: gates off from
         * reset, "reset: watchdog" in the next start-up report. */
    }
}

/* The fault path under the name the shared library glue calls
 * (hal/stm32/stm32_syscalls.c: _exit). */
void stm32_fault_halt(void) __attribute__((noreturn, alias("g4_fault_halt")));

/* Default hook: nothing more to do. */
__attribute__((weak)) void g4_board_fault_hook(void)
{
}

/* newlib's __libc_init_array calls _init (crti's, replaced by -nostartfiles). */
void _init(void);
void _fini(void);
void _init(void)
{
}
void _fini(void)
{
}

void Reset_Handler(void)
{
    /* The independent watchdog first (RM0440 IWDG: the key 0xCCCC starts it
     * with its reset prescaler /4 and reload 0xFFF, 4096 x 4 / f_LSI = 482 ..
     * 555 ms at the data sheet's 29.5 .. 34 kHz), frozen while a debugger
     * halts the core: a fault or a hang anywhere from here on ends in a reset
     * (the fault handlers wait for it) and a "reset: watchdog" report, never
     * in a silent halt. The application refreshes it between its start-up
     * steps and then sets its own time-out (g4_iwdg_start). */
    g4_wr(G4_IWDG + G4_IWDG_KR, G4_IWDG_KR_START);
    g4_set(G4_DBGMCU + G4_DBGMCU_APB1FZR1, G4_DBGMCU_APB1FZR1_IWDG_STOP);
    /* FPU (CP10, CP11) full access before any floating-point instruction. */
    g4_set(G4_SCB + G4_SCB_CPACR, 0xFu << 20);
    __asm__ volatile("dsb\n\tisb" ::: "memory");
    memcpy(&__data_start__, &__data_load__,
           (size_t)((uintptr_t)&__data_end__ - (uintptr_t)&__data_start__));
    memset(&__bss_start__, 0, (size_t)((uintptr_t)&__bss_end__ - (uintptr_t)&__bss_start__));
    /* MemManage, BusFault and UsageFault as their own handlers (all gates off). */
    g4_set(G4_SCB + G4_SCB_SHCSR, G4_SCB_SHCSR_FAULTS_ENA);
    __libc_init_array();
    (void)main();
    g4_fault_halt();
}
