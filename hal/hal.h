/*
 * The hardware interface: the only header the firmware uses to reach hardware.
 * Back-ends: hal/sim (host plant), hal/qemu_mps2 (Cortex-M4 in QEMU with the
 * plant in the loop), and boards. Every function takes the back-end's handle;
 * the firmware never sees what is behind it.
 *
 * Timing contract of one PWM period k (interrupt at the period start):
 *   hal_adc_read / hal_encoder_read return the samples taken at the start of k;
 *   hal_pwm_write sets the compare values that take effect at the start of k+1
 *   (shadow registers loaded on the period boundary), so the plan computed from
 *   the samples of k acts during [k+1, k+2).
 */
#ifndef HAL_HAL_H
#define HAL_HAL_H

#include <stdbool.h>
#include <stdint.h>

typedef struct hal hal_t; /* defined by the back-end */

/* Raw ADC counts of one sample set (right-aligned, 0 .. 2^bits - 1). */
typedef struct {
    uint16_t i_a, i_b, i_c; /* phase-current channels (i_c may be unused: see hal_info_t) */
    uint16_t vdc;           /* DC-link voltage channel */
} hal_adc_raw_t;

/* Incremental encoder, quadrature counter. */
typedef struct {
    uint32_t count;       /* free-running counter, wraps modulo 2^32 */
    bool index_seen;      /* an index pulse has been seen since start */
    uint32_t index_count; /* counter value latched at the last index pulse */
} hal_encoder_raw_t;

/* Centre-aligned PWM compare values: leg x is high while the up/down counter
 * is below cmp[x]; 0 = always low, period_counts = always high. */
typedef struct {
    uint32_t cmp[3];
} hal_pwm_t;

/* Static description of the hardware, read once by the firmware at start-up. */
typedef struct {
    uint32_t pwm_freq_hz;            /* PWM period frequency (== control frequency) */
    uint32_t period_counts;          /* compare value for 100 % duty */
    uint8_t adc_bits;                /* ADC resolution */
    double adc_current_a_per_count;  /* nominal gain (A per count); firmware calibrates offset */
    double adc_vdc_v_per_count;      /* nominal gain (V per count) */
    uint32_t encoder_counts_per_rev; /* quadrature counts per mechanical revolution */
    bool has_i_c;                    /* third phase-current channel present */
    /* Rate of hal_cycles() in Hz, for the deadline check
     * (cycle budget = cycle_clock_hz / pwm_freq_hz); 0 = unknown, check off. */
    uint32_t cycle_clock_hz;
    /* The largest compare value the back-end applies; hal_pwm_write limits
     * larger ones to it. Low-side shunt sensing needs a zero vector around the
     * sampling instant (dead time, settling, sampling), so a board keeps every
     * leg low for at least period_counts - pwm_cmp_max counts at the period
     * boundary. The pipeline limits its leg duties to it, so the estimator is
     * told the voltage actually applied (tests/loop/test_loop_duty_cap.c).
     * 0 = no limit (period_counts). */
    uint32_t pwm_cmp_max;
    /* Phase-current code (as hal_adc_read returns it) expected at zero
     * current, and the largest deviation the offset calibration accepts,
     * counts; tolerance 0 = not known to the back-end (mid-scale +- 1/32 of
     * full scale). */
    uint16_t adc_current_zero;
    uint16_t adc_current_zero_tol;
} hal_info_t;

void hal_info_get(const hal_t *h, hal_info_t *info);
void hal_adc_read(hal_t *h, hal_adc_raw_t *raw);
void hal_encoder_read(hal_t *h, hal_encoder_raw_t *enc);
void hal_pwm_write(hal_t *h, const hal_pwm_t *pwm);
/* Gates: disable takes effect immediately (all switches off), not at k+1. */
void hal_gate_enable(hal_t *h, bool enable);
/* Hardware trip comparator (latched by the hardware until hal_trip_clear). */
bool hal_trip_active(const hal_t *h);
void hal_trip_clear(hal_t *h);
/* Free-running cycle counter for deadline checks (DWT CYCCNT on a board). */
uint32_t hal_cycles(const hal_t *h);
/* Main loop: hold the control interrupt off (true) while the firmware
 * rewrites what it reads, and let it run as before (false). Holds nest; the
 * outermost release restores the interrupt's enable as it was at the
 * outermost hold (so a hold before the interrupt was first enabled leaves it
 * disabled). The PWM and the gates keep their state meanwhile; a period
 * that falls inside the hold runs late, once, when it ends. A back-end
 * whose control period is not an interrupt (the host simulation, the replay
 * and PIL targets) does nothing. */
void hal_ctrl_hold(hal_t *h, bool hold);

#endif /* HAL_HAL_H */
