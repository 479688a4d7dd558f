/*
 * What a CPU fault leaves for the next start-up: a record in RAM that the C
 * run-time does not clear (.noinit), written by the fault handler after the
 * gates are off, read and cleared by the next start-up's report. Shared by
 * every Cortex-M4 image here: the fault status registers and the exception
 * frame are the architecture's (ARMv7-M ARM B1.5.6 "Exception entry
 * behavior", B3.2.15-B3.2.18 CFSR, HFSR, MMFAR, BFAR), not a chip's.
 *
 * The record holds the exception number (IPSR), the stacked PC, LR and xPSR
 * (when the stack pointer at the fault lay inside RAM, so that reading the
 * frame cannot fault again), CFSR, HFSR, MMFAR and BFAR, and a check word:
 * RAM after a power-on holds anything, and a record is believed only with
 * its magic and its check.
 *
 * Hardware-free (the caller reads the registers): tests/board checks it on
 * the host.
 */
#ifndef HAL_STM32_STM32_FAULT_H
#define HAL_STM32_STM32_FAULT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define STM32_FAULT_MAGIC 0x544C5546u /* "FULT" in memory order */

typedef struct {
    uint32_t magic;
    uint32_t exception; /* IPSR: 2 NMI, 3 HardFault, 4 MemManage, 5 BusFault,
                           6 UsageFault, 16 + n IRQ n; 0: stopped by the
                           program (abort, exit) */
    uint32_t frame_ok;  /* 1: pc, lr, xpsr read from the exception frame */
    uint32_t pc, lr, xpsr;
    uint32_t cfsr, hfsr, mmfar, bfar;
    uint32_t check; /* stm32_fault_check of the words above */
} stm32_fault_rec_t;

/* The exception frame's words (B1.5.6): r0 r1 r2 r3 r12 lr pc xpsr. */
#define STM32_FRAME_LR 5u
#define STM32_FRAME_PC 6u
#define STM32_FRAME_XPSR 7u
#define STM32_FRAME_WORDS 8u

/* The check word of a record (its other words folded). */
uint32_t stm32_fault_check(const stm32_fault_rec_t *r);

/* Fill r: the frame is read only when it lies wholly inside [ram_lo, ram_hi)
 * (frame may be anything: a broken stack pointer is a cause of faults). */
void stm32_fault_fill(stm32_fault_rec_t *r, uint32_t exception, const uint32_t *frame,
                      uintptr_t ram_lo, uintptr_t ram_hi, uint32_t cfsr, uint32_t hfsr,
                      uint32_t mmfar, uint32_t bfar);

/* A record left by the previous run: true and *out filled when r holds one
 * (magic and check right); r is cleared either way. */
bool stm32_fault_take(stm32_fault_rec_t *r, stm32_fault_rec_t *out);

/* The exception's name: "NMI", "HardFault", "MemManage", "BusFault",
 * "UsageFault", "IRQ" (an interrupt without a handler), "stop" (0: the
 * program stopped itself) or "exception". */
const char *stm32_fault_exception_name(uint32_t exception);

/* One line for the start-up report, e.g. "BusFault at pc 0x30000000 (lr
 * 0x8012345, xpsr 0x1000037): instruction bus error; CFSR 0x100 HFSR 0x0"
 * (hexadecimal without width: the board images' formatter has no flags,
 * firmware/protocol/text_fmt.h). Returns the length snprintf would have
 * written. */
int stm32_fault_describe(const stm32_fault_rec_t *r, char *out, size_t cap);

#endif /* HAL_STM32_STM32_FAULT_H */
