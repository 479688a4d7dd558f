/* Two-candidate M2PTFC, thesis §6.3 (see ctrl_m2ptfc.h). Integer only. */
#include "ctrl_m2ptfc.h"

#include <stddef.h>

#include "plan.h"

/* V_{x+1}, V_{x+2}, V_{x+4}, V_{x+5} for x = 1..6 (index arithmetic of (4.14)
 * wrapped in 1..6); row 0 serves an invalid sector as sector 1. */
static const uint8_t m2ptfc_cand_tab[7][4] = {
    {2, 3, 5, 6}, {2, 3, 5, 6}, {3, 4, 6, 1}, {4, 5, 1, 2},
    {5, 6, 2, 3}, {6, 1, 3, 4}, {1, 2, 4, 5},
};

void ctrl_m2ptfc_candidates(uint8_t sector, q24_t torque_upper, q24_t torque_est, uint8_t out[2])
{
    /* (6.7): torque below the upper boundary -> the two vectors ahead of the
     * flux, else the two behind it. */
    const uint8_t *row = m2ptfc_cand_tab[sector <= 6u ? sector : 0u];
    const unsigned base = torque_upper >= torque_est ? 0u : 2u;
    out[0] = row[base];
    out[1] = row[base + 1u];
}

q24_t ctrl_m2ptfc_duty(q24_t num, q24_t den)
{
    if (num == 0) {
        return 0;
    }
    /* Magnitudes as uint32_t (exact also for INT32_MIN); D >= 0 needs equal signs. */
    const uint32_t n = num < 0 ? 0u - (uint32_t)num : (uint32_t)num;
    const uint32_t d = den < 0 ? 0u - (uint32_t)den : (uint32_t)den;
    /* (6.6): D < 0, D > 1 or no finite D -> the active vector all period. */
    if (den == 0 || (num < 0) != (den < 0) || n > d) {
        return FX_ONE;
    }
    return ctrl_mpc_ratio(n, d);
}

q24_t ctrl_m2ptfc_t_eval(const ctrl_m2ptfc_t *s, q24_t t1, q24_t t0)
{
    /* (**) of ctrl_m2ptfc.h: Te(k+1) + dT0/2 = Te(k+1) + (Te0(k+2) - Te(k+1))/2. */
    return s->centre != 0u ? fx_add(t1, fx_rshift32_round(fx_sub(t0, t1), 1u)) : t1;
}

void ctrl_m2ptfc_reset(void *state)
{
    ctrl_m2ptfc_t *s = state;
    s->sigma = 0;
    s->trace.n = 0u;
    s->psi2.valid = 0u; /* no psi_ref^2 memoised */
}

/* psi_ref^2 of (6.9) (MTPA (4.15) squared, ctrl_mpc_psi_ref2), memoised. */
static int32_t m2ptfc_psi2(ctrl_m2ptfc_t *s, const ctrl_params_t *p, const ctrl_refs_t *ref)
{
    if (ctrl_flux_memo_hit(&s->psi2, p, ref->psi, ref->torque) == 0) {
        s->psi2.value = ctrl_mpc_psi_ref2(p, ref);
    }
    return s->psi2.value;
}

void ctrl_m2ptfc_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out)
{
    ctrl_m2ptfc_t *s = state;
    /* Only V1..V3 are rotated: the two candidates are any V_i (ctrl_mpc_vec3_dq). */
    ctrl_mpc_basis3_t b;
    ctrl_mpc_model_track(&s->model, ctx->params);
    ctrl_mpc_basis3(&s->model, ctx->est, &b);
    const ctrl_estimate_t *est = ctx->est;
    const q24_t t_ref = ctx->ref->torque;
    const q24_t t1 = est->next.torque;

    /* Te of (6.5), (6.7), (6.8): Te(k+1), or Te_c for centre-aligned PWM (header). */
    const q24_t te = ctrl_m2ptfc_t_eval(s, t1, b.t0);

    /* (6.8) sigma_T = lambda (T_ref - Te) + (1 - lambda) sigma_T(k-1). With
     * 0 < lambda <= FX_ONE (init) the product is at most 2^24 * 2^31 = 2^55
     * in magnitude and its rounded Q24 value fits an int32_t: no saturation.
     * It holds while the error exceeds one period's largest torque change,
     * A (5.9) plus the zero vector's |Te0(k+2) - Te(k+1)|: that is a step's
     * rise, and wound up into T_ref + sigma_T it would carry a fixed flux past
     * its pull-out (docs/algorithms.md, "Virtual-reference wind-up"). */
    const q24_t chi = fx_sub(t_ref, te);
    if (s->sigma_max == 0 || fx_abs(chi) <= fx_add(s->sigma_max, fx_abs(fx_sub(b.t0, t1)))) {
        s->sigma = fx_add(s->sigma, fx_mul_nosat(s->lambda, fx_sub(chi, s->sigma)));
    }
    const q24_t t_upper = fx_add(t_ref, s->sigma);
    const q24_t num = fx_sub(t_upper, te); /* numerator of (6.5) */
    const q24_t two_sigma = fx_add(s->sigma, s->sigma);

    uint8_t cand[2];
    ctrl_m2ptfc_candidates(est->next.sector, t_upper, te, cand);

    /* psi_ref^2 of (6.9), compared on squares: no square root (MTPA (4.15) squared). */
    const int32_t r2 = m2ptfc_psi2(s, ctx->params, ctx->ref);

    q24_t duty[2];
    int32_t a2[2];
    for (unsigned k = 0; k < 2u; k++) {
        q24_t vd;
        q24_t vq;
        ctrl_mpc_vec3_dq(&b, cand[k], &vd, &vq);
        /* Te(k+2) with the vector for the whole period -> dTe[x+n] (6.10)-(6.11). */
        const q24_t t_full = ctrl_mpc_torque(&s->model, b.d0 + vd, b.q0 + vq);
        const q24_t den = fx_add(fx_sub(t_full, t1), two_sigma);
        duty[k] = ctrl_m2ptfc_duty(num, den); /* (6.5)-(6.6) */
        /* psi(k+2) for D Ts (ctrl_mpc_flux: components <= 12.4 pu, no overflow). */
        const q24_t pd = b.d0 + fx_mul_nosat(duty[k], vd);
        const q24_t pq = b.q0 + fx_mul_nosat(duty[k], vq);
        a2[k] = ctrl_mpc_amp2(pd, pq);
    }
    /* (6.9): keep the first candidate unless the second is strictly closer. */
    const unsigned best = ctrl_mpc_closer(a2[1], a2[0], r2) < 0 ? 1u : 0u;

    s->trace.n = 2u;
    s->trace.vec[0] = cand[0];
    s->trace.vec[1] = cand[1];
    s->trace.duty[0] = duty[0];
    s->trace.duty[1] = duty[1];
    ctrl_out_active_zero(out, cand[best], duty[best]);
}
