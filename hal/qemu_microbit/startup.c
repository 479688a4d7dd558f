/*
 * Start-up of the microbit image: vector table (ARMv6-M: the 16 system
 * entries), reset handler (.data, .bss, main, semihosting exit). Any fault
 * exits QEMU with status 4: this board runs no gates, only the benchmark.
 */
#include <stdint.h>

#include "qemu_microbit.h"

extern uint32_t __stack_top__;
extern uint32_t __data_start__, __data_end__, __data_load__;
extern uint32_t __bss_start__, __bss_end__;

int main(void);
void Reset_Handler(void);
void Fault_Handler(void);

typedef void (*vector_t)(void);

extern const vector_t qemu_microbit_vectors[16];
__attribute__((section(".vectors"), used))
const vector_t qemu_microbit_vectors[16] = {(vector_t)(uintptr_t)&__stack_top__,
                                            Reset_Handler,
                                            Fault_Handler,
                                            Fault_Handler,
                                            0,
                                            0,
                                            0,
                                            0,
                                            0,
                                            0,
                                            0,
                                            Fault_Handler,
                                            0,
                                            0,
                                            Fault_Handler,
                                            Fault_Handler};

void Fault_Handler(void)
{
    uart_puts("fault\n");
    semihost_exit(4);
}

void Reset_Handler(void)
{
    const uint32_t *src = &__data_load__;
    for (uint32_t *dst = &__data_start__; dst < &__data_end__;) {
        *dst++ = *src++;
    }
    for (uint32_t *dst = &__bss_start__; dst < &__bss_end__;) {
        *dst++ = 0u;
    }
    semihost_exit(main());
}
