/* The C run-time set-up of an STM32 image (stm32_startup.h). */
#include "stm32_startup.h"

#include <stdint.h>
#include <string.h>

extern uint32_t __data_start__, __data_end__, __data_load__;
extern uint32_t __bss_start__, __bss_end__;
void __libc_init_array(void);

/* System Control Block registers (ARMv7-M ARM B3.2.2): architectural
 * addresses, the same on every Cortex-M4. */
#define STM32_SCB_SHCSR ((volatile uint32_t *)0xE000ED24u)
#define STM32_SCB_SHCSR_FAULTS_ENA ((1u << 16) | (1u << 17) | (1u << 18)) /* MEM, BUS, USG */
#define STM32_SCB_CPACR ((volatile uint32_t *)0xE000ED88u)

/* newlib's __libc_init_array calls _init (crti's, replaced by -nostartfiles). */
void _init(void);
void _fini(void);
void _init(void)
{
}
void _fini(void)
{
}

void stm32_crt_init(void)
{
    *STM32_SCB_CPACR |= 0xFu << 20;
    __asm__ volatile("dsb\n\tisb" ::: "memory");
    memcpy(&__data_start__, &__data_load__,
           (size_t)((uintptr_t)&__data_end__ - (uintptr_t)&__data_start__));
    memset(&__bss_start__, 0, (size_t)((uintptr_t)&__bss_end__ - (uintptr_t)&__bss_start__));
    *STM32_SCB_SHCSR |= STM32_SCB_SHCSR_FAULTS_ENA;
    __libc_init_array();
}
