/*
 * PM flux from the voltage model with the encoder: the stator-flux observer
 * in CTRL_FOBS_ENCODER (flux_observer.h) run on the estimator's frame and at
 * a reduced rate (docs/algorithms.md, "PM flux from the voltage model").
 *
 * The observer is a complementary filter: the voltage model S1(37)-(38)
 * integrated in the stator frame, pulled towards the current model (3.9) at
 * the measured angle with corner w_c; its PM flux psi_d - Ld i_d, where the
 * voltage model is reliable (|omega| above a threshold), is filtered by a
 * first-order EMA (time constant tau). Only the integration must run every
 * period; the flux changes slowly against the correction and the EMA, so:
 *   every period   psi += Ts v(k-1) - Ts Rs (i(k-1) + i(k)) / 2  (Q48, two
 *                  multiply-accumulates per axis), v from the estimator's
 *                  duty voltage (or ctrl_fobs_voltage where the inverter's
 *                  dead time and drop are compensated);
 *   period 0 of N  the correction psi += k_N (psi_cm - psi) in the rotor frame
 *                  of the estimator (its sin/cos, i_dq: no table look-up, no
 *                  angle), k_N = 1 - (1 - w_c Ts)^N, the N per-period
 *                  corrections in one, and the EMA with 1 - exp(-N Ts / tau):
 *                  the observer's ctrl_fobs_pull_delta and
 *                  ctrl_fobs_psi_pm_step with these gains.
 * N is the largest divider (<= CTRL_PSI_TRACK_DIV_MAX) with which the flux
 * turns at most a quarter turn between two corrections at twice the rated
 * speed (beyond the machines' maximum speeds): the rotating current-model error the correction
 * filters is then sampled well above its frequency (N w Ts near 2 pi would alias it to DC), and the
 * attenuation (w_c / w) of the per-period filter changes by less than 3 % (|e^{j x} - 1| against x,
 * x <= pi/2). The speed gate reads the estimator's (encoder) speed; the observer's PLL and flux
 * angle are not needed here and do not run. Integer-only per period.
 */
#ifndef CONTROL_PSI_TRACK_H
#define CONTROL_PSI_TRACK_H

#include <stdbool.h>
#include <stdint.h>

#include "ctrl_params.h"
#include "ctrl_types.h"
#include "flux_observer.h"

/* Largest divider: the observer's Q48 flux is clamped (127 pu) at the
 * corrections only, and N unclamped increments (each below 2^56: Ts Vdc <=
 * 64 pu times |u| <= 1, plus Ts Rs <= 1 pu times the mean of two currents
 * < 64 pu) stay far inside int64_t. */
#define CTRL_PSI_TRACK_DIV_MAX 8u

typedef struct {
    ctrl_fobs_t obs; /* CTRL_FOBS_ENCODER: voltage compensation (with the duties
                      * of the period before), the correction (kenc_ts = k_N =
                      * 1 - (1 - w_c Ts)^N, < 1 - 2^-8), the PM-flux EMA (Q48) */
    q24_t i_prev[2]; /* i(k-1) (alpha, beta), Q24 pu */
    q24_t psi_k_n;   /* EMA coefficient per update, Q24: 1 - exp(-N Ts / tau) */
    q24_t speed_min; /* the EMA runs where |omega| >= this, Q24 pu */
    uint8_t div;     /* N: one correction every N periods */
    uint8_t until;   /* periods to the next correction, this one counted, 1..N */
    uint8_t duty_v;  /* 1: the estimator's duty voltage (no dead time, no drop to remove) */
} ctrl_psi_track_t;

/* The correction's inputs at period 0 of N (ctrl_psi_track_integrate): the
 * voltage model's flux at k and the estimator's frame, current and speed at k. */
typedef struct {
    int64_t acc[2];  /* flux at k (alpha, beta), Q48 pu */
    q24_t sin_theta; /* the estimator's frame at k, Q24 */
    q24_t cos_theta; /* Q24 */
    q24_t i_d, i_q;  /* current at k in that frame, Q24 pu */
    q24_t omega_e;   /* the estimator's (encoder) speed at k, Q24 pu */
} ctrl_psi_track_in_t;

/* Restart from the current model at the next step (keeps the settings and
 * the PM-flux estimate's gains; the estimate restarts from p->psi_pm). */
void ctrl_psi_track_reset(ctrl_psi_track_t *t);

/* Turn an observer set up by ctrl_fobs_init in CTRL_FOBS_ENCODER (its kenc_ts
 * and psi_k per period, psi_speed_min) into the tracker: N from twice the
 * rated speed, the gains of N periods. Returns CTRL_OK, or CTRL_EINVAL (not
 * encoder mode, no rated speed) with *t unchanged. Configuration time. */
int ctrl_psi_track_setup(ctrl_psi_track_t *t, const ctrl_params_t *p);

/* One period at sample k, after ctrl_estimator_update: est its estimate at k
 * (now.*: i_alpha/beta, sin/cos, i_d/q, theta_e; omega_e, vdc, u_alpha/beta),
 * applied the leg duties acting in [k, k+1) and i_a, i_b the measured phase
 * currents (Q24 pu; read only with dead-time or drop compensation). Returns
 * true when the PM-flux estimate has moved (ctrl_fobs_psi_pm of t->obs).
 * Every period: the voltage model (flux_observer.c's fobs_axis, without its
 * clamp, which the correction applies) in the observer's Q48 - the resistive
 * drop of [k-1, k), Ts Rs (i(k-1) + i(k)) / 2 (the half truncated: 2^-49 pu
 * per period, bounded by the correction), before the correction of period 0
 * of N, and the voltage of [k, k+1), Ts v, after it. The flux is read only
 * by the corrections and is an exact sum between two (no clamp), so adding
 * Ts v at k rather than at k+1 gives the correction the same value. Out of
 * line: inlined, the interrupt spent more on its registers than the call. */
bool ctrl_psi_track_step(ctrl_psi_track_t *t, const ctrl_params_t *p, const ctrl_estimate_t *est,
                         const ctrl_legs_t *applied, q24_t i_a, q24_t i_b);

/* ctrl_psi_track_step in two rates (the firmware's PWM interrupt and its
 * medium-rate task): the same flux and estimates, the correction's step added
 * later. ctrl_psi_track_integrate, every period: the integration; at period 0
 * of N it returns true with *due the correction's inputs. ctrl_psi_track_correct,
 * on those (the other rate): the correction's step of the flux into delta
 * (Q48) and the EMA; true when the PM-flux estimate moved. ctrl_psi_track_add
 * adds delta to the flux, at any period before the next correction's (the flux
 * is an exact sum between two). Ownership: integrate and add write the flux
 * (obs.psi_alpha_acc/beta_acc) and the counters, correct writes the EMA
 * (obs.psi_pm_acc) and the flux's Q24 view (obs.psi_alpha/beta). */
bool ctrl_psi_track_integrate(ctrl_psi_track_t *t, const ctrl_params_t *p,
                              const ctrl_estimate_t *est, const ctrl_legs_t *applied, q24_t i_a,
                              q24_t i_b, ctrl_psi_track_in_t *due);
bool ctrl_psi_track_correct(ctrl_psi_track_t *t, const ctrl_params_t *p,
                            const ctrl_psi_track_in_t *in, int64_t delta[2]);
void ctrl_psi_track_add(ctrl_psi_track_t *t, const int64_t delta[2]);

#endif /* CONTROL_PSI_TRACK_H */
