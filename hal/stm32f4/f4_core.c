/* Cortex-M4 core services (f4_core.h). */
#include "f4_core.h"

const char *f4_strerror(int rc)
{
    switch (rc) {
    case F4_OK:
        return "ok";
    case F4_E_CONFIG:
        return "value has no register encoding";
    case F4_E_HSE:
        return "HSE crystal not ready";
    case F4_E_PLL:
        return "PLL not locked";
    case F4_E_SWITCH:
        return "system clock switch not confirmed";
    case F4_E_FLASH:
        return "flash latency not taken";
    case F4_E_PWR:
        return "voltage scaling not in scale 1";
    case F4_E_SPI:
        return "SPI transfer timed out";
    case F4_E_ADC:
        return "ADC conversion timed out";
    case F4_E_LSI:
        return "LSI not running (IWDG_SR, RCC_CSR.LSIRDY): no watchdog";
    case F4_E_TIM:
        return "TIM1 update not at the counter peak";
    case F4_E_RANGE:
        return "measured value out of range";
    case F4_E_DRIVER:
        return "gate driver not configured";
    case F4_E_CLOCK:
        return "running on the fall-back clock";
    default:
        return "unknown";
    }
}

void f4_cycle_counter_init(void)
{
    f4_set(F4_SCB + F4_SCB_DEMCR, F4_SCB_DEMCR_TRCENA);
    f4_wr(F4_DWT + F4_DWT_CYCCNT, 0u);
    f4_set(F4_DWT + F4_DWT_CTRL, F4_DWT_CTRL_CYCCNTENA);
}

void f4_delay_cycles(uint32_t n)
{
    const uint32_t t0 = f4_cycles();
    for (uint32_t polls = n / F4_POLL_MIN_CYCLES; polls > 0u; polls--) {
        if (f4_cycles() - t0 >= n) {
            return;
        }
    }
}

bool f4_wait_bits(uintptr_t reg, uint32_t mask, uint32_t want, uint32_t timeout_cycles)
{
    const uint32_t t0 = f4_cycles();
    for (uint32_t polls = timeout_cycles / F4_POLL_MIN_CYCLES + 1u; polls > 0u; polls--) {
        if ((f4_rd(reg) & mask) == want) {
            return true;
        }
        if (f4_cycles() - t0 > timeout_cycles) {
            break;
        }
    }
    /* One last look: the condition may have become true meanwhile. */
    return (f4_rd(reg) & mask) == want;
}

void f4_nvic_set_priority(uint32_t irq, uint32_t prio)
{
    const uint32_t sh = F4_NVIC_IPR_SHIFT(irq);
    f4_mod(F4_NVIC + F4_NVIC_IPR_WORD(irq), 0xFu << sh, (prio & 0xFu) << sh);
}

void f4_pendsv_set_priority(uint32_t prio)
{
    f4_mod(F4_SCB + F4_SCB_SHPR3, 0xFu << F4_SCB_SHPR3_PENDSV_SHIFT,
           (prio & 0xFu) << F4_SCB_SHPR3_PENDSV_SHIFT);
}

void f4_nvic_enable(uint32_t irq)
{
    f4_wr(F4_NVIC + F4_NVIC_ISER(irq / 32u), 1u << (irq % 32u));
}

void f4_nvic_disable(uint32_t irq)
{
    f4_wr(F4_NVIC + F4_NVIC_ICER(irq / 32u), 1u << (irq % 32u));
}

bool f4_nvic_enabled(uint32_t irq)
{
    return (f4_rd(F4_NVIC + F4_NVIC_ISER(irq / 32u)) & (1u << (irq % 32u))) != 0u;
}
