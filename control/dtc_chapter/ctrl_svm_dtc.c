/*
 * SVM-DTC with the predictive controller of the book chapter (S1 §4,
 * S1(17)-(20), Fig. 25), per-sample part (integer-only). See ctrl_s1_dtc.h.
 */
#include <stddef.h>

#include "ctrl_s1_dtc.h"
#include "plan.h"
#include "svpwm.h"

#define SVM_INTEG_SHIFT 16u /* integrator Q40 = Q24 + 16 */
#define SVM_KI_QBITS 30u
#define SVM_DD_MAX 17569060        /* pi/3 rad, Q24 */
#define SVM_INTEG_MAX 8784530      /* pi/6 rad, Q24 */
#define SVM_RAD_TO_ANGLE 683565276 /* 2^32 / (2 pi), Q24 of fx_angle_t per rad */
#define SVM_PSI_MIN (FX_ONE / 64)  /* below this the flux has no usable direction */

void ctrl_svm_dtc_reset(void *state)
{
    ctrl_svm_dtc_state_t *s = state;
    s->integ = 0;
    s->limited = 0u;
    s->dd = 0;
    s->v_alpha = 0;
    s->v_beta = 0;
}

void ctrl_svm_dtc_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out)
{
    ctrl_svm_dtc_state_t *s = state;
    const ctrl_params_t *p = ctx->params;
    const ctrl_mstate_t *nx = &ctx->est->next; /* starting flux psi_s(k+1): delay compensation */
    const q24_t psi_ref = ctx->ref->psi > 0 ? ctx->ref->psi : s->psi_ref;
    const q24_t e = fx_sub(ctx->ref->torque, nx->torque);

    /* PI -> Delta delta (rad, Q24). */
    const q24_t integ = fx_sat32(fx_rshift64_round(s->integ, SVM_INTEG_SHIFT));
    q24_t dd = fx_add(fx_mul(s->kp, e), integ);
    dd = fx_clamp(dd, -SVM_DD_MAX, SVM_DD_MAX);
    const uint8_t pi_sat = (dd == SVM_DD_MAX || dd == -SVM_DD_MAX) ? 1u : 0u;
    if (s->ff != 0u) {
        dd = fx_add(dd, fx_mul(ctx->est->omega_e, p->ts)); /* rotor advance omega Ts */
    }
    s->dd = dd;

    /* Target psi_ref e^{j(lambda + dd)}, lambda the angle of the present flux
     * (no atan): the flux turned by dd and scaled by psi_ref / |psi| (one
     * division); without usable flux the magnet axis at k+1 scaled by
     * psi_ref. dd * 2^32/(2 pi) fits 64 bits; the angle wraps modulo a turn. */
    const int64_t ang = fx_rshift64_round((int64_t)dd * SVM_RAD_TO_ANGLE, FX_QBITS);
    int32_t rc;
    int32_t rs;
    fx_rot_q30(fx_u2i((uint32_t)(uint64_t)ang), &rc, &rs);
    q24_t rx;
    q24_t ry;
    q24_t g;
    if (nx->psi_amp >= SVM_PSI_MIN) {
        fx_rotate(nx->psi_alpha, nx->psi_beta, rc, rs, &rx, &ry);
        g = fx_div(psi_ref, nx->psi_amp);
    } else {
        fx_rotate(nx->cos_theta, nx->sin_theta, rc, rs, &rx, &ry);
        g = psi_ref;
    }
    const q24_t tx = fx_mul(g, rx);
    const q24_t ty = fx_mul(g, ry);
    /* S1(19)-(20): V = (psi_target - psi) / Ts + Rs i. */
    q24_t va =
        fx_add(fx_mul_qn(fx_sub(tx, nx->psi_alpha), s->inv_ts, 16u), fx_mul(p->rs, nx->i_alpha));
    q24_t vb =
        fx_add(fx_mul_qn(fx_sub(ty, nx->psi_beta), s->inv_ts, 16u), fx_mul(p->rs, nx->i_beta));
    s->v_alpha = va;
    s->v_beta = vb;
    out->plan.n_seg = 0u; /* leg duties (ctrl_types.h) */
    s->limited = ctrl_svpwm(&va, &vb, ctx->est->vdc, &out->legs);

    /* Integrator: conditional integration (hold while the PI output or the
     * voltage is saturated and the error pushes further), clamped to pi/6. */
    if (!((pi_sat != 0u || s->limited != 0u) && fx_sign(e) == fx_sign(dd))) {
        const int64_t lim = (int64_t)SVM_INTEG_MAX * ((int64_t)1 << SVM_INTEG_SHIFT);
        int64_t i =
            s->integ + fx_rshift64_round((int64_t)e * s->ki, SVM_KI_QBITS - SVM_INTEG_SHIFT);
        i = i > lim ? lim : (i < -lim ? -lim : i);
        s->integ = i;
    }
}
