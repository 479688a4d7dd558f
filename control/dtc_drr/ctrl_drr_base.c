/*
 * Duty-ratio baselines of thesis §5.5, per sample (integer-only):
 * D1 (5.19), D2 (5.21), D_PI (5.20), D_f (5.18) / D_RMS (5.17).
 * Active vector: the error-sign rule (5.1) (= AST, Table 4.4) on the
 * uncorrected errors T_ref - T(k+1), psi_ref - |psi(k+1)|; then the zero
 * vector of §5.4. No virtual reference, no voltage replacement.
 */
#include <stddef.h>

#include "ctrl_drr.h"
#include "mtpa.h"
#include "plan.h"
#include "vectors.h"

#define BASE_LIM (4 * FX_ONE) /* input clamp, as in ctrl_drr.c */

static q24_t base_lim(q24_t x)
{
    return fx_clamp(x, -BASE_LIM, BASE_LIM);
}

/* num / den clamped to [0, FX_ONE]; den == 0 counts as +0. |num|, |den| < 2^31. */
static q24_t base_ratio01(q24_t num, q24_t den)
{
    if (den < 0) {
        num = fx_neg(num);
        den = fx_neg(den);
    }
    if (num <= 0) {
        return 0;
    }
    if (den == 0 || num >= den) {
        return FX_ONE;
    }
    return fx_clamp(fx_div(num, den), 0, FX_ONE);
}

q24_t ctrl_drr_duty_d1(const ctrl_drr_base_state_t *s, q24_t t_err, q24_t psi_err)
{
    /* (5.19): D = |T_err / C_T| + |psi_err / C_psi|, reciprocals from init. */
    const q24_t d = fx_add(fx_mul(fx_abs(base_lim(t_err)), s->inv_ct),
                           fx_mul(fx_abs(base_lim(psi_err)), s->inv_cpsi));
    return fx_clamp(d, 0, FX_ONE);
}

q24_t ctrl_drr_duty_d2(const ctrl_drr_base_state_t *s, q24_t t_err, q24_t omega_e)
{
    /* (5.21): (2 T_err + K_b w) / (+-K_a - K_b w), sign of K_a by the sign of T_err. */
    const q24_t e = base_lim(t_err);
    const q24_t kbw = fx_mul(s->kb, base_lim(omega_e));
    const q24_t num = fx_add(fx_lshift_sat(e, 1u), kbw);
    const q24_t den = fx_sub(e >= 0 ? s->ka : fx_neg(s->ka), kbw);
    return base_ratio01(num, den);
}

q24_t ctrl_drr_duty_pi(const ctrl_drr_base_state_t *s, q24_t t_err, q24_t integ, q24_t omega_e)
{
    /* (5.20): D = | 3 |w| psi_pm / (2 Vdc) + K_P T_err + K_I int T_err |. */
    const q24_t ff = fx_mul(s->ff, fx_abs(base_lim(omega_e)));
    const q24_t d = fx_add(fx_add(ff, fx_mul(s->kp, base_lim(t_err))), integ);
    return fx_clamp(fx_abs(d), 0, FX_ONE);
}

q24_t ctrl_drr_duty_df(const ctrl_drr_base_state_t *s, const ctrl_params_t *p,
                       const ctrl_mstate_t *m, uint8_t vec, q24_t vdc, q24_t t_err, q24_t omega_e)
{
    /* (4.10) in pu (T = psi_r x psi / Ls):
     *   Delta T[v] = Ts/Ls [ psi_r x v - Rs/Ls (psi_r x psi) - w (psi_r . psi) ]
     * so Delta T[0] = -Ts/Ls [ Rs/Ls psi_pm psi_s sin(delta) + w psi_pm psi_s cos(delta) ]
     * and Delta T[x+n] - Delta T[0] = Ts/Ls (psi_r x v). psi_r = psi_pm on
     * the d axis: psi_r x psi = psi_pm psi_q, psi_r . psi = psi_pm psi_d,
     * psi_r x v = psi_pm v_q (rotor frame at k+1, m->sin/cos_theta). */
    q24_t va;
    q24_t vb;
    ctrl_vector_ab(vec, base_lim(vdc), &va, &vb);
    const q24_t cr_v = fx_mul(p->psi_pm, fx_cross(m->cos_theta, m->sin_theta, va, vb));
    const q24_t cr_p = fx_mul(p->psi_pm, base_lim(m->psi_q));
    const q24_t dot_p = fx_mul(p->psi_pm, base_lim(m->psi_d));
    const q24_t w = base_lim(omega_e);
    const int64_t z48 = (int64_t)s->rs_l * cr_p + (int64_t)w * dot_p; /* < 2^57 */
    const q24_t dt0 = fx_neg(fx_mul(s->ts_l, fx_sat32(fx_rshift64_round(z48, FX_QBITS))));
    const q24_t diff = fx_mul(s->ts_l, cr_v);
    const q24_t e = base_lim(t_err);
    const int want = e >= 0 ? 1 : -1;
    const int got = (diff > 0) - (diff < 0);
    if (got != want) {
        return 0; /* by (4.10) the vector does not beat a zero vector: zero vector */
    }
    if (s->rms != 0u) {
        /* (5.17): (2 T_err - dT0) / (2 dT[x+n] - dT0) = (2 T_err - dT0) / (2 diff + dT0). */
        const q24_t num = fx_sub(fx_lshift_sat(e, 1u), dt0);
        const q24_t den = fx_add(fx_lshift_sat(diff, 1u), dt0);
        const int dsg = (den > 0) - (den < 0);
        if (dsg != want) {
            return FX_ONE; /* the vector still beats the zero vector (diff has the sign) */
        }
        return base_ratio01(num, den);
    }
    /* (5.18): (T_err - dT0) / (dT[x+n] - dT0). */
    return base_ratio01(fx_sub(e, dt0), diff);
}

void ctrl_drr_base_reset(void *state)
{
    ctrl_drr_base_state_t *s = state;
    s->integ = 0;
    s->last_duty = 0;
    s->last_terr = 0;
    s->last_psierr = 0;
    s->flux_ref.valid = 0u;
}

void ctrl_drr_base_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out)
{
    ctrl_drr_base_state_t *s = state;
    const ctrl_mstate_t *nx = &ctx->est->next;
    const q24_t w = ctx->est->omega_e;
    const q24_t tref = ctx->ref->torque;
    const q24_t terr = fx_sub(tref, nx->torque);
    /* the flux reference of T_ref: formed only when an input moved (mtpa.h) */
    const q24_t psi_ref = ctrl_flux_ref_memo(&s->flux_ref, ctx->params, ctx->ref->psi, tref);
    const q24_t psierr = fx_sub(psi_ref, nx->psi_amp);
    const uint8_t vec = ctrl_drr_select(nx->sector, terr, psierr);
    q24_t duty = 0;
    switch ((ctrl_drr_base_kind_t)s->kind) {
    case CTRL_DRR_BASE_D1:
        duty = ctrl_drr_duty_d1(s, terr, psierr);
        break;
    case CTRL_DRR_BASE_D2:
        duty = ctrl_drr_duty_d2(s, terr, w);
        break;
    case CTRL_DRR_BASE_PI:
        /* Integrator of K_I T_err (Ts per sample), clamped to one period:
         * anti-windup, the duty cannot use more. */
        s->integ = fx_clamp(fx_add(s->integ, fx_mul(s->ki_ts, base_lim(terr))), -FX_ONE, FX_ONE);
        duty = ctrl_drr_duty_pi(s, terr, s->integ, w);
        break;
    case CTRL_DRR_BASE_DF:
        duty = ctrl_drr_duty_df(s, ctx->params, nx, vec,
                                ctx->est->vdc > 0 ? ctx->est->vdc : ctx->params->vdc_nom, terr, w);
        break;
    default:
        duty = 0;
        break;
    }
    s->last_terr = terr;
    s->last_psierr = psierr;
    s->last_duty = duty;
    ctrl_out_active_zero(out, vec, duty);
}
