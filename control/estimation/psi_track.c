/*
 * PM flux from the voltage model with the encoder (psi_track.h): the
 * encoder-mode observer's integration every period, its correction and PM-flux
 * EMA every N periods on the estimator's rotor frame.
 */
#include "psi_track.h"

void ctrl_psi_track_reset(ctrl_psi_track_t *t)
{
    t->obs.primed = 0u;
    t->vs_scale = 0;
    t->vs[0] = 0;
    t->vs[1] = 0;
    t->phase = 0u;
}

/* Correction towards the current model (3.9) at the measured angle in the
 * estimator's frame at k, and the PM-flux EMA where the voltage model is
 * reliable (the encoder's speed above the threshold): the observer's own
 * (ctrl_fobs_correct, encoder mode, its gains set to the N periods' k_N and
 * 1 - exp(-N Ts / tau), its speed gate left to this function; its PLL turns
 * but is not read). Returns whether the estimate moved. */
bool ctrl_psi_track_correct(ctrl_psi_track_t *t, const ctrl_params_t *p, const ctrl_estimate_t *est)
{
    ctrl_fobs_t *const o = &t->obs;
    const ctrl_mstate_t *n = &est->now;
    o->psi_alpha = fx_round_sat(o->psi_alpha_acc, FX_QBITS);
    o->psi_beta = fx_round_sat(o->psi_beta_acc, FX_QBITS);
    const bool gate = fx_abs(est->omega_e) >= t->speed_min;
    o->psi_k = gate ? t->psi_k_n : 0;
    ctrl_fobs_correct(o, p, n->theta_e, n->sin_theta, n->cos_theta, n->i_d, n->i_q);
    return gate && t->psi_k_n != 0;
}

void ctrl_psi_track_prime(ctrl_psi_track_t *t, const ctrl_params_t *p, const ctrl_estimate_t *est)
{
    /* From the current model at theta(k) (ctrl_fobs_reset's flux, Q48); the
     * correction and the EMA count from here. */
    ctrl_fobs_t *const o = &t->obs;
    const ctrl_mstate_t *n = &est->now;
    ctrl_fobs_reset(o, p, n->theta_e, est->omega_e, n->i_alpha, n->i_beta);
    t->phase = (uint8_t)(t->div - 1u);
}
