/*
 * Stator-flux observer (flux_observer.h): voltage model with a correction
 * towards the current model, angle of the active flux, PLL speed.
 * The flux is kept in Q48 so that the per-period increments Ts v (a Q24 x
 * Q24 product) add without rounding: no rounding drift accumulates.
 */
#include "flux_observer.h"

#include "angle_source.h"
#include "plan.h"
#include "transforms.h"

/* |flux| kept below 127 pu in Q48 so the Q24 view always fits an int32_t. */
#define FOBS_ACC_MAX ((int64_t)127 * ((int64_t)1 << 48))
/* PLL speed kept within +-127 pu (Q48). */
#define FOBS_OMEGA_MAX FOBS_ACC_MAX

static int64_t fobs_clamp(int64_t x)
{
    /* x in [-127 2^48, 127 2^48) - the usual case - exactly when its high
     * word, floor(x / 2^32), is in [-127 2^16, 127 2^16): one unsigned
     * compare of the high word moved by 127 2^16. */
    const uint32_t hi = (uint32_t)((uint64_t)x >> 32);
    if (hi + (127u << 16) < (254u << 16)) {
        return x;
    }
    return x > FOBS_ACC_MAX ? FOBS_ACC_MAX : (x < -FOBS_ACC_MAX ? -FOBS_ACC_MAX : x);
}

/* The Q24 view of a Q48 accumulator, rounded and saturated. */
static q24_t fobs_q24(int64_t acc)
{
    return fx_round_sat(acc, FX_QBITS);
}

/* The Q24 view of a flux or PLL accumulator: those are kept within
 * +-FOBS_ACC_MAX = +-127 2^48 just before each view (fobs_clamp, the PLL's clamp), so
 * (acc + 2^23) / 2^24 lies within +-(127 2^24 + 1) < 2^31 and the rounding
 * without saturation gives fobs_q24's value. */
static q24_t fobs_q24_clamped(int64_t acc)
{
    return fx_round_nosat(acc, FX_QBITS);
}

/* ctrl_fobs_reset in the frame (theta, s, c) with the current's i_d there. */
static void fobs_reset_at(ctrl_fobs_t *o, const ctrl_params_t *p, fx_angle_t theta, q24_t s,
                          q24_t c, q24_t i_d, q24_t omega, q24_t i_alpha, q24_t i_beta)
{
    /* Current model (3.9) at theta: psi = Lq i + psi_a e^{j theta},
     * psi_a = psi_pm + (Ld - Lq) i_d. */
    const q24_t psi_a = fx_add(p->psi_pm, fx_mul(o->dl, i_d));
    const q24_t ea = fx_mul(psi_a, c);
    const q24_t eb = fx_mul(psi_a, s);
    const q24_t pa = fx_add(fx_mul(p->lq, i_alpha), ea);
    const q24_t pb = fx_add(fx_mul(p->lq, i_beta), eb);
    o->psi_alpha_acc = (int64_t)pa * FX_ONE;
    o->psi_beta_acc = (int64_t)pb * FX_ONE;
    o->psi_alpha = pa;
    o->psi_beta = pb;
    o->eta_alpha = ea;
    o->eta_beta = eb;
    o->i_alpha_prev = i_alpha;
    o->i_beta_prev = i_beta;
    o->theta = theta;
    o->pll_theta = theta;
    o->pll_omega_acc = (int64_t)omega * FX_ONE;
    o->omega = omega;
    o->psi_pm_acc = (int64_t)p->psi_pm * FX_ONE;
    o->primed = 1u;
}

void ctrl_fobs_reset(ctrl_fobs_t *o, const ctrl_params_t *p, fx_angle_t theta, q24_t omega,
                     q24_t i_alpha, q24_t i_beta)
{
    q24_t s;
    q24_t c;
    fx_sincos(theta, &s, &c);
    fobs_reset_at(o, p, theta, s, c, fx_dot(c, s, i_alpha, i_beta), omega, i_alpha, i_beta);
}

void ctrl_fobs_reset_frame(ctrl_fobs_t *o, const ctrl_params_t *p, const ctrl_mstate_t *n,
                           q24_t omega)
{
    fobs_reset_at(o, p, n->theta_e, n->sin_theta, n->cos_theta, n->i_d, omega, n->i_alpha,
                  n->i_beta);
}

/* i / band clamped to [-1, 1], Q24. */
static q24_t fobs_soft_sign(const ctrl_fobs_t *o, q24_t i)
{
    return fx_clamp(fx_round_sat((int64_t)i * o->inv_band, CTRL_FOBS_BAND_SHIFT), -FX_ONE, FX_ONE);
}

/* Duty the leg really applies. After each edge both switches are off for t_d
 * and the current picks the diode: with i > 0 (out of the leg) the lower one,
 * so a low-to-high edge comes t_d late; with i < 0 the upper one, so a
 * high-to-low edge does. Centre-aligned legs are low at the period's ends
 * unless d = 1: an edge at the period start when the leg goes from d = 1 to
 * d < 1 or back (the dead time then falls in this period), and one rising and
 * one falling edge inside the period when 0 < d < 1 (a pulse shorter than t_d
 * is lost or stretched by at most its length or the gap). s is the soft sign
 * of the current, d_prev the duty of the period before. */
static q24_t fobs_duty_eff(q24_t d_prev, q24_t d, q24_t s, q24_t td)
{
    const int high_prev = d_prev >= FX_ONE;
    const int high = d >= FX_ONE;
    const int inside = d > 0 && !high;
    q24_t late_rise = 0; /* high time lost by rising edges when i > 0 */
    q24_t late_fall = 0; /* high time gained by falling edges when i < 0 */
    if (high && !high_prev) {
        late_rise = td;
    } else if (!high && high_prev) {
        late_fall = td;
    }
    if (inside) {
        late_rise = fx_add(late_rise, fx_min(td, d));
        late_fall = fx_add(late_fall, fx_min(td, fx_sub(FX_ONE, d)));
    }
    if (s > 0) {
        return fx_sub(d, fx_mul(s, late_rise));
    }
    return fx_add(d, fx_mul(fx_neg(s), late_fall));
}

void ctrl_fobs_voltage(ctrl_fobs_t *o, const ctrl_legs_t *legs, q24_t vdc, q24_t i_a, q24_t i_b,
                       q24_t *v_alpha, q24_t *v_beta)
{
    const ctrl_legs_t prev = o->legs_prev;
    o->legs_prev = *legs;
    if (o->dt_frac == 0 && o->v_fwd == 0) {
        ctrl_legs_voltage(legs, vdc, v_alpha, v_beta);
        return;
    }
    const q24_t i_c = fx_neg(fx_add(i_a, i_b));
    const q24_t sa = fobs_soft_sign(o, i_a);
    const q24_t sb = fobs_soft_sign(o, i_b);
    const q24_t sc = fobs_soft_sign(o, i_c);
    ctrl_legs_t eff;
    eff.duty[0] = fobs_duty_eff(prev.duty[0], legs->duty[0], sa, o->dt_frac);
    eff.duty[1] = fobs_duty_eff(prev.duty[1], legs->duty[1], sb, o->dt_frac);
    eff.duty[2] = fobs_duty_eff(prev.duty[2], legs->duty[2], sc, o->dt_frac);
    q24_t va;
    q24_t vb;
    ctrl_legs_voltage(&eff, vdc, &va, &vb);
    if (o->v_fwd != 0) {
        /* Leg voltage - v_fwd sign(i), through Clarke (3.3):
         * alpha = (2 a - b - c) / 3, beta = (b - c) / sqrt(3). */
        /* soft signs in [-1, 1]: |2 sa - sb - sc| <= 2^26, the products
         * below 2^56 and the results below 2^25, no saturation */
        const q24_t fa = fx_round_nosat((int64_t)(2 * sa - sb - sc) * FX_Q30_1_3, 30u);
        const q24_t fb = fx_round_nosat((int64_t)(sb - sc) * FX_Q30_INV_SQRT3, 30u);
        va = fx_sub(va, fx_mul(o->v_fwd, fa));
        vb = fx_sub(vb, fx_mul(o->v_fwd, fb));
    }
    *v_alpha = va;
    *v_beta = vb;
}

/* One axis of the voltage model: acc + Ts v - Ts Rs (i_prev + i) / 2, Q48
 * (S1(37)-(38): the resistive drop at the average of the two samples). */
static int64_t fobs_axis(const ctrl_params_t *p, int64_t acc, q24_t v, q24_t i_prev, q24_t i)
{
    /* Ts Rs (i_prev + i) as two products summed (SMULL, SMLAL): 0 <= ts_rs <
     * 2^31 and |i| <= 2^31, each below 2^62 in magnitude, the sum below 2^63 */
    const int64_t rs_sum = (int64_t)p->ts_rs * i_prev + (int64_t)p->ts_rs * i;
    const int64_t inc = (int64_t)p->ts * v - fx_rshift64_round(rs_sum, 1u);
    return fobs_clamp(acc + inc);
}

fx_angle_t ctrl_fobs_integrate(ctrl_fobs_t *o, const ctrl_params_t *p, q24_t v_alpha, q24_t v_beta,
                               q24_t i_alpha, q24_t i_beta)
{
    if (o->primed == 0u) {
        o->i_alpha_prev = i_alpha;
        o->i_beta_prev = i_beta;
        return o->theta;
    }
    o->psi_alpha_acc = fobs_axis(p, o->psi_alpha_acc, v_alpha, o->i_alpha_prev, i_alpha);
    o->psi_beta_acc = fobs_axis(p, o->psi_beta_acc, v_beta, o->i_beta_prev, i_beta);
    o->i_alpha_prev = i_alpha;
    o->i_beta_prev = i_beta;
    o->psi_alpha = fobs_q24_clamped(o->psi_alpha_acc);
    o->psi_beta = fobs_q24_clamped(o->psi_beta_acc);
    /* Active flux psi - Lq i: on the d axis whatever the saliency. */
    o->eta_alpha = fx_sub(o->psi_alpha, fx_mul(p->lq, i_alpha));
    o->eta_beta = fx_sub(o->psi_beta, fx_mul(p->lq, i_beta));
    o->theta = fx_atan2(o->eta_beta, o->eta_alpha);
    return o->theta;
}

/* Type-2 PLL on the reference angle: e = theta_r - theta_pll (wrapped),
 * omega_i += ki e, theta_pll += omega_i Ts + kp e. The speed is the PLL's
 * frequency omega_i + kp e / Ts, the rate theta_pll turns at: no lag for a
 * constant acceleration (the integrator alone would lag by 2 a / w_n). */
static void fobs_pll(ctrl_fobs_t *o, const ctrl_params_t *p, fx_angle_t theta_r)
{
    const int32_t e = fx_u2i(theta_r - o->pll_theta);
    const int64_t w = o->pll_omega_acc + (int64_t)e * o->pll_ki; /* |.| < 2^55 + 2^62 */
    o->pll_omega_acc =
        w > FOBS_OMEGA_MAX ? FOBS_OMEGA_MAX : (w < -FOBS_OMEGA_MAX ? -FOBS_OMEGA_MAX : w);
    const q24_t omega_i = fobs_q24_clamped(o->pll_omega_acc);
    /* kp e: |e| <= 2^31, 0 <= kp < 2^23 (2 w_n Ts <= 0.5): |kp e| < 2^30. */
    const int32_t kpe = fx_round_sat((int64_t)e * o->pll_kp, FX_QBITS);
    o->omega = fx_add(omega_i, fx_round_sat((int64_t)kpe * p->dangle_to_omega, CTRL_DANGLE_SHIFT));
    o->pll_theta += ctrl_angle_step(p, omega_i) + (fx_angle_t)(uint32_t)kpe;
}

/* The flux (*a, *b: alpha, beta, Q48) moved by the correction (corr_d,
 * corr_q) of the frame (s, c): inverse Park (3.7) inline, the same rounded and
 * saturated sums as ctrl_inv_park (alpha = c d - s q, beta = s d + c q), then
 * the clamp. One copy for the sensorless observer's correction and the
 * encoder mode's pull. */
static void fobs_move(int64_t *a, int64_t *b, q24_t corr_d, q24_t corr_q, q24_t s, q24_t c)
{
    const q24_t ca = fx_cross(c, s, corr_q, corr_d);
    const q24_t cb = fx_dot(s, c, corr_d, corr_q);
    *a = fobs_clamp(*a + (int64_t)ca * FX_ONE);
    *b = fobs_clamp(*b + (int64_t)cb * FX_ONE);
}

q24_t ctrl_fobs_pull_delta(const ctrl_fobs_t *o, const ctrl_params_t *p, const int64_t acc[2],
                           q24_t s, q24_t c, q24_t i_d, q24_t i_q, int64_t delta[2])
{
    /* The flux at k in the measured frame (Park (3.7)), towards the current
     * model (3.9) there. */
    const q24_t psi_d = fx_dot(c, s, o->psi_alpha, o->psi_beta);
    const q24_t psi_q = fx_cross(c, s, o->psi_alpha, o->psi_beta);
    const q24_t ld_id = fx_mul(p->ld, i_d);
    const q24_t e_d = fx_sub(fx_add(ld_id, p->psi_pm), psi_d);
    const q24_t e_q = fx_sub(fx_mul(p->lq, i_q), psi_q);
    int64_t a = acc[0];
    int64_t b = acc[1];
    fobs_move(&a, &b, fx_mul(o->kenc_ts, e_d), fx_mul(o->kenc_ts, e_q), s, c);
    delta[0] = a - acc[0]; /* |acc| < 2^62 (psi_track.h), |a| <= 127 2^48: no overflow */
    delta[1] = b - acc[1];
    return fx_sub(psi_d, ld_id);
}

void ctrl_fobs_psi_pm_step(ctrl_fobs_t *o, q24_t pm, q24_t k)
{
    const q24_t out = fobs_q24(o->psi_pm_acc);
    o->psi_pm_acc += (int64_t)fx_sub(pm, out) * k; /* an EMA of Q24 values */
}

void ctrl_fobs_correct(ctrl_fobs_t *o, const ctrl_params_t *p, fx_angle_t theta_r, q24_t s, q24_t c,
                       q24_t i_d, q24_t i_q)
{
    if (o->primed == 0u) {
        return;
    }
    q24_t pm; /* PM flux psi_d - Ld i_d of the flux at k */
    if (o->mode == CTRL_FOBS_ENCODER) {
        /* towards the current model at the measured angle */
        const int64_t acc[2] = {o->psi_alpha_acc, o->psi_beta_acc};
        int64_t delta[2];
        pm = ctrl_fobs_pull_delta(o, p, acc, s, c, i_d, i_q, delta);
        o->psi_alpha_acc = acc[0] + delta[0];
        o->psi_beta_acc = acc[1] + delta[1];
    } else {
        /* Magnitude of the active flux towards psi_a, along (psi_a, -(Ld - Lq) i_q). */
        const q24_t eta_d = fx_dot(c, s, o->eta_alpha, o->eta_beta);
        const q24_t psi_a = fx_add(p->psi_pm, fx_mul(o->dl, i_d));
        const q24_t w = fx_abs(o->omega);
        const q24_t kts = fx_min(fx_add(o->k0_ts, fx_mul(o->kappa_ts, w)), CTRL_FOBS_KTS_MAX);
        const q24_t g = fx_mul(fx_mul(kts, fx_sub(psi_a, eta_d)), p->inv_psi_pm);
        fobs_move(&o->psi_alpha_acc, &o->psi_beta_acc, fx_mul(g, psi_a),
                  fx_neg(fx_mul(g, fx_mul(o->dl, i_q))), s, c);
        pm = 0;
        if (o->psi_k != 0) {
            /* formed only for the PM-flux estimate that reads it */
            const q24_t psi_d = fx_dot(c, s, o->psi_alpha, o->psi_beta);
            pm = fx_sub(psi_d, fx_mul(p->ld, i_d));
        }
    }

    fobs_pll(o, p, theta_r);

    /* PM flux where the voltage model is reliable. */
    if (o->psi_k != 0 && fx_abs(o->omega) >= o->psi_speed_min) {
        ctrl_fobs_psi_pm_step(o, pm, o->psi_k);
    }
}

fx_angle_t ctrl_fobs_update(ctrl_fobs_t *o, const ctrl_params_t *p, q24_t v_alpha, q24_t v_beta,
                            q24_t i_alpha, q24_t i_beta, fx_angle_t theta_enc)
{
    const fx_angle_t th = ctrl_fobs_integrate(o, p, v_alpha, v_beta, i_alpha, i_beta);
    const fx_angle_t th_r = o->mode == CTRL_FOBS_ENCODER ? theta_enc : th;
    q24_t s;
    q24_t c;
    fx_sincos_inline(th_r, &s, &c); /* fx_sincos without the call */
    /* Park (3.7) inline, the same rounded and saturated sums as ctrl_park. */
    const q24_t i_d = fx_dot(c, s, i_alpha, i_beta);
    const q24_t i_q = fx_cross(c, s, i_alpha, i_beta);
    o->frame.sin_theta = s;
    o->frame.cos_theta = c;
    ctrl_fobs_correct(o, p, th_r, s, c, i_d, i_q);
    return th;
}

q24_t ctrl_fobs_omega(const ctrl_fobs_t *o)
{
    return o->omega;
}

fx_angle_t ctrl_fobs_pll_angle(const ctrl_fobs_t *o)
{
    return o->pll_theta;
}

q24_t ctrl_fobs_psi_pm(const ctrl_fobs_t *o)
{
    return fobs_q24(o->psi_pm_acc);
}
