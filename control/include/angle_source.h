/*
 * Angle sources: where the estimator takes the rotor angle theta and the
 * electrical speed omega from (docs/architecture.md, "Angle sources").
 *
 * A source is a read-only descriptor with an opaque state block of
 * state_size bytes (<= CTRL_ANGLE_STATE_MAX) that the estimator owns. Once per
 * period, before anything else, ctrl_estimator_update() hands it the
 * measurements of sample k and takes back theta(k) and omega(k); every
 * rotor-frame quantity of the period follows from these two. Built in:
 *   ctrl_angle_encoder  the position sensor's angle, speed from its
 *                       differences (first-order low-pass, p->speed_lpf_k);
 *   ctrl_angle_forced   an angle that advances by a commanded speed (open
 *                       loop: start-up, alignment, motor identification).
 * A sensorless observer is a third descriptor: it sets uses_voltage and reads
 * the current and the mean voltage of the last period.
 *
 * Integer-only (called in the interrupt).
 */
#ifndef CONTROL_ANGLE_SOURCE_H
#define CONTROL_ANGLE_SOURCE_H

#include <stddef.h>
#include <stdint.h>

#include "ctrl_params.h"
#include "fx.h"

/* What a source sees at sample k (Q24 pu, angles fx_angle_t). */
typedef struct {
    fx_angle_t theta_meas; /* position sensor's electrical angle (ctrl_meas_t.theta_e) */
    q24_t i_alpha, i_beta; /* stator current at k, stator frame */
    q24_t v_alpha, v_beta; /* mean stator voltage over [k-1, k); 0 unless uses_voltage */
    q24_t vdc;             /* DC link at k */
} ctrl_angle_in_t;

/* The frame at an angle as a source may have formed it for its own use:
 * its sin and cos (fx_sincos, Q24). */
typedef struct {
    q24_t sin_theta, cos_theta;
} ctrl_angle_frame_t;

/* What it returns: the d-axis angle and the electrical speed at k; frame:
 * NULL (the estimator's default), or the frame at theta, which the
 * estimator then takes instead of forming it again (the same values:
 * fx_sincos is a function of the angle alone); i_fund: NULL, or the
 * current the estimator is to take instead of the measured one (the
 * sensorless source's with an injection: the current without the
 * injection's ripple, alpha and beta, Q24 pu). */
typedef struct {
    fx_angle_t theta;                /* electrical angle of the d axis */
    q24_t omega;                     /* electrical speed, Q24 pu (positive: theta increasing) */
    const ctrl_angle_frame_t *frame; /* NULL, or the frame at theta */
#if !defined(CTRL_SL_HFI) || CTRL_SL_HFI
    const q24_t *i_fund; /* NULL, or {i_alpha, i_beta} */
#endif
} ctrl_angle_out_t;

/* bytes of a source's state (estimator.h): the sensorless one, 328 with the
 * initial angle, 600 with the injection (CTRL_SL_HFI, hfi.h) */
#if !defined(CTRL_SL_HFI) || CTRL_SL_HFI
#define CTRL_ANGLE_STATE_MAX 600
#else
#define CTRL_ANGLE_STATE_MAX 336
#endif

typedef struct ctrl_angle_src {
    const char *name;     /* "encoder", "forced", ... */
    size_t state_size;    /* <= CTRL_ANGLE_STATE_MAX */
    uint8_t uses_voltage; /* 1: the estimator fills v_alpha, v_beta (costs a few
                           * instructions per period, so only when read) */
    /* Forget the history (the estimator's reset and the source's selection). */
    void (*reset)(void *state, const ctrl_params_t *p);
    /* theta and omega at k; called once per period, integer-only. */
    void (*update)(void *state, const ctrl_params_t *p, const ctrl_angle_in_t *in,
                   ctrl_angle_out_t *out);
} ctrl_angle_src_t;

extern const ctrl_angle_src_t ctrl_angle_encoder;
extern const ctrl_angle_src_t ctrl_angle_forced;

/* The encoder source's state and its update (inline: the estimator calls it
 * directly when the encoder is the source). */
typedef struct {
    int64_t omega_acc;     /* filtered electrical speed, Q48 pu */
    q24_t omega;           /* its Q24 value (the last output) */
    fx_angle_t theta_prev; /* angle at k-1 */
    uint8_t primed;        /* 0 before the first update after reset */
} ctrl_angle_encoder_t;

/* Forced angle: from the next period on, theta(k) starts at theta and
 * advances by omega Ts per period, omega reported as the speed. Call from the
 * main loop with the interrupt masked or between periods (like every other
 * configuration of the estimator). state: the forced source's state
 * (ctrl_estimator_angle_state). */
void ctrl_angle_forced_set(void *state, const ctrl_params_t *p, fx_angle_t theta, q24_t omega);

/* Angle increment over one control period at electrical speed omega_e (Q24
 * pu): omega_e Ts in fx_angle_t units, modulo one turn. |omega| <= 2^31 and
 * omega_to_dangle < 2^31: the product is below 2^62, and the low 32 bits of
 * the rounded shift are the increment modulo 2^32 (no signed conversion). */
static inline fx_angle_t ctrl_angle_step(const ctrl_params_t *p, q24_t omega_e)
{
    const uint64_t u = (uint64_t)((int64_t)omega_e * p->omega_to_dangle) + ((uint64_t)1 << 23);
    return (fx_angle_t)(u >> FX_QBITS);
}

/* Encoder: theta = the sensor's angle; omega = dtheta / Ts (pu), then a
 * first-order EMA kept in Q48 so that it settles to the input exactly (no
 * dead band). |omega_acc| stays below 2^55 (an average of values < 2^31 in
 * Q24 with 24 guard bits). */
static inline void ctrl_angle_encoder_step(ctrl_angle_encoder_t *s, const ctrl_params_t *p,
                                           fx_angle_t theta_meas, ctrl_angle_out_t *out)
{
    if (s->primed != 0u) {
        const int32_t dth = fx_u2i(theta_meas - s->theta_prev); /* [-pi, pi) */
        const q24_t raw = fx_round_sat((int64_t)dth * p->dangle_to_omega, CTRL_DANGLE_SHIFT);
        s->omega_acc += (int64_t)fx_sub(raw, s->omega) * p->speed_lpf_k;
        s->omega = fx_round_sat(s->omega_acc, FX_QBITS);
    }
    s->theta_prev = theta_meas;
    s->primed = 1u;
    out->theta = theta_meas;
    out->omega = s->omega;
}

#endif /* CONTROL_ANGLE_SOURCE_H */
