/*
 * Cortex-M4 core services of the STM32F4 chip support: time-outs and delays,
 * NVIC enable/priority, PendSV, interrupt masking; the return codes of the
 * chip support.
 *
 * Time-outs: the DWT cycle counter (ARMv7-M ARM C1.8) measures them on the
 * chip. QEMU's STM32F405 machine (netduinoplus2) does not model the DWT: its
 * CYCCNT reads 0 and would never end a wait. Every wait therefore also
 * counts its polls and gives up after timeout / F4_POLL_MIN_CYCLES of them:
 * one poll (a peripheral load, a load of CYCCNT, a compare and a taken
 * branch) takes at least that many core cycles on a Cortex-M4 (ARM Cortex-M4
 * TRM, instruction timings: LDR 2, B taken 2 cycles), so the poll count can
 * only end a wait that the cycle counter would have ended too, never an
 * earlier one. On the chip the cycle counter ends it at the stated time; in
 * the emulator the poll count ends it.
 */
#ifndef HAL_STM32F4_F4_CORE_H
#define HAL_STM32F4_F4_CORE_H

#include <stdbool.h>
#include <stdint.h>

#include "f4_regs.h"
#include "stm32_calc.h"

/* Return codes of the chip-support init functions. */
typedef enum {
    F4_OK = 0,
    F4_E_CONFIG = -1,  /* a requested value has no register encoding (see the function) */
    F4_E_HSE = -2,     /* HSE did not become ready (no crystal / broken) */
    F4_E_PLL = -3,     /* PLL did not lock */
    F4_E_SWITCH = -4,  /* system clock switch not confirmed by SWS */
    F4_E_FLASH = -5,   /* FLASH_ACR latency read-back differs */
    F4_E_PWR = -6,     /* voltage scaling not in scale 1 */
    F4_E_SPI = -7,     /* SPI transfer did not complete */
    F4_E_ADC = -8,     /* ADC conversion did not complete */
    F4_E_LSI = -9,     /* LSI not running: IWDG not updated, LSIRDY low */
    F4_E_TIM = -10,    /* TIM1 update phase wrong (see f4_tim1_start) */
    F4_E_RANGE = -11,  /* a measured value outside its plausible range */
    F4_E_DRIVER = -12, /* the gate driver refused or did not answer (f4_hal.h) */
    F4_E_CLOCK = -13   /* the board runs on the fall-back clock (no PWM timing) */
} f4_rc_t;
_Static_assert(F4_OK == STM32_OK && F4_E_CONFIG == STM32_E_CONFIG, "shared return codes");

const char *f4_strerror(int rc);

#define F4_POLL_MIN_CYCLES 4u

/* DWT cycle counter on (DEMCR.TRCENA, DWT_CTRL.CYCCNTENA). */
void f4_cycle_counter_init(void);
static inline uint32_t f4_cycles(void)
{
    return f4_rd(F4_DWT + F4_DWT_CYCCNT);
}
/* Busy-waits at least n core cycles. */
void f4_delay_cycles(uint32_t n);
/* Waits until (*reg & mask) == want; false after timeout_cycles core cycles. */
bool f4_wait_bits(uintptr_t reg, uint32_t mask, uint32_t want, uint32_t timeout_cycles);

/* NVIC: priority 0 (highest) .. 15, then enable / disable. */
void f4_nvic_set_priority(uint32_t irq, uint32_t prio);
void f4_nvic_enable(uint32_t irq);
void f4_nvic_disable(uint32_t irq);
bool f4_nvic_enabled(uint32_t irq);

/* PendSV (the firmware's medium-rate task): priority 0 .. 15 (SHPR3), and
 * pending it (ICSR.PENDSVSET). */
void f4_pendsv_set_priority(uint32_t prio);
static inline void f4_pendsv_pend(void)
{
    f4_wr(F4_SCB + F4_SCB_ICSR, F4_SCB_ICSR_PENDSVSET);
}

/* Every configurable-priority exception held off (PRIMASK, CPSID i: ARMv7-M
 * ARM B1.4.3) for a few instructions; the previous PRIMASK back on unlock.
 * The traced register model keeps a PRIMASK of its own and holds its
 * modelled interrupts off while it is set; the untraced array build (the
 * instruction-count image) runs one context: no-ops there. */
static inline uint32_t f4_irq_lock(void)
{
#if defined(F4_MEM_ARRAYS) && defined(F4_REG_TRACE)
    return f4_trace_irq_lock();
#elif defined(F4_MEM_ARRAYS)
    return 0u;
#else
    uint32_t primask;
    __asm__ volatile("mrs %0, primask\n\tcpsid i" : "=r"(primask)::"memory");
    return primask;
#endif
}
static inline void f4_irq_unlock(uint32_t primask)
{
#if defined(F4_MEM_ARRAYS) && defined(F4_REG_TRACE)
    f4_trace_irq_unlock(primask);
#elif defined(F4_MEM_ARRAYS)
    (void)primask;
#else
    __asm__ volatile("msr primask, %0" ::"r"(primask) : "memory");
#endif
}

#endif /* HAL_STM32F4_F4_CORE_H */
