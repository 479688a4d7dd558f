/*
 * Board description of the ST B-G431B-ESC1 (board_esc1.h).
 *
 * Sources, cited per line:
 *   [UM2516]  ST user manual UM2516 "Electronic speed controller Discovery kit
 *             for drones with STM32G431CB", table 4 "Main board STM32G431CB
 *             pinout for motor control". Not read here in ST's text: known from
 *             two independent transcriptions that agree (NuttX board.h /
 *             stm32_foc.c and a Rust board crate quoting the table).
 *   [DS]      STM32G431 datasheet DS12589 pin alternate functions and ADC
 *             channels, as carried by NuttX's stm32g4xxc/k_pinmap.h
 *   [LL]      ST's LL driver stm32g4xx_ll_comp.h: COMP plus input IO1 = PA1
 *             (COMP1), PA7 (COMP2), PB0 (COMP4); INMSEL 100 = DAC3_CH1 for
 *             COMP1/3, DAC3_CH2 for COMP2/4
 *   [NuttX]   boards/arm/stm32/b-g431b-esc1 (stm32_foc.c, board.h): op-amp
 *             wiring and PGA code, 3 mOhm shunts, current gain -9.14,
 *             Vbus gain 0.0962, 25 V (6S), 40 A peak, L6387 active-high inputs
 *   [SimpleFOC] B-G431B-ESC1 examples: current gain -64/7 = -9.1429
 * Values no source confirmed are marked UNVERIFIED; docs/bringup.md checks
 * them on the bench before the gates are enabled.
 */
#include "board_esc1.h"

#define A 0u
#define B 1u
#define C 2u

const g4_board_t g4_board_esc1 = {
    .name = "B-G431B-ESC1",
    .hse_hz = 8000000u,      /* [UM2516] 8 MHz crystal on PF0/PF1 */
    .sysclk_hz = 170000000u, /* maximum of the STM32G431 (range-1 boost) */

    /* TIM1 CH1/2/3 PA8/PA9/PA10 AF6, CH1N PC13 AF4, CH2N PA12 AF6,
     * CH3N PB15 AF4 [UM2516][DS]. */
    .pwm_high = {{A, 8u, 6u}, {A, 9u, 6u}, {A, 10u, 6u}},
    .pwm_low = {{C, 13u, 4u}, {A, 12u, 6u}, {B, 15u, 4u}},
    .gate_active_low = false, /* L6387 HIN/LIN active high [NuttX] */
    .dead_time_ns = 500u,     /* [NuttX] default; the L6387 adds its own interlock */
    /* UNVERIFIED: ~1.3 us measured by one project (SimpleFOC-based FOC-Stim
     * bsp) from FET off to a settled current sample; 1.5 us kept. */
    .sense_settle_ns = 1500u,
    .break_filter = 10u, /* BKF 1010: f_DTS/16, N = 5: 80 / 170 MHz = 0.47 us */

    /* Phase U: OPAMP1 VINP0 PA1, VINM0 PA3, VOUT PA2 = ADC1_IN3; PA1 =
     * ADC1_IN2; COMP1 IO1 = PA1, DAC3_CH1. Phase V: OPAMP2 VINP0 PA7, VINM0
     * PA5, VOUT PA6 = ADC2_IN3; PA7 = ADC2_IN4; COMP2 IO1 = PA7, DAC3_CH2.
     * Phase W: OPAMP3 VINP0 PB0, VINM0 PB2, VOUT PB1 = ADC1_IN12; PB0 =
     * ADC1_IN15; COMP4 IO1 = PB0, DAC3_CH2. [UM2516][DS][LL][NuttX] */
    .phase =
        {
            {1u, 0u, {A, 1u, 0u}, {A, 3u, 0u}, {A, 2u, 0u}, 1u, 3u, 1u, 2u, 1u, 1u},
            {2u, 0u, {A, 7u, 0u}, {A, 5u, 0u}, {A, 6u, 0u}, 2u, 3u, 1u, 4u, 2u, 2u},
            {3u, 0u, {B, 0u, 0u}, {B, 2u, 0u}, {B, 1u, 0u}, 1u, 12u, 2u, 15u, 4u, 2u},
        },
    /* PGA_GAIN 01011: non-inverting gain 16, VINM0 as input/bias [NuttX] */
    .opamp_pga_code = 11u,
    .opamp_pga_gain = 16.0,
    .shunt_ohm = 0.003,        /* [UM2516][NuttX] */
    .sense_gain = -64.0 / 7.0, /* [SimpleFOC]; [NuttX] -9.14 */
    .current_smp_half = 13u,   /* 6.5 cycles: the op-amp output is low impedance */
    /* Bias of VINP (ST schematic MB1419, as an independent review read it): 2.2 kOhm
     * to ground, 22 kOhm to 3.3 V, 1.5 kOhm to the shunt: VINP = 0.1286 V +
     * 4/7 V_shunt (4/7 x 16 = 64/7, the sense gain above), zero current at
     * 16 x 0.1286 V = 2.06 V = ADC code 2553. UNVERIFIED: the resistor
     * tolerance (1 %), the op-amp input offset (3 mV) and PGA gain error
     * (2 %) as worst cases; one forum source reports about 1.65 V at zero
     * current instead. docs/bringup.md step 2 prints the measured levels. */
    .sense_r_gnd = 2200.0,
    .sense_r_bias = 22000.0,
    .sense_r_shunt = 1500.0,
    .sense_r_tol = 0.01,
    .opamp_vio_v = 0.003,
    .opamp_gain_err = 0.02,

    /* Vbus PA0 = ADC2_IN1 [DS]; divider 18 k / (18 k + 169 k) [NuttX]. */
    .vbus_pin = {A, 0u, 0u},
    .vbus_adc = 2u,
    .vbus_channel = 1u,
    .vbus_rank = 2u,
    .vbus_ratio = 18.0 / (18.0 + 169.0),
    /* 47.5 cycles = 1.1 us: the divider's 16.3 kOhm source needs
     * t_S >= (R_AIN + R_ADC) C_ADC ln(2^14) ~ 0.8 us with C_ADC ~ 5 pF (DS) */
    .vbus_smp_half = 95u,

    /* Board NTC on PB14 = ADC1_IN5 [UM2516][NuttX board.h]. UNVERIFIED
     * linear model (ST MC SDK's description of this board as reported by
     * users): 1.055 V at 25 C, 22.7 mV/C. Outside 0.05 .. 3.25 V the sensor
     * is taken as open or shorted (trip). */
    .temp_pin = {B, 14u, 0u},
    .temp_adc = 1u,
    .temp_channel = 5u,
    .temp_smp_half = 495u, /* 247.5 cycles */
    .temp_v0 = 1.055,
    .temp_t0_c = 25.0,
    .temp_dv_dt = 0.0227,
    .temp_v_min = 0.05,
    .temp_v_max = 3.25,
    .temp_trip_c = 90.0,
    .vref = 3.3, /* VDDA = VREF+ = 3.3 V [NuttX ADC_REF_VOLTAGE] */

    /* Encoder / Hall connector J8: A+ PB6, B+ PB7, Z+ PB8 = TIM4_CH1/2/3 AF2
     * [UM2516][DS]; PB6/PB7 have RC filters on the board. */
    .enc_a = {B, 6u, 2u},
    .enc_b = {B, 7u, 2u},
    .enc_index = {B, 8u, 2u},
    .enc_has_index = true,
    /* PB8 is also BOOT0. UNVERIFIED: pulled up on the board (an independent
     * review's reading of ST's MB1419 schematic); ST ships the board with
     * nSWBOOT0 = 0, nBOOT0 = 1 (BOOT0 from the option bit, the pin ignored).
     * docs/bringup.md step 1 reads the option bytes and PB8. */
    .boot0_pulled_up = true,
    .enc_filter = 6u, /* ICF 0110: f_DTS/4, N = 6: 24 / 170 MHz = 0.14 us */

    /* USART2 TX PB3, RX PB4, AF7: the ST-LINK virtual COM port [UM2516][DS]. */
    .uart_tx = {B, 3u, 7u},
    .uart_rx = {B, 4u, 7u},
    .baud = 115200u,

    /* The PWM pad (the flight controller's throttle): PA15 = TIM2_CH1 AF1
     * [UM2516][DS]. UNVERIFIED: the pad's series resistor / pull network. */
    .throttle = {A, 15u, 1u},
    .throttle_filter = 15u, /* ICF 1111: f_DTS/32, N = 8: 256 / 170 MHz = 1.5 us */

    .led = {C, 6u, 0u}, /* LD2, active high [UM2516][NuttX] */
    /* PB4 (USART2 RX) and PB6 (encoder A) are the UCPD1 CC2/CC1 pins, pulled
     * down after reset (RM0440 PWR_CR3.UCPD1_DBDIS; NuttX does the same). */
    .ucpd_dead_battery_off = true,

    .current_peak_a = 40.0, /* [UM2516][NuttX] 40 A peak */
    .vbus_max_v = 25.2,     /* 6S LiPo [UM2516] */
};
