/*
 * System clock of the STM32G4: HSE crystal -> main PLL -> SYSCLK = HCLK =
 * PCLK1 = PCLK2 (RM0440 RCC chapter, "Clock tree").
 *
 *   f_VCO    = f_HSE / M * N          M 1..16, N 8..127
 *   f_SYSCLK = f_VCO / R              R 2, 4, 6, 8
 * with 2.66 MHz <= f_HSE / M <= 16 MHz and 64 MHz <= f_VCO <= 344 MHz
 * (RCC_PLLCFGR field descriptions; the same limits are in ST's LL driver,
 * stm32g4xx_ll_utils.c UTILS_PLLVCO_*), f_SYSCLK <= 170 MHz in range-1 boost
 * mode, <= 150 MHz in range-1 normal mode.
 *
 * Flash wait states (RM0440 FLASH chapter, table "Number of wait states
 * according to CPU clock (HCLK) frequency"): range-1 boost mode
 * 0 WS <= 34 MHz, 1 <= 68, 2 <= 102, 3 <= 136, 4 <= 170 MHz; range-1 normal
 * mode 30/60/90/120/150 MHz.
 */
#ifndef HAL_STM32G4_G4_CLOCK_H
#define HAL_STM32G4_G4_CLOCK_H

#include <stdbool.h>
#include <stdint.h>

#define G4_HSI_HZ 16000000u /* HSI16, the clock after reset */
#define G4_SYSCLK_MAX_HZ 170000000u
#define G4_BOOST_ABOVE_HZ 150000000u /* range-1 normal mode limit */

typedef struct {
    uint32_t m, n, r;   /* divider / multiplier values (not register codes) */
    uint32_t vco_in_hz; /* f_HSE / M */
    uint32_t vco_hz;    /* f_VCO */
    uint32_t sysclk_hz; /* f_VCO / R, exactly the requested frequency */
} g4_pll_t;

/* Finds M, N, R that give exactly sysclk_hz from hse_hz within the limits
 * above (smallest M, then smallest R). G4_OK or G4_E_CONFIG. */
int g4_pll_solve(uint32_t hse_hz, uint32_t sysclk_hz, g4_pll_t *pll);

/* RCC_PLLCFGR value for HSE as PLL source and PLLR enabled. */
uint32_t g4_pll_cfgr(const g4_pll_t *pll);

/* Flash wait states for an HCLK frequency (boost: range-1 boost mode).
 * Returns 0..4, or -1 above the mode's limit. */
int g4_flash_latency(uint32_t hclk_hz, bool boost);

/* Switches the system clock to the PLL from the HSE crystal (the order of
 * RM0440 "Dynamic voltage scaling management" and ST's HAL_RCC_ClockConfig):
 * boost mode when needed, HSE on, PLL on, wait states, AHB /2, switch to PLL,
 * >= 1 us at the intermediate clock, AHB /1; then the clock security system
 * (an HSE failure raises NMI and, by hardware, the TIM1 system break).
 * Every wait has a time-out; on failure the system stays on HSI16 and the
 * error is returned (the board then never arms: no PWM is started).
 * Needs the DWT cycle counter (g4_cycle_counter_init) for the time-outs. */
int g4_clock_init(uint32_t hse_hz, uint32_t sysclk_hz);

#endif /* HAL_STM32G4_G4_CLOCK_H */
