/*
 * Machine state from the stator flux, and the one-step prediction.
 *
 * Current from flux in the rotor frame, (3.9) inverted ((6.12) generalised to
 * Ld != Lq): i_d = (psi_d - psi_pm) / Ld, i_q = psi_q / Lq, with the reciprocals
 * precomputed in ctrl_params_t (no division per sample). Torque in pu is the
 * cross product (3.6)/(4.6): Te = psi_alpha i_beta - psi_beta i_alpha
 * (T_base = 1.5 p psi_base i_base). Amplitude (4.3), sector (4.5).
 *
 * Prediction (5.15)/(6.10): psi(k+1) = psi(k) + Ts (v(k) - Rs i(k)), forward
 * Euler of (3.2); theta(k+1) = theta(k) + omega_e Ts; then the state at k+1
 * from the predicted flux, (6.11)-(6.12).
 */
#ifndef CONTROL_PREDICT_H
#define CONTROL_PREDICT_H

#include "ctrl_params.h"
#include "ctrl_types.h"
#include "fx.h"

/* Angle increment over one control period at electrical speed omega_e (Q24 pu):
 * omega_e * Ts in fx_angle_t units (2^32 = one turn), wrapping modulo a turn. */
fx_angle_t ctrl_angle_step(const ctrl_params_t *p, q24_t omega_e);

/* Full state from the stator flux at rotor angle theta_e (one fx_sincos). */
void ctrl_mstate_from_flux(const ctrl_params_t *p, q24_t psi_alpha, q24_t psi_beta,
                           fx_angle_t theta_e, ctrl_mstate_t *out);

/* Same with sin/cos of theta_e given (Q24), for callers that evaluate several
 * fluxes at the same angle (e.g. the candidates of a predictive controller). */
void ctrl_mstate_from_flux_sc(const ctrl_params_t *p, q24_t psi_alpha, q24_t psi_beta,
                              fx_angle_t theta_e, q24_t sin_theta, q24_t cos_theta,
                              ctrl_mstate_t *out);

/* Same as ctrl_mstate_from_flux_sc without the amplitude: out->psi_amp = 0
 * (not computed; saves the square root, ~75 Cortex-M4 instructions). For
 * callers that need the state but not |psi| (or compare squared amplitudes). */
void ctrl_mstate_from_flux_noamp(const ctrl_params_t *p, q24_t psi_alpha, q24_t psi_beta,
                                 fx_angle_t theta_e, q24_t sin_theta, q24_t cos_theta,
                                 ctrl_mstate_t *out);

/* Flux only, (5.15): psi + Ts (v - Rs i) from the state now (no angle, no current). */
void ctrl_predict_flux(const ctrl_params_t *p, const ctrl_mstate_t *now, q24_t v_alpha,
                       q24_t v_beta, q24_t *psi_alpha, q24_t *psi_beta);

/* One-step prediction with the period-average voltage (v_alpha, v_beta) applied
 * during [k, k+1) and speed omega_e (both Q24 pu). next may not alias now. */
void ctrl_predict(const ctrl_params_t *p, const ctrl_mstate_t *now, q24_t v_alpha, q24_t v_beta,
                  q24_t omega_e, ctrl_mstate_t *next);

#endif /* CONTROL_PREDICT_H */
