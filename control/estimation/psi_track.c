/*
 * PM flux from the voltage model with the encoder (psi_track.h): the
 * encoder-mode observer's integration every period, its correction and PM-flux
 * EMA every N periods on the estimator's rotor frame.
 */
#include "psi_track.h"

/* The flux in Q49; taken within +-64 pu at each correction (the estimator's
 * flux range, EST_PSI_LIM): its Q24 view fits 2^30 and the Park transforms
 * below need no saturation. */
#define TRACK_QBITS 49u
#define TRACK_ACC_MAX ((int64_t)1 << (TRACK_QBITS + 6u))
#define TRACK_LIM ((q24_t)1 << 30) /* 64 pu, Q24 */

void ctrl_psi_track_reset(ctrl_psi_track_t *t)
{
    t->obs.primed = 0u;
    t->vs_scale = 0;
    t->vs[0] = 0;
    t->vs[1] = 0;
    t->phase = 0u;
    t->raw_valid = 0u;
}

/* The voltage of [k, k+1) for the next period's integration. */
static void track_voltage(ctrl_psi_track_t *t, const ctrl_params_t *p, const ctrl_estimate_t *est,
                          const ctrl_legs_t *applied, q24_t i_a, q24_t i_b)
{
    ctrl_fobs_t *const o = &t->obs;
    if (o->dt_frac == 0 && o->v_fwd == 0) {
        /* The estimator's duty voltage per unit of DC link: Ts Vdc <= 64 pu,
         * the product below 2^55 (no saturation). */
        t->vs_scale = fx_mul_nosat(p->ts, est->vdc);
        t->vs[0] = est->u_alpha;
        t->vs[1] = est->u_beta;
    } else {
        ctrl_fobs_voltage(o, applied, est->vdc, i_a, i_b, &t->vs[0], &t->vs[1]);
        t->vs_scale = p->ts;
    }
}

/* The flux of one axis within +-64 pu (kept), its Q24 view. */
static q24_t track_view(int64_t *acc)
{
    const int64_t x = *acc;
    *acc = x > TRACK_ACC_MAX ? TRACK_ACC_MAX : (x < -TRACK_ACC_MAX ? -TRACK_ACC_MAX : x);
    return fx_round_nosat(*acc, TRACK_QBITS - FX_QBITS);
}

/* Correction towards the current model (3.9) at the measured angle, in the
 * estimator's frame at k, and the PM flux of the flux before it. */
static void track_correct(ctrl_psi_track_t *t, const ctrl_params_t *p, const ctrl_estimate_t *est)
{
    const ctrl_mstate_t *n = &est->now;
    const q24_t s = n->sin_theta;
    const q24_t c = n->cos_theta;
    const q24_t pa = track_view(&t->acc[0]);
    const q24_t pb = track_view(&t->acc[1]);
    /* Park (3.7); |psi| <= 2^30 sqrt(2), |(s, c)| <= 2^24: sums below 2^55. */
    const q24_t psi_d = fx_dot_nosat(c, s, pa, pb);
    const q24_t psi_q = fx_cross_nosat(c, s, pa, pb);
    /* The current model's flux (the estimator's psi_d = Ld i_d + psi_pm,
     * psi_q = Lq i_q) minus the observer's. */
    const q24_t e_d = fx_sub(n->psi_d, psi_d);
    const q24_t e_q = fx_sub(n->psi_q, psi_q);
    /* k_n < 1 - 2^-8: products below 2^55 - 2^47; a correction beyond
     * 64 pu per update is taken as 64 pu, so that the inverse Park below
     * needs no saturation either. */
    const q24_t cd = fx_clamp(fx_mul_nosat(t->k_n, e_d), -TRACK_LIM, TRACK_LIM - 1);
    const q24_t cq = fx_clamp(fx_mul_nosat(t->k_n, e_q), -TRACK_LIM, TRACK_LIM - 1);
    t->acc[0] += (int64_t)fx_cross_nosat(c, s, cq, cd) * (2 * FX_ONE);
    t->acc[1] += (int64_t)fx_dot_nosat(s, c, cd, cq) * (2 * FX_ONE);
    /* PM flux psi_d - Ld i_d = psi_pm - e_d, where the voltage model is
     * reliable (the encoder's speed above the threshold). */
    if (t->psi_k_n != 0 && fx_abs(est->omega_e) >= t->obs.psi_speed_min) {
        t->psi_raw = fx_sub(p->psi_pm, e_d);
        t->raw_valid = 1u;
    }
}

bool ctrl_psi_track_step(ctrl_psi_track_t *t, const ctrl_params_t *p, const ctrl_estimate_t *est,
                         const ctrl_legs_t *applied, q24_t i_a, q24_t i_b)
{
    ctrl_fobs_t *const o = &t->obs;
    const ctrl_mstate_t *n = &est->now;
    const q24_t i_now[2] = {n->i_alpha, n->i_beta};
    if (o->primed == 0u) {
        /* From the current model at theta(k) (ctrl_fobs_reset's flux, Q48). */
        ctrl_fobs_reset(o, p, n->theta_e, est->omega_e, n->i_alpha, n->i_beta);
        t->acc[0] = o->psi_alpha_acc * 2;
        t->acc[1] = o->psi_beta_acc * 2;
        t->i_prev[0] = i_now[0];
        t->i_prev[1] = i_now[1];
        t->phase = 0u;
        t->raw_valid = 0u;
        track_voltage(t, p, est, applied, i_a, i_b);
        return false;
    }
    /* Voltage model over [k-1, k) (flux_observer.c's fobs_axis, without its
     * clamp, which the correction applies), in Q49: 2 Ts v - Ts Rs (i(k-1) +
     * i(k)). The currents are the estimator's (|i_alpha| <= 32 pu,
     * |i_beta| < 56 pu): their sums fit an int32_t. */
    for (unsigned x = 0u; x < 2u; x++) {
        const int32_t i_sum = t->i_prev[x] + i_now[x];
        t->acc[x] += (int64_t)t->vs_scale * (2 * (int64_t)t->vs[x]) - (int64_t)p->ts_rs * i_sum;
        t->i_prev[x] = i_now[x];
    }
    track_voltage(t, p, est, applied, i_a, i_b);

    bool moved = false;
    const unsigned ph = t->phase;
    if (ph == 0u) {
        track_correct(t, p, est);
    }
    if (t->raw_valid != 0u && (ph == 1u || t->div == 1u)) {
        /* EMA of Q24 values in Q48 (settles on the input exactly). */
        const q24_t out = fx_round_sat(o->psi_pm_acc, FX_QBITS);
        o->psi_pm_acc += (int64_t)fx_sub(t->psi_raw, out) * t->psi_k_n;
        t->raw_valid = 0u;
        moved = true;
    }
    t->phase = (uint8_t)(ph + 1u >= t->div ? 0u : ph + 1u);
    return moved;
}

q24_t ctrl_psi_track_psi_pm(const ctrl_psi_track_t *t)
{
    return ctrl_fobs_psi_pm(&t->obs);
}
