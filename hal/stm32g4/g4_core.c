/* Cortex-M4 core services (g4_core.h). */
#include "g4_core.h"

#include <stdatomic.h>

const char *g4_strerror(int rc)
{
    switch (rc) {
    case G4_OK:
        return "ok";
    case G4_E_CONFIG:
        return "value has no register encoding";
    case G4_E_HSE:
        return "HSE crystal not ready";
    case G4_E_PLL:
        return "PLL not locked";
    case G4_E_SWITCH:
        return "system clock switch not confirmed";
    case G4_E_FLASH:
        return "flash latency not taken";
    case G4_E_PWR:
        return "voltage scaling not ready";
    case G4_E_ADC_CAL:
        return "ADC calibration timed out";
    case G4_E_ADC_RDY:
        return "ADC not ready";
    case G4_E_DAC:
        return "DAC not ready";
    case G4_E_LSI:
        return "LSI not ready";
    case G4_E_TIM:
        return "TIM1 update not at the counter peak";
    case G4_E_RANGE:
        return "measured value out of range";
    default:
        return "unknown";
    }
}

void g4_cycle_counter_init(void)
{
    g4_set(G4_SCB + G4_SCB_DEMCR, G4_SCB_DEMCR_TRCENA);
    g4_wr(G4_DWT + G4_DWT_CYCCNT, 0u);
    g4_set(G4_DWT + G4_DWT_CTRL, G4_DWT_CTRL_CYCCNTENA);
}

void g4_delay_cycles(uint32_t n)
{
    const uint32_t t0 = g4_cycles();
    while (g4_cycles() - t0 < n) {
    }
}

bool g4_wait_bits(uintptr_t reg, uint32_t mask, uint32_t want, uint32_t timeout_cycles)
{
    const uint32_t t0 = g4_cycles();
    for (;;) {
        if ((g4_rd(reg) & mask) == want) {
            return true;
        }
        if (g4_cycles() - t0 > timeout_cycles) {
            /* One last look: the condition may have become true meanwhile. */
            return (g4_rd(reg) & mask) == want;
        }
    }
}

void g4_nvic_set_priority(uint32_t irq, uint32_t prio)
{
    const uint32_t sh = G4_NVIC_IPR_SHIFT(irq);
    g4_mod(G4_NVIC + G4_NVIC_IPR_WORD(irq), 0xFu << sh, (prio & 0xFu) << sh);
}

void g4_pendsv_set_priority(uint32_t prio)
{
    g4_mod(G4_SCB + G4_SCB_SHPR3, 0xFu << G4_SCB_SHPR3_PENDSV_SHIFT,
           (prio & 0xFu) << G4_SCB_SHPR3_PENDSV_SHIFT);
}

void g4_nvic_enable(uint32_t irq)
{
    /* What the main loop stored for the handler (a reconfiguration under
     * hal_ctrl_hold) before the handler can run: a compiler barrier, as the
     * volatile register store orders only volatile accesses. The core keeps
     * its own stores in order for its interrupts. */
    atomic_signal_fence(memory_order_release);
    g4_wr(G4_NVIC + G4_NVIC_ISER(irq / 32u), 1u << (irq % 32u));
}

void g4_nvic_disable(uint32_t irq)
{
    g4_wr(G4_NVIC + G4_NVIC_ICER(irq / 32u), 1u << (irq % 32u));
#if !defined(G4_MEM_ARRAYS)
    /* masked before the next instruction (ARMv7-M ARM B3.4: the write's
     * effect is guaranteed only after a DSB and an ISB) */
    __asm__ volatile("dsb\n\tisb" ::: "memory");
#endif
    /* ... and nothing after it moved before it by the compiler. */
    atomic_signal_fence(memory_order_acquire);
}

bool g4_nvic_enabled(uint32_t irq)
{
    return (g4_rd(G4_NVIC + G4_NVIC_ISER(irq / 32u)) & (1u << (irq % 32u))) != 0u;
}
