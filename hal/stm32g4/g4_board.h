/*
 * What an STM32G4 motor board is made of, for the G4 back-end of hal.h
 * (g4_hal.c). A board is one constant of this type in its own description
 * file (hal/boards/<board>/); another G4 board with TIM1 on the gates,
 * ADC1/ADC2 on the currents and the on-chip op-amps/comparators is a new
 * description file, nothing else.
 *
 * Fixed by this chip support (STM32G431: the instances it has): TIM1 drives
 * the gates, ADC1/ADC2 sample the currents (injected, TIM1_TRGO2), DAC3
 * channels set the comparator thresholds, TIM4 counts the encoder, USART2
 * carries the serial link.
 */
#ifndef HAL_STM32G4_G4_BOARD_H
#define HAL_STM32G4_G4_BOARD_H

#include <stdbool.h>
#include <stdint.h>

#include "g4_periph.h"

/* Current sensing of one phase: shunt -> op-amp (PGA) -> ADC; the comparator
 * watches the op-amp's plus input (the conditioned shunt voltage). */
typedef struct {
    uint8_t opamp;       /* OPAMPx, 1..3 */
    uint8_t opamp_vpsel; /* OPAMPx_CSR.VPSEL: which VINP pin */
    g4_pin_t vinp, vinm, vout;
    uint8_t adc;          /* 1 or 2: the ADC sampling vout */
    uint8_t adc_channel;  /* ADCx_INy of vout */
    uint8_t adc_rank;     /* injected rank on that ADC (1..4) */
    uint8_t vinp_channel; /* ADCx_INy of vinp on the same ADC (zero-current level) */
    uint8_t comp;         /* COMPx with vinp as plus input (IO1) */
    uint8_t dac_channel;  /* DAC3 channel on that comparator's minus input (1, 2) */
} g4_phase_sense_t;

typedef struct {
    const char *name;
    /* clock */
    uint32_t hse_hz;    /* crystal */
    uint32_t sysclk_hz; /* SYSCLK = HCLK = PCLK1 = PCLK2 = timer clocks */
    /* inverter */
    g4_pin_t pwm_high[3], pwm_low[3]; /* TIM1 CH1..3, CH1N..3N */
    bool gate_active_low;             /* gate-driver inputs */
    uint32_t dead_time_ns;
    /* Time from a leg's low-side turn-on until its shunt signal is valid at
     * the ADC; with the dead time it sets the zero-vector window the HAL keeps
     * around the sampling instant (compare values are limited). */
    uint32_t sense_settle_ns;
    uint8_t break_filter; /* TIM1_BDTR.BKF code */
    /* current sense */
    g4_phase_sense_t phase[3]; /* U, V, W = hal.h i_a, i_b, i_c */
    uint8_t opamp_pga_code;    /* OPAMPx_CSR.PGA_GAIN */
    double opamp_pga_gain;     /* its non-inverting gain: V_out / V_INP slope */
    double shunt_ohm;
    /* ADC volts per shunt volt, signed (negative: the ADC voltage rises when
     * current flows from the motor into the inverter leg). */
    double sense_gain;
    uint32_t current_smp_half; /* sampling time of the current channels, half cycles */
    /* Zero-current level: each op-amp plus input (VINP) sits on a divider of
     * r_gnd to ground, r_bias to VDDA and r_shunt from the shunt; VINM0 at
     * ground. At zero current V_out = pga_gain VDDA G_bias / (G_gnd + G_bias +
     * G_shunt) (G = 1/R), a fixed fraction of VREF+ = VDDA. Its spread: the
     * resistors at +-r_tol, the op-amp's input offset (up to opamp_vio_v,
     * times the gain) and the PGA's gain error (opamp_gain_err, relative).
     * r_bias = 0: not described (g4_hal_current_zero gives no window). */
    double sense_r_gnd, sense_r_bias, sense_r_shunt, sense_r_tol;
    double opamp_vio_v, opamp_gain_err;
    /* DC link */
    g4_pin_t vbus_pin;
    uint8_t vbus_adc, vbus_channel, vbus_rank;
    double vbus_ratio; /* ADC volts per DC-link volt */
    uint32_t vbus_smp_half;
    /* board temperature (regular conversion from the main loop) */
    g4_pin_t temp_pin;
    uint8_t temp_adc, temp_channel;
    uint32_t temp_smp_half;
    /* Linear sensor model T = t0 + (V - v0) / dv_dt; limits of a working sensor
     * (outside: open or shorted), trip level. */
    double temp_v0, temp_t0_c, temp_dv_dt, temp_v_min, temp_v_max, temp_trip_c;
    double vref; /* VREF+ = VDDA */
    /* encoder (TIM4) */
    g4_pin_t enc_a, enc_b, enc_index;
    bool enc_has_index;
    uint8_t enc_filter; /* TIM4_CCMRx.ICxF code */
    /* serial link (USART2) */
    g4_pin_t uart_tx, uart_rx;
    uint32_t baud;
    /* BOOT0 pin (PB8 on the STM32G431CB) pulled up by the board: the option
     * bytes must take BOOT0 from nBOOT0 (g4_boot_risk). */
    bool boot0_pulled_up;
    /* servo-style throttle input: TIM2_CH1 (g4_tim2_capture_init) */
    g4_pin_t throttle;
    uint8_t throttle_filter; /* TIM2_CCMR1.IC1F code */
    /* status LED */
    g4_pin_t led;
    /* USB Type-C dead-battery pull-downs on PB4/PB6 (UCPD1 CC pins) switched
     * off (PWR_CR3.UCPD1_DBDIS) because those pins carry other signals. */
    bool ucpd_dead_battery_off;
    /* ratings of the power stage */
    double current_peak_a; /* highest hardware trip threshold */
    double vbus_max_v;
} g4_board_t;

#endif /* HAL_STM32G4_G4_BOARD_H */
