/*
 * Board description of the ODrive v3.6, axis M0 (board_odrive_v36.h).
 *
 * Sources, cited per line:
 *   [MAIN]  ODrive firmware (odriverobotics/ODrive) Firmware/Board/v3/Inc/
 *           main.h, the HW_VERSION 3.5/3.6 pin map (pin names M0_*, M1_*,
 *           EN_GATE, nFAULT, VBUS_S, GPIO_n)
 *   [BRD]   Firmware/Board/v3/board.cpp and Inc/board.h (SHUNT_RESISTANCE
 *           500 uOhm for v3.5+, VBUS_S_DIVIDER_RATIO 19 for the 48/56 V
 *           boards and 11 for the 24 V ones, CURRENT_SENSE_MIN/MAX_VOLT, the
 *           phase B and C measurement, the FET thermistor's polynomial)
 *   [CUBE]  Src/adc.c, tim.c, spi.c, usart.c, main.c (alternate functions,
 *           ADC sampling, PLL M 4, N 168, P 2, FLASH_LATENCY_5, TIM1 dead
 *           time 20 clocks)
 *   [DRV]   Drivers/DRV8301/drv8301.cpp (SPI mode, the control words ODrive
 *           writes: OC_ADJ 21, latch shut-down, gain from the current range)
 *   [THERM] tools/odrive/utils.py calculate_thermistor_coeffs and
 *           analysis/thermistors.py: the component values only (Rload
 *           3.3 kOhm, 10 kOhm, beta 3434); the latter models the NTC to
 *           ground (thermistor_bottom=True), which [BRD]'s polynomial
 *           contradicts (see .temp)
 *   [DS]    STM32F405 data sheet DS8626, alternate functions and ADC inputs
 * Values no source confirmed are marked UNVERIFIED; docs/bringup-odrive-v36.md
 * checks them on the bench before the gates are enabled.
 */
#include "board_odrive_v36.h"

#define A 0u
#define B 1u
#define C 2u
#define D 3u
/* The DRV8301 amplifiers' GAIN code, 40 V/V: written to the driver and the
 * sense chain's gain (f4_hal_describe checks the two agree). */
#define ODRIVE_V36_GAIN_CODE 2u

#define NONE                                                                                       \
    {                                                                                              \
        F4_PORT_NONE, 0u, 0u                                                                       \
    }

const f4_board_t f4_board_odrive_v36 = {
    .name = "ODrive v3.6 M0",
    .hse_hz = 8000000u,      /* [CUBE] stm32f4xx_hal_conf.h HSE_VALUE; main.c PLLM 4: 2 MHz */
    .sysclk_hz = 168000000u, /* [CUBE] PLLN 168, PLLP 2 */

    /* M0_AH/BH/CH PA8/PA9/PA10, M0_AL/BL/CL PB13/PB14/PB15 [MAIN]: TIM1
     * CH1..3 and CH1N..3N on AF1 [CUBE] tim.c GPIO_AF1_TIM1 [DS]. */
    .pwm_high = {{A, 8u, 1u}, {A, 9u, 1u}, {A, 10u, 1u}},
    .pwm_low = {{B, 13u, 1u}, {B, 14u, 1u}, {B, 15u, 1u}},
    .gate_active_low = false,
    .dead_time_ns = 120u, /* [MAIN] TIM_1_8_DEADTIME_CLOCKS 20 at 168 MHz = 119 ns */
    /* UNVERIFIED: the DRV8301 amplifiers' settling after the low-side
     * switch turns on; 2 us kept (the B-G431B-ESC1 measured 1.3 us with its
     * op-amps). docs/bringup-odrive-v36.md step 3. */
    .sense_settle_ns = 2000u,
    .break_in = NONE, /* PB12 (a BKIN pin) is EN_GATE here */
    .break_active_low = false,

    /* EN_GATE PB12 (shared by both axes' drivers), nFAULT PD2 (shared,
     * open drain) [MAIN][BRD]; nOCTW not wired to the MCU. M0's DRV8301:
     * nSCS PC13 [MAIN] M0_nCS; SPI3 SCK PC10, MISO PC11, MOSI PC12 on AF6
     * [CUBE] spi.c, SPI mode 1, 16 bits, prescaler 16 from 42 MHz [DRV]. */
    .en_gate = {B, 12u, 0u},
    .nfault = {D, 2u, 0u},
    .noctw = NONE,
    .drv_spi = 3u,
    .drv_sck = {C, 10u, 6u},
    .drv_miso = {C, 11u, 6u},
    .drv_mosi = {C, 12u, 6u},
    .drv_cs = {C, 13u, 0u},
    .drv_spi_max_hz = 2700000u, /* ODrive's 42 MHz / 16 = 2.6 MHz [DRV] */
    /* As ODrive writes them [DRV]: gate current 1.7 A, latched shut-down
     * at OC_ADJ 21 = 0.730 V ("approximately 150 A at 100 degC"), six-input
     * PWM; OCTW both; gain 40 V/V, the one ODrive picks for its default
     * 60 A current range (1.35 V swing / (60 A x 0.5 mOhm) = 45, rounded
     * down to a gain the driver has). */
    .drv = {.gate_current = 0u,
            .ocp_mode = 1u,
            .oc_adj = 21u,
            .gain = ODRIVE_V36_GAIN_CODE,
            .octw_mode = 0u,
            .oc_toff = false},
    .fet_rds_on_ohm = 0.0, /* not in the firmware sources: no VDS-trip current derived */

    /* Phase A is not measured: rebuilt from B and C [BRD] (current0 =
     * {-phB - phC, phB, phC}). M0_IB PC0 = ADC123_IN10 on ADC2, M0_IC PC1 =
     * ADC123_IN11 on ADC3, injected rank 1 each [CUBE] adc.c. */
    .phase =
        {
            {0u, 0u, 0u, NONE},
            {2u, 10u, 1u, {C, 0u, 0u}},
            {3u, 11u, 1u, {C, 1u, 0u}},
        },
    /* 0.5 mOhm low-side shunts [BRD]; the DRV8301's amplifier, gain as
     * configured above, referenced to VREF/2 = 1.65 V, linear 0.3 .. 3.0 V
     * [BRD] CURRENT_SENSE_MIN/MAX_VOLT; positive as ODrive reads it
     * (phase_current_from_adcval: (code - 2048) / gain / R). UNVERIFIED: the
     * zero level's spread (the amplifier offset times 40: 0.15 V assumed)
     * and the direction of positive current; docs/bringup-odrive-v36.md
     * step 2. */
    .sense = {.shunt_ohm = 0.0005,
              .gain = (double)DRV8301_GAIN_VV(ODRIVE_V36_GAIN_CODE),
              .zero_v = 1.65,
              .zero_tol_v = 0.15,
              .out_min_v = 0.3,
              .out_max_v = 3.0,
              .low_side = true,
              .drv_amp = true},
    .current_smp_cycles = 15u, /* [CUBE] samples in 3 cycles; 15 kept for margin */

    /* VBUS_S PA6 = ADC12_IN6 on ADC1, injected rank 1 [MAIN][CUBE]; the
     * 56 V board's divider 1/19 [BRD] (the 24 V board: 1/11). */
    .vbus = {1u, 6u, 1u, {A, 6u, 0u}},
    .vbus_ratio = 1.0 / 19.0,
    .vbus_smp_cycles = 28u,
    /* M0_TEMP PC5 = ADC12_IN15 [MAIN][CUBE]: a 10 kOhm NTC (beta 3434)
     * [THERM] to VREF over 3.3 kOhm to ground. The placement's evidence is
     * ODrive's own conversion, [BRD] fet_thermistor_poly_coeffs (a cubic in
     * the normalised ADC voltage): with the NTC to VREF it gives 25.7 C at
     * 25 C and 101.1 C at 100 C; with the NTC to ground (as
     * analysis/thermistors.py models it) 96.9 C at 25 C and 23.0 C at
     * 100 C. Regular conversions on ADC2. Trip at 100 C (ODrive limits the
     * current from 100 C on). */
    .temp = {.pin = {C, 5u, 0u},
             .adc = 2u,
             .channel = 15u,
             .smp_cycles = 144u,
             .ntc_high = true,
             .r_fixed = 3300.0,
             .r25 = 10000.0,
             .beta = 3434.0,
             .trip_c = 100.0},
    .vref = 3.3,

    /* M0 encoder: ENC0_A PB4, ENC0_B PB5 = TIM3_CH1/CH2 on AF2 [MAIN][CUBE];
     * ENC0_Z PC9 [MAIN], TIM3_CH4 on AF2 [DS] (ODrive reads it by EXTI). */
    .enc_tim = 3u,
    .enc_a = {B, 4u, 2u},
    .enc_b = {B, 5u, 2u},
    .enc_index = {C, 9u, 2u},
    .enc_index_ch = 4u,
    .enc_filter = 6u,

    /* UART_A: GPIO1 PA0 = UART4_TX, GPIO2 PA1 = UART4_RX, AF8 [BRD]
     * alternate_functions [DS]; 115200 baud, ODrive's default. */
    .uart = 4u,
    .uart_tx = {A, 0u, 8u},
    .uart_rx = {A, 1u, 8u},
    .baud = 115200u,

    /* Throttle on GPIO4 PA3 = TIM5_CH4, AF2 ([BRD] pwm0_input on TIM5,
     * [CUBE] tim.c). */
    .throttle_tim = 5u,
    .throttle_ch = 4u,
    .throttle = {A, 3u, 2u},
    .throttle_filter = 15u,

    /* TIM2 drives the brake resistor in ODrive's firmware; here that switch
     * is held off and TIM2 counts microseconds. */
    .tick_tim = 2u,
    .led = NONE, /* no LED on a microcontroller pin */
    .led_fault = NONE,
    /* Axis M1 is not driven: its DRV8301 is enabled with M0's (shared
     * EN_GATE), so its six gate inputs M1_AH/BH/CH PC6/PC7/PC8 and
     * M1_AL/BL/CL PA7/PB0/PB1 are held low (both switches of every leg
     * off) and its nSCS PC14 high [MAIN]; the brake-resistor switch's
     * inputs AUX_L PB10, AUX_H PB11 [MAIN] are held low (resistor off). */
    .hold_low = {{C, 6u, 0u},
                 {C, 7u, 0u},
                 {C, 8u, 0u},
                 {A, 7u, 0u},
                 {B, 0u, 0u},
                 {B, 1u, 0u},
                 {B, 10u, 0u},
                 {B, 11u, 0u}},
    .hold_high = {{C, 14u, 0u}, NONE},
    .pull_up = {NONE, NONE},

    .current_peak_a = ODRIVE_V36_CURRENT_PEAK_A,
    .vbus_max_v = ODRIVE_V36_VBUS_MAX_V,
};
