/*
 * ARM semihosting calls for the QEMU images (ARM DUI 0471, "Semihosting
 * operations"; on M-profile cores the trap is BKPT 0xAB). SYS_EXIT_EXTENDED
 * makes QEMU exit with the given status; SYS_EXIT is the fallback for a
 * debugger without the extension.
 */
#ifndef HAL_ARM_SEMIHOST_H
#define HAL_ARM_SEMIHOST_H

#include <stdint.h>

#define SYS_OPEN 0x01
#define SYS_WRITE0 0x04
#define SYS_WRITE 0x05
#define SYS_READ 0x06
#define SYS_EXIT 0x18
#define SYS_EXIT_EXTENDED 0x20
#define ADP_STOPPED_APPLICATION_EXIT 0x20026u

static inline int arm_semihost_call(int op, const void *arg)
{
    register int r0 __asm__("r0") = op;
    register const void *r1 __asm__("r1") = arg;
    __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

/* Exit QEMU with code & 0xFF; never returns. */
__attribute__((noreturn)) static inline void arm_semihost_exit(int code)
{
    const uint32_t block[2] = {ADP_STOPPED_APPLICATION_EXIT, (uint32_t)code};
    (void)arm_semihost_call(SYS_EXIT_EXTENDED, block);
    (void)arm_semihost_call(SYS_EXIT, (const void *)(uintptr_t)ADP_STOPPED_APPLICATION_EXIT);
    for (;;) {
    }
}

#endif /* HAL_ARM_SEMIHOST_H */
