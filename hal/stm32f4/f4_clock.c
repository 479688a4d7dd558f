/* System clock: PLL factors, flash latency, the switch sequence (f4_clock.h). */
#include "f4_clock.h"

#include "f4_core.h"
#include "f4_regs.h"

#define F4_PLL_M_MIN 2u
#define F4_PLL_M_MAX 63u
#define F4_PLL_N_MIN 50u
#define F4_PLL_N_MAX 432u
#define F4_PLL_Q_MIN 2u
#define F4_PLL_Q_MAX 15u
#define F4_VCO_IN_MIN_HZ 1000000u
#define F4_VCO_IN_MAX_HZ 2000000u
#define F4_VCO_MIN_HZ 100000000u
#define F4_VCO_MAX_HZ 432000000u
#define F4_USB_HZ 48000000u
#define F4_FLASH_WS_STEP_HZ 30000000u /* table 10, 2.7 .. 3.6 V */

/* Time-outs in core cycles at HSI 16 MHz: HSE start-up 100 ms (a crystal's
 * start-up time is a few ms: DS8626 "HSE 4-26 MHz oscillator
 * characteristics", t_SU(HSE) 2 ms typical), PLL lock 10 ms (DS8626 "Main PLL
 * characteristics", t_LOCK <= 300 us), clock switch 1 ms. */
#define F4_TIMEOUT_HSE (F4_HSI_HZ / 10u)
#define F4_TIMEOUT_PLL (F4_HSI_HZ / 100u)
#define F4_TIMEOUT_SHORT (F4_HSI_HZ / 1000u)

int f4_pll_solve(uint32_t hse_hz, uint32_t sysclk_hz, f4_pll_t *pll)
{
    if (pll == 0 || hse_hz == 0u || sysclk_hz == 0u || sysclk_hz > F4_SYSCLK_MAX_HZ) {
        return F4_E_CONFIG;
    }
    /* The VCO input from 2 MHz down: the highest input first (ST's
     * recommendation), i.e. the smallest M. */
    for (uint32_t m = F4_PLL_M_MIN; m <= F4_PLL_M_MAX; m++) {
        if (hse_hz % m != 0u) {
            continue;
        }
        const uint32_t vin = hse_hz / m;
        if (vin < F4_VCO_IN_MIN_HZ || vin > F4_VCO_IN_MAX_HZ) {
            continue;
        }
        for (uint32_t p = 2u; p <= 8u; p += 2u) {
            const uint64_t vco = (uint64_t)sysclk_hz * p;
            if (vco % vin != 0u || vco < F4_VCO_MIN_HZ || vco > F4_VCO_MAX_HZ) {
                continue;
            }
            const uint64_t n = vco / vin;
            if (n < F4_PLL_N_MIN || n > F4_PLL_N_MAX) {
                continue;
            }
            uint32_t q = (uint32_t)((vco + F4_USB_HZ - 1u) / F4_USB_HZ);
            if (q < F4_PLL_Q_MIN) {
                q = F4_PLL_Q_MIN;
            }
            if (q > F4_PLL_Q_MAX) {
                continue;
            }
            pll->m = m;
            pll->n = (uint32_t)n;
            pll->p = p;
            pll->q = q;
            pll->vco_in_hz = vin;
            pll->vco_hz = (uint32_t)vco;
            pll->sysclk_hz = sysclk_hz;
            return F4_OK;
        }
    }
    return F4_E_CONFIG;
}

uint32_t f4_pll_cfgr(const f4_pll_t *pll)
{
    /* PLLP code = P / 2 - 1; bit 29 reserved, reset value 1 (sec. 7.3.2:
     * "keep at reset value"). */
    return F4_BIT(29) | F4_RCC_PLLCFGR_PLLSRC_HSE | F4_FIELD(pll->m, F4_RCC_PLLCFGR_PLLM_POS) |
           F4_FIELD(pll->n, F4_RCC_PLLCFGR_PLLN_POS) |
           F4_FIELD(pll->p / 2u - 1u, F4_RCC_PLLCFGR_PLLP_POS) |
           F4_FIELD(pll->q, F4_RCC_PLLCFGR_PLLQ_POS);
}

int f4_flash_latency(uint32_t hclk_hz)
{
    if (hclk_hz > F4_SYSCLK_MAX_HZ) {
        return -1;
    }
    return (int)((hclk_hz - (hclk_hz > 0u ? 1u : 0u)) / F4_FLASH_WS_STEP_HZ);
}

int f4_ppre_code(uint32_t div)
{
    switch (div) {
    case 1u:
        return 0;
    case 2u:
        return 4;
    case 4u:
        return 5;
    case 8u:
        return 6;
    case 16u:
        return 7;
    default:
        return -1;
    }
}

void f4_clocks_hsi(f4_clocks_t *c)
{
    c->sysclk_hz = c->pclk1_hz = c->pclk2_hz = F4_HSI_HZ;
    c->tim_apb1_hz = c->tim_apb2_hz = F4_HSI_HZ;
    c->pll = false;
}

/* Back to HSI with every prescaler /1 (the clock the fall-back reports),
 * HSE and PLL off. */
static void f4_clock_fall_back(void)
{
    f4_mod(F4_RCC + F4_RCC_CFGR, F4_RCC_CFGR_SW_MASK, F4_RCC_CFGR_SW_HSI);
    (void)f4_wait_bits(F4_RCC + F4_RCC_CFGR, F4_RCC_CFGR_SWS_MASK, F4_RCC_CFGR_SWS_HSI,
                       F4_TIMEOUT_SHORT);
    f4_mod(F4_RCC + F4_RCC_CFGR,
           F4_RCC_CFGR_HPRE_MASK | F4_RCC_CFGR_PPRE1_MASK | F4_RCC_CFGR_PPRE2_MASK, 0u);
    f4_clr(F4_RCC + F4_RCC_CR, F4_RCC_CR_PLLON | F4_RCC_CR_HSEON);
}

int f4_clock_init(uint32_t hse_hz, uint32_t sysclk_hz, f4_clocks_t *out)
{
    f4_clocks_hsi(out);
    f4_pll_t pll;
    if (f4_pll_solve(hse_hz, sysclk_hz, &pll) != F4_OK) {
        return F4_E_CONFIG;
    }
    const int ws = f4_flash_latency(sysclk_hz);
    /* APB1 <= 42 MHz, APB2 <= 84 MHz: the smallest dividers. */
    uint32_t div1 = 1u, div2 = 1u;
    while (sysclk_hz / div1 > F4_PCLK1_MAX_HZ) {
        div1 *= 2u;
    }
    while (sysclk_hz / div2 > F4_PCLK2_MAX_HZ) {
        div2 *= 2u;
    }
    const int ppre1 = f4_ppre_code(div1), ppre2 = f4_ppre_code(div2);
    if (ws < 0 || ppre1 < 0 || ppre2 < 0) {
        return F4_E_CONFIG;
    }
    /* Voltage scale 1 (PWR_CR.VOS = 1, its reset value on the F405/407):
     * needed above 144 MHz (sec. 5.1.4); written while the PLL is off, read
     * back once it runs. */
    f4_rcc_enable(F4_RCC_APB1ENR, F4_RCC_APB1ENR_PWREN);
    f4_set(F4_PWR + F4_PWR_CR, F4_PWR_CR_VOS);
    /* HSE crystal (not bypass). */
    f4_set(F4_RCC + F4_RCC_CR, F4_RCC_CR_HSEON);
    if (!f4_wait_bits(F4_RCC + F4_RCC_CR, F4_RCC_CR_HSERDY, F4_RCC_CR_HSERDY, F4_TIMEOUT_HSE)) {
        f4_clock_fall_back();
        return F4_E_HSE;
    }
    /* PLL: configured while off (sec. 7.3.2: "written only when the PLL is
     * disabled"), then on. */
    f4_clr(F4_RCC + F4_RCC_CR, F4_RCC_CR_PLLON);
    if (!f4_wait_bits(F4_RCC + F4_RCC_CR, F4_RCC_CR_PLLRDY, 0u, F4_TIMEOUT_SHORT)) {
        f4_clock_fall_back();
        return F4_E_PLL;
    }
    f4_wr(F4_RCC + F4_RCC_PLLCFGR, f4_pll_cfgr(&pll));
    f4_set(F4_RCC + F4_RCC_CR, F4_RCC_CR_PLLON);
    if (!f4_wait_bits(F4_RCC + F4_RCC_CR, F4_RCC_CR_PLLRDY, F4_RCC_CR_PLLRDY, F4_TIMEOUT_PLL)) {
        f4_clock_fall_back();
        return F4_E_PLL;
    }
    if ((f4_rd(F4_PWR + F4_PWR_CR) & F4_PWR_CR_VOS) == 0u) {
        f4_clock_fall_back();
        return F4_E_PWR;
    }
    /* Wait states before the frequency rises (sec. 3.5.1: "check that the
     * new number of wait states is taken into account by reading
     * FLASH_ACR"); prefetch and both caches on. */
    f4_mod(F4_FLASH + F4_FLASH_ACR,
           F4_FLASH_ACR_LATENCY_MASK | F4_FLASH_ACR_PRFTEN | F4_FLASH_ACR_ICEN | F4_FLASH_ACR_DCEN,
           (uint32_t)ws | F4_FLASH_ACR_PRFTEN | F4_FLASH_ACR_ICEN | F4_FLASH_ACR_DCEN);
    if ((f4_rd(F4_FLASH + F4_FLASH_ACR) & F4_FLASH_ACR_LATENCY_MASK) != (uint32_t)ws) {
        f4_clock_fall_back();
        return F4_E_FLASH;
    }
    /* The bus dividers before the switch (the buses never run above their
     * limits), then SYSCLK = PLL. */
    f4_mod(F4_RCC + F4_RCC_CFGR,
           F4_RCC_CFGR_HPRE_MASK | F4_RCC_CFGR_PPRE1_MASK | F4_RCC_CFGR_PPRE2_MASK,
           F4_FIELD((uint32_t)ppre1, F4_RCC_CFGR_PPRE1_POS) |
               F4_FIELD((uint32_t)ppre2, F4_RCC_CFGR_PPRE2_POS));
    f4_mod(F4_RCC + F4_RCC_CFGR, F4_RCC_CFGR_SW_MASK, F4_RCC_CFGR_SW_PLL);
    if (!f4_wait_bits(F4_RCC + F4_RCC_CFGR, F4_RCC_CFGR_SWS_MASK, F4_RCC_CFGR_SWS_PLL,
                      F4_TIMEOUT_SHORT)) {
        f4_clock_fall_back();
        return F4_E_SWITCH;
    }
    /* Clock security system: an HSE failure switches to HSI and raises the
     * NMI (sec. 7.2.7), whose handler turns the gates off. */
    f4_set(F4_RCC + F4_RCC_CR, F4_RCC_CR_CSSON);
    out->sysclk_hz = sysclk_hz;
    out->pclk1_hz = sysclk_hz / div1;
    out->pclk2_hz = sysclk_hz / div2;
    out->tim_apb1_hz = div1 == 1u ? out->pclk1_hz : 2u * out->pclk1_hz;
    out->tim_apb2_hz = div2 == 1u ? out->pclk2_hz : 2u * out->pclk2_hz;
    out->pll = true;
    return F4_OK;
}
