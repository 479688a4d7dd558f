/*
 * HAL simulation back-end: implements hal.h on the host plant (sim_host/plant.h).
 *
 * One PWM period k of length T = 1/pwm_freq_hz, driven by the caller:
 *   hal_sim_period_begin(h)   load the shadow compare values written during
 *                             k-1 (and a pending gate enable), sample ADC and
 *                             encoder from the plant state at t_k
 *   <firmware ISR>            hal_adc_read / hal_encoder_read return those
 *                             samples; hal_pwm_write fills the shadow registers
 *   hal_sim_period_end(h)     advance the plant through [t_k, t_k + T) with the
 *                             active compare values (or all switches off)
 *
 * PWM: up/down counter clocked at timer_clock_hz, period_counts = N =
 * round(timer_clock_hz / (2 pwm_freq_hz)); the period starts at the counter top
 * (N), reaches 0 at mid-period and returns to N. Leg x is high while the
 * counter is below cmp[x], i.e. during [T/2 (1 - d), T/2 (1 + d)], d = cmp/N:
 * exactly the centre-aligned instants of plant_advance_period. (The plant
 * period is exactly 1/pwm_freq_hz; a timer clock that does not divide it
 * only changes the duty resolution, 1/N.)
 *
 * Gates: hal_gate_enable(false) opens every switch at once for the rest of the
 * current period (the ISR runs at the period start, so the whole period k);
 * the plant then conducts through the free-wheeling diodes (PLANT_LEG_OFF: the
 * leg voltage follows the current sign), i.e. the machine feeds the DC link
 * through the diode bridge until the current dies. hal_gate_enable(true)
 * takes effect at the next period start, together with the compare values.
 *
 * ADC (12 bit by default): the phase currents are the inverter output currents
 * (plant_i_inverter_abc, the shunts of a real board) or, with
 * sense_motor_side, the motor currents; they differ only with a plant output
 * filter. Current channel count = mid + off + (1 + g) i / lsb
 * + noise, lsb = 2 i_fullscale / 2^bits, mid = 2^(bits-1); DC-link channel
 * count = off + (1 + g) vdc / lsb_v + noise, lsb_v = vdc_fullscale / 2^bits;
 * rounded and clamped to [0, 2^bits - 1]. Noise: Gaussian, sigma in counts,
 * from a seeded PRNG (splitmix64 + Box-Muller; no rand()).
 *
 * Encoder: lines per revolution x 4 counts, count = floor(dir (theta_m -
 * enc_zero_rad) cpr / 2 pi) + zero_count (modulo 2^32): the encoder reads
 * zero_count where the rotor's mechanical angle is enc_zero_rad (electrical:
 * p enc_zero_rad, the machine file's encoder_offset_deg) and counts down when
 * enc_dir = -1. The defaults (0, +1) are an encoder aligned with the d axis
 * on phase a. Optional index where dir (theta_m - enc_zero_rad) = 0 mod 2 pi:
 * the counter value (spurious counts included) is latched in index_count,
 * detected at the period starts.
 *
 * Cycle counter (hal_cycles): advances by cycle_clock_hz / pwm_freq_hz per
 * period, plus cycles_per_read on each read (so an ISR that reads it twice
 * sees a non-zero duration), plus injected overruns (see below).
 *
 * Hardware trip comparator: latched when |measured phase current| exceeds
 * trip_level_a (0 = off) at a period start, cleared by hal_trip_clear.
 *
 * Fault injection (tests): each takes effect at the next period start.
 *  - short circuit: a fault current rising at slope A/s is added to phase a
 *    and subtracted from phase b of the sensed currents while the gates are
 *    enabled (a line-to-line short through the switches); opening the gates
 *    interrupts it (the fault current is reset to 0). The plant's own
 *    currents are not affected (the plant has no fault path).
 *  - DC link sag/surge: sets the plant's DC source voltage (stiff link).
 *  - stuck encoder: the counter freezes at its current value.
 *  - encoder glitch: the counter jumps by n counts once (and keeps the offset,
 *    like spurious edges).
 *  - overrun: the next ISR's second hal_cycles read is late by n cycles.
 *  - motor disconnected (open phases): the plant is advanced with every
 *    switch open whatever the gates do, so no current flows (a machine at
 *    rest with no current, as on a bench with the motor leads off).
 *  - winding short between the a and b leads through an inductance l_s: a
 *    fault current with di/dt = (v_a - v_b) / l_s (the period's mean leg
 *    voltages from the active compare values) flows out of leg a and into
 *    leg b, so the a and b current sensors see +i and -i; opening the gates
 *    interrupts it. The plant's own currents are not affected.
 * ADC channel polarity (adc_invert bit x): the current channel x reads the
 * negated current (a sense resistor or op-amp wired the other way).
 */
#ifndef HAL_SIM_HAL_SIM_H
#define HAL_SIM_HAL_SIM_H

#include <stdbool.h>
#include <stdint.h>

#include "hal.h"
#include "plant.h"

#define HAL_SIM_OK 0
#define HAL_SIM_EINVAL (-1)

typedef struct {
    uint32_t pwm_freq_hz;        /* control/PWM frequency (> 0) */
    uint32_t timer_clock_hz;     /* PWM timer clock, default 100 MHz */
    uint32_t cycle_clock_hz;     /* hal_cycles rate (CPU clock), default 100 MHz */
    uint32_t cycles_per_read;    /* cycles added by each hal_cycles call, default 50 */
    uint8_t adc_bits;            /* 8..16, default 12 */
    double i_fullscale_a;        /* current channel range +-i_fullscale_a (> 0) */
    double vdc_fullscale_v;      /* DC-link channel range 0..vdc_fullscale_v (> 0) */
    double adc_offset_counts[4]; /* offset error of i_a, i_b, i_c, vdc, counts */
    double adc_gain_err[4];      /* relative gain error of i_a, i_b, i_c, vdc */
    double adc_noise_counts;     /* Gaussian noise sigma, counts (>= 0) */
    uint32_t enc_lines;          /* lines per revolution (x4 counts), default 2500 */
    bool enc_index;              /* index pulse modelled */
    uint32_t enc_zero_count;     /* counter value at theta_m = enc_zero_rad */
    double enc_zero_rad;         /* mechanical angle where the encoder reads zero_count */
    int8_t enc_dir;              /* -1: counts down as theta_m grows; else up */
    uint8_t adc_invert;          /* bit x: current channel x negated */
    double trip_level_a;         /* hardware comparator level, A; 0 = off */
    uint64_t seed;               /* PRNG seed for the ADC noise */
    bool sense_motor_side;       /* currents sensed at the motor terminals instead of the
                                    inverter output (the shunts of a real board); differs
                                    only with a plant output filter; default false */
    double duty_max;             /* largest leg duty applied, (0, 1]; 0 = 1 (no limit). A
                                    board with low-side shunts keeps a zero vector around
                                    the sampling instant (B-G431B-ESC1: 3910/4250 = 0.92 at
                                    20 kHz); reported as hal_info_t.pwm_cmp_max */
} hal_sim_config_t;

/* The back-end's handle (hal_t in hal.h). Fields are private. */
struct hal {
    hal_sim_config_t cfg;
    plant_t *plant;
    uint32_t period_counts;
    uint32_t cmp_max; /* floor(duty_max period_counts), or period_counts */
    double period_s;
    uint64_t period_index; /* index k of the current period */
    hal_pwm_t shadow, active;
    bool gates_on, gate_enable_pending;
    bool trip;
    uint32_t hold_depth; /* hal_ctrl_hold's nesting (no interrupt to hold here) */
    hal_adc_raw_t adc;
    hal_encoder_raw_t enc;
    uint64_t rng;
    /* cycle counter */
    uint32_t cycles;
    uint32_t overrun_pending;
    uint32_t reads_this_period;
    /* injections */
    bool motor_off;         /* motor disconnected */
    double short_l_h;       /* winding short through this inductance; 0 = none */
    double short_slope_a_s; /* 0 = no short */
    double short_i_a;       /* present fault current, A */
    bool enc_stuck;
    uint32_t enc_stuck_count;
    int32_t enc_glitch_total; /* counts added by glitches */
    int64_t enc_turns_prev;   /* for the index */
    bool primed;
};

/* Defaults for a machine: i_fullscale = 1.5 current_max_a, vdc_fullscale =
 * 2 vdc_v, 12 bit, no offset/gain error, noise 0.5 count, 2500 lines,
 * 100 MHz clocks, trip at 1.25 current_max_a, seed 1. */
void hal_sim_config_default(hal_sim_config_t *c, uint32_t pwm_freq_hz, double current_max_a,
                            double vdc_v);

/* Validate cfg and bind the plant (not owned). Returns HAL_SIM_OK or HAL_SIM_EINVAL. */
int hal_sim_init(hal_t *h, const hal_sim_config_t *cfg, plant_t *plant);

void hal_sim_period_begin(hal_t *h);
/* Returns the plant's status (PLANT_OK or a PLANT_E* code). */
int hal_sim_period_end(hal_t *h);

/* Observation for tests and tools. */
uint64_t hal_sim_period(const hal_t *h);
bool hal_sim_gates_on(const hal_t *h); /* switches may conduct in this period */
void hal_sim_pwm_active(const hal_t *h, hal_pwm_t *pwm);

/* Fault injection. */
void hal_sim_inject_short(hal_t *h, double slope_a_per_s);
void hal_sim_inject_vdc(hal_t *h, double vdc_v);
void hal_sim_inject_encoder_stuck(hal_t *h, bool stuck);
void hal_sim_inject_encoder_glitch(hal_t *h, int32_t counts);
void hal_sim_inject_overrun(hal_t *h, uint32_t cycles);
void hal_sim_inject_motor_off(hal_t *h, bool off);
void hal_sim_inject_winding_short(hal_t *h, double l_short_h);

#endif /* HAL_SIM_HAL_SIM_H */
