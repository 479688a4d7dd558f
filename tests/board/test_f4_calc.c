/*
 * Configuration computations of the STM32F405 chip support, the DRV8301
 * driver and the two board descriptions, against values worked out by hand
 * from RM0090's formulas, the DRV8301 data sheet's register map and the
 * boards' sources (each test says which). No register access but the clock
 * result's read of the model.
 */
#include <math.h>

#include "board_odrive_v36.h"
#include "board_vesc6.h"
#include "drv8301.h"
#include "f4_adc.h"
#include "f4_clock.h"
#include "f4_core.h"
#include "f4_hal.h"
#include "f4_model.h"
#include "f4_periph.h"
#include "f4_spi.h"
#include "stm32_calc.h"
#include "unity.h"

void setUp(void)
{
    f4_model_reset();
}

void tearDown(void)
{
}

/* RCC_PLLCFGR: f_VCO_in = 8 MHz / M in 1..2 MHz: M = 4 gives the
 * recommended 2 MHz; P = 2: f_VCO = 336 MHz = 2 MHz x 168 (N 168, within
 * 50..432, VCO within 100..432 MHz); Q = 336 / 48 = 7. ODrive v3 uses
 * exactly M 4, N 168, P 2, Q 7 (Board/v3/Src/main.c). Register: bit 29
 * (reserved, reset value 1) | PLLSRC (bit 22) | M 4 | N 168 << 6 | P code 0 |
 * Q 7 << 24 = 0x2000_0000 | 0x0040_0000 | 0x4 | 0x2A00 | 0x0700_0000 =
 * 0x2740_2A04. */
static void test_pll_8mhz_to_168mhz(void)
{
    f4_pll_t p;
    TEST_ASSERT_EQUAL_INT(F4_OK, f4_pll_solve(8000000u, 168000000u, &p));
    TEST_ASSERT_EQUAL_UINT32(4u, p.m);
    TEST_ASSERT_EQUAL_UINT32(168u, p.n);
    TEST_ASSERT_EQUAL_UINT32(2u, p.p);
    TEST_ASSERT_EQUAL_UINT32(7u, p.q);
    TEST_ASSERT_EQUAL_UINT32(2000000u, p.vco_in_hz);
    TEST_ASSERT_EQUAL_UINT32(336000000u, p.vco_hz);
    TEST_ASSERT_EQUAL_HEX32(0x27402A04u, f4_pll_cfgr(&p));
}

/* 25 MHz: no M gives 2 MHz exactly (25 / 12.5); 1 MHz with M = 25, N =
 * 336 (VESC's N for its 1 MHz input). 8 MHz -> 100 MHz: M 4, P 2, N 100,
 * Q = ceil(200 / 48) = 5 (USB at 40 MHz, not 48: nothing divides). Above
 * 168 MHz: refused. 8 MHz -> 167 MHz: N = 167 at P 2 (334 MHz) works:
 * the solver is exact, not limited to 168. 9 MHz: M 5 -> 1.8 MHz, 336 /
 * 1.8 = 186.67: no N; M 6 -> 1.5 MHz, N 224 (before M 9 -> 1 MHz). */
static void test_pll_other_and_impossible(void)
{
    f4_pll_t p;
    TEST_ASSERT_EQUAL_INT(F4_OK, f4_pll_solve(25000000u, 168000000u, &p));
    TEST_ASSERT_EQUAL_UINT32(25u, p.m);
    TEST_ASSERT_EQUAL_UINT32(336u, p.n);
    TEST_ASSERT_EQUAL_INT(F4_OK, f4_pll_solve(8000000u, 100000000u, &p));
    TEST_ASSERT_EQUAL_UINT32(100u, p.n);
    TEST_ASSERT_EQUAL_UINT32(5u, p.q);
    TEST_ASSERT_EQUAL_INT(F4_E_CONFIG, f4_pll_solve(8000000u, 180000000u, &p));
    TEST_ASSERT_EQUAL_INT(F4_OK, f4_pll_solve(8000000u, 167000000u, &p));
    TEST_ASSERT_EQUAL_UINT32(167u, p.n);
    TEST_ASSERT_EQUAL_INT(F4_OK, f4_pll_solve(9000000u, 168000000u, &p));
    TEST_ASSERT_EQUAL_UINT32(6u, p.m);
    TEST_ASSERT_EQUAL_UINT32(224u, p.n);
}

/* RM0090 table 10 (2.7 .. 3.6 V): 0 WS up to 30 MHz, +1 per 30 MHz, 5 WS
 * at 168 MHz (ODrive: FLASH_LATENCY_5). APB codes (RCC_CFGR PPREx):
 * 1 -> 000, 2 -> 100, 4 -> 101, 8 -> 110, 16 -> 111. */
static void test_flash_latency_and_bus_codes(void)
{
    TEST_ASSERT_EQUAL_INT(5, f4_flash_latency(168000000u));
    TEST_ASSERT_EQUAL_INT(4, f4_flash_latency(150000000u));
    TEST_ASSERT_EQUAL_INT(0, f4_flash_latency(30000000u));
    TEST_ASSERT_EQUAL_INT(1, f4_flash_latency(30000001u));
    TEST_ASSERT_EQUAL_INT(0, f4_flash_latency(16000000u));
    TEST_ASSERT_EQUAL_INT(-1, f4_flash_latency(168000001u));
    TEST_ASSERT_EQUAL_INT(0, f4_ppre_code(1u));
    TEST_ASSERT_EQUAL_INT(4, f4_ppre_code(2u));
    TEST_ASSERT_EQUAL_INT(5, f4_ppre_code(4u));
    TEST_ASSERT_EQUAL_INT(7, f4_ppre_code(16u));
    TEST_ASSERT_EQUAL_INT(-1, f4_ppre_code(3u));
}

/* At 168 MHz: APB1 / 4 = 42 MHz, APB2 / 2 = 84 MHz (their 42 / 84 MHz
 * limits), the timers at twice their bus (RM0090 sec. 6.2): TIM2..5 84 MHz,
 * TIM1 168 MHz. The fall-back: HSI 16 MHz on every bus. */
static void test_clock_result(void)
{
    f4_clocks_t c;
    TEST_ASSERT_EQUAL_INT(F4_OK, f4_clock_init(8000000u, 168000000u, &c));
    TEST_ASSERT_TRUE(c.pll);
    TEST_ASSERT_EQUAL_UINT32(168000000u, c.sysclk_hz);
    TEST_ASSERT_EQUAL_UINT32(42000000u, c.pclk1_hz);
    TEST_ASSERT_EQUAL_UINT32(84000000u, c.pclk2_hz);
    TEST_ASSERT_EQUAL_UINT32(84000000u, c.tim_apb1_hz);
    TEST_ASSERT_EQUAL_UINT32(168000000u, c.tim_apb2_hz);
    f4_model_reset();
    f4_model.hse_broken = true;
    TEST_ASSERT_EQUAL_INT(F4_E_HSE, f4_clock_init(8000000u, 168000000u, &c));
    TEST_ASSERT_FALSE(c.pll);
    TEST_ASSERT_EQUAL_UINT32(16000000u, c.sysclk_hz);
    TEST_ASSERT_EQUAL_UINT32(16000000u, c.pclk1_hz);
    TEST_ASSERT_EQUAL_UINT32(16000000u, c.tim_apb2_hz);
}

/* Centre-aligned PWM at 168 MHz: ARR = 168e6 / (2 fs): 20 kHz 4200,
 * 30 kHz 2800, 40 kHz 2100, PSC 0. Dead time: 360 ns (VESC's) = 60.48
 * t_DTS -> 61 (DTG 0x3D, 363 ns, never less); 120 ns (ODrive's 20 clocks)
 * = 20.16 -> 21. */
static void test_pwm_timing_and_dead_time(void)
{
    stm32_pwm_timing_t t;
    TEST_ASSERT_EQUAL_INT(STM32_OK, stm32_pwm_timing(168000000u, 20000u, &t));
    TEST_ASSERT_EQUAL_UINT32(4200u, t.arr);
    TEST_ASSERT_EQUAL_UINT32(0u, t.psc);
    TEST_ASSERT_EQUAL_INT(STM32_OK, stm32_pwm_timing(168000000u, 30000u, &t));
    TEST_ASSERT_EQUAL_UINT32(2800u, t.arr);
    TEST_ASSERT_EQUAL_INT(STM32_OK, stm32_pwm_timing(168000000u, 40000u, &t));
    TEST_ASSERT_EQUAL_UINT32(2100u, t.arr);
    uint8_t dtg;
    TEST_ASSERT_EQUAL_INT(STM32_OK, stm32_dtg_encode(168000000u, 360u, &dtg));
    TEST_ASSERT_EQUAL_HEX8(0x3Du, dtg);
    TEST_ASSERT_EQUAL_INT(STM32_OK, stm32_dtg_encode(168000000u, 120u, &dtg));
    TEST_ASSERT_EQUAL_UINT32(21u, stm32_dtg_ticks(dtg));
}

/* ADC_JSQR is right-aligned (RM0090 sec. 13.13.12; ST's HAL ADC_JSQR shifts
 * by 5 (rank + 3 - n)): two conversions ch10, ch13: JL = 1 (bit 20), rank 1
 * in JSQ3 (bits 14:10), rank 2 in JSQ4 (19:15): 0x10_0000 | 10 << 10 | 13
 * << 15 = 0x16_A800. One conversion ch11: JL = 0, JSQ4 = 11 << 15 =
 * 0x5_8000. Sampling codes: 3, 15, 28, 56, 84, 112, 144, 480 cycles = 0..7;
 * 20 cycles has none. A rank ends its sampling after the ranks before it
 * (SMP + 12 each) and its own SMP: ranks 15, 28 with latency 2: rank 2 ends
 * at 2 + 27 + 28 = 57. */
static void test_adc_sequence(void)
{
    const uint8_t two[2] = {10u, 13u};
    const uint8_t one[1] = {11u};
    TEST_ASSERT_EQUAL_HEX32(0x0016A800u, f4_adc_jsqr(two, 2u));
    TEST_ASSERT_EQUAL_HEX32(0x00058000u, f4_adc_jsqr(one, 1u));
    uint32_t code;
    TEST_ASSERT_EQUAL_INT(F4_OK, f4_adc_smp_code(15u, &code));
    TEST_ASSERT_EQUAL_UINT32(1u, code);
    TEST_ASSERT_EQUAL_INT(F4_OK, f4_adc_smp_code(480u, &code));
    TEST_ASSERT_EQUAL_UINT32(7u, code);
    TEST_ASSERT_EQUAL_INT(F4_E_CONFIG, f4_adc_smp_code(20u, &code));
    const uint32_t smp[2] = {15u, 28u};
    TEST_ASSERT_EQUAL_UINT32(57u, f4_adc_sample_end(smp, 2u, 2u));
}

/* The compare limit at 20 kHz (ARR 4200, 168 MHz counts): VESC 6: dead
 * time 360 + settling 1000 ns = 1360 ns; its current samples end 2 + 15
 * ADC cycles after the trigger at 21 MHz = 810 ns: the larger, 1360 ns,
 * is ceil(1360e-9 x 168e6) = ceil(228.48) = 229 counts: cmp_max 3971.
 * ODrive: 120 + 2000 ns = 356.16 -> 357: 3843. */
static void test_compare_limit(void)
{
    stm32_pwm_timing_t t;
    uint32_t m;
    TEST_ASSERT_EQUAL_INT(STM32_OK, stm32_pwm_timing(168000000u, 20000u, &t));
    TEST_ASSERT_EQUAL_INT(F4_OK, f4_hal_cmp_max(&f4_board_vesc6, &t, 168000000u, 21000000u, &m));
    TEST_ASSERT_EQUAL_UINT32(3971u, m);
    TEST_ASSERT_EQUAL_INT(F4_OK,
                          f4_hal_cmp_max(&f4_board_odrive_v36, &t, 168000000u, 21000000u, &m));
    TEST_ASSERT_EQUAL_UINT32(3843u, m);
}

/* hal.h's description of each board at 20 kHz on the PLL's clocks:
 * VESC 6: 3.3 / 4095 / (20 x 0.5 mOhm) = 0.080586 A per count,
 * 3.3 / 4095 x 41.2 / 2.2 = 0.015092 V per count; zero at 1.65 V =
 * 2047.5 -> 2048, tolerance ceil(0.1 / 3.3 x 4095) = 125. ODrive v3.6:
 * 3.3 / 4095 / (40 x 0.5 mOhm) = 0.040293 A, 3.3 / 4095 x 19 = 0.015311 V;
 * tolerance ceil(0.15 / 3.3 x 4095) = 187; phase A rebuilt with k =
 * 3 x 2048. */
static void test_board_descriptions(void)
{
    const f4_clocks_t clk = {168000000u, 42000000u, 84000000u, 84000000u, 168000000u, true};
    const f4_hal_cfg_t cfg = {20000u, 4096u};
    static hal_t h;
    TEST_ASSERT_EQUAL_INT(F4_OK, f4_hal_describe(&h, &f4_board_vesc6, &cfg, &clk));
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 0.080586, h.info.adc_current_a_per_count);
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 0.015092, h.info.adc_vdc_v_per_count);
    TEST_ASSERT_EQUAL_UINT16(2048u, h.info.adc_current_zero);
    TEST_ASSERT_EQUAL_UINT16(125u, h.info.adc_current_zero_tol);
    TEST_ASSERT_EQUAL_UINT32(3u, h.rebuilt);
    TEST_ASSERT_EQUAL_UINT32(4200u, h.info.period_counts);
    TEST_ASSERT_EQUAL_UINT32(168000000u, h.info.cycle_clock_hz);
    TEST_ASSERT_EQUAL_INT(F4_OK, f4_hal_describe(&h, &f4_board_odrive_v36, &cfg, &clk));
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 0.040293, h.info.adc_current_a_per_count);
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 0.015311, h.info.adc_vdc_v_per_count);
    TEST_ASSERT_EQUAL_UINT16(187u, h.info.adc_current_zero_tol);
    TEST_ASSERT_EQUAL_UINT32(0u, h.rebuilt);
    TEST_ASSERT_EQUAL_UINT32(6144u, h.rebuild_k);
    /* out of range: 9 kHz, 41 kHz, 3 counts per revolution */
    const f4_hal_cfg_t slow = {9000u, 4096u}, fast = {41000u, 4096u}, cpr = {20000u, 3u};
    TEST_ASSERT_EQUAL_INT(F4_E_CONFIG, f4_hal_describe(&h, &f4_board_vesc6, &slow, &clk));
    TEST_ASSERT_EQUAL_INT(F4_E_CONFIG, f4_hal_describe(&h, &f4_board_vesc6, &fast, &clk));
    TEST_ASSERT_EQUAL_INT(F4_E_CONFIG, f4_hal_describe(&h, &f4_board_vesc6, &cpr, &clk));
}

/* Board descriptions f4_hal_describe refuses: active-low gate inputs (TIM1
 * idles its outputs at 0 with MOE cleared: such inputs would sit active);
 * the ODrive's DRV8301 gain changed alone (written 20 V/V, currents scaled
 * for 40: every current read 2x too large), or the sense gain alone. The
 * VESC 6's own amplifiers do not depend on the DRV8301's gain. */
static void test_board_refusals(void)
{
    const f4_clocks_t clk = {168000000u, 42000000u, 84000000u, 84000000u, 168000000u, true};
    const f4_hal_cfg_t cfg = {20000u, 4096u};
    static hal_t h;
    f4_board_t b = f4_board_vesc6;
    b.gate_active_low = true;
    TEST_ASSERT_EQUAL_INT(F4_E_CONFIG, f4_hal_describe(&h, &b, &cfg, &clk));
    b = f4_board_odrive_v36;
    TEST_ASSERT_TRUE(b.sense.drv_amp);
    TEST_ASSERT_EQUAL_DOUBLE(40.0, b.sense.gain);
    b.drv.gain = 1u;
    TEST_ASSERT_EQUAL_INT(F4_E_CONFIG, f4_hal_describe(&h, &b, &cfg, &clk));
    b = f4_board_odrive_v36;
    b.sense.gain = 20.0;
    TEST_ASSERT_EQUAL_INT(F4_E_CONFIG, f4_hal_describe(&h, &b, &cfg, &clk));
    b.sense.gain = -40.0; /* the sign is the wiring's, not the driver's */
    TEST_ASSERT_EQUAL_INT(F4_OK, f4_hal_describe(&h, &b, &cfg, &clk));
    b = f4_board_vesc6;
    b.drv.gain = 3u;
    TEST_ASSERT_EQUAL_INT(F4_OK, f4_hal_describe(&h, &b, &cfg, &clk));
}

/* SPI_CR1.BR: f_PCLK / 2^(BR + 1) <= max. 42 MHz, 5 MHz: /2 21, /4 10.5,
 * /8 5.25, /16 2.625 MHz -> BR 3 (ODrive's prescaler 16); 16 MHz (the
 * fall-back): /4 = 4 MHz -> BR 1. USART BRR at 42 MHz, 115200 baud:
 * 364.58 -> 365 (115 068 baud, -0.11 %); at 16 MHz 138.9 -> 139. */
static void test_spi_and_usart_dividers(void)
{
    uint32_t br, sck, brr;
    TEST_ASSERT_EQUAL_INT(F4_OK, f4_spi_br(42000000u, 5000000u, &br, &sck));
    TEST_ASSERT_EQUAL_UINT32(3u, br);
    TEST_ASSERT_EQUAL_UINT32(2625000u, sck);
    TEST_ASSERT_EQUAL_INT(F4_OK, f4_spi_br(16000000u, 5000000u, &br, &sck));
    TEST_ASSERT_EQUAL_UINT32(1u, br);
    TEST_ASSERT_EQUAL_INT(F4_E_CONFIG, f4_spi_br(168000000u, 100000u, &br, &sck));
    TEST_ASSERT_EQUAL_INT(STM32_OK, stm32_usart_brr(42000000u, 115200u, &brr));
    TEST_ASSERT_EQUAL_UINT32(365u, brr);
    TEST_ASSERT_EQUAL_INT(STM32_OK, stm32_usart_brr(16000000u, 115200u, &brr));
    TEST_ASSERT_EQUAL_UINT32(139u, brr);
}

/* IWDG, 100 ms at the nominal 32 kHz: divider 4 reaches it with 800 ticks
 * (PR 0, RLR 799). The LSI's 17 .. 47 kHz spread (DS8626) makes it 68 ms
 * at the fastest (800 x 4 / 47000 = 68.1) and 188 ms at the slowest. 2 s:
 * divider 16 (PR 2): 4000 ticks, RLR 3999; 1361 .. 3764 ms. */
static void test_iwdg_window(void)
{
    uint32_t pr, rlr, lo, hi;
    TEST_ASSERT_EQUAL_INT(STM32_OK, stm32_iwdg_config(100u, F4_LSI_TYP_HZ, &pr, &rlr));
    TEST_ASSERT_EQUAL_UINT32(0u, pr);
    TEST_ASSERT_EQUAL_UINT32(799u, rlr);
    f4_iwdg_window(pr, rlr, &lo, &hi);
    TEST_ASSERT_EQUAL_UINT32(68u, lo);
    TEST_ASSERT_EQUAL_UINT32(188u, hi);
    TEST_ASSERT_EQUAL_INT(STM32_OK, stm32_iwdg_config(2000u, F4_LSI_TYP_HZ, &pr, &rlr));
    TEST_ASSERT_EQUAL_UINT32(2u, pr);
    TEST_ASSERT_EQUAL_UINT32(3999u, rlr);
    f4_iwdg_window(pr, rlr, &lo, &hi);
    TEST_ASSERT_EQUAL_UINT32(1361u, lo);
    TEST_ASSERT_EQUAL_UINT32(3764u, hi);
}

/* DRV8301 control words (data sheet register map, = MotorWare / VESC /
 * ODrive): ODrive's (21 << 6) | (01 << 4) = 0x550 and gain 40 (code 2 <<
 * 2) = 0x008, exactly what its drv8301.cpp writes; VESC 6 here: 16 << 6 |
 * 01 << 4 = 0x410, gain 20: 0x004. VESC's literal 0x0430 (OC disabled,
 * OCP_MODE 11) from its fields. Command words: write CR1 0x550 = 2 << 11 |
 * 0x550 = 0x1550; read status 1 = 0x8000; read CR2 = 0x9800. Reserved
 * codes refused: gate current 3, OCTW mode 3. */
static void test_drv8301_words(void)
{
    uint16_t cr1, cr2;
    TEST_ASSERT_EQUAL_INT(DRV8301_OK, drv8301_words(&f4_board_odrive_v36.drv, &cr1, &cr2));
    TEST_ASSERT_EQUAL_HEX16(0x550u, cr1);
    TEST_ASSERT_EQUAL_HEX16(0x008u, cr2);
    TEST_ASSERT_EQUAL_INT(DRV8301_OK, drv8301_words(&f4_board_vesc6.drv, &cr1, &cr2));
    TEST_ASSERT_EQUAL_HEX16(0x410u, cr1);
    TEST_ASSERT_EQUAL_HEX16(0x004u, cr2);
    const drv8301_cfg_t vesc_literal = {0u, 3u, 16u, 0u, 0u, false};
    TEST_ASSERT_EQUAL_INT(DRV8301_OK, drv8301_words(&vesc_literal, &cr1, &cr2));
    TEST_ASSERT_EQUAL_HEX16(0x430u, cr1);
    TEST_ASSERT_EQUAL_HEX16(0x1550u, drv8301_frame(false, 2u, 0x550u));
    TEST_ASSERT_EQUAL_HEX16(0x8000u, drv8301_frame(true, 0u, 0u));
    TEST_ASSERT_EQUAL_HEX16(0x9800u, drv8301_frame(true, 3u, 0u));
    const drv8301_cfg_t bad_gc = {3u, 1u, 16u, 0u, 0u, false};
    const drv8301_cfg_t bad_octw = {0u, 1u, 16u, 0u, 3u, false};
    TEST_ASSERT_EQUAL_INT(DRV8301_E_CONFIG, drv8301_words(&bad_gc, &cr1, &cr2));
    TEST_ASSERT_EQUAL_INT(DRV8301_E_CONFIG, drv8301_words(&bad_octw, &cr1, &cr2));
}

/* OC_ADJ_SET table (data sheet; MotorWare DRV8301_VdsLevel_e): code 0 =
 * 60 mV, 16 = 403, 21 = 730 (ODrive's "about 150 A at 100 C"), 31 = 2400;
 * the largest code at most 400 mV is 15 (358 mV), at most 403 mV is 16;
 * below 60 mV none. Gains 10, 20, 40, 80. */
static void test_drv8301_tables(void)
{
    TEST_ASSERT_EQUAL_UINT32(60u, drv8301_vds_mv(0u));
    TEST_ASSERT_EQUAL_UINT32(403u, drv8301_vds_mv(16u));
    TEST_ASSERT_EQUAL_UINT32(730u, drv8301_vds_mv(21u));
    TEST_ASSERT_EQUAL_UINT32(2400u, drv8301_vds_mv(31u));
    TEST_ASSERT_EQUAL_UINT32(0u, drv8301_vds_mv(32u));
    TEST_ASSERT_EQUAL_INT(15, drv8301_oc_adj_at_most(400u));
    TEST_ASSERT_EQUAL_INT(16, drv8301_oc_adj_at_most(403u));
    TEST_ASSERT_EQUAL_INT(-1, drv8301_oc_adj_at_most(59u));
    TEST_ASSERT_EQUAL_UINT32(10u, drv8301_gain(0u));
    TEST_ASSERT_EQUAL_UINT32(80u, drv8301_gain(3u));
}

/* Status bits by name: status 1 0x420 = FETHA_OC (bit 5) and FAULT (bit 10);
 * status 2 bit 7 GVDD_OV; the device ID (bits 3:0) is no fault. */
static void test_drv8301_fault_names(void)
{
    char buf[96];
    (void)drv8301_fault_names(0x420u, 0x001u, buf, sizeof buf);
    TEST_ASSERT_EQUAL_STRING("FETHA_OC FAULT", buf);
    (void)drv8301_fault_names(0x000u, 0x081u, buf, sizeof buf);
    TEST_ASSERT_EQUAL_STRING("GVDD_OV", buf);
    (void)drv8301_fault_names(0x000u, 0x001u, buf, sizeof buf);
    TEST_ASSERT_EQUAL_STRING("none", buf);
    (void)drv8301_fault_names(0x300u, 0x000u, buf, 8u);
    TEST_ASSERT_EQUAL_STRING("PVDD_UV", buf);
}

/* NTC beta model. VESC 6: 10 kOhm NTC to VREF, 10 kOhm to ground: at
 * 25 C the midpoint, 2047.5 counts. ODrive: 10 kOhm NTC (beta 3434) to VREF
 * over 3.3 kOhm: 25 C at 3.3 x 3300 / 13300 = 0.8188 V = 1016.0 counts;
 * 100 C: R = 10k exp(3434 (1/373.15 - 1/298.15)) = 988.4 Ohm, v = 3.3 x
 * 3300 / 4288.4 = 2.5394 V = 3151.2 counts. A reading at a rail (open or
 * shorted sensor): NaN, not a temperature. */
static void test_ntc(void)
{
    TEST_ASSERT_DOUBLE_WITHIN(0.05, 25.0, f4_hal_temp_c(&f4_board_vesc6, 2048));
    TEST_ASSERT_DOUBLE_WITHIN(0.05, 25.0, f4_hal_temp_c(&f4_board_odrive_v36, 1016));
    TEST_ASSERT_DOUBLE_WITHIN(0.05, 100.0, f4_hal_temp_c(&f4_board_odrive_v36, 3151));
    /* ODrive's own conversion of the same readings, independent of the
     * model (its v3 board.cpp fet_thermistor_poly_coeffs, a cubic in the
     * normalised voltage): 25.7 C and 101.1 C; with the NTC placed to ground
     * the model would give 96.9 C and 23.0 C for these codes. */
    static const double odrive_poly[4] = {363.93910201, -462.15369634, 307.55129571, -27.72569531};
    const int32_t codes[2] = {1016, 3151};
    for (unsigned k = 0; k < 2u; k++) {
        const double x = (double)codes[k] / 4095.0;
        const double t_odrive =
            ((odrive_poly[0] * x + odrive_poly[1]) * x + odrive_poly[2]) * x + odrive_poly[3];
        TEST_ASSERT_DOUBLE_WITHIN(2.0, t_odrive, f4_hal_temp_c(&f4_board_odrive_v36, codes[k]));
    }
    TEST_ASSERT_TRUE(isnan(f4_hal_temp_c(&f4_board_vesc6, 0)));
    TEST_ASSERT_TRUE(isnan(f4_hal_temp_c(&f4_board_vesc6, 4095)));
    TEST_ASSERT_TRUE(isnan(f4_hal_temp_c(&f4_board_vesc6, -1)));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_pll_8mhz_to_168mhz);
    RUN_TEST(test_pll_other_and_impossible);
    RUN_TEST(test_flash_latency_and_bus_codes);
    RUN_TEST(test_clock_result);
    RUN_TEST(test_pwm_timing_and_dead_time);
    RUN_TEST(test_adc_sequence);
    RUN_TEST(test_compare_limit);
    RUN_TEST(test_board_descriptions);
    RUN_TEST(test_board_refusals);
    RUN_TEST(test_spi_and_usart_dividers);
    RUN_TEST(test_iwdg_window);
    RUN_TEST(test_drv8301_words);
    RUN_TEST(test_drv8301_tables);
    RUN_TEST(test_drv8301_fault_names);
    RUN_TEST(test_ntc);
    return UNITY_END();
}
