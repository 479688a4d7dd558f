/*
 * System clock of the STM32F405/407: HSE crystal -> main PLL -> SYSCLK
 * (RM0090 sec. 6.2 "Clocks", sec. 7.3.2 RCC_PLLCFGR):
 *
 *   f_VCO_in = f_HSE / M    M 2..63, 1..2 MHz (2 MHz recommended: less jitter)
 *   f_VCO    = f_VCO_in x N N 50..432, 100..432 MHz
 *   f_SYSCLK = f_VCO / P    P 2, 4, 6, 8; at most 168 MHz
 *   f_USB    = f_VCO / Q    Q 2..15, 48 MHz when the VCO allows it
 * AHB /1 (HCLK = SYSCLK), APB1 /4 (PCLK1 <= 42 MHz), APB2 /2 (PCLK2 <= 84
 * MHz): the bus limits of the STM32F405 datasheet (DS8626, "general operating
 * conditions"); the timers on a divided APB run at twice its clock (RM0090
 * sec. 6.2, clock tree: "if the APB prescaler is 1, x1, else x2"), so TIM1
 * counts at 168 MHz and TIM2..5 at 84 MHz. The same factors are used by
 * VESC (hwconf/mcuconf.h: M 8, N 336, P 2, Q 7, PPRE1 /4, PPRE2 /2) and ODrive
 * v3 (Board/v3/Src/main.c: M 4, N 168, P 2, Q 7, FLASH_LATENCY_5).
 *
 * Flash wait states (RM0090 sec. 3.5.1, table 10, 2.7 V .. 3.6 V): 0 WS up to
 * 30 MHz, then one more per 30 MHz: 5 WS at 168 MHz.
 */
#ifndef HAL_STM32F4_F4_CLOCK_H
#define HAL_STM32F4_F4_CLOCK_H

#include <stdbool.h>
#include <stdint.h>

#define F4_HSI_HZ 16000000u /* HSI RC, the clock after reset */
#define F4_SYSCLK_MAX_HZ 168000000u
#define F4_PCLK1_MAX_HZ 42000000u
#define F4_PCLK2_MAX_HZ 84000000u

typedef struct {
    uint32_t m, n, p, q; /* divider / multiplier values (not register codes) */
    uint32_t vco_in_hz;  /* f_HSE / M */
    uint32_t vco_hz;     /* f_VCO */
    uint32_t sysclk_hz;  /* f_VCO / P, exactly the requested frequency */
} f4_pll_t;

/* The clocks the board runs on (after f4_clock_init, or the fall-back). */
typedef struct {
    uint32_t sysclk_hz; /* = HCLK = the core clock */
    uint32_t pclk1_hz, pclk2_hz;
    uint32_t tim_apb1_hz, tim_apb2_hz; /* timer clocks of the APB1 / APB2 timers */
    bool pll;                          /* false: HSI 16 MHz, every bus /1 */
} f4_clocks_t;

/* Finds M, N, P, Q that give exactly sysclk_hz from hse_hz within the limits
 * above: VCO input 2 MHz when possible (else the largest from 1 MHz up), the
 * smallest P; Q for 48 MHz if one divides, else the smallest Q that keeps
 * f_USB <= 48 MHz. F4_OK or F4_E_CONFIG. */
int f4_pll_solve(uint32_t hse_hz, uint32_t sysclk_hz, f4_pll_t *pll);

/* RCC_PLLCFGR value for HSE as PLL source (bit 29, reserved, kept at its
 * reset value 1). */
uint32_t f4_pll_cfgr(const f4_pll_t *pll);

/* Flash wait states for an HCLK frequency at 2.7 .. 3.6 V (0 .. 7), or -1
 * above 168 MHz. */
int f4_flash_latency(uint32_t hclk_hz);

/* The APB prescalers' register codes for a divider (1, 2, 4, 8, 16), or -1. */
int f4_ppre_code(uint32_t div);

/* The clocks of the fall-back (HSI 16 MHz, every prescaler /1). */
void f4_clocks_hsi(f4_clocks_t *c);

/* Switches the system clock to the PLL from the HSE crystal, in the order of
 * RM0090 sec. 6.3 / ST's HAL_RCC_OscConfig and HAL_RCC_ClockConfig: power
 * interface clock and voltage scale 1 (its reset value), HSE on, PLL
 * configured while off, PLL on, wait states (read back), APB prescalers,
 * switch to the PLL (SWS confirms it), then the clock security system (an HSE
 * failure raises the NMI). Every wait has a time-out counted at the HSI's
 * 16 MHz (f4_core.h); on any failure the system stays on (or returns to)
 * HSI 16 MHz with every prescaler /1, *out describes that, and the error is
 * returned (the board then never arms). */
int f4_clock_init(uint32_t hse_hz, uint32_t sysclk_hz, f4_clocks_t *out);

#endif /* HAL_STM32F4_F4_CLOCK_H */
