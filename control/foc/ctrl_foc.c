/*
 * Rotor-field-oriented control (S1 §2, Algorithm 1), per-sample part
 * (integer-only). Design, gains and delay compensation: ctrl_foc.h.
 */
#include "ctrl_foc.h"

#include <stddef.h>

#include "mtpa.h"
#include "plan.h"
#include "svpwm.h"
#include "transforms.h"
#include "vectors.h"

void ctrl_foc_iref(const ctrl_params_t *p, const ctrl_foc_iref_t *r, q24_t t, q24_t *i_d,
                   q24_t *i_q)
{
    if (r->mtpa != 0u) {
        ctrl_mtpa_current(p, t, i_d, i_q);
        return;
    }
    /* i_d = 0 (Algorithm 1): Te = psi_pm i_q (3.10). */
    const q24_t q = fx_mul(fx_min(fx_abs(t), r->t_max), p->inv_psi_pm);
    *i_d = 0;
    *i_q = t < 0 ? fx_neg(q) : q;
}

/* The integrator in Q24: integ / 2^n rounded (ties up), n = ki_shift in
 * 17..30; |integ| <= lim <= 2^59 puts the result within 2^29, so it is the
 * low word of the rounded shift (fx_round_nosat's value), formed in 32-bit
 * halves (the compiler's variable 64-bit shift costs ~15 instructions). */
static inline q24_t foc_integ_q24(int64_t integ, unsigned n)
{
    const uint64_t u = (uint64_t)integ + ((uint32_t)1 << (n - 1u));
    return fx_u2i(((uint32_t)u >> n) | ((uint32_t)(u >> 32) << (32u - n)));
}

/* The bodies of ctrl_foc_pi_out and ctrl_foc_pi_update, inline in the step. */
static inline q24_t foc_pi_out(const ctrl_foc_pi_t *pi, q24_t err)
{
    return fx_add(fx_mul_qn(err, pi->kp, FOC_KP_QBITS), foc_integ_q24(pi->integ, pi->ki_shift));
}

static inline void foc_pi_update(ctrl_foc_pi_t *pi, q24_t err, q24_t v, uint8_t limited)
{
    if (limited != 0u && ((err > 0 && v > 0) || (err < 0 && v < 0))) {
        return; /* conditional integration: hold while pushing into the limit */
    }
    /* err Q24 * ki_ts Q(ki_shift): the increment in the integrator's own
     * Q(24 + ki_shift), exact (no rounding per period); |integ| <= 2^59,
     * |product| < 2^62: the sum cannot overflow. */
    const int64_t lim = pi->lim;
    int64_t i = pi->integ + (int64_t)err * pi->ki_ts;
    i = i > lim ? lim : (i < -lim ? -lim : i);
    pi->integ = i;
}

q24_t ctrl_foc_pi_out(const ctrl_foc_pi_t *pi, q24_t err)
{
    return foc_pi_out(pi, err);
}

void ctrl_foc_pi_update(ctrl_foc_pi_t *pi, q24_t err, q24_t v, uint8_t limited)
{
    foc_pi_update(pi, err, v, limited);
}

void ctrl_foc_reset(void *state)
{
    ctrl_foc_state_t *s = state;
    s->legs = 0u;
    s->limited = 0u;
    s->pi_d.integ = 0;
    s->pi_q.integ = 0;
    s->v_d = 0;
    s->v_q = 0;
#if PMSM_LIVE_PARAMS
    s->e_d = 0;
    s->e_q = 0;
#endif
    ctrl_fieldweak_reset(&s->fieldweak);
}

/* foc: PI current loops + SVPWM. */
static void foc_pi_step(ctrl_foc_state_t *s, const ctrl_ctx_t *ctx, q24_t id_ref, q24_t iq_ref,
                        ctrl_out_t *out)
{
    const ctrl_mstate_t *nx = &ctx->est->next; /* state at k+1: delay compensation */
    const q24_t w = ctx->est->omega_e;
    const q24_t e_d = fx_sub(id_ref, nx->i_d);
    const q24_t e_q = fx_sub(iq_ref, nx->i_q);
    /* Decoupling feed-forward of S1(1): -omega Lq i_q and omega (Ld i_d + psi_pm). */
    const q24_t v_d = fx_add(fx_neg(fx_mul(w, nx->psi_q)), foc_pi_out(&s->pi_d, e_d));
    const q24_t v_q = fx_add(fx_mul(w, nx->psi_d), foc_pi_out(&s->pi_q, e_q));
    s->v_d = v_d;
    s->v_q = v_q;
#if PMSM_LIVE_PARAMS
    s->e_d = e_d; /* foc_retune's */
    s->e_q = e_q;
#endif
    /* Mean rotor angle over [k+1, k+2): theta(k+1) + omega Ts / 2 =
     * theta(k) + 3/2 delta: the estimator's sine and cosine at k turned by
     * 3/2 delta (formed in 64 bits, rounded, taken modulo one turn). */
    const int64_t d15 = (int64_t)ctx->est->dtheta * 3;
    int32_t rc;
    int32_t rs;
    fx_rot_q30(fx_u2i((uint32_t)(uint64_t)fx_rshift64_round(d15, 1u)), &rc, &rs);
    const ctrl_mstate_t *now = &ctx->est->now;
    q24_t cs;
    q24_t sn;
    fx_rotate(now->cos_theta, now->sin_theta, rc, rs, &cs, &sn);
    q24_t va;
    q24_t vb;
    ctrl_inv_park(v_d, v_q, sn, cs, &va, &vb);
    out->plan.n_seg = 0u; /* leg duties (ctrl_types.h) */
    s->limited = ctrl_svpwm(&va, &vb, ctx->est->vdc, &out->legs);
    foc_pi_update(&s->pi_d, e_d, v_d, s->limited);
    foc_pi_update(&s->pi_q, e_q, v_q, s->limited);
}

/* foc_hyst: per-phase hysteresis current control, one vector per period. */
static void foc_hyst_step(ctrl_foc_state_t *s, const ctrl_ctx_t *ctx, q24_t id_ref, q24_t iq_ref,
                          ctrl_out_t *out)
{
    const ctrl_mstate_t *nx = &ctx->est->next; /* currents at k+1 (delay compensation) */
    /* Phase errors i_ref - i(k+1): the rotor-frame error turned to the stator
     * frame (inverse Park at theta(k+1)) and split into phases (inverse
     * Clarke), both linear. */
    q24_t ea;
    q24_t eb;
    ctrl_inv_park(fx_sub(id_ref, nx->i_d), fx_sub(iq_ref, nx->i_q), nx->sin_theta, nx->cos_theta,
                  &ea, &eb);
    q24_t err[3];
    ctrl_inv_clarke(ea, eb, &err[0], &err[1], &err[2]);
    uint8_t legs = s->legs;
    for (unsigned x = 0u; x < 3u; x++) {
        const q24_t e = err[x];
        const uint8_t bit = (uint8_t)(1u << x);
        if (e >= s->h_i) {
            legs = (uint8_t)(legs | bit); /* current too low: leg high */
        } else if (e <= -s->h_i) {
            legs = (uint8_t)(legs & (uint8_t)~bit);
        }
    }
    s->legs = legs;
    ctrl_out_single(out, ctrl_vec_of_legs[legs & 7u]);
}

void ctrl_foc_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out)
{
    ctrl_foc_state_t *s = state;
    q24_t id_ref;
    q24_t iq_ref;
    if (ctx->ref->psi > 0) {
        /* d-axis current from the voltage limit: the flux circle the voltage
         * allows (MTPA currents when their flux is inside it). */
        ctrl_fieldweak_currents(&s->fieldweak, ctx->params, ctx->ref->torque, ctx->ref->psi,
                                &id_ref, &iq_ref);
    } else {
        ctrl_foc_iref(ctx->params, &s->iref, ctx->ref->torque, &id_ref, &iq_ref);
    }
    if (s->hyst != 0u) {
        foc_hyst_step(s, ctx, id_ref, iq_ref, out);
    } else {
        foc_pi_step(s, ctx, id_ref, iq_ref, out);
    }
}
