/*
 * Board description of the VESC 6, hardware "60" (board_vesc6.h).
 *
 * Sources, cited per line:
 *   [HW60]   VESC firmware (vedderb/bldc) hwconf/trampa/vesc6/hw_60.h and
 *            hw_60_core.h (pins, ADC channels, component values, limits),
 *            hw_60_core.c (hw_init_gpio: pin modes and alternate functions)
 *   [VESC]   the same firmware's shared defaults: mc_interface.h
 *            (HW_DEAD_TIME_NSEC 360), mcconf_default.h (DRV8301 OC_ADJ 16),
 *            hwconf/drv8301.c (the DRV8301's SPI use), hwconf/mcuconf.h and
 *            board.h (8 MHz HSE, PLL to 168 MHz)
 *   [DS]     STM32F405 data sheet DS8626, table "Alternate function
 *            mapping" and the pin table's ADC channels
 * Values no source confirmed are marked UNVERIFIED; docs/bringup-vesc6.md
 * checks them on the bench before the gates are enabled.
 */
#include "board_vesc6.h"

#define A 0u
#define B 1u
#define C 2u
#define D 3u
#define NONE                                                                                       \
    {                                                                                              \
        F4_PORT_NONE, 0u, 0u                                                                       \
    }

const f4_board_t f4_board_vesc6 = {
    .name = "VESC 6 (hw 60)",
    .hse_hz = 8000000u,      /* [VESC] board.h STM32_HSECLK */
    .sysclk_hz = 168000000u, /* [VESC] mcuconf.h: PLL M 8, N 336, P 2 */

    /* TIM1 CH1/2/3 PA8/PA9/PA10, CH1N/2N/3N PB13/PB14/PB15, AF1 [HW60]
     * hw_init_gpio, [DS]. DRV8301 inputs INHx/INLx active high. */
    .pwm_high = {{A, 8u, 1u}, {A, 9u, 1u}, {A, 10u, 1u}},
    .pwm_low = {{B, 13u, 1u}, {B, 14u, 1u}, {B, 15u, 1u}},
    .gate_active_low = false,
    .dead_time_ns = 360u, /* [VESC] HW_DEAD_TIME_NSEC default */
    /* UNVERIFIED: the phase amplifiers' recovery after a switching edge;
     * 1 us kept (docs/bringup-vesc6.md step 3 looks at it). */
    .sense_settle_ns = 1000u,
    .break_in = NONE, /* no BKIN signal on this board */
    .break_active_low = false,

    /* DRV8301: EN_GATE PB5 (the first PCB had PB6), nFAULT PB7 (read as
     * IS_DRV_FAULT = !PB7, pulled up) [HW60]; nOCTW not wired to the MCU
     * (hw_60 names none). SPI: SCK PC10, MISO PC11, MOSI PC12, nSCS PC9
     * [HW60] (VESC bit-bangs them); PC10/11/12 are SPI3's SCK/MISO/MOSI on
     * AF6 [DS], used here. */
    .en_gate = {B, 5u, 0u},
    .nfault = {B, 7u, 0u},
    .noctw = NONE,
    .drv_spi = 3u,
    .drv_sck = {C, 10u, 6u},
    .drv_miso = {C, 11u, 6u},
    .drv_mosi = {C, 12u, 6u},
    .drv_cs = {C, 9u, 0u},
    .drv_spi_max_hz = 5000000u, /* the DRV8301's 10 MHz maximum, halved */
    /* Gate current 1.7 A peak (VESC writes 0x0430: GATE_CURRENT 00) [VESC];
     * latched shut-down on a VDS over-current at OC_ADJ 16 = 0.403 V (the
     * level VESC's default configuration uses; VESC's default mode is the
     * cycle-by-cycle limit) reported on nFAULT; the amplifiers' gain 20 as
     * VESC sets it (they are unused here: the phase shunts have their own). */
    .drv = {.gate_current = 0u,
            .ocp_mode = 1u,
            .oc_adj = 16u,
            .gain = 1u,
            .octw_mode = 0u,
            .oc_toff = false},
    .fet_rds_on_ohm = 0.0, /* not published in [HW60]: no VDS-trip current derived */

    /* Phase shunts in the motor lines, 0.5 mOhm, amplifier gain 20 about
     * VREF/2 [HW60] CURRENT_SHUNT_RES, CURRENT_AMP_GAIN (the HP variant:
     * 0.3 mOhm). CURR1/2/3 on PC0/PC1/PC2 = ADC123_IN10/11/12 [HW60][DS],
     * one per ADC, injected rank 1 of ADC1/2/3 (as VESC samples them). */
    .phase =
        {
            {1u, 10u, 1u, {C, 0u, 0u}},
            {2u, 11u, 1u, {C, 1u, 0u}},
            {3u, 12u, 1u, {C, 2u, 0u}},
        },
    /* UNVERIFIED: the sign (VESC 6 does not define
     * INVERTED_SHUNT_POLARITY: current into the motor raises the voltage),
     * the zero level's spread (reference divider and amplifier offset:
     * 0.1 V assumed) and the linear range (0.1 .. 3.2 V assumed):
     * docs/bringup-vesc6.md step 2 measures them. */
    .sense = {.shunt_ohm = 0.0005,
              .gain = 20.0,
              .zero_v = 1.65,
              .zero_tol_v = 0.1,
              .out_min_v = 0.1,
              .out_max_v = 3.2,
              .low_side = false},
    .current_smp_cycles = 15u, /* [HW60] ADC_SampleTime_15Cycles */

    /* DC link: AN_IN PC3 = ADC123_IN13, divider 39 k / 2.2 k [HW60] VIN_R1,
     * VIN_R2; rank 2 of ADC1. 28 cycles: the divider's 2.1 kOhm source. */
    .vbus = {1u, 13u, 2u, {C, 3u, 0u}},
    .vbus_ratio = 2200.0 / (39000.0 + 2200.0),
    .vbus_smp_cycles = 28u,
    /* MOSFET NTC: TEMP_PCB PA3 = ADC123_IN3 [HW60]; NTC_RES: 10 kOhm NTC to
     * VREF over 10 kOhm to ground, beta 3380 [HW60] NTC_TEMP. Regular
     * conversions on ADC2. Trip at 100 C, below [HW60]'s 110 C limit. */
    .temp = {.pin = {A, 3u, 0u},
             .adc = 2u,
             .channel = 3u,
             .smp_cycles = 144u,
             .ntc_high = true,
             .r_fixed = 10000.0,
             .r25 = 10000.0,
             .beta = 3380.0,
             .trip_c = 100.0},
    .vref = 3.3, /* [HW60] V_REG */

    /* Hall/encoder port: PC6/PC7 = TIM3_CH1/CH2, PC8 index (TIM3_CH3), AF2
     * [HW60] HW_ENC_TIM, HW_ENC_TIM_AF [DS]. */
    .enc_tim = 3u,
    .enc_a = {C, 6u, 2u},
    .enc_b = {C, 7u, 2u},
    .enc_index = {C, 8u, 2u},
    .enc_index_ch = 3u,
    .enc_filter = 6u, /* ICF 0110: f_DTS/4, N = 6: 24 / 84 MHz = 0.29 us */

    /* COMM port: USART3 TX PB10, RX PB11, AF7 [HW60] HW_UART_DEV [DS]. */
    .uart = 3u,
    .uart_tx = {B, 10u, 7u},
    .uart_rx = {B, 11u, 7u},
    .baud = 115200u,

    /* Servo/PPM input: PB6 = TIM4_CH1, AF2 [HW60] HW_ICU_TIMER [DS]. */
    .throttle_tim = 4u,
    .throttle_ch = 1u,
    .throttle = {B, 6u, 2u},
    .throttle_filter = 15u, /* ICF 1111: f_DTS/32, N = 8: 256 / 84 MHz = 3 us */

    .tick_tim = 2u,           /* TIM2 is free on this board */
    .led = {B, 0u, 0u},       /* green [HW60] LED_GREEN */
    .led_fault = {B, 1u, 0u}, /* red [HW60] LED_RED */
    /* PD2 low: the current filter off, as hw_init_gpio leaves it [HW60]. On
     * the first hardware 60 (HW_HAS_PERMANENT_NRF) PD2 is the permanent
     * NRF24's MISO instead, and its CSN PB12 [HW60] NRF_PIN_CSN floats
     * unless driven: PB12 pulled up first, so the NRF stays deselected and
     * its MISO high-impedance (PB12 is another chip's pin on later variants:
     * a pull-up, not an output). */
    .hold_low = {{D, 2u, 0u}, NONE, NONE, NONE, NONE, NONE, NONE, NONE},
    .hold_high = {NONE, NONE},
    .pull_up = {{B, 12u, 0u}, NONE},

    .current_peak_a = VESC6_CURRENT_PEAK_A,
    .vbus_max_v = VESC6_VBUS_MAX_V,
};
