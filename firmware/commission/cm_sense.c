/*
 * Step "sense" (bring-up): current-sense polarity and gain, one short
 * voltage pulse per phase, compared with what Rs and L predict.
 *
 * Method: for phase x = a, b, c in turn, from rest and zero current, a
 * voltage V_p along the phase's axis (theta_x = 0, 120, 240 deg) for m_p
 * periods, then -V_p for m_p (back to zero current), then a rest. For a
 * short pulse the RL model of the winding predicts the current change along
 * the axis
 *     dI = S Ts / L (1 - m_p Ts Rs / (2 L)),   S = sum of the applied volts
 * with L between Ld and Lq (the rotor's angle is unknown here), so the
 * measured dI_x must lie in [sense_lo dI(Lmax), sense_hi dI(Lmin)]; the
 * other two phases must carry the return current (each negative; for a
 * round rotor -dI_x / 2). L and Rs are the identified ones when they exist,
 * else the configured ones. Verdicts:
 *   - dI_x <= 0, or another phase's change positive: sense_polarity (phase,
 *     measured, predicted);
 *   - dI_x outside the band: sense_gain (phase, measured/predicted Q24);
 *   - with a third channel, the three changes not summing to zero within
 *     15 % of dI_x: sense_sum.
 * Pass: the three measured/predicted ratios (detail[0..2], Q24).
 */
#include "cm_internal.h"

/* Scratch: a[0] V_p, k[0] m_p, k[1] phase index 0..2, a[1..3] currents at
 * the pulse start, s[0] applied volt-periods along the axis, a[4] L_min,
 * a[5] L_max. */

static const fx_angle_t cm_axis[3] = {0u, 0x55555555u, 0xAAAAAAABu};

void cm_sense_begin(cm_t *cm)
{
    cm_scratch_t *x = &cm->x;
    const cm_par_t *p = &cm->par;
    q24_t ld = p->l_cfg_d, lq = p->l_cfg_q;
    if ((cm->res.have & CM_HAVE_LDQ) != 0u) {
        ld = cm->res.ld;
        lq = cm->res.lq;
    } else if ((cm->res.have & CM_HAVE_LPROBE) != 0u) {
        ld = lq = cm->res.l_probe;
    }
    x->a[4] = fx_min(ld, lq);
    x->a[5] = fx_max(ld, lq);
    /* m_p periods at V_p so that dI reaches about i_sense with L_min. */
    q24_t vp = p->v_lim - p->v_lim / 5;
    q24_t r = 0;
    int32_t m = 64; /* a very large inductance: the longest pulse */
    if (cm_ratio(fx_mul(p->i_sense, x->a[4]), fx_mul(vp, p->ts), &r)) {
        m = r / FX_ONE;
    }
    if (m < 1) {
        m = 1;
        (void)cm_muldiv(p->i_sense, x->a[4], p->ts, &vp);
    }
    x->a[0] = vp;
    x->k[0] = m > 64 ? 64 : m;
}

int cm_sense_period(cm_t *cm, const cm_in_t *in, cm_out_t *out)
{
    cm_scratch_t *x = &cm->x;
    const cm_par_t *p = &cm->par;
    const int32_t m = x->k[0];
    const uint32_t ph = cm->phase;
    if (ph >= 3u) {
        cm_out_off(cm, out);
        return CM_DONE;
    }
    cm->progress = (uint16_t)(ph * 333u);
    const fx_angle_t ax = cm_axis[ph];
    const int32_t t = (int32_t)cm->t;
    const q24_t i_c = p->has_i_c ? in->i_c : fx_neg(fx_add(in->i_a, in->i_b));
    const q24_t ix[3] = {in->i_a, in->i_b, i_c};
    if (t == 0) {
        x->a[1] = ix[0];
        x->a[2] = ix[1];
        x->a[3] = ix[2];
        x->s[0] = 0;
    }
    q24_t vd, vq;
    if (t >= 2 && t < m + 2 && cm_acted(cm, ax, &vd, &vq)) {
        x->s[0] += vd;
    }
    if (t == m + 1) {
        /* The +V_p part has fully acted: compare with the RL prediction. */
        q24_t d[3];
        d[0] = fx_sub(ix[0], x->a[1]);
        d[1] = fx_sub(ix[1], x->a[2]);
        d[2] = fx_sub(ix[2], x->a[3]);
        const q24_t own = d[ph];
        const q24_t sv = fx_sat32(x->s[0]);
        q24_t rs = (cm->res.have & CM_HAVE_RS) != 0u ? cm->res.rs : p->rs_cfg;
        /* dI(L) = S Ts / L (1 - m Ts Rs / (2 L)) */
        q24_t hi = 0, lo = 0, mid = 0;
        const q24_t lmid = (q24_t)(((int64_t)x->a[4] + x->a[5]) / 2);
        const q24_t svt = fx_mul(sv, p->ts);
        q24_t c = 0;
        (void)cm_ratio(fx_mul(m * p->ts, rs), 2 * (int64_t)x->a[4], &c);
        (void)cm_ratio(fx_mul(svt, fx_sub(FX_ONE, c)), x->a[4], &hi);
        (void)cm_ratio(fx_mul(svt, fx_sub(FX_ONE, c / 2)), x->a[5], &lo);
        (void)cm_ratio(fx_mul(svt, fx_sub(FX_ONE, c / 2)), lmid, &mid);
        q24_t ratio = 0;
        (void)cm_ratio(own, mid, &ratio);
        cm->detail[ph] = ratio;
        if (own <= 0) {
            return cm_fail(cm, CM_E_SENSE_POLARITY, (int32_t)ph, own, mid);
        }
        for (uint32_t k = 0; k < 3u; k++) {
            if (k != ph && d[k] > fx_neg(own / 10)) {
                return cm_fail(cm, CM_E_SENSE_POLARITY, (int32_t)k, d[k], fx_neg(mid / 2));
            }
        }
        if (own < fx_mul(p->sense_lo, lo) || own > fx_mul(p->sense_hi, hi)) {
            return cm_fail(cm, CM_E_SENSE_GAIN, (int32_t)ph, ratio, own);
        }
        if (p->has_i_c) {
            const q24_t sum = fx_abs(fx_add(fx_add(d[0], d[1]), d[2]));
            if (sum > own / 7 + 4 * p->i_lsb) {
                return cm_fail(cm, CM_E_SENSE_SUM, sum, own, (int32_t)ph);
            }
        }
    }
    q24_t v = 0;
    if (t < m) {
        v = x->a[0];
    } else if (t < 2 * m) {
        v = fx_neg(x->a[0]);
    }
    q24_t al, be;
    cm_from_frame(v, 0, ax, &al, &be);
    cm_modulate(cm, al, be, out);
    if (t + 1 >= 6 * m + 16) {
        cm_next(cm);
    }
    return CM_RUN;
}
