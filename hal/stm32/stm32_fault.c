/* The fault record left for the next start-up (stm32_fault.h). */
#include "stm32_fault.h"

#include <stdio.h>
#include <string.h>

uint32_t stm32_fault_check(const stm32_fault_rec_t *r)
{
    const uint32_t w[] = {r->magic, r->exception, r->frame_ok, r->pc,    r->lr,
                          r->xpsr,  r->cfsr,      r->hfsr,     r->mmfar, r->bfar};
    uint32_t c = 0x9E3779B9u;
    for (size_t i = 0; i < sizeof w / sizeof w[0]; i++) {
        c = (c ^ w[i]) * 0x01000193u; /* FNV-1a's prime: every word moves every bit */
    }
    return c;
}

void stm32_fault_fill(stm32_fault_rec_t *r, uint32_t exception, const uint32_t *frame,
                      uintptr_t ram_lo, uintptr_t ram_hi, uint32_t cfsr, uint32_t hfsr,
                      uint32_t mmfar, uint32_t bfar)
{
    const uintptr_t f = (uintptr_t)frame;
    const bool ok = frame != NULL && (f & 3u) == 0u && f >= ram_lo && f < ram_hi &&
                    ram_hi - f >= STM32_FRAME_WORDS * sizeof(uint32_t);
    r->magic = STM32_FAULT_MAGIC;
    r->exception = exception;
    r->frame_ok = ok ? 1u : 0u;
    r->pc = ok ? frame[STM32_FRAME_PC] : 0u;
    r->lr = ok ? frame[STM32_FRAME_LR] : 0u;
    r->xpsr = ok ? frame[STM32_FRAME_XPSR] : 0u;
    r->cfsr = cfsr;
    r->hfsr = hfsr;
    r->mmfar = mmfar;
    r->bfar = bfar;
    r->check = stm32_fault_check(r);
}

bool stm32_fault_take(stm32_fault_rec_t *r, stm32_fault_rec_t *out)
{
    const bool have = r->magic == STM32_FAULT_MAGIC && r->check == stm32_fault_check(r);
    if (have) {
        *out = *r;
    }
    memset(r, 0, sizeof *r);
    return have;
}

const char *stm32_fault_exception_name(uint32_t exception)
{
    static const char *const names[] = {"stop",      "exception", "NMI",       "HardFault",
                                        "MemManage", "BusFault",  "UsageFault"};
    if (exception < sizeof names / sizeof names[0]) {
        return names[exception];
    }
    return exception >= 16u ? "IRQ" : "exception";
}

/* CFSR's and HFSR's fault bits (ARMv7-M ARM B3.2.15, B3.2.16). */
static const struct {
    uint8_t hfsr; /* 0: CFSR's bit, 1: HFSR's */
    uint8_t bit;
    const char *what;
} stm32_fault_bits[] = {
    {0, 0, "instruction access violation"},
    {0, 1, "data access violation"},
    {0, 3, "MPU fault on unstacking"},
    {0, 4, "MPU fault on stacking"},
    {0, 5, "MPU fault on lazy FP stacking"},
    {0, 8, "instruction bus error"},
    {0, 9, "precise data bus error"},
    {0, 10, "imprecise data bus error"},
    {0, 11, "bus error on unstacking"},
    {0, 12, "bus error on stacking"},
    {0, 13, "bus error on lazy FP stacking"},
    {0, 16, "undefined instruction"},
    {0, 17, "invalid state (Thumb bit clear)"},
    {0, 18, "invalid EXC_RETURN"},
    {0, 19, "coprocessor access (FPU off)"},
    {0, 24, "unaligned access"},
    {0, 25, "division by zero"},
    {1, 1, "vector table read"},
    {1, 30, "escalated to HardFault"},
    {1, 31, "debug event"},
};

int stm32_fault_describe(const stm32_fault_rec_t *r, char *out, size_t cap)
{
    char causes[128];
    size_t n = 0;
    causes[0] = '\0';
    for (size_t i = 0; i < sizeof stm32_fault_bits / sizeof stm32_fault_bits[0]; i++) {
        const uint32_t reg = stm32_fault_bits[i].hfsr != 0u ? r->hfsr : r->cfsr;
        if ((reg >> stm32_fault_bits[i].bit & 1u) != 0u) {
            const int k = snprintf(causes + n, sizeof causes - n, "%s%s", n > 0u ? ", " : "",
                                   stm32_fault_bits[i].what);
            if (k < 0 || (size_t)k >= sizeof causes - n) {
                break;
            }
            n += (size_t)k;
        }
    }
    char where[64];
    if (r->frame_ok != 0u) {
        (void)snprintf(where, sizeof where, " at pc 0x%lx (lr 0x%lx, xpsr 0x%lx)",
                       (unsigned long)r->pc, (unsigned long)r->lr, (unsigned long)r->xpsr);
    } else {
        (void)snprintf(where, sizeof where, "%s",
                       r->exception == 0u ? "" : " (stack pointer outside RAM: no frame)");
    }
    char addr[32];
    addr[0] = '\0';
    if ((r->cfsr & (1u << 15)) != 0u) { /* BFARVALID */
        (void)snprintf(addr, sizeof addr, " BFAR 0x%lx", (unsigned long)r->bfar);
    } else if ((r->cfsr & (1u << 7)) != 0u) { /* MMARVALID */
        (void)snprintf(addr, sizeof addr, " MMFAR 0x%lx", (unsigned long)r->mmfar);
    }
    char name[40];
    if (r->exception >= 16u) {
        (void)snprintf(name, sizeof name, "IRQ %lu (no handler)",
                       (unsigned long)(r->exception - 16u));
    } else {
        (void)snprintf(name, sizeof name, "%s", stm32_fault_exception_name(r->exception));
    }
    return snprintf(out, cap, "%s%s: %s; CFSR 0x%lx HFSR 0x%lx%s", name, where,
                    n > 0u ? causes : "no fault status bit", (unsigned long)r->cfsr,
                    (unsigned long)r->hfsr, addr);
}
