/* System clock: PLL factors, flash latency, the switch sequence (g4_clock.h). */
#include "g4_clock.h"

#include "g4_core.h"
#include "g4_regs.h"

#define G4_PLL_M_MAX 16u
#define G4_PLL_N_MIN 8u
#define G4_PLL_N_MAX 127u
#define G4_VCO_IN_MIN_HZ 2660000u
#define G4_VCO_IN_MAX_HZ 16000000u
#define G4_VCO_MIN_HZ 64000000u
#define G4_VCO_MAX_HZ 344000000u

/* Time-outs in core cycles, counted at the clock running during the wait
 * (HSI16 before the switch): HSE start-up 100 ms (the crystal's start-up
 * time is a few ms), PLL lock 10 ms, clock switch and VOSF 1 ms. */
#define G4_TIMEOUT_HSE (G4_HSI_HZ / 10u)
#define G4_TIMEOUT_PLL (G4_HSI_HZ / 100u)
#define G4_TIMEOUT_SHORT (G4_HSI_HZ / 1000u)
/* >= 1 us at the intermediate HCLK (sysclk / 2 <= 85 MHz): 200 cycles. */
#define G4_AHB_STEP_CYCLES 200u

int g4_pll_solve(uint32_t hse_hz, uint32_t sysclk_hz, g4_pll_t *pll)
{
    if (pll == 0 || hse_hz == 0u || sysclk_hz == 0u || sysclk_hz > G4_SYSCLK_MAX_HZ) {
        return G4_E_CONFIG;
    }
    static const uint32_t r_values[4] = {2u, 4u, 6u, 8u};
    for (uint32_t m = 1u; m <= G4_PLL_M_MAX; m++) {
        if (hse_hz % m != 0u) {
            continue;
        }
        const uint32_t vin = hse_hz / m;
        if (vin < G4_VCO_IN_MIN_HZ || vin > G4_VCO_IN_MAX_HZ) {
            continue;
        }
        for (unsigned i = 0; i < 4u; i++) {
            const uint64_t vco = (uint64_t)sysclk_hz * r_values[i];
            if (vco % vin != 0u) {
                continue;
            }
            const uint64_t n = vco / vin;
            if (n < G4_PLL_N_MIN || n > G4_PLL_N_MAX || vco < G4_VCO_MIN_HZ ||
                vco > G4_VCO_MAX_HZ) {
                continue;
            }
            pll->m = m;
            pll->n = (uint32_t)n;
            pll->r = r_values[i];
            pll->vco_in_hz = vin;
            pll->vco_hz = (uint32_t)vco;
            pll->sysclk_hz = sysclk_hz;
            return G4_OK;
        }
    }
    return G4_E_CONFIG;
}

uint32_t g4_pll_cfgr(const g4_pll_t *pll)
{
    /* PLLM field = M - 1; PLLR code = R / 2 - 1. */
    return G4_RCC_PLLCFGR_PLLSRC_HSE | G4_FIELD(pll->m - 1u, G4_RCC_PLLCFGR_PLLM_POS) |
           G4_FIELD(pll->n, G4_RCC_PLLCFGR_PLLN_POS) |
           G4_FIELD(pll->r / 2u - 1u, G4_RCC_PLLCFGR_PLLR_POS) | G4_RCC_PLLCFGR_PLLREN;
}

int g4_flash_latency(uint32_t hclk_hz, bool boost)
{
    const uint32_t step = boost ? 34000000u : 30000000u;
    for (int ws = 0; ws <= 4; ws++) {
        if (hclk_hz <= step * (uint32_t)(ws + 1)) {
            return ws;
        }
    }
    return -1;
}

int g4_clock_init(uint32_t hse_hz, uint32_t sysclk_hz)
{
    g4_pll_t pll;
    if (g4_pll_solve(hse_hz, sysclk_hz, &pll) != G4_OK) {
        return G4_E_CONFIG;
    }
    const bool boost = sysclk_hz > G4_BOOST_ABOVE_HZ;
    const int ws = g4_flash_latency(sysclk_hz, boost);
    if (ws < 0) {
        return G4_E_CONFIG;
    }
    /* Voltage scaling: range 1 is the reset value; boost mode (R1MODE = 0)
     * before the frequency goes above 150 MHz. */
    g4_set(G4_RCC + G4_RCC_APB1ENR1, G4_RCC_APB1ENR1_PWREN);
    if ((g4_rd(G4_PWR + G4_PWR_CR1) & G4_PWR_CR1_VOS_MASK) != G4_PWR_CR1_VOS_RANGE1) {
        return G4_E_PWR;
    }
    if (boost) {
        g4_clr(G4_PWR + G4_PWR_CR5, G4_PWR_CR5_R1MODE);
    }
    if (!g4_wait_bits(G4_PWR + G4_PWR_SR2, G4_PWR_SR2_VOSF, 0u, G4_TIMEOUT_SHORT)) {
        return G4_E_PWR;
    }
    /* HSE crystal (not bypass). */
    g4_set(G4_RCC + G4_RCC_CR, G4_RCC_CR_HSEON);
    if (!g4_wait_bits(G4_RCC + G4_RCC_CR, G4_RCC_CR_HSERDY, G4_RCC_CR_HSERDY, G4_TIMEOUT_HSE)) {
        g4_clr(G4_RCC + G4_RCC_CR, G4_RCC_CR_HSEON);
        return G4_E_HSE;
    }
    /* PLL: configured while off, then on. */
    g4_clr(G4_RCC + G4_RCC_CR, G4_RCC_CR_PLLON);
    if (!g4_wait_bits(G4_RCC + G4_RCC_CR, G4_RCC_CR_PLLRDY, 0u, G4_TIMEOUT_SHORT)) {
        return G4_E_PLL;
    }
    g4_wr(G4_RCC + G4_RCC_PLLCFGR, g4_pll_cfgr(&pll));
    g4_set(G4_RCC + G4_RCC_CR, G4_RCC_CR_PLLON);
    if (!g4_wait_bits(G4_RCC + G4_RCC_CR, G4_RCC_CR_PLLRDY, G4_RCC_CR_PLLRDY, G4_TIMEOUT_PLL)) {
        return G4_E_PLL;
    }
    /* Wait states before the frequency rises; read back (RM0440: check that
     * the new latency is taken into account by reading FLASH_ACR). Only the
     * latency and cache bits change: the register also holds DBG_SWEN (reset
     * value 1), and clearing it locks the debugger out. */
    g4_mod(G4_FLASH + G4_FLASH_ACR,
           G4_FLASH_ACR_LATENCY_MASK | G4_FLASH_ACR_PRFTEN | G4_FLASH_ACR_ICEN | G4_FLASH_ACR_DCEN,
           (uint32_t)ws | G4_FLASH_ACR_PRFTEN | G4_FLASH_ACR_ICEN | G4_FLASH_ACR_DCEN);
    if ((g4_rd(G4_FLASH + G4_FLASH_ACR) & G4_FLASH_ACR_LATENCY_MASK) != (uint32_t)ws) {
        return G4_E_FLASH;
    }
    /* Above 80 MHz the switch goes through AHB / 2 for at least 1 us
     * (current step on the regulator). APB1 = APB2 = HCLK. */
    g4_mod(G4_RCC + G4_RCC_CFGR,
           G4_RCC_CFGR_HPRE_MASK | G4_RCC_CFGR_PPRE1_MASK | G4_RCC_CFGR_PPRE2_MASK,
           G4_RCC_CFGR_HPRE_DIV2);
    g4_mod(G4_RCC + G4_RCC_CFGR, G4_RCC_CFGR_SW_MASK, G4_RCC_CFGR_SW_PLL);
    if (!g4_wait_bits(G4_RCC + G4_RCC_CFGR, G4_RCC_CFGR_SWS_MASK, G4_RCC_CFGR_SWS_PLL,
                      G4_TIMEOUT_SHORT)) {
        /* Back to HSI16 at AHB / 1, the clock the caller falls back to (its
         * serial port's baud rate): a switch that completed late would
         * otherwise leave the core on the PLL at half speed. */
        g4_mod(G4_RCC + G4_RCC_CFGR, G4_RCC_CFGR_SW_MASK, G4_RCC_CFGR_SW_HSI);
        (void)g4_wait_bits(G4_RCC + G4_RCC_CFGR, G4_RCC_CFGR_SWS_MASK, G4_RCC_CFGR_SWS_HSI,
                           G4_TIMEOUT_SHORT);
        g4_mod(G4_RCC + G4_RCC_CFGR, G4_RCC_CFGR_HPRE_MASK, G4_RCC_CFGR_HPRE_DIV1);
        return G4_E_SWITCH;
    }
    g4_delay_cycles(G4_AHB_STEP_CYCLES);
    g4_mod(G4_RCC + G4_RCC_CFGR, G4_RCC_CFGR_HPRE_MASK, G4_RCC_CFGR_HPRE_DIV1);
    /* Clock security system: HSE failure -> NMI (+ TIM1 system break). */
    g4_set(G4_RCC + G4_RCC_CR, G4_RCC_CR_CSSON);
    return G4_OK;
}
