/*
 * Register image of the STM32F405 chip support on the VESC 6 and ODrive v3.6
 * descriptions, built with the peripheral base addresses pointing into
 * arrays (f4_model.h, every register at its RM0090 reset value): the clock
 * and board start-up must end with the register values below (each worked
 * out from the RM0090 bit fields in the comment) and make their writes in
 * the order RM0090 and the DRV8301 data sheet require (each order check
 * names the rule); the gate driver over the model of its SPI interface
 * (drv8301_model.h): configured and read back, silent, refusing a bit,
 * faulted; then the run-time functions of hal.h on the same registers.
 */
#include <math.h>
#include <string.h>

#include "board_odrive_v36.h"
#include "board_vesc6.h"
#include "drv8301_model.h"
#include "f4_adc.h"
#include "f4_clock.h"
#include "f4_core.h"
#include "f4_hal.h"
#include "f4_model.h"
#include "f4_periph.h"
#include "f4_tim.h"
#include "unity.h"

/* Every bit of mask set / clear in v. */
#define ASSERT_BITS_SET(mask, v) TEST_ASSERT_EQUAL_HEX32((mask), (v) & (mask))
#define ASSERT_BITS_CLEAR(mask, v) TEST_ASSERT_EQUAL_HEX32(0u, (v) & (mask))

static hal_t hal;
static f4_clocks_t clk;
static const f4_hal_cfg_t cfg20k = {20000u, 4096u};

void setUp(void)
{
    f4_model_reset();
    f4_cycle_counter_init();
}

void tearDown(void)
{
}

static uint32_t reg(uintptr_t r)
{
    return f4_model_get(r);
}

/* "a happens before b" with both present. */
static void assert_before(int a, int b, const char *rule)
{
    TEST_ASSERT_TRUE_MESSAGE(a >= 0, rule);
    TEST_ASSERT_TRUE_MESSAGE(b >= 0, rule);
    TEST_ASSERT_TRUE_MESSAGE(a < b, rule);
}

/* Index of the first BSRR write that sets (high) or resets a pin. */
static int pin_write(f4_pin_t p, bool high, int from)
{
    const uint32_t bit = high ? F4_BIT(p.pin) : F4_BIT(p.pin + 16u);
    return f4_model_find(f4_gpio_base(p.port) + F4_GPIO_BSRR, bit, bit, from);
}

static void attach_drv(const f4_board_t *b)
{
    drv8301_model_attach(b->en_gate, b->drv_cs, b->nfault, b->drv_spi);
}

/* Every peripheral clock enable read back before any other access (ST
 * erratum ES0182, "Delay after an RCC peripheral clock enabling"). */
static void assert_rcc_synced(void)
{
    TEST_ASSERT_EQUAL_UINT32_MESSAGE(0u, f4_model.rcc_enable_unsynced,
                                     "an access right after an RCC clock enable (ES0182)");
}

static int board_init(const f4_board_t *b)
{
    int rc = f4_clock_init(b->hse_hz, b->sysclk_hz, &clk);
    TEST_ASSERT_EQUAL_INT(F4_OK, rc);
    rc = f4_hal_init(&hal, b, &cfg20k, &clk);
    TEST_ASSERT_FALSE_MESSAGE(f4_model.log_overflow, "write log full");
    assert_rcc_synced();
    return rc;
}

/* ---- clock ---- */

/* End state: PLLCFGR 0x2740_2A04 (test_f4_calc); FLASH_ACR = LATENCY 5 |
 * PRFTEN | ICEN | DCEN = 0x705 (reset value 0); RCC_CFGR SW = 10 (PLL),
 * SWS = 10, PPRE1 = 101 (/4) at 12:10, PPRE2 = 100 (/2) at 15:13, HPRE /1:
 * 0x2 | 0x8 | 0x1400 | 0x8000 = 0x940A; RCC_CR HSEON, PLLON, CSSON on top of
 * HSION | HSIRDY (and the ready flags). Order (RM0090 sec. 7.3.2, 3.5.1,
 * 6.3.3): PLLCFGR written after HSE is on and while the PLL is off, before
 * PLLON; the wait states before the switch; the APB dividers before the
 * switch; CSS after it. */
static void test_clock_image_and_order(void)
{
    TEST_ASSERT_EQUAL_INT(F4_OK, f4_clock_init(8000000u, 168000000u, &clk));
    TEST_ASSERT_EQUAL_HEX32(0x27402A04u, reg(F4_RCC + F4_RCC_PLLCFGR));
    TEST_ASSERT_EQUAL_HEX32(0x00000705u, reg(F4_FLASH + F4_FLASH_ACR));
    TEST_ASSERT_EQUAL_HEX32(0x0000940Au, reg(F4_RCC + F4_RCC_CFGR));
    const uint32_t cr = reg(F4_RCC + F4_RCC_CR);
    ASSERT_BITS_SET(F4_RCC_CR_HSEON | F4_RCC_CR_PLLON | F4_RCC_CR_CSSON | F4_RCC_CR_HSION, cr);
    ASSERT_BITS_SET(F4_PWR_CR_VOS, reg(F4_PWR + F4_PWR_CR));
    const int hse = f4_model_find(F4_RCC + F4_RCC_CR, F4_RCC_CR_HSEON, F4_RCC_CR_HSEON, 0);
    const int pllcfgr = f4_model_find(F4_RCC + F4_RCC_PLLCFGR, 0xFFFFFFFFu, 0x27402A04u, 0);
    const int pllon = f4_model_find(F4_RCC + F4_RCC_CR, F4_RCC_CR_PLLON, F4_RCC_CR_PLLON, 0);
    const int ws = f4_model_find(F4_FLASH + F4_FLASH_ACR, 7u, 5u, 0);
    const int ppre = f4_model_find(F4_RCC + F4_RCC_CFGR, F4_RCC_CFGR_PPRE1_MASK,
                                   F4_FIELD(5u, F4_RCC_CFGR_PPRE1_POS), 0);
    const int sw = f4_model_find(F4_RCC + F4_RCC_CFGR, F4_RCC_CFGR_SW_MASK, F4_RCC_CFGR_SW_PLL, 0);
    const int css = f4_model_find(F4_RCC + F4_RCC_CR, F4_RCC_CR_CSSON, F4_RCC_CR_CSSON, 0);
    assert_before(hse, pllcfgr, "HSE on before the PLL is configured");
    assert_before(pllcfgr, pllon, "PLLCFGR written while the PLL is off");
    assert_before(ws, sw, "wait states raised before the clock (RM0090 3.5.1)");
    assert_before(ppre, sw, "APB dividers before the switch: no bus above its limit");
    assert_before(sw, css, "clock security system once on the HSE");
}

/* Fall-backs: no crystal (QEMU's netduinoplus2 reads RCC as zero, the same
 * case): F4_E_HSE after the time-out, HSE off again, the PLL never on,
 * SW = HSI, every divider /1, the result says HSI 16 MHz. A PLL that never
 * locks: F4_E_PLL, no switch. A switch never confirmed: F4_E_SWITCH, SW back
 * to HSI, dividers /1. Wait states not taken: F4_E_FLASH before any switch
 * (a clock above 30 MHz on 0 WS reads wrong instructions). */
static void test_clock_fall_backs(void)
{
    f4_model.hse_broken = true;
    TEST_ASSERT_EQUAL_INT(F4_E_HSE, f4_clock_init(8000000u, 168000000u, &clk));
    ASSERT_BITS_CLEAR(F4_RCC_CR_HSEON | F4_RCC_CR_PLLON, reg(F4_RCC + F4_RCC_CR));
    TEST_ASSERT_EQUAL_INT(-1,
                          f4_model_find(F4_RCC + F4_RCC_CR, F4_RCC_CR_PLLON, F4_RCC_CR_PLLON, 0));
    TEST_ASSERT_EQUAL_HEX32(0u, reg(F4_RCC + F4_RCC_CFGR) & 0xFFFFu);
    TEST_ASSERT_FALSE(clk.pll);
    TEST_ASSERT_EQUAL_UINT32(16000000u, clk.sysclk_hz);

    f4_model_reset();
    f4_model.pll_broken = true;
    TEST_ASSERT_EQUAL_INT(F4_E_PLL, f4_clock_init(8000000u, 168000000u, &clk));
    TEST_ASSERT_EQUAL_INT(
        -1, f4_model_find(F4_RCC + F4_RCC_CFGR, F4_RCC_CFGR_SW_MASK, F4_RCC_CFGR_SW_PLL, 0));

    f4_model_reset();
    f4_model.sws_stuck = true;
    TEST_ASSERT_EQUAL_INT(F4_E_SWITCH, f4_clock_init(8000000u, 168000000u, &clk));
    TEST_ASSERT_EQUAL_HEX32(F4_RCC_CFGR_SW_HSI, reg(F4_RCC + F4_RCC_CFGR) &
                                                    (F4_RCC_CFGR_SW_MASK | F4_RCC_CFGR_PPRE1_MASK |
                                                     F4_RCC_CFGR_PPRE2_MASK));
    TEST_ASSERT_EQUAL_UINT32(16000000u, clk.pclk1_hz);

    f4_model_reset();
    f4_model.latency_stuck = true;
    TEST_ASSERT_EQUAL_INT(F4_E_FLASH, f4_clock_init(8000000u, 168000000u, &clk));
    TEST_ASSERT_EQUAL_INT(
        -1, f4_model_find(F4_RCC + F4_RCC_CFGR, F4_RCC_CFGR_SW_MASK, F4_RCC_CFGR_SW_PLL, 0));
}

/* ---- board start-up ---- */

/* VESC 6 at 20 kHz, DRV8301 answering. End state:
 *  - DRV8301 control 1 = 0x410 (OC_ADJ 16, latch shut-down), control 2 =
 *    0x004 (gain 20) in the model's registers; EN_GATE (PB5) high;
 *  - TIM1: CR1 = CMS 01 | ARPE | CEN = 0xA1 (and DIR, read-only in
 *    centre-aligned mode: 1 right after the update at the peak); CR2 MMS 010 (TRGO update) =
 *    0x20; CCMR1 = 0x6868, CCMR2 = 0x0068 (PWM mode 1 + preload, CH1..3);
 *    CCER = CC1E|CC1NE|CC2E|CC2NE|CC3E|CC3NE = 0x555; BDTR = DTG 0x3D |
 *    OSSI | OSSR = 0x0C3D (MOE 0, no break: the board has no BKIN); RCR 1;
 *    ARR 4200;
 *  - ADC1 JSQR 0x16A800 (CURR1 ch10, Vbus ch13), ADC2 ch11 = 0x58000, ADC3
 *    ch12 = 0x60000; CR2 of each ADON | JEXTSEL 0001 (TIM1_TRGO) | JEXTEN
 *    01 = 0x0011_0001; ADC1's sequence ends last (two ranks): its CR1 has
 *    JEOCIE: SCAN | JEOCIE = 0x180, the others SCAN 0x100; ADC_CCR ADCPRE
 *    01 (PCLK2 / 4) = 0x10000;
 *  - TIM3 encoder: SMCR 011, CCMR1 IC1/IC2 on TI1/TI2 with filter 0110 =
 *    0x6161, CCMR2 IC3 = 0x61, CCER CC3E (index capture) = 0x100, ARR 0xFFFF;
 *  - nFAULT PB7 on EXTI line 7 falling: SYSCFG_EXTICR2 bits 15:12 = 0001
 *    (port B), FTSR and IMR bit 7;
 *  - gate pins PA8/9/10, PB13/14/15 on AF1; PD2 held low.
 * Order: the gate pins and EN_GATE driven low before anything; EN_GATE low
 * then high (the driver's reset, > 20 us) before the first SPI frame; the
 * control registers written before TIM1 is configured; TIM1's BDTR (MOE 0)
 * before the pins become AF; the counter started last. */
/* The break interrupt as the image has it (TIM1_BRK_TIM9_IRQHandler ->
 * f4_hal_break_irq), BIF latched by the hardware's break; the log index of
 * its write that clears MOE. */
static int break_clear = -1;
static void break_irq(void)
{
    f4_model_put(F4_TIM1 + F4_TIM_SR, f4_model_get(F4_TIM1 + F4_TIM_SR) | F4_TIM_SR_BIF);
    const int from = (int)f4_model.n_log;
    f4_hal_break_irq(&hal);
    break_clear = f4_model_find(F4_TIM1 + F4_TIM_BDTR, F4_TIM_BDTR_MOE, 0u, from);
}

static void test_vesc6_start_up_image(void)
{
    const f4_board_t *b = &f4_board_vesc6;
    attach_drv(b);
    TEST_ASSERT_EQUAL_INT(F4_OK, board_init(b));
    TEST_ASSERT_EQUAL_HEX16(0x410u, drv8301_model.reg[2]);
    TEST_ASSERT_EQUAL_HEX16(0x004u, drv8301_model.reg[3]);
    TEST_ASSERT_TRUE(f4_model_pin_out(1u, 5u));
    TEST_ASSERT_EQUAL_HEX32(0xA1u, reg(F4_TIM1 + F4_TIM_CR1) & 0xEFu);
    TEST_ASSERT_EQUAL_HEX32(0x20u, reg(F4_TIM1 + F4_TIM_CR2));
    TEST_ASSERT_EQUAL_HEX32(0x6868u, reg(F4_TIM1 + F4_TIM_CCMR1));
    TEST_ASSERT_EQUAL_HEX32(0x0068u, reg(F4_TIM1 + F4_TIM_CCMR2));
    TEST_ASSERT_EQUAL_HEX32(0x555u, reg(F4_TIM1 + F4_TIM_CCER));
    TEST_ASSERT_EQUAL_HEX32(0x0C3Du, reg(F4_TIM1 + F4_TIM_BDTR));
    TEST_ASSERT_EQUAL_UINT32(1u, reg(F4_TIM1 + F4_TIM_RCR));
    TEST_ASSERT_EQUAL_UINT32(4200u, reg(F4_TIM1 + F4_TIM_ARR));
    TEST_ASSERT_EQUAL_HEX32(0x0016A800u, reg(F4_ADC1 + F4_ADC_JSQR));
    TEST_ASSERT_EQUAL_HEX32(0x00058000u, reg(F4_ADC2 + F4_ADC_JSQR));
    TEST_ASSERT_EQUAL_HEX32(0x00060000u, reg(F4_ADC3 + F4_ADC_JSQR));
    TEST_ASSERT_EQUAL_HEX32(0x00110001u, reg(F4_ADC1 + F4_ADC_CR2));
    TEST_ASSERT_EQUAL_HEX32(0x00110001u, reg(F4_ADC3 + F4_ADC_CR2));
    TEST_ASSERT_EQUAL_HEX32(0x180u, reg(F4_ADC1 + F4_ADC_CR1));
    TEST_ASSERT_EQUAL_HEX32(0x100u, reg(F4_ADC2 + F4_ADC_CR1));
    TEST_ASSERT_EQUAL_HEX32(0x10000u, reg(F4_ADC_COMMON + F4_ADC_CCR));
    TEST_ASSERT_EQUAL_HEX32(3u, reg(F4_TIM3 + F4_TIM_SMCR));
    TEST_ASSERT_EQUAL_HEX32(0x6161u, reg(F4_TIM3 + F4_TIM_CCMR1));
    TEST_ASSERT_EQUAL_HEX32(0x61u, reg(F4_TIM3 + F4_TIM_CCMR2));
    TEST_ASSERT_EQUAL_HEX32(0x100u, reg(F4_TIM3 + F4_TIM_CCER));
    TEST_ASSERT_EQUAL_HEX32(0x1000u, reg(F4_SYSCFG + F4_SYSCFG_EXTICR(7u)) & 0xF000u);
    ASSERT_BITS_SET(F4_BIT(7), reg(F4_EXTI + F4_EXTI_FTSR));
    ASSERT_BITS_SET(F4_BIT(7), reg(F4_EXTI + F4_EXTI_IMR));
    for (unsigned x = 0; x < 3u; x++) {
        TEST_ASSERT_EQUAL_UINT32(2u, f4_model_pin_mode(b->pwm_high[x].port, b->pwm_high[x].pin));
        TEST_ASSERT_EQUAL_UINT32(1u, f4_model_pin_af(b->pwm_high[x].port, b->pwm_high[x].pin));
        TEST_ASSERT_EQUAL_UINT32(2u, f4_model_pin_mode(b->pwm_low[x].port, b->pwm_low[x].pin));
        TEST_ASSERT_EQUAL_UINT32(1u, f4_model_pin_af(b->pwm_low[x].port, b->pwm_low[x].pin));
    }
    TEST_ASSERT_EQUAL_UINT32(1u, f4_model_pin_mode(3u, 2u));
    TEST_ASSERT_FALSE(f4_model_pin_out(3u, 2u));
    TEST_ASSERT_FALSE(hal_trip_active(&hal));

    const int en_low = pin_write(b->en_gate, false, 0);
    const int gate_low = pin_write(b->pwm_low[0], false, 0);
    const int en_high = pin_write(b->en_gate, true, 0);
    const int first_frame = f4_model_find(F4_SPI3 + F4_SPI_DR, 0u, 0u, 0);
    const int tim1_bdtr = f4_model_find(F4_TIM1 + F4_TIM_BDTR, F4_TIM_BDTR_DTG_MASK, 0x3Du, 0);
    const int pins_af = f4_model_find(F4_GPIOA + F4_GPIO_MODER, 3u << 16, 2u << 16, 0);
    const int cen = f4_model_find(F4_TIM1 + F4_TIM_CR1, F4_TIM_CR1_CEN, F4_TIM_CR1_CEN, 0);
    assert_before(en_low, en_high, "EN_GATE low (driver reset) before it is raised");
    assert_before(gate_low, en_high, "gate inputs inactive before the driver is enabled");
    assert_before(en_high, first_frame, "SPI only with EN_GATE high (it powers the interface)");
    assert_before(first_frame, tim1_bdtr, "driver configured before the PWM is set up");
    assert_before(tim1_bdtr, pins_af, "TIM1 outputs safe (MOE 0) before the pins are TIM1's");
    assert_before(pins_af, cen, "the counter started last");
    TEST_ASSERT_EQUAL_INT(
        -1, f4_model_find(F4_TIM1 + F4_TIM_BDTR, F4_TIM_BDTR_MOE, F4_TIM_BDTR_MOE, 0));
}

/* The arm's MOE against the break interrupt (hal_gate_enable): the break
 * taken right after the arm's read of TIM1_BDTR, inside its read-modify-
 * write. The trip check and the write are one step with the interrupts
 * masked, so the interrupt runs after the write and its clear of MOE is the
 * last word: no write sets MOE after it. Before, the write stored the MOE
 * read before the break, setting it again until the re-check cleared it. */
static void test_break_inside_the_arm_keeps_the_gates_off(void)
{
    const f4_board_t *b = &f4_board_vesc6;
    attach_drv(b);
    TEST_ASSERT_EQUAL_INT(F4_OK, board_init(b));
    TEST_ASSERT_FALSE(hal_trip_active(&hal));
    f4_model.irq_on_read = F4_TIM1 + F4_TIM_BDTR;
    f4_model.irq = break_irq;
    const uint32_t locks = f4_model.n_locks;
    hal_gate_enable(&hal, true);
    TEST_ASSERT_NULL_MESSAGE(f4_model.irq, "the break interrupt was taken");
    TEST_ASSERT_TRUE_MESSAGE(break_clear >= 0, "the interrupt cleared MOE");
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        -1, f4_model_find(F4_TIM1 + F4_TIM_BDTR, F4_TIM_BDTR_MOE, F4_TIM_BDTR_MOE, break_clear),
        "MOE set again after the break interrupt's clear");
    TEST_ASSERT_EQUAL_HEX32(0u, reg(F4_TIM1 + F4_TIM_BDTR) & F4_TIM_BDTR_MOE);
    TEST_ASSERT_TRUE(hal_trip_active(&hal));
    TEST_ASSERT_TRUE(f4_model.n_locks > locks); /* and the lock let go */
    TEST_ASSERT_EQUAL_UINT32(0u, f4_model.primask);
}

/* ODrive v3.6 M0: control 1 = 0x550, control 2 = 0x008 (ODrive's own
 * words); EN_GATE PB12 high; phase A not sampled (rebuilt): ADC1 JSQR Vbus
 * ch6 = 6 << 15 = 0x30000, ADC2 ch10 = 0x50000, ADC3 ch11 = 0x58000; index
 * on TIM3_CH4: CCER CC4E = 0x1000, CCMR2 IC4 on TI4 filter 0110 = 0x6100;
 * nFAULT PD2 on EXTI line 2: EXTICR1 bits 11:8 = 0011 (port D); axis M1's
 * gate inputs PC6/7/8, PA7, PB0/1 and AUX PB10/11 outputs low, its nSCS PC14
 * output high, all of them before EN_GATE rises (it enables M1's driver
 * too). */
static void test_odrive_start_up_image(void)
{
    const f4_board_t *b = &f4_board_odrive_v36;
    attach_drv(b);
    TEST_ASSERT_EQUAL_INT(F4_OK, board_init(b));
    TEST_ASSERT_EQUAL_HEX16(0x550u, drv8301_model.reg[2]);
    TEST_ASSERT_EQUAL_HEX16(0x008u, drv8301_model.reg[3]);
    TEST_ASSERT_TRUE(f4_model_pin_out(1u, 12u));
    TEST_ASSERT_EQUAL_HEX32(0x00030000u, reg(F4_ADC1 + F4_ADC_JSQR));
    TEST_ASSERT_EQUAL_HEX32(0x00050000u, reg(F4_ADC2 + F4_ADC_JSQR));
    TEST_ASSERT_EQUAL_HEX32(0x00058000u, reg(F4_ADC3 + F4_ADC_JSQR));
    TEST_ASSERT_EQUAL_UINT32(0u, hal.rebuilt);
    TEST_ASSERT_EQUAL_HEX32(0x1000u, reg(F4_TIM3 + F4_TIM_CCER));
    TEST_ASSERT_EQUAL_HEX32(0x6100u, reg(F4_TIM3 + F4_TIM_CCMR2));
    TEST_ASSERT_EQUAL_HEX32(0x0300u, reg(F4_SYSCFG + F4_SYSCFG_EXTICR(2u)) & 0x0F00u);
    const int en_high = pin_write(b->en_gate, true, 0);
    for (unsigned k = 0; k < 8u; k++) {
        const f4_pin_t p = b->hold_low[k];
        TEST_ASSERT_EQUAL_UINT32(1u, f4_model_pin_mode(p.port, p.pin));
        TEST_ASSERT_FALSE(f4_model_pin_out(p.port, p.pin));
        assert_before(pin_write(p, false, 0), en_high, "axis M1's inputs low before EN_GATE");
    }
    TEST_ASSERT_EQUAL_UINT32(1u, f4_model_pin_mode(2u, 14u));
    TEST_ASSERT_TRUE(f4_model_pin_out(2u, 14u));
    assert_before(pin_write(b->hold_high[0], true, 0), en_high, "M1's nSCS high before EN_GATE");
}

/* Nothing answers on SPI (QEMU: the SPI model has no peer, reads 0): the
 * first read-back (control 1, address 2) comes back as 0x0000, whose
 * address field (0) is not 2: "no answer", not a read-back mismatch, and
 * not an empty status 1. Gates held off for good: EN_GATE low, TIM1 never
 * started, MOE never set even when asked, the trip latched (hold). The
 * same with the bus pulled up (0xFFFF: address 15). */
static void test_drv_silent(void)
{
    const f4_board_t *b = &f4_board_vesc6;
    attach_drv(b);
    drv8301_model.connected = false;
    TEST_ASSERT_EQUAL_INT(F4_E_DRIVER, board_init(b));
    TEST_ASSERT_EQUAL_INT(DRV8301_E_SILENT, hal.drv.err);
    char why[96];
    (void)drv8301_explain(&hal.drv, why, sizeof why);
    TEST_ASSERT_EQUAL_STRING("no answer on SPI (register 2 came back as 0x0)", why);
    TEST_ASSERT_FALSE(f4_model_pin_out(b->en_gate.port, b->en_gate.pin));
    TEST_ASSERT_EQUAL_INT(-1,
                          f4_model_find(F4_TIM1 + F4_TIM_CR1, F4_TIM_CR1_CEN, F4_TIM_CR1_CEN, 0));
    TEST_ASSERT_TRUE(hal_trip_active(&hal));
    ASSERT_BITS_SET(F4_TRIP_HOLD, f4_hal_trip_cause(&hal));
    hal_gate_enable(&hal, true);
    ASSERT_BITS_CLEAR(F4_TIM_BDTR_MOE, reg(F4_TIM1 + F4_TIM_BDTR));

    f4_model_reset();
    f4_cycle_counter_init();
    attach_drv(b);
    drv8301_model.connected = false;
    drv8301_model.idle = 0xFFFFu;
    TEST_ASSERT_EQUAL_INT(F4_E_DRIVER, board_init(b));
    TEST_ASSERT_EQUAL_INT(DRV8301_E_SILENT, hal.drv.err);
}

/* A control bit that never takes a 1 (OC_ADJ bit 6 stuck): written three
 * times, read back each time, then refused by name with both values
 * (control 1 reads 0x510, wrote 0x550): gates held off, EN_GATE low. The
 * first writes after EN_GATE rises lost (as ODrive suspects of its driver):
 * the second attempt reads back, start-up passes. */
static void test_drv_readback(void)
{
    const f4_board_t *b = &f4_board_odrive_v36;
    attach_drv(b);
    drv8301_model.stuck_zero[0] = 0x040u;
    TEST_ASSERT_EQUAL_INT(F4_E_DRIVER, board_init(b));
    TEST_ASSERT_EQUAL_INT(DRV8301_E_READBACK, hal.drv.err);
    char why[96];
    (void)drv8301_explain(&hal.drv, why, sizeof why);
    TEST_ASSERT_EQUAL_STRING("control 1 reads 0x510, wrote 0x550", why);
    TEST_ASSERT_EQUAL_UINT32(6u, drv8301_model.writes); /* 3 x (CR1, CR2) */
    TEST_ASSERT_FALSE(f4_model_pin_out(b->en_gate.port, b->en_gate.pin));
    TEST_ASSERT_TRUE(hal_trip_active(&hal));

    f4_model_reset();
    f4_cycle_counter_init();
    attach_drv(b);
    drv8301_model.lose_writes = 2u;
    TEST_ASSERT_EQUAL_INT(F4_OK, board_init(b));
    TEST_ASSERT_EQUAL_HEX16(0x550u, drv8301_model.reg[2]);
    TEST_ASSERT_FALSE(hal_trip_active(&hal));
}

/* Frames the driver takes as invalid (the frame-error bit, 15, of its
 * response words; TI SLOS842 table 4): the read-back's answer carries the
 * right address but its data is not the register's; refused as an SPI
 * error naming the bit, not as a read-back mismatch or a clean status:
 * gates held off, EN_GATE low. The same at run time: the gates off and the
 * configuration taken as lost (written again once stopped). */
static void test_drv_frame_error(void)
{
    const f4_board_t *b = &f4_board_vesc6;
    attach_drv(b);
    drv8301_model.frame_fault = true;
    TEST_ASSERT_EQUAL_INT(F4_E_DRIVER, board_init(b));
    TEST_ASSERT_EQUAL_INT(DRV8301_E_SPI, hal.drv.err);
    char why[96];
    (void)drv8301_explain(&hal.drv, why, sizeof why);
    TEST_ASSERT_EQUAL_STRING("SPI frame error (register 2, answer 0x9000)", why);
    TEST_ASSERT_FALSE(f4_model_pin_out(b->en_gate.port, b->en_gate.pin));
    TEST_ASSERT_TRUE(hal_trip_active(&hal));

    f4_model_reset();
    f4_cycle_counter_init();
    attach_drv(b);
    TEST_ASSERT_EQUAL_INT(F4_OK, board_init(b));
    hal_gate_enable(&hal, true);
    drv8301_model.frame_fault = true;
    (void)f4_hal_drv_service(&hal, false);
    ASSERT_BITS_CLEAR(F4_TIM_BDTR_MOE, reg(F4_TIM1 + F4_TIM_BDTR));
    ASSERT_BITS_SET(F4_TRIP_CONFIG, f4_hal_trip_cause(&hal));
    drv8301_model.frame_fault = false;
    (void)f4_hal_drv_service(&hal, true);
    ASSERT_BITS_CLEAR(F4_TRIP_CONFIG, f4_hal_trip_cause(&hal));
}

/* A fault present at start-up (GVDD under-voltage, persisting): configured
 * and read back, but its status names it: gates held off, "fault GVDD_UV
 * FAULT". nFAULT held low with a clean status (the other axis's driver on
 * the shared line): named as FAULT as well. */
static void test_drv_fault_at_start(void)
{
    const f4_board_t *b = &f4_board_vesc6;
    attach_drv(b);
    drv8301_model_fault(0x200u, true); /* GVDD_UV, persisting */
    TEST_ASSERT_EQUAL_INT(F4_E_DRIVER, board_init(b));
    char why[96];
    (void)drv8301_explain(&hal.drv, why, sizeof why);
    TEST_ASSERT_EQUAL_STRING("fault GVDD_UV FAULT", why);
    TEST_ASSERT_TRUE(hal_trip_active(&hal));
}

/* The fall-back clock: the driver is still configured and checked (its
 * SPI runs from HSI), then start-up stops with F4_E_CLOCK before TIM1 (the
 * PWM timing assumes the PLL): held off, EN_GATE low. */
static void test_clock_fall_back_holds(void)
{
    const f4_board_t *b = &f4_board_vesc6;
    attach_drv(b);
    f4_clocks_hsi(&clk);
    TEST_ASSERT_EQUAL_INT(F4_E_CLOCK, f4_hal_init(&hal, b, &cfg20k, &clk));
    TEST_ASSERT_EQUAL_INT(DRV8301_OK, hal.drv_rc);
    TEST_ASSERT_EQUAL_HEX16(0x410u, drv8301_model.reg[2]);
    TEST_ASSERT_FALSE(f4_model_pin_out(b->en_gate.port, b->en_gate.pin));
    TEST_ASSERT_EQUAL_INT(-1,
                          f4_model_find(F4_TIM1 + F4_TIM_CR1, F4_TIM_CR1_CEN, F4_TIM_CR1_CEN, 0));
    TEST_ASSERT_TRUE(hal_trip_active(&hal));
    /* Held for good: the main loop's service leaves the reset driver
     * alone (no frame, no configuration lost, nothing to report). */
    const uint32_t frames = f4_model.spi_frames;
    for (unsigned k = 0; k < 3u; k++) {
        TEST_ASSERT_FALSE(f4_hal_drv_service(&hal, true));
    }
    TEST_ASSERT_EQUAL_UINT32(frames, f4_model.spi_frames);
    TEST_ASSERT_FALSE(hal.cfg_lost);
    TEST_ASSERT_FALSE(f4_model_pin_out(b->en_gate.port, b->en_gate.pin));
}

/* TIM1's update at the valley (RCR written after the start): F4_E_TIM,
 * counter stopped again, held off. */
static void test_tim1_phase(void)
{
    attach_drv(&f4_board_vesc6);
    f4_model.uev_at_valley = true;
    TEST_ASSERT_EQUAL_INT(F4_E_TIM, board_init(&f4_board_vesc6));
    ASSERT_BITS_CLEAR(F4_TIM_CR1_CEN, reg(F4_TIM1 + F4_TIM_CR1));
    TEST_ASSERT_TRUE(hal_trip_active(&hal));
}

/* ---- run time ---- */

/* nFAULT falls (an over-current latched by the driver): its interrupt clears
 * MOE and latches the trip; a clear while nFAULT is low changes nothing; the
 * main loop, drive stopped, reads the status (names FETHA_OC), resets the
 * driver (GATE_RESET written: control 1 | 0x004), nFAULT rises; the next
 * clear acknowledges, the gates may come on again. */
static void test_nfault_trip_and_reset(void)
{
    const f4_board_t *b = &f4_board_vesc6;
    attach_drv(b);
    TEST_ASSERT_EQUAL_INT(F4_OK, board_init(b));
    hal_gate_enable(&hal, true);
    ASSERT_BITS_SET(F4_TIM_BDTR_MOE, reg(F4_TIM1 + F4_TIM_BDTR));
    TEST_ASSERT_FALSE(f4_hal_drv_service(&hal, false)); /* nothing to report */

    drv8301_model_fault(0x020u, false); /* FETHA_OC */
    f4_hal_nfault_irq(&hal);
    ASSERT_BITS_CLEAR(F4_TIM_BDTR_MOE, reg(F4_TIM1 + F4_TIM_BDTR));
    TEST_ASSERT_TRUE(hal_trip_active(&hal));
    ASSERT_BITS_SET(F4_TRIP_DRIVER, f4_hal_trip_cause(&hal));
    hal_trip_clear(&hal);
    TEST_ASSERT_TRUE(hal_trip_active(&hal));
    hal_gate_enable(&hal, true);
    ASSERT_BITS_CLEAR(F4_TIM_BDTR_MOE, reg(F4_TIM1 + F4_TIM_BDTR));

    TEST_ASSERT_TRUE(f4_hal_drv_service(&hal, true));
    char names[64];
    (void)drv8301_fault_names(hal.drv.status[0], hal.drv.status[1], names, sizeof names);
    TEST_ASSERT_EQUAL_STRING("FETHA_OC FAULT", names);
    TEST_ASSERT_EQUAL_UINT32(1u, drv8301_model.gate_resets);
    TEST_ASSERT_FALSE(f4_hal_nfault_low(&hal));
    hal_trip_clear(&hal);
    TEST_ASSERT_FALSE(hal_trip_active(&hal));
    hal_gate_enable(&hal, true);
    ASSERT_BITS_SET(F4_TIM_BDTR_MOE, reg(F4_TIM1 + F4_TIM_BDTR));
}

/* The driver's control registers lost while running (a GVDD under-voltage
 * resets them: the read-back says so): gates off at once, F4_TRIP_CONFIG;
 * once stopped they are written again and the cause released only when
 * they read back. */
static void test_config_lost(void)
{
    attach_drv(&f4_board_odrive_v36);
    TEST_ASSERT_EQUAL_INT(F4_OK, board_init(&f4_board_odrive_v36));
    hal_gate_enable(&hal, true);
    drv8301_model.reg[2] = 0u;
    drv8301_model.reg[3] = 0u;
    (void)f4_hal_drv_service(&hal, false);
    ASSERT_BITS_CLEAR(F4_TIM_BDTR_MOE, reg(F4_TIM1 + F4_TIM_BDTR));
    ASSERT_BITS_SET(F4_TRIP_CONFIG, f4_hal_trip_cause(&hal));
    drv8301_model.stuck_zero[1] = 0x008u; /* it refuses once more */
    (void)f4_hal_drv_service(&hal, true);
    ASSERT_BITS_SET(F4_TRIP_CONFIG, f4_hal_trip_cause(&hal));
    drv8301_model.stuck_zero[1] = 0u;
    (void)f4_hal_drv_service(&hal, true);
    ASSERT_BITS_CLEAR(F4_TRIP_CONFIG, f4_hal_trip_cause(&hal));
    TEST_ASSERT_EQUAL_HEX16(0x550u, drv8301_model.reg[2]);
    TEST_ASSERT_FALSE(hal_trip_active(&hal));
}

/* hal_adc_read on the ODrive: B = 2148, C = 2008 in ADC2/ADC3 JDR1 (+100
 * and -40 counts about 2048), Vbus 1000 in ADC1 JDR1; A rebuilt:
 * 6144 - 2148 - 2008 = 1988 (-60 counts: -(+100 - 40)). Both measured
 * phases saturated high: A = 6144 - 8190 < 0 -> 0, the range's end. */
static void test_adc_read_rebuilds_phase_a(void)
{
    attach_drv(&f4_board_odrive_v36);
    TEST_ASSERT_EQUAL_INT(F4_OK, board_init(&f4_board_odrive_v36));
    f4_model_put(F4_ADC2 + F4_ADC_JDR(1u), 2148u);
    f4_model_put(F4_ADC3 + F4_ADC_JDR(1u), 2008u);
    f4_model_put(F4_ADC1 + F4_ADC_JDR(1u), 1000u);
    hal_adc_raw_t raw;
    hal_adc_read(&hal, &raw);
    TEST_ASSERT_EQUAL_UINT16(1988u, raw.i_a);
    TEST_ASSERT_EQUAL_UINT16(2148u, raw.i_b);
    TEST_ASSERT_EQUAL_UINT16(2008u, raw.i_c);
    TEST_ASSERT_EQUAL_UINT16(1000u, raw.vdc);
    f4_model_put(F4_ADC2 + F4_ADC_JDR(1u), 4095u);
    f4_model_put(F4_ADC3 + F4_ADC_JDR(1u), 4095u);
    hal_adc_read(&hal, &raw);
    TEST_ASSERT_EQUAL_UINT16(0u, raw.i_a);
}

/* Compare values above cmp_max (3971 for the VESC 6 at 20 kHz) are limited
 * to it; the interrupt's acknowledge clears JEOC of every sampling ADC and
 * nothing else (rc_w0). The encoder's index on TIM3_CH3: the count at the
 * capture (CNT 1000, CCR3 990: 10 counts before). */
static void test_pwm_limit_ack_and_encoder(void)
{
    attach_drv(&f4_board_vesc6);
    TEST_ASSERT_EQUAL_INT(F4_OK, board_init(&f4_board_vesc6));
    const hal_pwm_t pwm = {{100u, 4000u, 4200u}};
    hal_pwm_write(&hal, &pwm);
    TEST_ASSERT_EQUAL_UINT32(100u, reg(F4_TIM1 + F4_TIM_CCR(1u)));
    TEST_ASSERT_EQUAL_UINT32(3971u, reg(F4_TIM1 + F4_TIM_CCR(2u)));
    TEST_ASSERT_EQUAL_UINT32(3971u, reg(F4_TIM1 + F4_TIM_CCR(3u)));
    f4_model_put(F4_ADC1 + F4_ADC_SR, F4_ADC_SR_JEOC | F4_ADC_SR_EOC);
    f4_model_put(F4_ADC3 + F4_ADC_SR, F4_ADC_SR_JEOC);
    f4_hal_adc_irq_ack(&hal);
    TEST_ASSERT_EQUAL_HEX32(F4_ADC_SR_EOC, reg(F4_ADC1 + F4_ADC_SR));
    TEST_ASSERT_EQUAL_HEX32(0u, reg(F4_ADC3 + F4_ADC_SR));
    hal_encoder_raw_t enc;
    f4_model_put(F4_TIM3 + F4_TIM_CNT, 1000u);
    hal_encoder_read(&hal, &enc);
    TEST_ASSERT_EQUAL_UINT32(1000u, enc.count);
    TEST_ASSERT_FALSE(enc.index_seen);
    f4_model_put(F4_TIM3 + F4_TIM_CCR(3u), 990u);
    f4_model_put(F4_TIM3 + F4_TIM_SR, F4_TIM_SR_CCIF(3u));
    hal_encoder_read(&hal, &enc);
    TEST_ASSERT_TRUE(enc.index_seen);
    TEST_ASSERT_EQUAL_UINT32(990u, enc.index_count);
}

/* Servo capture on TIM4 CH1 (rising) / CH2 (falling): CCMR1 = IC1 on TI1
 * (CC1S 01) and IC2 on TI1 (CC2S 10), both filtered 1111: 0xF1 | 0xF200 =
 * 0xF2F1; CCER = CC1E | CC2E | CC2P (falling) = 0x31. The first rising edge
 * only primes; then a fall at rise + 1500 and a rise at + 20000 give width
 * 1500, period 20000 (1 MHz ticks: 1.5 ms in a 50 Hz frame); across the
 * 16-bit wrap (rise 60000, fall 61500, rise 80000 - 65536 = 14464) the same.
 * An overcapture (CC1OF) drops the pulse and counts it. */
static void test_servo_capture(void)
{
    f4_capture_t cap;
    f4_capture_init(4u, 1u, 83u, 15u);
    assert_rcc_synced();
    f4_capture_start(&cap, 4u, 1u);
    TEST_ASSERT_EQUAL_HEX32(0xF2F1u, reg(F4_TIM4 + F4_TIM_CCMR1));
    TEST_ASSERT_EQUAL_HEX32(0x31u, reg(F4_TIM4 + F4_TIM_CCER));
    uint32_t w, p;
    const uintptr_t t = F4_TIM4;
    f4_model_put(t + F4_TIM_CCR(1u), 60000u);
    f4_model_put(t + F4_TIM_SR, F4_TIM_SR_CCIF(1u));
    TEST_ASSERT_FALSE(f4_capture_read(&cap, &w, &p));
    f4_model_put(t + F4_TIM_CCR(2u), 61500u);
    f4_model_put(t + F4_TIM_CCR(1u), (60000u + 20000u) & 0xFFFFu);
    f4_model_put(t + F4_TIM_SR, F4_TIM_SR_CCIF(1u) | F4_TIM_SR_CCIF(2u));
    TEST_ASSERT_TRUE(f4_capture_read(&cap, &w, &p));
    TEST_ASSERT_EQUAL_UINT32(1500u, w);
    TEST_ASSERT_EQUAL_UINT32(20000u, p);
    f4_model_put(t + F4_TIM_CCR(2u), 14464u + 1200u);
    f4_model_put(t + F4_TIM_CCR(1u), 14464u + 20000u);
    f4_model_put(t + F4_TIM_SR, F4_TIM_SR_CCIF(1u) | F4_TIM_SR_CCIF(2u) | F4_TIM_SR_CCOF(1u));
    TEST_ASSERT_FALSE(f4_capture_read(&cap, &w, &p));
    TEST_ASSERT_EQUAL_UINT32(1u, cap.missed);
    ASSERT_BITS_CLEAR(F4_TIM_SR_CCOF(1u), reg(t + F4_TIM_SR));
}

/* The six gate pins and EN_GATE, as the fault handlers leave them: GPIO
 * outputs at the inactive level, EN_GATE low (whatever ran before). */
static void test_gate_pins_safe(void)
{
    const f4_board_t *b = &f4_board_odrive_v36;
    attach_drv(b);
    TEST_ASSERT_EQUAL_INT(F4_OK, board_init(b));
    f4_hal_gate_pins_safe(b);
    TEST_ASSERT_FALSE(f4_model_pin_out(b->en_gate.port, b->en_gate.pin));
    for (unsigned x = 0; x < 3u; x++) {
        TEST_ASSERT_EQUAL_UINT32(1u, f4_model_pin_mode(b->pwm_high[x].port, b->pwm_high[x].pin));
        TEST_ASSERT_FALSE(f4_model_pin_out(b->pwm_high[x].port, b->pwm_high[x].pin));
        TEST_ASSERT_EQUAL_UINT32(1u, f4_model_pin_mode(b->pwm_low[x].port, b->pwm_low[x].pin));
        TEST_ASSERT_FALSE(f4_model_pin_out(b->pwm_low[x].port, b->pwm_low[x].pin));
    }
}

/* From the reset values (every GPIO clock off but the debug ports'): each
 * pin f4_hal_gate_pins_safe drives gets its port's clock before its level
 * (a BSRR write to a port without clock is lost) and its level before its
 * output mode (else it drives ODR's reset value 0 for a moment: the ODrive's
 * M1 nSCS PC14 would select the other driver). */
static void test_gate_pins_clock_level_mode(void)
{
    const f4_board_t *boards[2] = {&f4_board_vesc6, &f4_board_odrive_v36};
    for (unsigned k = 0; k < 2u; k++) {
        const f4_board_t *b = boards[k];
        f4_model_reset();
        f4_hal_gate_pins_safe(b);
        f4_pin_t pins[19];
        bool level[19];
        unsigned n = 0u;
        pins[n] = b->en_gate;
        level[n++] = false;
        for (unsigned x = 0; x < 3u; x++) {
            pins[n] = b->pwm_high[x];
            level[n++] = false;
            pins[n] = b->pwm_low[x];
            level[n++] = false;
        }
        for (unsigned j = 0; j < 8u; j++) {
            pins[n] = b->hold_low[j];
            level[n++] = false;
        }
        for (unsigned j = 0; j < 2u; j++) {
            pins[n] = b->hold_high[j];
            level[n++] = true;
        }
        for (unsigned j = 0; j < n; j++) {
            const f4_pin_t p = pins[j];
            if (!f4_pin_used(p)) {
                continue;
            }
            const int clock =
                f4_model_find(F4_RCC + F4_RCC_AHB1ENR, F4_BIT(p.port), F4_BIT(p.port), 0);
            const int lvl = pin_write(p, level[j], 0);
            const int mode = f4_model_find(f4_gpio_base(p.port) + F4_GPIO_MODER, 3u << (2u * p.pin),
                                           1u << (2u * p.pin), 0);
            assert_before(clock, lvl, "the port's clock before the pin's level (BSRR)");
            assert_before(lvl, mode, "the pin's level before its output mode");
            TEST_ASSERT_EQUAL(level[j], f4_model_pin_out(p.port, p.pin));
        }
        assert_rcc_synced();
    }
    /* The VESC 6's PB12 (the first hardware 60's NRF24 CSN) an input
     * pulled up before PD2 (its MISO there) becomes an output. */
    const f4_board_t *b = &f4_board_vesc6;
    f4_model_reset();
    f4_hal_gate_pins_safe(b);
    TEST_ASSERT_EQUAL_UINT32(0u, f4_model_pin_mode(1u, 12u));
    TEST_ASSERT_EQUAL_HEX32(1u, (reg(F4_GPIOB + F4_GPIO_PUPDR) >> 24) & 3u);
    const int pull = f4_model_find(F4_GPIOB + F4_GPIO_PUPDR, 3u << 24, 1u << 24, 0);
    const int pd2 = f4_model_find(F4_GPIOD + F4_GPIO_MODER, 3u << 4, 1u << 4, 0);
    assert_before(pull, pd2, "the NRF24's CSN pulled up before PD2 drives");
}

/* The watchdog: started with the start key (which forces the LSI on),
 * unlocked, PR and RLR written, refreshed, frozen under a debugger halt
 * (RM0090 sec. 21.3.2-21.3.4, DBGMCU_APB1_FZ); without LSIRDY (QEMU, a dead
 * LSI) it is refused by name. */
static void test_iwdg_start_and_lsi(void)
{
    uint32_t pr, rlr;
    TEST_ASSERT_EQUAL_INT(STM32_OK, stm32_iwdg_config(100u, F4_LSI_TYP_HZ, &pr, &rlr));
    TEST_ASSERT_EQUAL_INT(F4_OK, f4_iwdg_start(pr, rlr, 16000000u));
    const uint32_t flags = reg(F4_RCC + F4_RCC_CSR) & 0xFE000000u;
    TEST_ASSERT_TRUE(flags != 0u); /* the reset's flags (model: power-on) */
    const int start = f4_model_find(F4_IWDG + F4_IWDG_KR, 0xFFFFu, F4_IWDG_KR_START, 0);
    /* LSION, and the reset flags kept for the start-up report */
    ASSERT_BITS_SET(F4_RCC_CSR_LSION | F4_RCC_CSR_LSIRDY, reg(F4_RCC + F4_RCC_CSR));
    const int unlock = f4_model_find(F4_IWDG + F4_IWDG_KR, 0xFFFFu, F4_IWDG_KR_UNLOCK, 0);
    const int refresh = f4_model_find(F4_IWDG + F4_IWDG_KR, 0xFFFFu, F4_IWDG_KR_REFRESH, 0);
    assert_before(start, unlock, "IWDG: started (LSI on) before the unlock");
    assert_before(unlock, f4_model_find(F4_IWDG + F4_IWDG_PR, 0u, 0u, 0), "PR after the unlock");
    assert_before(f4_model_find(F4_IWDG + F4_IWDG_RLR, 0u, 0u, 0), refresh, "RLR, then refresh");
    TEST_ASSERT_EQUAL_UINT32(pr, reg(F4_IWDG + F4_IWDG_PR));
    TEST_ASSERT_EQUAL_UINT32(rlr, reg(F4_IWDG + F4_IWDG_RLR));
    ASSERT_BITS_SET(F4_DBGMCU_APB1_FZ_IWDG_STOP, reg(F4_DBGMCU + F4_DBGMCU_APB1_FZ));
    f4_model_reset();
    f4_model.lsi_dead = true;
    TEST_ASSERT_EQUAL_INT(F4_E_LSI, f4_iwdg_start(pr, rlr, 16000000u));

    /* PVU / RVU clear within 5 periods of the prescaled LSI (ST's HAL,
     * stm32f4xx_hal_iwdg.c): the wait covers them at the slowest LSI for
     * every prescaler; at /256 (PR 6) 5 x 256 / 17 kHz = 75.3 ms, 1 204 706
     * cycles at 16 MHz: the start waits them out (a fixed 10 ms did not). */
    for (uint32_t p = 0u; p <= 6u; p++) {
        TEST_ASSERT_TRUE((uint64_t)f4_iwdg_update_ms(p) * F4_LSI_MIN_HZ >=
                         5ull * (4u << p) * 1000u);
    }
    f4_model_reset();
    f4_model.iwdg_update_cycles = 1204706u;
    TEST_ASSERT_EQUAL_INT(F4_OK, f4_iwdg_start(6u, 0xFFFu, 16000000u));
    TEST_ASSERT_NOT_NULL(strstr(f4_strerror(F4_E_LSI), "LSI"));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_clock_image_and_order);
    RUN_TEST(test_clock_fall_backs);
    RUN_TEST(test_vesc6_start_up_image);
    RUN_TEST(test_odrive_start_up_image);
    RUN_TEST(test_drv_silent);
    RUN_TEST(test_drv_readback);
    RUN_TEST(test_drv_frame_error);
    RUN_TEST(test_drv_fault_at_start);
    RUN_TEST(test_clock_fall_back_holds);
    RUN_TEST(test_tim1_phase);
    RUN_TEST(test_nfault_trip_and_reset);
    RUN_TEST(test_config_lost);
    RUN_TEST(test_adc_read_rebuilds_phase_a);
    RUN_TEST(test_pwm_limit_ack_and_encoder);
    RUN_TEST(test_servo_capture);
    RUN_TEST(test_break_inside_the_arm_keeps_the_gates_off);
    RUN_TEST(test_gate_pins_safe);
    RUN_TEST(test_gate_pins_clock_level_mode);
    RUN_TEST(test_iwdg_start_and_lsi);
    return UNITY_END();
}
