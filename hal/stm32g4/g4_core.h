/*
 * Cortex-M4 core services of the STM32G4 chip support: the DWT cycle counter
 * (time-outs, delays, hal_cycles), NVIC enable/priority, fault enables.
 */
#ifndef HAL_STM32G4_G4_CORE_H
#define HAL_STM32G4_G4_CORE_H

#include <stdbool.h>
#include <stdint.h>

#include "g4_regs.h"

/* Return codes of the chip-support init functions. */
typedef enum {
    G4_OK = 0,
    G4_E_CONFIG = -1,  /* a requested value has no register encoding (see the function) */
    G4_E_HSE = -2,     /* HSE did not become ready (no crystal / broken) */
    G4_E_PLL = -3,     /* PLL did not lock */
    G4_E_SWITCH = -4,  /* system clock switch not confirmed by SWS */
    G4_E_FLASH = -5,   /* FLASH_ACR latency read-back differs */
    G4_E_PWR = -6,     /* voltage scaling not ready (VOSF) */
    G4_E_ADC_CAL = -7, /* ADC calibration did not finish */
    G4_E_ADC_RDY = -8, /* ADC did not report ADRDY */
    G4_E_DAC = -9,     /* DAC channel not ready */
    G4_E_LSI = -10,    /* LSI (IWDG clock) not ready */
    G4_E_TIM = -11,    /* TIM1 update phase wrong (see g4_tim1_check_phase) */
    G4_E_RANGE = -12   /* a measured value outside its plausible range */
} g4_rc_t;

const char *g4_strerror(int rc);

/* DWT cycle counter on (DEMCR.TRCENA, DWT_CTRL.CYCCNTENA): ARMv7-M ARM C1.8. */
void g4_cycle_counter_init(void);
static inline uint32_t g4_cycles(void)
{
    return g4_rd(G4_DWT + G4_DWT_CYCCNT);
}
/* Busy-waits at least n core cycles. */
void g4_delay_cycles(uint32_t n);
/* Waits until (*reg & mask) == want; false after timeout_cycles core cycles. */
bool g4_wait_bits(uintptr_t reg, uint32_t mask, uint32_t want, uint32_t timeout_cycles);

/* NVIC: priority 0 (highest) .. 15, then enable / disable. */
void g4_nvic_set_priority(uint32_t irq, uint32_t prio);
void g4_nvic_enable(uint32_t irq);
void g4_nvic_disable(uint32_t irq);
bool g4_nvic_enabled(uint32_t irq);

/* PendSV, the software-triggered exception (the firmware's medium-rate task):
 * its priority 0 .. 15 (SHPR3), and pending it (ICSR.PENDSVSET); it runs when
 * no higher-priority handler is active. */
void g4_pendsv_set_priority(uint32_t prio);
static inline void g4_pendsv_pend(void)
{
    g4_wr(G4_SCB + G4_SCB_ICSR, G4_SCB_ICSR_PENDSVSET);
}

/* Every configurable-priority exception held off (PRIMASK, CPSID i: ARMv7-M
 * ARM B1.4.3) for a few instructions that one interrupt may also run; the
 * previous PRIMASK back on unlock. The traced register model keeps a
 * PRIMASK of its own and holds its modelled interrupts off while it is set;
 * the untraced array build (the instruction-count image) runs one context:
 * no-ops there. */
static inline uint32_t g4_irq_lock(void)
{
#if defined(G4_MEM_ARRAYS) && defined(G4_REG_TRACE)
    return g4_trace_irq_lock();
#elif defined(G4_MEM_ARRAYS)
    return 0u;
#else
    uint32_t primask;
    __asm__ volatile("mrs %0, primask\n\tcpsid i" : "=r"(primask)::"memory");
    return primask;
#endif
}
static inline void g4_irq_unlock(uint32_t primask)
{
#if defined(G4_MEM_ARRAYS) && defined(G4_REG_TRACE)
    g4_trace_irq_unlock(primask);
#elif defined(G4_MEM_ARRAYS)
    (void)primask;
#else
    __asm__ volatile("msr primask, %0" ::"r"(primask) : "memory");
#endif
}

#endif /* HAL_STM32G4_G4_CORE_H */
