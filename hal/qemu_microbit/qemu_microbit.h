/*
 * Board support for QEMU's microbit machine (nRF51822, Cortex-M0: ARMv6-M, the
 * instruction set of the Cortex-M0+), used to count instructions of the
 * interrupt path on ARMv6-M (tools/bench). Start-up (startup.c), UART0 output
 * and ARM semihosting exit (board.c). Memory map: microbit.ld.
 */
#ifndef HAL_QEMU_MICROBIT_H
#define HAL_QEMU_MICROBIT_H

#include <stdint.h>

/* Flash above the image, free for QEMU's loader device (microbit.ld). */
#define QEMU_MICROBIT_FLASH_FREE 0x00030000u
#define QEMU_MICROBIT_FLASH_FREE_SIZE 0x00010000u /* 64 KiB */

void uart_puts(const char *s);
void uart_put_u32(uint32_t v); /* decimal */
void semihost_exit(int code) __attribute__((noreturn));

#endif /* HAL_QEMU_MICROBIT_H */
