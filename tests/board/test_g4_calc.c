/*
 * Configuration computations of the STM32G4 chip support and the
 * B-G431B-ESC1 description, against values worked out by hand from RM0440's
 * formulas (each test says which). No register access: pure functions.
 */
#include <math.h>

#include "board_esc1.h"
#include "g4_adc.h"
#include "g4_analog.h"
#include "g4_clock.h"
#include "g4_core.h"
#include "g4_hal.h"
#include "g4_model.h"
#include "g4_periph.h"
#include "g4_tim.h"
#include "unity.h"

void setUp(void)
{
    g4_model_reset();
}

void tearDown(void)
{
}

/* RCC_PLLCFGR: f_VCO = f_HSE / M x N, f_SYSCLK = f_VCO / R, 2.66 MHz <=
 * f_HSE / M <= 16 MHz, 64 <= f_VCO <= 344 MHz, N 8..127, R 2/4/6/8.
 * 8 MHz -> 170 MHz: M = 1 would need N = 170 x 2 / 8 = 42.5 (R 2) or a VCO
 * of 680 MHz (R 4): no; M = 2: 4 MHz x 85 = 340 MHz, / 2 = 170 MHz. Register:
 * PLLSRC 11 (HSE) | (M-1 = 1) << 4 | 85 << 8 | PLLREN << 24 | PLLR 00 (/2)
 * = 0x3 | 0x10 | 0x5500 | 0x0100_0000 = 0x0100_5513. */
static void test_pll_8mhz_to_170mhz(void)
{
    g4_pll_t p;
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_pll_solve(8000000u, 170000000u, &p));
    TEST_ASSERT_EQUAL_UINT32(2u, p.m);
    TEST_ASSERT_EQUAL_UINT32(85u, p.n);
    TEST_ASSERT_EQUAL_UINT32(2u, p.r);
    TEST_ASSERT_EQUAL_UINT32(4000000u, p.vco_in_hz);
    TEST_ASSERT_EQUAL_UINT32(340000000u, p.vco_hz);
    TEST_ASSERT_EQUAL_HEX32(0x01005513u, g4_pll_cfgr(&p));
}

/* 8 MHz -> 150 MHz: M = 2, N = 75, R = 2 (VCO 300 MHz). 24 MHz -> 170 MHz:
 * M = 1, 2, 3, 4, 5 give 24 (too high), 12, 8, 6, 4.8 MHz with no integer N
 * for 340 MHz (28.3, 42.5, 56.7, 70.8) and 680 MHz is above 344; M = 6:
 * 4 MHz x 85. 8 MHz -> 169 MHz: N would be 84.5 (M 2), 42.25 (M 1), 126.75
 * (M 3, 2.67 MHz): no exact setting -> refused, not approximated. 171 MHz is
 * above the device maximum. */
static void test_pll_other_and_impossible(void)
{
    g4_pll_t p;
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_pll_solve(8000000u, 150000000u, &p));
    TEST_ASSERT_EQUAL_UINT32(2u, p.m);
    TEST_ASSERT_EQUAL_UINT32(75u, p.n);
    TEST_ASSERT_EQUAL_UINT32(2u, p.r);
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_pll_solve(24000000u, 170000000u, &p));
    TEST_ASSERT_EQUAL_UINT32(6u, p.m);
    TEST_ASSERT_EQUAL_UINT32(85u, p.n);
    TEST_ASSERT_EQUAL_UINT32(2u, p.r);
    TEST_ASSERT_EQUAL_INT(G4_E_CONFIG, g4_pll_solve(8000000u, 169000000u, &p));
    TEST_ASSERT_EQUAL_INT(G4_E_CONFIG, g4_pll_solve(8000000u, 171000000u, &p));
    TEST_ASSERT_EQUAL_INT(G4_E_CONFIG, g4_pll_solve(0u, 170000000u, &p));
}

/* RM0440 FLASH, wait states vs HCLK: boost 34/68/102/136/170 MHz, normal
 * 30/60/90/120/150 MHz for 0..4 WS. */
static void test_flash_latency(void)
{
    TEST_ASSERT_EQUAL_INT(4, g4_flash_latency(170000000u, true));
    TEST_ASSERT_EQUAL_INT(3, g4_flash_latency(136000000u, true));
    TEST_ASSERT_EQUAL_INT(4, g4_flash_latency(136000001u, true));
    TEST_ASSERT_EQUAL_INT(0, g4_flash_latency(34000000u, true));
    TEST_ASSERT_EQUAL_INT(1, g4_flash_latency(34000001u, true));
    TEST_ASSERT_EQUAL_INT(-1, g4_flash_latency(170000001u, true));
    TEST_ASSERT_EQUAL_INT(4, g4_flash_latency(150000000u, false));
    TEST_ASSERT_EQUAL_INT(-1, g4_flash_latency(150000001u, false));
    TEST_ASSERT_EQUAL_INT(0, g4_flash_latency(16000000u, false));
}

/* Centre-aligned: f_PWM = f_TIM / (2 ARR (PSC + 1)). 170 MHz: 20 kHz ->
 * ARR 4250, 40 kHz -> 2125, 10 kHz -> 8500 (PSC 0); 1 kHz -> 85000 > 65535,
 * PSC 1 -> 42500. 30 kHz -> 8500 / 3 timer clocks per half period: no integer
 * setting at any prescaler -> refused. */
static void test_pwm_timing(void)
{
    g4_pwm_timing_t t;
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_pwm_timing(170000000u, 20000u, &t));
    TEST_ASSERT_EQUAL_UINT32(0u, t.psc);
    TEST_ASSERT_EQUAL_UINT32(4250u, t.arr);
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_pwm_timing(170000000u, 40000u, &t));
    TEST_ASSERT_EQUAL_UINT32(2125u, t.arr);
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_pwm_timing(170000000u, 10000u, &t));
    TEST_ASSERT_EQUAL_UINT32(8500u, t.arr);
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_pwm_timing(170000000u, 1000u, &t));
    TEST_ASSERT_EQUAL_UINT32(1u, t.psc);
    TEST_ASSERT_EQUAL_UINT32(42500u, t.arr);
    TEST_ASSERT_EQUAL_INT(G4_E_CONFIG, g4_pwm_timing(170000000u, 30000u, &t));
    TEST_ASSERT_EQUAL_INT(G4_E_CONFIG, g4_pwm_timing(170000000u, 0u, &t));
}

/* TIMx_BDTR.DTG at f_DTS = 170 MHz (t_DTS = 5.882 ns), rounded up:
 *   500 ns  = 85.0 t      range 1: DTG = 85 = 0x55
 *   747 ns  = 126.99 t    -> 127: 0x7F (largest of range 1)
 *   752 ns  = 127.84 t    -> 128: range 2, (64 + 0) x 2: 0x80
 *   1000 ns = 170 t       range 2: (64 + 21) x 2 = 170: 0x80 | 21 = 0x95
 *   1001 ns = 170.17 t    -> 171 -> (64 + 22) x 2 = 172 t = 1011.8 ns: 0x96
 *   2000 ns = 340 t       range 3: ceil(340 / 8) = 43 = 32 + 11: 0xCB, 344 t
 *   4000 ns = 680 t       range 4: ceil(680 / 16) = 43: 0xEB, 688 t
 *   5929 ns = 1007.9 t    -> 1008 = 63 x 16: 0xFF
 *   5930 ns = 1008.1 t    -> above 1008 t: refused */
static void test_dead_time_four_ranges(void)
{
    static const struct {
        uint32_t ns;
        uint8_t dtg;
        uint32_t ticks;
    } v[] = {{0u, 0x00u, 0u},      {500u, 0x55u, 85u},   {747u, 0x7Fu, 127u},
             {752u, 0x80u, 128u},  {1000u, 0x95u, 170u}, {1001u, 0x96u, 172u},
             {2000u, 0xCBu, 344u}, {4000u, 0xEBu, 688u}, {5929u, 0xFFu, 1008u}};
    for (unsigned i = 0; i < sizeof v / sizeof v[0]; i++) {
        uint8_t dtg = 0xAAu;
        TEST_ASSERT_EQUAL_INT(G4_OK, g4_dtg_encode(170000000u, v[i].ns, &dtg));
        TEST_ASSERT_EQUAL_HEX8(v[i].dtg, dtg);
        TEST_ASSERT_EQUAL_UINT32(v[i].ticks, g4_dtg_ticks(dtg));
        /* never shorter than requested: ticks / 170 MHz >= ns */
        TEST_ASSERT_TRUE((uint64_t)v[i].ticks * 1000000000u >= (uint64_t)v[i].ns * 170000000u);
    }
    uint8_t dtg;
    TEST_ASSERT_EQUAL_INT(G4_E_CONFIG, g4_dtg_encode(170000000u, 5930u, &dtg));
}

/* Filter codes (BKF / ICxF): code 1010 = f_DTS/16, N = 5 -> 80 cycles
 * (0.47 us at 170 MHz, the ESC1's break filter); 0110 = f_DTS/4, N = 6 -> 24
 * (the encoder inputs); 0011 = f_CK_INT, N = 8 -> 8; 1111 = f_DTS/32, N = 8. */
static void test_filter_codes(void)
{
    TEST_ASSERT_EQUAL_UINT32(0u, g4_filter_cycles(0u));
    TEST_ASSERT_EQUAL_UINT32(8u, g4_filter_cycles(3u));
    TEST_ASSERT_EQUAL_UINT32(24u, g4_filter_cycles(6u));
    TEST_ASSERT_EQUAL_UINT32(80u, g4_filter_cycles(10u));
    TEST_ASSERT_EQUAL_UINT32(256u, g4_filter_cycles(15u));
    TEST_ASSERT_EQUAL_UINT32(80u, g4_filter_cycles(g4_board_esc1.break_filter));
}

/* ADC_SMPRx codes: 2.5, 6.5, 12.5, 24.5, 47.5, 92.5, 247.5, 640.5 cycles. */
static void test_adc_sampling_codes(void)
{
    uint32_t c;
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_adc_smp_code(5u, &c));
    TEST_ASSERT_EQUAL_UINT32(0u, c);
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_adc_smp_code(13u, &c));
    TEST_ASSERT_EQUAL_UINT32(1u, c);
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_adc_smp_code(95u, &c));
    TEST_ASSERT_EQUAL_UINT32(4u, c);
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_adc_smp_code(1281u, &c));
    TEST_ASSERT_EQUAL_UINT32(7u, c);
    TEST_ASSERT_EQUAL_INT(G4_E_CONFIG, g4_adc_smp_code(14u, &c));
    /* ADC_JSQR: JL = n - 1, JEXTSEL at 2, JEXTEN 01 (rising) at 7, JSQ1 at 9,
     * JSQ2 at 15. ADC1 of the ESC1: channels 3 (U) and 12 (W) on TIM1_TRGO2
     * (JEXTSEL 8): 1 | 8 << 2 | 1 << 7 | 3 << 9 | 12 << 15 = 0x0006_06A1. */
    const uint8_t ch[2] = {3u, 12u};
    TEST_ASSERT_EQUAL_HEX32(0x000606A1u, g4_adc_jsqr(ch, 2u, 8u));
}

/* The current samples against the PWM centre. TRGO2 = the update event at
 * the counter peak (centre of V0). ADC clock 170 / 4 = 42.5 MHz, 1 half
 * cycle = 11.76 ns; latency bound 3 cycles. ADC1 of the ESC1 converts U then
 * W, 6.5 cycles sampling each, 12.5 cycles conversion:
 *   U sampling: [3, 3 + 6.5] cycles = [70.6, 223.5] ns after the peak
 *   W sampling: [3 + 19, 3 + 19 + 6.5] = [517.6, 670.6] ns
 * The zero vector lasts (ARR - cmp_max) / f_TIM on each side of the peak:
 * cmp_max = ARR - ceil((500 + 1500) ns x 170 MHz) = 4250 - 340 = 3910 at
 * 20 kHz: 2.0 us >= dead time + settling before, >= 670.6 ns after; the
 * largest leg duty is 3910 / 4250 = 92.0 %. 40 kHz: 2125 - 340 = 1785 (84 %);
 * 10 kHz: 8160. A 10 us settling time would need 1700 counts, more than a
 * quarter of the 20 kHz period (1062): refused. */
static void test_sampling_window_against_pwm_centre(void)
{
    const uint32_t smp[2] = {13u, 13u};
    uint32_t s0, s1;
    g4_adc_sample_window(smp, 1u, 6u, &s0, &s1);
    TEST_ASSERT_EQUAL_UINT32(6u, s0);
    TEST_ASSERT_EQUAL_UINT32(19u, s1);
    g4_adc_sample_window(smp, 2u, 6u, &s0, &s1);
    TEST_ASSERT_EQUAL_UINT32(44u, s0);
    TEST_ASSERT_EQUAL_UINT32(57u, s1);
    /* 57 half cycles at 85 MHz = 670.6 ns < 2000 ns of V0 after the peak */
    TEST_ASSERT_TRUE(57u * 1000000000ull / 85000000u < 2000u);

    const g4_board_t *b = &g4_board_esc1;
    g4_pwm_timing_t t;
    uint32_t m;
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_pwm_timing(b->sysclk_hz, 20000u, &t));
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_hal_cmp_max(b, &t, &m));
    TEST_ASSERT_EQUAL_UINT32(3910u, m);
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_pwm_timing(b->sysclk_hz, 40000u, &t));
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_hal_cmp_max(b, &t, &m));
    TEST_ASSERT_EQUAL_UINT32(1785u, m);
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_pwm_timing(b->sysclk_hz, 10000u, &t));
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_hal_cmp_max(b, &t, &m));
    TEST_ASSERT_EQUAL_UINT32(8160u, m);
    g4_board_t slow = *b;
    slow.sense_settle_ns = 10000u;
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_pwm_timing(b->sysclk_hz, 20000u, &t));
    TEST_ASSERT_EQUAL_INT(G4_E_CONFIG, g4_hal_cmp_max(&slow, &t, &m));
}

/* Comparator threshold on the op-amp plus input for a trip current:
 * V_th = V_zero + |G| / G_pga x R x I, DAC code = floor(V_th / 3.3 x 4096)
 * (DAC: V = VREF+ x DOR / 4096; ADC: V = VREF+ x code / 4095).
 * ESC1: |G| / G_pga = (64/7) / 16 = 0.571429, R = 3 mOhm.
 *   zero 128 counts = 0.103150 V; 8 A: + 0.0137143 V = 0.116864 V -> 145.05
 *   -> 145; 40 A: + 0.0685714 = 0.171722 V -> 213.1 -> 213.
 * Zeros U 128, V 140, W 120 counts: DAC3_CH1 (U) 145; DAC3_CH2 serves V
 * (0.112821 + 0.0137143 = 0.126535 V -> 157.06) and W (0.096703 + 0.0137143
 * = 0.110417 V -> 137.05): the lower, 137, so both trip at or below 8 A.
 * Above the board's 40 A, or 0 A: refused. */
static void test_comparator_dac_code_for_current(void)
{
    const g4_board_t *b = &g4_board_esc1;
    uint32_t code[2];
    const uint16_t z[3] = {128u, 128u, 128u};
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_hal_trip_codes(b, z, 8.0, code));
    TEST_ASSERT_EQUAL_UINT32(145u, code[0]);
    TEST_ASSERT_EQUAL_UINT32(145u, code[1]);
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_hal_trip_codes(b, z, 40.0, code));
    TEST_ASSERT_EQUAL_UINT32(213u, code[0]);
    const uint16_t z2[3] = {128u, 140u, 120u};
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_hal_trip_codes(b, z2, 8.0, code));
    TEST_ASSERT_EQUAL_UINT32(145u, code[0]);
    TEST_ASSERT_EQUAL_UINT32(137u, code[1]);
    TEST_ASSERT_EQUAL_INT(G4_E_CONFIG, g4_hal_trip_codes(b, z, 40.01, code));
    TEST_ASSERT_EQUAL_INT(G4_E_CONFIG, g4_hal_trip_codes(b, z, 0.0, code));
    TEST_ASSERT_EQUAL_INT(G4_E_CONFIG, g4_dac_code(3.3, 3.3, &code[0]));
}

/* hal.h scales of the ESC1: 3.3 V / 4095 / (64/7 x 3 mOhm) = 0.0293803 A per
 * count (NuttX: 0.02939); DC link 3.3 / 4095 / (18 / 187) = 0.00837200 V per
 * count (full scale 34.3 V). */
static void test_esc1_scales(void)
{
    const g4_board_t *b = &g4_board_esc1;
    const double a = b->vref / 4095.0 / (fabs(b->sense_gain) * b->shunt_ohm);
    const double v = b->vref / 4095.0 / b->vbus_ratio;
    TEST_ASSERT_DOUBLE_WITHIN(1e-7, 0.0293803, a);
    TEST_ASSERT_DOUBLE_WITHIN(1e-8, 0.00837200, v);
}

/* USART, oversampling 16: BRR = round(f_ck / baud). 170 MHz / 115200 =
 * 1475.69 -> 1476 (115176 Bd, -0.02 %); 16 MHz (HSI) -> 138.9 -> 139. */
static void test_usart_brr(void)
{
    uint32_t brr;
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_usart_brr(170000000u, 115200u, &brr));
    TEST_ASSERT_EQUAL_UINT32(1476u, brr);
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_usart_brr(16000000u, 115200u, &brr));
    TEST_ASSERT_EQUAL_UINT32(139u, brr);
    TEST_ASSERT_EQUAL_INT(G4_E_CONFIG, g4_usart_brr(1000000u, 115200u, &brr));
}

/* IWDG: time-out = (RLR + 1) x 4 x 2^PR / f_LSI. 100 ms at 32 kHz: PR 0
 * (/4): 800 ticks -> RLR 799. 1 s: /4 needs 8000 > 4096, /8: 4000 -> PR 1,
 * RLR 3999. 32 s: /256: 4000 -> PR 6. 40 s: 5000 > 4096 at /256: refused. */
static void test_iwdg(void)
{
    uint32_t pr, rlr;
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_iwdg_config(100u, 32000u, &pr, &rlr));
    TEST_ASSERT_EQUAL_UINT32(0u, pr);
    TEST_ASSERT_EQUAL_UINT32(799u, rlr);
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_iwdg_config(1000u, 32000u, &pr, &rlr));
    TEST_ASSERT_EQUAL_UINT32(1u, pr);
    TEST_ASSERT_EQUAL_UINT32(3999u, rlr);
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_iwdg_config(32000u, 32000u, &pr, &rlr));
    TEST_ASSERT_EQUAL_UINT32(6u, pr);
    TEST_ASSERT_EQUAL_INT(G4_E_CONFIG, g4_iwdg_config(40000u, 32000u, &pr, &rlr));
}

/* Encoder: TIM4 in encoder mode 3 counts 4 per line (1024 lines -> 4096 per
 * revolution). The 16-bit counter is extended by its signed 16-bit change:
 * 65530 (first read, sign-extended: -6), 5 (+11), 65526 (-15: -10), then a
 * capture of the index at CCR3 = 65500 while the counter reads 100: the
 * counter moved (100 - 65500) mod 65536 = 136 counts since, so the index is
 * at count - 136. Unambiguous below 32768 counts per period: 32768 x 20 kHz /
 * 4096 = 160 000 rev/s. */
static void test_encoder_extension(void)
{
    g4_enc_ext_t e = {0u, 0u, false};
    TEST_ASSERT_EQUAL_UINT32(0xFFFFFFFAu, g4_enc_extend(&e, 65530u));
    TEST_ASSERT_EQUAL_UINT32(5u, g4_enc_extend(&e, 5u));
    TEST_ASSERT_EQUAL_UINT32(0xFFFFFFF6u, g4_enc_extend(&e, 65526u));
    for (uint32_t k = 0; k < 40u; k++) { /* +30000 per read, 40 reads: no alias */
        (void)g4_enc_extend(&e, (uint16_t)(65526u + 30000u * (k + 1u)));
    }
    TEST_ASSERT_EQUAL_UINT32(0xFFFFFFF6u + 1200000u, e.count);
    g4_enc_ext_t f = {0u, 0u, false};
    (void)g4_enc_extend(&f, 0u);
    const uint32_t c = g4_enc_extend(&f, 100u);
    TEST_ASSERT_EQUAL_UINT32(100u, c);
    TEST_ASSERT_EQUAL_UINT32(100u - 136u, g4_enc_at_capture(&f, 100u, 65500u));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_pll_8mhz_to_170mhz);
    RUN_TEST(test_pll_other_and_impossible);
    RUN_TEST(test_flash_latency);
    RUN_TEST(test_pwm_timing);
    RUN_TEST(test_dead_time_four_ranges);
    RUN_TEST(test_filter_codes);
    RUN_TEST(test_adc_sampling_codes);
    RUN_TEST(test_sampling_window_against_pwm_centre);
    RUN_TEST(test_comparator_dac_code_for_current);
    RUN_TEST(test_esc1_scales);
    RUN_TEST(test_usart_brr);
    RUN_TEST(test_iwdg);
    RUN_TEST(test_encoder_extension);
    return UNITY_END();
}
