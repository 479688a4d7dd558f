/*
 * PM flux from the voltage model with the encoder (psi_track.h): the
 * encoder-mode observer's integration every period, its correction and PM-flux
 * EMA every N periods on the estimator's rotor frame.
 */
#include "psi_track.h"

void ctrl_psi_track_reset(ctrl_psi_track_t *t)
{
    t->obs.primed = 0u;
    t->until = 1u;
}

/* Correction towards the current model (3.9) at the measured angle in the
 * estimator's frame at k, and the PM-flux EMA where the voltage model is
 * reliable (the encoder's speed above the threshold): the observer's own
 * (ctrl_fobs_pull_delta, ctrl_fobs_psi_pm_step) with the gains of N periods,
 * k_N and 1 - exp(-N Ts / tau); its PLL is not needed here. */
bool ctrl_psi_track_correct(ctrl_psi_track_t *t, const ctrl_params_t *p,
                            const ctrl_psi_track_in_t *in, int64_t delta[2])
{
    ctrl_fobs_t *const o = &t->obs;
    o->psi_alpha = fx_round_sat(in->acc[0], FX_QBITS);
    o->psi_beta = fx_round_sat(in->acc[1], FX_QBITS);
    const q24_t pm =
        ctrl_fobs_pull_delta(o, p, in->acc, in->sin_theta, in->cos_theta, in->i_d, in->i_q, delta);
    if (t->psi_k_n == 0 || fx_abs(in->omega_e) < t->speed_min) {
        return false;
    }
    ctrl_fobs_psi_pm_step(o, pm, t->psi_k_n);
    return true;
}

void ctrl_psi_track_add(ctrl_psi_track_t *t, const int64_t delta[2])
{
    t->obs.psi_alpha_acc += delta[0];
    t->obs.psi_beta_acc += delta[1];
}

static void psi_track_prime(ctrl_psi_track_t *t, const ctrl_params_t *p, const ctrl_estimate_t *est)
{
    /* From the current model at theta(k) in the estimator's frame
     * (ctrl_fobs_reset's flux, Q48); the correction and the EMA count from
     * here. */
    ctrl_fobs_reset_frame(&t->obs, p, &est->now, est->omega_e);
    t->until = (uint8_t)(t->div > 1u ? 2u : 1u); /* the first correction at the next step */
}

bool ctrl_psi_track_integrate(ctrl_psi_track_t *t, const ctrl_params_t *p,
                              const ctrl_estimate_t *est, const ctrl_legs_t *applied, q24_t i_a,
                              q24_t i_b, ctrl_psi_track_in_t *due)
{
    ctrl_fobs_t *const o = &t->obs;
    const ctrl_mstate_t *n = &est->now;
    /* The estimator's currents (|i_alpha| <= 32 pu, |i_beta| < 56 pu): their
     * sums fit an int32_t. */
    const q24_t i_now[2] = {n->i_alpha, n->i_beta};
    int64_t *const acc[2] = {&o->psi_alpha_acc, &o->psi_beta_acc};
    if (o->primed != 0u) {
        /* trunc(Ts Rs s / 2) of the sum s = 2 m + r (m = trunc(s / 2), r in
         * {-1, 0, 1} with the sign of s) is Ts Rs m + trunc(Ts Rs / 2) r: both
         * terms have the sign of the product, so the half dropped is the
         * same; two multiply-accumulates instead of a 64-bit division. */
        const int32_t ts_rs = p->ts_rs;
        const int32_t ts_rs_half = ts_rs / 2;
        for (unsigned x = 0u; x < 2u; x++) {
            const int32_t i_sum = t->i_prev[x] + i_now[x];
            const int32_t m = i_sum / 2;
            *acc[x] -= (int64_t)ts_rs * m + (int64_t)ts_rs_half * (i_sum - 2 * m);
        }
    } else {
        psi_track_prime(t, p, est);
    }
    t->i_prev[0] = i_now[0];
    t->i_prev[1] = i_now[1];
    bool is_due = false;
    if (--t->until == 0u) {
        /* the flux at k (before the voltage of [k, k+1)) and the frame */
        t->until = t->div;
        due->acc[0] = o->psi_alpha_acc;
        due->acc[1] = o->psi_beta_acc;
        due->sin_theta = n->sin_theta;
        due->cos_theta = n->cos_theta;
        due->i_d = n->i_d;
        due->i_q = n->i_q;
        due->omega_e = est->omega_e;
        is_due = true;
    }
    /* the voltage of [k, k+1) */
    if (t->duty_v != 0u) {
        /* The estimator's duty voltage per unit of DC link: Ts Vdc <= 64 pu,
         * the product below 2^55 (no saturation). */
        const q24_t ts_vdc = fx_mul_nosat(p->ts, est->vdc);
        o->psi_alpha_acc += (int64_t)ts_vdc * est->u_alpha;
        o->psi_beta_acc += (int64_t)ts_vdc * est->u_beta;
    } else {
        q24_t v_alpha;
        q24_t v_beta;
        ctrl_fobs_voltage(o, applied, est->vdc, i_a, i_b, &v_alpha, &v_beta);
        o->psi_alpha_acc += (int64_t)p->ts * v_alpha;
        o->psi_beta_acc += (int64_t)p->ts * v_beta;
    }
    return is_due;
}

bool ctrl_psi_track_step(ctrl_psi_track_t *t, const ctrl_params_t *p, const ctrl_estimate_t *est,
                         const ctrl_legs_t *applied, q24_t i_a, q24_t i_b)
{
    ctrl_psi_track_in_t due;
    if (!ctrl_psi_track_integrate(t, p, est, applied, i_a, i_b, &due)) {
        return false;
    }
    int64_t delta[2];
    const bool moved = ctrl_psi_track_correct(t, p, &due, delta);
    ctrl_psi_track_add(t, delta);
    return moved;
}
