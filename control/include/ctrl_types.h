/*
 * Signals exchanged between the estimator, the controllers and the PWM stage.
 * All q24_t fields are Q24 per-unit (bases in ctrl_params.h); angles are
 * fx_angle_t (2^32 = 2*pi, electrical).
 *
 * Conventions (docs/conventions.md): amplitude-invariant Clarke (3.3), alpha
 * on phase a; voltage vectors of Table 4.2, V1=100 ... V6=101, V0=000, V7=111;
 * sector x of (4.5): (2x-3)pi/6 < theta_s <= (2x-1)pi/6, x = 1..6.
 */
#ifndef CONTROL_CTRL_TYPES_H
#define CONTROL_CTRL_TYPES_H

#include <stdint.h>

#include "fx.h"

/* Measurements after conversion from raw counts (done by the firmware). */
typedef struct {
    q24_t i_a, i_b;     /* phase currents a, b (i_c = -i_a - i_b), pu */
    q24_t vdc;          /* DC-link voltage, pu */
    fx_angle_t theta_e; /* electrical rotor angle (d axis), from the encoder */
} ctrl_meas_t;

/* Machine state at one instant (measured at k, or predicted for k+1), rotor
 * frame first. The stator-frame fields, the amplitude, the sector and the
 * predicted sine and cosine are optional outputs of the estimator
 * (estimator.h, CTRL_EST_*). */
typedef struct {
    q24_t i_d, i_q;             /* stator current, rotor frame, pu */
    q24_t psi_d, psi_q;         /* stator flux linkage, rotor frame, pu */
    q24_t torque;               /* Te, pu: psi x i (3.10) */
    fx_angle_t theta_e;         /* rotor electrical angle */
    q24_t sin_theta, cos_theta; /* of theta_e, Q24 */
    q24_t i_alpha, i_beta;      /* stator current, stator frame, pu */
    q24_t psi_alpha, psi_beta;  /* stator flux linkage, stator frame, pu */
    q24_t psi_amp;              /* |psi_s|, pu (4.3) */
    uint8_t sector;             /* stator-flux sector 1..6 (4.5) */
    uint64_t psi_amp_sq;        /* |psi_s|^2, Q48 pu, exact: psi_amp without its square root
                                 * (compare through fx_mag_le_lim / fx_mag_ge_lim) */
} ctrl_mstate_t;

/* What the estimator hands every controller at sample k. */
typedef struct {
    ctrl_mstate_t now;    /* at sample k, from the measurements (3.4)/(4.1) */
    ctrl_mstate_t next;   /* predicted for k+1 with the duties applied in [k, k+1) (5.15) */
    q24_t omega_e;        /* electrical speed, pu (from the angle source) */
    q24_t vdc;            /* DC link, pu */
    int32_t dtheta;       /* omega_e Ts: the angle one period turns, fx_angle_t units, signed */
    int32_t rot_c, rot_s; /* cos and sin of dtheta, Q30 (fx_rot_q30): the frame at
                           * k+1 is the frame at k turned by dtheta */
    /* Stator-frame voltage of the duties applied in [k, k+1) per unit of DC
     * link (4.4), Q24 (0 without duties). */
    q24_t u_alpha, u_beta;
} ctrl_estimate_t;

/* References from the outer loop / command interface. */
typedef struct {
    q24_t torque; /* torque reference, pu */
    q24_t psi;    /* stator-flux amplitude reference, pu; 0 = controller's own (MTPA) */
#if CTRL_COGGING
    /* The share of torque that is the anti-cogging feed-forward
     * (cogging_ff.h), pu: a known cancellation of the cogging that moves at
     * each encoder count, not a command; FST's step detection (st_dtc.h)
     * leaves it out. 0 with the feed-forward off. */
    q24_t torque_ff;
#endif
} ctrl_refs_t;

/*
 * Switching plan for one PWM period: up to four segments, each a voltage
 * vector index 0..7 (Table 4.2) and its on-time as a Q24 fraction of the
 * period (sum of durations == FX_ONE). Segment 0 is the "selected" active
 * vector reported by telemetry. The order of segments carries no timing: the
 * plan's volt-seconds are realised as centre-aligned leg duties (plan.h).
 */
#define CTRL_PLAN_MAX_SEG 4
typedef struct {
    uint8_t n_seg;
    uint8_t vec[CTRL_PLAN_MAX_SEG];
    q24_t dur[CTRL_PLAN_MAX_SEG];
} ctrl_plan_t;

/* Leg duties for centre-aligned PWM, Q24 fraction of the period in [0, FX_ONE]:
 * leg x is high for duty[x] * Ts, centred in the period. */
typedef struct {
    q24_t duty[3];
} ctrl_legs_t;

/* What a controller's step writes for [k+1, k+2): the leg duties, always,
 * and the switching plan they realise when it has one (switching tables,
 * duty-ratio DTC, predictive control), for telemetry; plan.n_seg == 0 for
 * space-vector modulation. plan.h: ctrl_out_plan() derives the duties of a
 * plan, ctrl_out_single() and ctrl_out_active_zero() write both at once. */
typedef struct {
    ctrl_legs_t legs;
    ctrl_plan_t plan;
} ctrl_out_t;

#endif /* CONTROL_CTRL_TYPES_H */
