/*
 * Per-period estimator in the rotor frame (estimator.h): current model
 * (3.9), torque (3.10), and the k+1 prediction (5.15)/(6.10)-(6.12) with one
 * table sine/cosine per period.
 */
#include "estimator.h"

#include <string.h>

#include "plan.h"
#include "vectors.h"

void ctrl_estimator_init(ctrl_estimator_t *e, const ctrl_params_t *p)
{
    e->src = &ctrl_angle_encoder;
    e->outputs = CTRL_EST_ALL;
    memset(e->src_state.bytes, 0, sizeof e->src_state.bytes);
    ctrl_estimator_reset(e, p);
}

void ctrl_estimator_reset(ctrl_estimator_t *e, const ctrl_params_t *p)
{
    memset(&e->in, 0, sizeof e->in);
    e->src->reset(e->src_state.bytes, p);
}

int ctrl_estimator_set_angle_src(ctrl_estimator_t *e, const ctrl_params_t *p,
                                 const ctrl_angle_src_t *src)
{
    if (e == NULL || p == NULL || src == NULL || src->update == NULL || src->reset == NULL ||
        src->state_size > CTRL_ANGLE_STATE_MAX) {
        return CTRL_EINVAL;
    }
    e->src = src;
    memset(e->src_state.bytes, 0, sizeof e->src_state.bytes);
    ctrl_estimator_reset(e, p);
    return CTRL_OK;
}

void ctrl_estimator_set_outputs(ctrl_estimator_t *e, unsigned outputs)
{
    if (outputs & CTRL_EST_SECTOR_NOW) {
        outputs |= CTRL_EST_PSI_AB_NOW;
    }
    if (outputs & CTRL_EST_SECTOR_NEXT) {
        outputs |= CTRL_EST_PSI_AB_NEXT;
    }
    if (outputs & CTRL_EST_I_AB_NEXT) {
        outputs |= CTRL_EST_SC_NEXT;
    }
    e->outputs = (uint16_t)(outputs & CTRL_EST_ALL);
}

/* The optional outputs (estimator.h), tested in groups (the outputs at k
 * and the two amplitudes at k+1), as most controllers read none of a group.
 * (hd, hq): the predicted flux in the frame at theta(k), psi' of (5.15); its
 * stator-frame image is psi(k+1). */
static void estimator_options(unsigned outputs, q24_t hd, q24_t hq, ctrl_estimate_t *est)
{
    ctrl_mstate_t *now = &est->now;
    ctrl_mstate_t *nx = &est->next;
    const q24_t s = now->sin_theta;
    const q24_t c = now->cos_theta;
    if (outputs & (CTRL_EST_AMP_NOW | CTRL_EST_PSI_AB_NOW)) {
        if (outputs & CTRL_EST_AMP_NOW) {
            now->psi_amp = fx_mag(now->psi_d, now->psi_q); /* (4.3), rotation-invariant */
        }
        if (outputs & CTRL_EST_PSI_AB_NOW) {
            now->psi_alpha = fx_cross(c, s, now->psi_q, now->psi_d); /* inverse Park */
            now->psi_beta = fx_dot(s, c, now->psi_d, now->psi_q);
            if (outputs & CTRL_EST_SECTOR_NOW) {
                now->sector = ctrl_sector(now->psi_alpha, now->psi_beta); /* (4.5) */
            }
        }
    }
    if (outputs & (CTRL_EST_AMP_NEXT | CTRL_EST_AMP_SQ_NEXT)) {
        if (outputs & CTRL_EST_AMP_NEXT) {
            nx->psi_amp = fx_mag(hd, hq); /* = |psi(k+1)|, one rounding less */
        }
        if (outputs & CTRL_EST_AMP_SQ_NEXT) {
            /* psi_amp's S: |hd|, |hq| <= 2^30, the sum <= 2^61, exact */
            nx->psi_amp_sq = (uint64_t)((int64_t)hd * hd + (int64_t)hq * hq);
        }
    }
    if (outputs & CTRL_EST_PSI_AB_NEXT) {
        /* |psi'| <= 91 pu (clamped), |(s, c)| <= 1: no saturation */
        nx->psi_alpha = fx_cross_nosat(c, s, hq, hd);
        nx->psi_beta = fx_dot_nosat(s, c, hd, hq);
        if (outputs & CTRL_EST_SECTOR_NEXT) {
            nx->sector = ctrl_sector(nx->psi_alpha, nx->psi_beta);
        }
    }
    if (outputs & CTRL_EST_SC_NEXT) {
        /* theta(k+1) = theta(k) + delta: (s, c) turned by (rot_c, rot_s). */
        const int32_t rc = est->rot_c;
        const int32_t rs = est->rot_s;
        const q24_t c1 = fx_round_nosat((int64_t)c * rc - (int64_t)s * rs, 30u);
        const q24_t s1 = fx_round_nosat((int64_t)s * rc + (int64_t)c * rs, 30u);
        nx->sin_theta = s1;
        nx->cos_theta = c1;
        if (outputs & CTRL_EST_I_AB_NEXT) {
            nx->i_alpha = fx_cross(c1, s1, nx->i_q, nx->i_d);
            nx->i_beta = fx_dot(s1, c1, nx->i_d, nx->i_q);
        }
    }
}

/* Range of the per-period arithmetic (estimator.h): phase currents within
 * [-CTRL_EST_I_LIM, CTRL_EST_I_LIM), leg duties in [0, FX_ONE], the DC link
 * in [0, 64 pu). */
#define EST_VDC_LIM ((q24_t)1 << 30) /* 64 pu */
#define EST_PSI_LIM ((q24_t)1 << 30) /* 64 pu */
/* the limits as the bit widths of their SSAT (FX_SAT below) */
_Static_assert(CTRL_EST_I_LIM == (q24_t)1 << (30 - 1), "FX_SAT(i, 30)");
_Static_assert(EST_PSI_LIM == (q24_t)1 << (31 - 1), "FX_SAT(psi', 31)");

void ctrl_estimator_update(ctrl_estimator_t *e, const ctrl_params_t *p, const ctrl_meas_t *m,
                           const ctrl_legs_t *applied, ctrl_estimate_t *est)
{
    ctrl_mstate_t *now = &est->now;
    ctrl_mstate_t *nx = &est->next;
    /* Clarke (3.3): beta = (a + 2 b)/sqrt(3); |a|, |b| <= 2^29: |beta| <= 55.5 pu,
     * the products < 2^60, no saturation. */
    const q24_t i_a = FX_SAT(m->i_a, 30); /* [-CTRL_EST_I_LIM, CTRL_EST_I_LIM) */
    const q24_t i_b = FX_SAT(m->i_b, 30);
    q24_t i_alpha = i_a;
    q24_t i_beta =
        fx_round_nosat((int64_t)i_a * FX_Q30_INV_SQRT3 + (int64_t)i_b * FX_Q30_2_SQRT3, 30u);
    const q24_t vdc = fx_clamp(m->vdc, 0, EST_VDC_LIM - 1); /* one USAT */

    /* theta(k), omega(k) from the angle source. */
    ctrl_angle_in_t *in = &e->in;
    in->theta_meas = m->theta_e;
    in->i_alpha = i_alpha;
    in->i_beta = i_beta;
    in->vdc = vdc;
    fx_angle_t th;
    q24_t omega;
    const ctrl_angle_frame_t *fr = NULL;
    if (e->src == &ctrl_angle_encoder) {
        /* the usual source, called directly (inline; its own output record,
         * which the compiler keeps in registers) */
        ctrl_angle_out_t ang;
        ctrl_angle_encoder_step((ctrl_angle_encoder_t *)(void *)e->src_state.bytes, p, m->theta_e,
                                &ang);
        th = ang.theta;
        omega = ang.omega;
    } else {
        ctrl_angle_out_t ang;
        ang.frame = NULL;
#if CTRL_SL_HFI
        ang.i_fund = NULL;
#endif
        e->src->update(e->src_state.bytes, p, in, &ang);
        th = ang.theta;
        omega = ang.omega;
        fr = ang.frame;
#if CTRL_SL_HFI
        if (ang.i_fund != NULL) {
            /* the source's current (an injection's ripple removed), within
             * the same range as the measured one */
            i_alpha = FX_SAT(ang.i_fund[0], 30);
            i_beta = FX_SAT(ang.i_fund[1], 30);
        }
#endif
    }

    /* The one table sine/cosine of the period, unless the source formed it
     * at th (the sensorless observer: the same values, not formed twice). */
    q24_t s;
    q24_t c;
    if (fr != NULL) {
        s = fr->sin_theta;
        c = fr->cos_theta;
    } else {
        fx_sincos_inline(th, &s, &c);
    }
    /* The turn over the period. */
    const int32_t dth = fx_u2i(ctrl_angle_step(p, omega));
    int32_t rc;
    int32_t rs;
    fx_rot_q30_inline(dth, &rc, &rs);
    /* stored where formed: fewer values live across the period's arithmetic */
    est->omega_e = omega;
    est->vdc = vdc;
    est->dtheta = dth;
    est->rot_c = rc;
    est->rot_s = rs;
    now->theta_e = th;
    nx->theta_e = th + (fx_angle_t)dth;

    /* k: Park (3.7) (|i| <= 64 pu: no saturation), current model (3.9),
     * torque (3.10). */
    const q24_t i_d = fx_dot_nosat(c, s, i_alpha, i_beta);
    const q24_t i_q = fx_cross_nosat(c, s, i_alpha, i_beta);
    const q24_t psi_d = fx_add(fx_mul(p->ld, i_d), p->psi_pm);
    const q24_t psi_q = fx_mul(p->lq, i_q);
    now->i_d = i_d;
    now->i_q = i_q;
    now->psi_d = psi_d;
    now->psi_q = psi_q;
    now->torque = fx_cross(psi_d, psi_q, i_d, i_q);
    now->sin_theta = s;
    now->cos_theta = c;
    now->i_alpha = i_alpha;
    now->i_beta = i_beta;

    /* (5.15) in the frame at theta(k): psi' = psi + Ts Vdc u - Ts Rs i, u the
     * duties' voltage per unit of DC link turned into that frame. Ts Vdc <=
     * 64 pu, |u| <= 2/3, Ts Rs <= 1 pu: the products fit without saturation;
     * the sums saturate. */
    q24_t hd = fx_sub(psi_d, fx_mul_nosat(p->ts_rs, i_d));
    q24_t hq = fx_sub(psi_q, fx_mul_nosat(p->ts_rs, i_q));
    if (applied != NULL) {
        /* (4.4) averaged over the period: (2 d_a - d_b - d_c)/3 and
         * (d_b - d_c)/sqrt(3), the duties in [0, 2^24]: exact in 32 bits. */
        const int32_t da = (int32_t)ctrl_plan_dur(applied->duty[0]);
        const int32_t db = (int32_t)ctrl_plan_dur(applied->duty[1]);
        const int32_t dc = (int32_t)ctrl_plan_dur(applied->duty[2]);
        const q24_t ua = fx_round_nosat((int64_t)(2 * da - db - dc) * FX_Q30_1_3, 30u);
        const q24_t ub = fx_round_nosat((int64_t)(db - dc) * FX_Q30_INV_SQRT3, 30u);
        const q24_t ts_vdc = fx_mul_nosat(p->ts, vdc);
        hd = fx_add(hd, fx_mul_nosat(ts_vdc, fx_dot_nosat(c, s, ua, ub)));
        hq = fx_add(hq, fx_mul_nosat(ts_vdc, fx_cross_nosat(c, s, ua, ub)));
        if (e->src->uses_voltage != 0u) {
            in->v_alpha = fx_mul_nosat(vdc, ua);
            in->v_beta = fx_mul_nosat(vdc, ub);
        }
        est->u_alpha = ua;
        est->u_beta = ub;
    } else {
        in->v_alpha = 0;
        in->v_beta = 0;
        est->u_alpha = 0;
        est->u_beta = 0;
    }

    /* k+1: the frame turned by delta = omega Ts, psi(k+1) = psi' e^{-j delta}
     * (6.12); current (3.9) inverted, torque (3.10). psi' is taken within
     * +-64 pu (EST_PSI_LIM; twice the flux the core's range allows at
     * current_max): the turned flux and its stator-frame image stay below
     * 91 pu, no saturation. */
    hd = FX_SAT(hd, 31); /* [-EST_PSI_LIM, EST_PSI_LIM) */
    hq = FX_SAT(hq, 31);
    const q24_t psi1_d = fx_round_nosat((int64_t)hd * rc + (int64_t)hq * rs, 30u);
    const q24_t psi1_q = fx_round_nosat((int64_t)hq * rc - (int64_t)hd * rs, 30u);
    const q24_t i1_d = fx_mul(fx_sub(psi1_d, p->psi_pm), p->inv_ld);
    const q24_t i1_q = fx_mul(psi1_q, p->inv_lq);
    nx->i_d = i1_d;
    nx->i_q = i1_q;
    nx->psi_d = psi1_d;
    nx->psi_q = psi1_q;
    nx->torque = fx_cross(psi1_d, psi1_q, i1_d, i1_q);
    if (e->outputs != 0u) {
        estimator_options(e->outputs, hd, hq, est);
    }
}
