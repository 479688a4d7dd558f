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
 *                  of the estimator (its sin/cos, i_dq and current-model flux:
 *                  no table look-up, no angle), k_N = 1 - (1 - w_c Ts)^N, the
 *                  N per-period corrections in one;
 *   period 1 of N  the EMA with the PM flux of period 0 and 1 - exp(-N Ts / tau)
 *                  (spread over two periods, so the worst period carries one
 *                  of the two).
 * N is the largest divider (<= CTRL_PSI_TRACK_DIV_MAX) with which the flux
 * turns at most a quarter turn between two corrections at the highest speed
 * given: the rotating current-model error the correction filters is then
 * sampled well above its frequency (N w Ts near 2 pi would alias it to DC),
 * and the attenuation (w_c / w) of the per-period filter changes by less than
 * 3 % (|e^{j x} - 1| against x, x <= pi/2).
 * The speed gate reads the estimator's (encoder) speed; the observer's PLL
 * and flux angle are not needed here and do not run.
 * Integer-only per period.
 */
#ifndef CONTROL_PSI_TRACK_H
#define CONTROL_PSI_TRACK_H

#include <stdbool.h>
#include <stdint.h>

#include "ctrl_params.h"
#include "ctrl_types.h"
#include "flux_observer.h"

/* Largest divider: the Q49 flux is clamped at the corrections only, and N
 * unclamped increments (each below 2^57: 2 Ts Vdc <= 128 pu times |u| <= 1,
 * plus Ts Rs <= 1 pu times two currents < 128 pu) stay far inside int64_t. */
#define CTRL_PSI_TRACK_DIV_MAX 8u

typedef struct {
    ctrl_fobs_t obs; /* CTRL_FOBS_ENCODER: gains, voltage compensation (with the
                      * duties of the period before), the PM-flux EMA (Q48) */
    /* Stator flux (alpha, beta), Q49 pu: the observer's Q48 with one more
     * bit, so that the trapezoid's half is exact. */
    int64_t acc[2];
    q24_t i_prev[2];   /* i(k-1) (alpha, beta), Q24 pu */
    q24_t vs_scale;    /* volt-seconds of the period before, Q48 per axis: */
    q24_t vs[2];       /* vs_scale x vs[axis], each Q24 */
    q24_t k_n;         /* correction per update, Q24: 1 - (1 - w_c Ts)^N (< 1 - 2^-8) */
    q24_t psi_k_n;     /* EMA coefficient per update, Q24: 1 - exp(-N Ts / tau) */
    q24_t psi_raw;     /* PM flux psi_d - Ld i_d at the last correction, Q24 pu */
    uint8_t div;       /* N: one correction every N periods */
    uint8_t phase;     /* period within the N, 0..N-1 */
    uint8_t raw_valid; /* psi_raw awaits the EMA (the speed gate was open) */
} ctrl_psi_track_t;

/* Restart from the current model at the next step (keeps the settings and
 * the PM-flux estimate's gains; the estimate restarts from p->psi_pm). */
void ctrl_psi_track_reset(ctrl_psi_track_t *t);

/* One period at sample k, after ctrl_estimator_update: est its estimate at k
 * (now.*: i_alpha/beta, sin/cos, i_d/q, psi_d/q, theta_e; omega_e, vdc,
 * u_alpha/beta), applied the leg duties acting in [k, k+1) and i_a, i_b the
 * measured phase currents (Q24 pu; read only with dead-time or drop
 * compensation). Returns true when the PM-flux estimate has moved
 * (ctrl_psi_track_psi_pm). */
bool ctrl_psi_track_step(ctrl_psi_track_t *t, const ctrl_params_t *p, const ctrl_estimate_t *est,
                         const ctrl_legs_t *applied, q24_t i_a, q24_t i_b);

/* The PM-flux estimate, Q24 pu. */
q24_t ctrl_psi_track_psi_pm(const ctrl_psi_track_t *t);

#endif /* CONTROL_PSI_TRACK_H */
