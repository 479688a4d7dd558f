/*
 * What an STM32F405/407 motor board with a TI DRV8301 gate driver is made
 * of, for the F4 back-end of hal.h (f4_hal.c). A board is one constant of
 * this type in its own description file (hal/boards/<board>/); another such
 * board (a VESC 6 derivative, another ODrive axis) is a new description file,
 * nothing else.
 *
 * Fixed by this chip support: TIM1 drives the gates (CH1..3 and CH1N..3N),
 * its TRGO starts the injected conversions of the ADCs; the rest (which ADC
 * samples which phase, the encoder and throttle timers, the USART, the SPI
 * of the gate driver) is the board's.
 */
#ifndef HAL_STM32F4_F4_BOARD_H
#define HAL_STM32F4_F4_BOARD_H

#include <stdbool.h>
#include <stdint.h>

#include "drv8301.h"
#include "f4_periph.h"

/* One analog quantity sampled at the PWM centre: ADC 1..3 (0: not sampled),
 * its channel and injected rank, the pin. */
typedef struct {
    uint8_t adc, channel, rank;
    f4_pin_t pin;
} f4_sample_t;

/* How a phase current is sensed: amplified shunt voltage about a reference,
 * V_adc = zero_v + sense_gain x R_shunt x i (sense_gain signed: negative
 * when the voltage falls as current flows from the motor into the leg). */
typedef struct {
    double shunt_ohm;
    double gain;       /* ADC volts per shunt volt */
    double zero_v;     /* output at zero current (the amplifier's reference) */
    double zero_tol_v; /* its spread: reference divider, amplifier offset x gain */
    double out_min_v;  /* the amplifier's linear output range */
    double out_max_v;
    bool low_side; /* shunts in the low-side legs: valid only while that leg's low
                      switch conducts (else in-line phase shunts) */
    bool drv_amp;  /* the amplifiers are the DRV8301's: |gain| must equal
                      drv8301_gain(drv.gain) (f4_hal_describe refuses others) */
} f4_current_sense_t;

/* An NTC thermistor in a divider from VREF: with r_fixed to ground and the
 * NTC to VREF (ntc_high = true) or the reverse; beta model about 25 C. */
typedef struct {
    f4_pin_t pin;
    uint8_t adc, channel;
    uint32_t smp_cycles;
    bool ntc_high;
    double r_fixed, r25, beta;
    double trip_c;
} f4_ntc_t;

typedef struct {
    const char *name;
    /* clock */
    uint32_t hse_hz;    /* crystal */
    uint32_t sysclk_hz; /* SYSCLK = HCLK = TIM1's clock */
    /* inverter */
    f4_pin_t pwm_high[3], pwm_low[3]; /* TIM1 CH1..3 (AF1), CH1N..3N (AF1) */
    /* Gate-driver inputs active low: refused by f4_hal_describe (TIM1's
     * idle levels are 0); f4_hal_gate_pins_safe drives the inactive level. */
    bool gate_active_low;
    uint32_t dead_time_ns; /* TIM1's (the gate driver may add its own) */
    /* Time from a leg's switching until its current signal is valid at the
     * ADC (amplifier settling); with the dead time it sets the window the HAL
     * keeps free of switching around the sampling instant (compare values
     * limited, hal_info_t.pwm_cmp_max). */
    uint32_t sense_settle_ns;
    f4_pin_t break_in; /* TIM1_BKIN (PA6 / PB12, AF1), or F4_PORT_NONE */
    bool break_active_low;
    /* gate driver */
    f4_pin_t en_gate; /* DRV8301 EN_GATE: high enables it (and its SPI) */
    f4_pin_t nfault;  /* DRV8301 nFAULT (open drain, active low) */
    f4_pin_t noctw;   /* DRV8301 nOCTW, or F4_PORT_NONE */
    uint8_t drv_spi;  /* SPI1..3 */
    f4_pin_t drv_sck, drv_miso, drv_mosi, drv_cs;
    uint32_t drv_spi_max_hz;
    drv8301_cfg_t drv;     /* what the HAL writes to its control registers */
    double fet_rds_on_ohm; /* the MOSFETs' on-resistance (the VDS trip current) */
    /* current sense: phases U, V, W = hal.h i_a, i_b, i_c; a phase with adc
     * 0 is not sampled and is rebuilt from the other two (i_a + i_b + i_c =
     * 0) */
    f4_sample_t phase[3];
    f4_current_sense_t sense;
    uint32_t current_smp_cycles; /* ADC sampling time, cycles */
    /* DC link */
    f4_sample_t vbus;
    double vbus_ratio; /* ADC volts per DC-link volt */
    uint32_t vbus_smp_cycles;
    f4_ntc_t temp; /* power stage temperature (regular conversion, main loop) */
    double vref;   /* VREF+ = VDDA */
    /* encoder: TIMn (2..5) CH1/CH2, index on channel 3 or 4 (0: none) */
    uint8_t enc_tim;
    f4_pin_t enc_a, enc_b, enc_index;
    uint8_t enc_index_ch;
    uint8_t enc_filter; /* TIMx_CCMRx.ICxF code */
    /* serial console: USART1..6 */
    uint8_t uart;
    f4_pin_t uart_tx, uart_rx;
    uint32_t baud;
    /* servo-style throttle: TIMn (2..5) channel ch */
    uint8_t throttle_tim, throttle_ch;
    f4_pin_t throttle;
    uint8_t throttle_filter;
    /* a 32-bit timer (2 or 5) free for the main loop's microsecond clock
     * (f4_ticks_init) */
    uint8_t tick_tim;
    /* status LEDs (F4_PORT_NONE: none) */
    f4_pin_t led, led_fault;
    /* Outputs held at a fixed level from start-up on, before anything else,
     * and by the fault handlers (F4_PORT_NONE: unused entries): a board's
     * optional filters, the gate inputs and chip select of a second gate
     * driver sharing EN_GATE, named in its description. */
    f4_pin_t hold_low[8];
    f4_pin_t hold_high[2];
    /* Inputs held high by their internal pull-up, before the outputs above:
     * another chip's active-low select on a line that some variants of the
     * board use otherwise (a pull-up fights no driver). */
    f4_pin_t pull_up[2];
    /* ratings of the power stage */
    double current_peak_a; /* the highest current the hardware trip may be set to */
    double vbus_max_v;
} f4_board_t;

/* EN_GATE low (the DRV8301 holds every gate low), the six gate pins as GPIO
 * outputs at their inactive level, the board's pull_up inputs, its
 * hold_low / hold_high pins at their levels: f4_hal_init's first step, the fault handlers' last,
 * the PIL image's first (f4_gates.c: GPIO only). */
void f4_hal_gate_pins_safe(const f4_board_t *b);

#endif /* HAL_STM32F4_F4_BOARD_H */
