/*
 * Start-up of the mps2-an386 image: vector table, reset handler, fault handlers.
 * The reset handler enables the FPU first (before any floating-point instruction
 * can run, otherwise the first one takes a NOCP UsageFault), then initialises
 * .data/.bss, turns on UART0 and Timer1 (board_init), runs the constructors and
 * calls exit(main()).
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "qemu_mps2.h"

/* Linker-script symbols (mps2_an386.ld). */
extern uint32_t __stack_top__;
extern uint32_t __data_start__, __data_end__, __data_load__;
extern uint32_t __bss_start__, __bss_end__;

int main(void);
void __libc_init_array(void);
void _init(void);
void _fini(void);
void Reset_Handler(void);
void Default_Handler(void);
void HardFault_Handler(void);

/* Exception handlers: weak, so that a module can provide its own. */
void NMI_Handler(void) __attribute__((weak, alias("Default_Handler")));
void MemManage_Handler(void) __attribute__((weak, alias("HardFault_Handler")));
void BusFault_Handler(void) __attribute__((weak, alias("HardFault_Handler")));
void UsageFault_Handler(void) __attribute__((weak, alias("HardFault_Handler")));
void SVC_Handler(void) __attribute__((weak, alias("Default_Handler")));
void DebugMon_Handler(void) __attribute__((weak, alias("Default_Handler")));
void PendSV_Handler(void) __attribute__((weak, alias("Default_Handler")));
void SysTick_Handler(void) __attribute__((weak, alias("Default_Handler")));
/* External interrupts of the AN386 (IRQ number in the comment). */
void UART0_RX_Handler(void) __attribute__((weak, alias("Default_Handler")));  /* 0 */
void UART0_TX_Handler(void) __attribute__((weak, alias("Default_Handler")));  /* 1 */
void TIMER0_Handler(void) __attribute__((weak, alias("Default_Handler")));    /* 8 */
void TIMER1_Handler(void) __attribute__((weak, alias("Default_Handler")));    /* 9 */
void DUALTIMER_Handler(void) __attribute__((weak, alias("Default_Handler"))); /* 10 */

#define QEMU_MPS2_NUM_IRQ 32u

typedef void (*vector_t)(void);

/* Kept by the linker script (KEEP(*(.vectors))) and referenced with
 * -Wl,--undefined=qemu_mps2_vectors so that the archive member is linked. */
extern const vector_t qemu_mps2_vectors[16u + QEMU_MPS2_NUM_IRQ];
__attribute__((section(".vectors"), used))
const vector_t qemu_mps2_vectors[16u + QEMU_MPS2_NUM_IRQ] = {
    (vector_t)(uintptr_t)&__stack_top__, /* initial MSP */
    Reset_Handler,
    NMI_Handler,
    HardFault_Handler,
    MemManage_Handler,
    BusFault_Handler,
    UsageFault_Handler,
    0,
    0,
    0,
    0,
    SVC_Handler,
    DebugMon_Handler,
    0,
    PendSV_Handler,
    SysTick_Handler,
    /* IRQ 0.. */
    UART0_RX_Handler,
    UART0_TX_Handler,
    Default_Handler,
    Default_Handler,
    Default_Handler,
    Default_Handler,
    Default_Handler,
    Default_Handler,
    TIMER0_Handler,
    TIMER1_Handler,
    DUALTIMER_Handler,
    /* the remaining entries default to 0 (no handler) and are filled below */
    [16u + 11u] = Default_Handler,
    [16u + 12u] = Default_Handler,
    [16u + 13u] = Default_Handler,
    [16u + 14u] = Default_Handler,
    [16u + 15u] = Default_Handler,
    [16u + 16u] = Default_Handler,
    [16u + 17u] = Default_Handler,
    [16u + 18u] = Default_Handler,
    [16u + 19u] = Default_Handler,
    [16u + 20u] = Default_Handler,
    [16u + 21u] = Default_Handler,
    [16u + 22u] = Default_Handler,
    [16u + 23u] = Default_Handler,
    [16u + 24u] = Default_Handler,
    [16u + 25u] = Default_Handler,
    [16u + 26u] = Default_Handler,
    [16u + 27u] = Default_Handler,
    [16u + 28u] = Default_Handler,
    [16u + 29u] = Default_Handler,
    [16u + 30u] = Default_Handler,
    [16u + 31u] = Default_Handler,
};

#define SCB_CPACR (*(volatile uint32_t *)0xE000ED88u)
#define SCB_ICSR (*(volatile uint32_t *)0xE000ED04u)
#define SCB_CFSR (*(volatile uint32_t *)0xE000ED28u)
#define SCB_HFSR (*(volatile uint32_t *)0xE000ED2Cu)

/* Exit status of an image that took a fault or an unexpected interrupt. */
#define QEMU_MPS2_EXIT_FAULT 127

void Reset_Handler(void)
{
    /* CP10/CP11 full access (FPU) before anything else. */
    SCB_CPACR |= 0xFu << 20;
    __asm__ volatile("dsb\n\tisb" ::: "memory");

    size_t data_bytes = (size_t)((uintptr_t)&__data_end__ - (uintptr_t)&__data_start__);
    size_t bss_bytes = (size_t)((uintptr_t)&__bss_end__ - (uintptr_t)&__bss_start__);
    memcpy(&__data_start__, &__data_load__, data_bytes);
    memset(&__bss_start__, 0, bss_bytes);

    board_init(); /* UART0 before any output (a disabled CMSDK UART never drains) */
    __libc_init_array();
    exit(main());
}

/* newlib's __libc_init_array/__libc_fini_array call these (crti/crtn are not linked). */
void _init(void)
{
}

void _fini(void)
{
}

static void fault_report(const char *what)
{
    uart_puts("\n*** ");
    uart_puts(what);
    uart_puts(": exception ");
    uart_put_u32(SCB_ICSR & 0x1FFu);
    uart_puts(" CFSR=");
    uart_put_u32(SCB_CFSR);
    uart_puts(" HFSR=");
    uart_put_u32(SCB_HFSR);
    uart_puts("\n");
    semihost_exit(QEMU_MPS2_EXIT_FAULT);
}

void HardFault_Handler(void)
{
    fault_report("fault");
}

void Default_Handler(void)
{
    fault_report("unexpected interrupt");
}
