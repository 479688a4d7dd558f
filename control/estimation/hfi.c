/* High-frequency injection: square wave on the estimated d axis,
 * demodulation, tracking and the polarity pulses (hfi.h). */
#include "hfi.h"

#include "angle_source.h"

/* PLL speed kept within +-127 pu (Q48), as the flux observer's. */
#define HFI_OMEGA_MAX ((int64_t)127 * ((int64_t)1 << 48))

void ctrl_hfi_start(ctrl_hfi_t *h, fx_angle_t theta, q24_t omega, q24_t torque, q24_t i_alpha,
                    q24_t i_beta)
{
    h->on = 1u;
    h->stopping = 0u;
    h->pos[0] = h->pos[1] = 0;
    h->amp[0] = h->amp[1] = 0;
    h->clip[0] = h->clip[1] = 0u;
    h->cs[0][0] = h->cs[1][0] = FX_ONE;
    h->cs[0][1] = h->cs[1][1] = 0;
    h->dq_ok = 0u;
    h->i_prev_a = i_alpha;
    h->i_prev_b = i_beta;
    h->dq_prev_d = h->dq_prev_q = 0;
    h->hm_d = h->h0;
    h->hm_q = 0;
    h->vt_prev = 0;
    h->rq_prev = 0;
    h->r_ok = 0u;
    h->ua_act[0] = h->ua_act[1] = 0;
    h->ub_act[0] = h->ub_act[1] = 0;
    h->w_sq = FX_ONE;
    h->theta = theta;
    h->omega_acc = (int64_t)omega * FX_ONE;
    h->load_acc = (int64_t)h->k_acc * torque; /* steady: the torque holds the load */
    h->omega = omega;
    h->err = 0;
    h->u_alpha = h->u_beta = 0;
}

void ctrl_hfi_stop(ctrl_hfi_t *h)
{
    if (h->on != 0u) {
        h->stopping = 1u;
    }
}

void ctrl_hfi_halt(ctrl_hfi_t *h)
{
    h->on = 0u;
    h->stopping = 0u;
    h->pos[0] = h->pos[1] = 0;
    h->amp[0] = h->amp[1] = 0;
    h->clip[0] = h->clip[1] = 0u;
    h->u_alpha = h->u_beta = 0;
    h->err = 0;
}

/* The tracking observer (hfi.h) one period on, with the angle error e
 * (fx_angle_t units, rotor minus tracked) and the torque estimate (Q24 pu):
 * speed += k_acc T^ - load + l2 e, load -= l3 e, angle += speed Ts + l1 e. */
static void hfi_track(ctrl_hfi_t *h, const ctrl_params_t *p, int32_t e, q24_t torque)
{
    /* |load| kept within the speed's range: |l3 e| < 2^22 2^29 */
    int64_t ld = h->load_acc - fx_rshift64_round((int64_t)e * h->l3, 16u);
    ld = ld > HFI_OMEGA_MAX ? HFI_OMEGA_MAX : (ld < -HFI_OMEGA_MAX ? -HFI_OMEGA_MAX : ld);
    h->load_acc = ld;
    /* |k_acc T| < 2^62, |l2 e| < 2^62, the speed and the load within 127 2^48:
     * the sum of the four stays below 2^63 */
    const int64_t w = h->omega_acc + (int64_t)h->k_acc * torque + (int64_t)e * h->l2 - ld;
    h->omega_acc = w > HFI_OMEGA_MAX ? HFI_OMEGA_MAX : (w < -HFI_OMEGA_MAX ? -HFI_OMEGA_MAX : w);
    /* |omega_acc| <= 127 2^48: the rounded Q24 value fits without saturation */
    h->omega = fx_round_nosat(h->omega_acc, FX_QBITS);
    /* |e| <= err_max = 2^29, 0 <= l1 < 2^23: |l1 e| < 2^52 */
    const int32_t l1e = fx_round_sat((int64_t)e * h->l1, FX_QBITS);
    h->theta += ctrl_angle_step(p, h->omega) + (fx_angle_t)(uint32_t)l1e;
}

void ctrl_hfi_update(ctrl_hfi_t *h, const ctrl_params_t *p, q24_t v_alpha, q24_t v_beta,
                     q24_t i_alpha, q24_t i_beta, q24_t torque, q24_t *if_alpha, q24_t *if_beta)
{
    /* The change since k-1 in the frame of the injection that caused it
     * (decided at k-2; |di| <= 2^32 would overflow only for currents beyond
     * the estimator's 32 pu range, which the caller clamps). */
    const q24_t di_a = fx_sub(i_alpha, h->i_prev_a);
    const q24_t di_b = fx_sub(i_beta, h->i_prev_b);
    h->i_prev_a = i_alpha;
    h->i_prev_b = i_beta;
    const q24_t c2 = h->cs[1][0];
    const q24_t s2 = h->cs[1][1];
    /* less the change the controller's voltage of the period makes, Ts L^-1 v
     * at the tracked angle (Park (3.7) of both): what is left of it is the
     * model's error times the voltage's change from one period to the next
     * (a modulated controller's voltage jumps from period to period; only
     * its slow part would cancel in the difference below) */
    const q24_t vd = fx_dot(c2, s2, v_alpha, v_beta);
    const q24_t vq = fx_cross(c2, s2, v_alpha, v_beta);
    const q24_t dq_d = fx_sub(fx_dot(c2, s2, di_a, di_b), fx_mul(h->ts_inv_ld, vd));
    const q24_t dq_q = fx_sub(fx_cross(c2, s2, di_a, di_b), fx_mul(h->ts_inv_lq, vq));
    /* The injection the legs applied in that period (ctrl_hfi_add_to_legs),
     * in its frame, at the nominal DC link (pu); the change the model gives
     * it along q taken out too (0 unless a clamp turned it). */
    const q24_t ja = fx_mul(h->ua_act[1], h->v_nom);
    const q24_t jb = fx_mul(h->ub_act[1], h->v_nom);
    const q24_t inj_d = fx_dot(c2, s2, ja, jb);
    const q24_t inj_q = fx_cross(c2, s2, ja, jb);
    const q24_t r_q = fx_sub(dq_q, fx_mul(h->ts_inv_lq, inj_q));
    const q24_t vt_d = fx_add(vd, inj_d);
    const int8_t amp2 = h->amp[1];
    const uint8_t full = (amp2 == 2 || amp2 == -2) && h->clip[1] == 0u ? 1u : 0u;
    h->err = 0;
    if (h->r_ok != 0u) {
        /* The excitation along the tracked axis: the d voltage's change over
         * the two periods (the injection's 2 V sgn, what a clamp left of it,
         * and the controller's), in units of 2 V: w = sgn with the
         * injection alone; within +-8. Off by e, the model leaves
         * -2 Ts D e times that change on q: weighted by w and normalised by
         * the mean of w^2 (at least 1), a controller whose voltage alternates
         * with the injection adds to the information instead of cancelling
         * it (against the injection, w -> 0: none). */
        const q24_t w_lim = 8 * FX_ONE;
        const q24_t w = fx_clamp(fx_mul(fx_sub(vt_d, h->vt_prev), h->inv_2vh), -w_lim, w_lim);
        h->w_sq = fx_add(h->w_sq, fx_mul(h->h_k, fx_sub(fx_mul(w, w), h->w_sq)));
        const q24_t yw = fx_div(fx_rshift32_round(fx_mul(fx_sub(r_q, h->rq_prev), w), 1u),
                                fx_max(h->w_sq, FX_ONE));
        /* angle error (rotor minus tracked) = y_q / (2 Ts V D) for small errors */
        const int32_t e = fx_round_sat((int64_t)yw * h->k_err, h->k_err_shift);
        h->err = fx_clamp(e, -h->err_max, h->err_max);
    }
    if (full != 0u && h->dq_ok != 0u) {
        /* the ripple model: y = sgn (dq(k) - dq(k-1)) / 2 = h, the step of
         * one full pulse */
        q24_t y_d = fx_rshift32_round(fx_sub(dq_d, h->dq_prev_d), 1u);
        q24_t y_q = fx_rshift32_round(fx_sub(dq_q, h->dq_prev_q), 1u);
        if (amp2 < 0) {
            y_d = fx_neg(y_d);
            y_q = fx_neg(y_q);
        }
        h->hm_d = fx_add(h->hm_d, fx_mul(h->h_k, fx_sub(y_d, h->hm_d)));
        h->hm_q = fx_add(h->hm_q, fx_mul(h->h_k, fx_sub(y_q, h->hm_q)));
    }
    h->dq_prev_d = dq_d;
    h->dq_prev_q = dq_q;
    h->dq_ok = full;
    h->rq_prev = r_q;
    h->vt_prev = vt_d;
    h->r_ok = 1u;
    hfi_track(h, p, h->err, torque);

    /* The fundamental: the ripple's sample pos(k-2) hm / 2 (injection frame
     * of k-2) removed. */
    q24_t ia = i_alpha;
    q24_t ib = i_beta;
    const int8_t side = h->pos[1];
    if (side != 0) {
        const q24_t rd = fx_rshift32_round(h->hm_d, 1u);
        const q24_t rq = fx_rshift32_round(h->hm_q, 1u);
        /* inverse Park of (rd, rq) */
        const q24_t ra = fx_cross(c2, s2, rq, rd);
        const q24_t rb = fx_dot(s2, c2, rd, rq);
        if (side > 0) {
            ia = fx_sub(ia, ra);
            ib = fx_sub(ib, rb);
        } else {
            ia = fx_add(ia, ra);
            ib = fx_add(ib, rb);
        }
    }
    *if_alpha = ia;
    *if_beta = ib;

    /* The injection for [k+1, k+2): on the tracked axis at the middle of that
     * period (theta + 1.5 omega Ts). */
    int8_t amp = 0;
    int8_t pos = h->pos[0];
    if (h->stopping != 0u) {
        amp = (int8_t)-pos; /* back to the centre: a half pulse (or none) */
        pos = 0;
        h->stopping = 0u;
        h->on = 0u;
    } else if (h->on != 0u) {
        amp = pos == 0 ? 1 : (int8_t)(-2 * pos);
        pos = pos == 0 ? 1 : (int8_t)-pos;
    }
    const int64_t step = fx_u2i(ctrl_angle_step(p, h->omega)); /* within +-pi */
    const fx_angle_t th = h->theta + (fx_angle_t)(uint64_t)(step + step / 2);
    q24_t sn;
    q24_t cn;
    fx_sincos_inline(th, &sn, &cn);
    h->pos[1] = h->pos[0];
    h->amp[1] = h->amp[0];
    h->clip[1] = h->clip[0];
    h->clip[0] = 0u;
    h->ua_act[1] = h->ua_act[0];
    h->ub_act[1] = h->ub_act[0];
    h->cs[1][0] = h->cs[0][0];
    h->cs[1][1] = h->cs[0][1];
    h->pos[0] = pos;
    h->amp[0] = amp;
    h->cs[0][0] = cn;
    h->cs[0][1] = sn;
    /* u = amp/2 u_h (cos, sin): |u_h| <= 1/2, no saturation */
    const q24_t a = fx_rshift32_round(h->u_h * amp, 1u);
    h->u_alpha = fx_mul(a, cn);
    h->u_beta = fx_mul(a, sn);
    h->ua_act[0] = h->u_alpha; /* until ctrl_hfi_add_to_legs says what the legs apply */
    h->ub_act[0] = h->u_beta;
}

uint8_t ctrl_hfi_add_to_legs(ctrl_hfi_t *h, q24_t duty[3], q24_t dmax)
{
    if (h->amp[0] == 0) {
        return 0u;
    }
    /* per leg: a = u_alpha, b = -u_alpha/2 + sqrt3/2 u_beta, c = -u_alpha/2 - sqrt3/2 u_beta
     * (|u| <= 1/2: the products fit) */
    const q24_t half_a = fx_rshift32_round(h->u_alpha, 1u);
    const q24_t s3b = fx_round_nosat((int64_t)h->u_beta * FX_Q30_SQRT3_2, 30u);
    const q24_t d[3] = {fx_add(duty[0], h->u_alpha), fx_add(duty[1], fx_sub(s3b, half_a)),
                        fx_sub(duty[2], fx_add(s3b, half_a))};
    const q24_t hi = fx_max(d[0], fx_max(d[1], d[2]));
    const q24_t lo = fx_min(d[0], fx_min(d[1], d[2]));
    /* the common mode moved so that the three fit [0, dmax], where their spread allows */
    q24_t shift = 0;
    if (hi > dmax) {
        shift = fx_sub(dmax, hi);
    } else if (lo < 0) {
        shift = fx_neg(lo);
    }
    uint8_t clipped = 0u;
    int32_t delta[3];
    for (int x = 0; x < 3; x++) {
        const q24_t v = fx_add(d[x], shift);
        const q24_t c = fx_clamp(v, 0, dmax);
        clipped |= (uint8_t)(c != v);
        delta[x] = c - duty[x]; /* both in [0, 2^24]: exact */
        duty[x] = c;
    }
    /* what the legs apply of it, (4.4) of the change: the demodulation's
     * excitation (in full, or what a clamp left) */
    h->ua_act[0] = fx_round_nosat((int64_t)(2 * delta[0] - delta[1] - delta[2]) * FX_Q30_1_3, 30u);
    h->ub_act[0] = fx_round_nosat((int64_t)(delta[1] - delta[2]) * FX_Q30_INV_SQRT3, 30u);
    h->clip[0] = clipped;
    return clipped;
}

/* ---- polarity: d-axis saturation pulses ---- */

void ctrl_hfi_pol_start(ctrl_hfi_t *h, fx_angle_t theta)
{
    h->pol_n = 0u;
    h->pol_theta = theta;
    h->pol_acc[0] = h->pol_acc[1] = 0;
    h->pol_result = CTRL_HFI_POL_RUNNING;
    h->pol_asym = 0;
    h->pol_i_last = 0;
}

uint32_t ctrl_hfi_pol_periods(const ctrl_hfi_t *h)
{
    return 4u * (uint32_t)h->n_pol * h->pol_rounds + 2u;
}

uint8_t ctrl_hfi_pol_step(ctrl_hfi_t *h, q24_t i_alpha, q24_t i_beta, q24_t *v_alpha, q24_t *v_beta)
{
    q24_t s;
    q24_t c;
    fx_sincos(h->pol_theta, &s, &c);
    const uint32_t n = h->n_pol;
    const uint32_t j = h->pol_n;
    const uint32_t total = 4u * n * h->pol_rounds;
    /* Decision j acts in [j+1, j+2) and shows in the current at j+2: the
     * quarters' ends are the samples 1 + m n. */
    if (j >= 1u && (j - 1u) % n == 0u) {
        const q24_t id = fx_dot(c, s, i_alpha, i_beta);
        const uint32_t m = (j - 1u) / n; /* quarters completed */
        if (m > 0u) {
            const q24_t prev = h->pol_i_last;
            const uint32_t q = (m - 1u) & 3u; /* the quarter that just ended */
            if (q == 0u) {
                h->pol_acc[0] += fx_sub(id, prev); /* 0 -> +I */
            } else if (q == 2u) {
                h->pol_acc[1] += fx_sub(prev, id); /* 0 -> -I */
            }
        }
        h->pol_i_last = id;
    }
    h->pol_n = (uint16_t)(j + 1u);
    q24_t v = 0;
    if (j < total) {
        const uint32_t q = (j / n) & 3u; /* +, -, -, + */
        v = (q == 0u || q == 3u) ? h->v_pol : fx_neg(h->v_pol);
    }
    *v_alpha = fx_mul(v, c);
    *v_beta = fx_mul(v, s);
    if (j < total + 1u) {
        return 1u;
    }
    /* a = (I+ - I-) / (I+ + I-), in Q24 (both sums positive for any sane
     * machine; a non-positive sum leaves the polarity unknown) */
    const int64_t sp = h->pol_acc[0];
    const int64_t sm = h->pol_acc[1];
    const int64_t den = sp + sm;
    q24_t a = 0;
    if (sp > 0 && sm > 0) {
        /* |sp - sm| < den: the quotient is within (-1, 1) */
        const int64_t num = (sp - sm) * (int64_t)FX_ONE;
        a = (q24_t)(num / den);
    }
    h->pol_asym = a;
    if (sp <= 0 || sm <= 0 || fx_abs(a) < h->pol_min) {
        h->pol_result = CTRL_HFI_POL_NONE;
    } else {
        h->pol_result = a > 0 ? CTRL_HFI_POL_NORTH : CTRL_HFI_POL_SOUTH;
    }
    *v_alpha = 0;
    *v_beta = 0;
    return 0u;
}
