/*
 * Step "cogging": the anti-cogging table from a slow sweep both ways under a
 * stiff position loop (method, formats and errors in cm_cogging.h).
 * cm_cogging_configure runs once at configuration (double); the step's
 * period is integer-only.
 */
#include "cm_cogging.h"

#include <math.h>
#include <stddef.h>

#include "cm_internal.h"

#if CTRL_COGGING

#define CM_COG_TWO_PI 6.283185307179586

/* ---- configuration (main loop) ---- */

/* k >= 0 as round(k 2^s) with the mantissa in [2^29, 2^30) where s <= 62
 * allows it; false when k is not finite, negative or too large. */
static bool cm_cog_gain(double k, cm_cog_gain_t *g)
{
    if (!(k >= 0.0) || !(k < 1.0e9)) {
        return false;
    }
    int s = 0;
    double m = k;
    while (m < 536870912.0 && s < 62) {
        m *= 2.0;
        s++;
    }
    if (s < 1) {
        return false; /* k >= 2^29: no format here needs it */
    }
    g->m = (int32_t)llround(m);
    g->s = (uint8_t)s;
    return true;
}

int cm_cogging_configure(cm_cog_t *c, const cm_cog_config_t *cfg, const ctrl_machine_t *m,
                         const ctrl_params_t *p, const ctrl_bases_t *b, uint32_t fs_hz,
                         uint32_t cpr)
{
    if (c == NULL || cfg == NULL || m == NULL || p == NULL || b == NULL || fs_hz == 0u) {
        return -1;
    }
    c->ok = 0u;
    if (ctrl_cogging_init(&c->map, c->table, CTRL_COG_N_LOG2, cpr, p->torque_rated) != 0) {
        return -1;
    }
    const double rpm = cfg->rpm > 0.0 ? cfg->rpm : CM_COG_RPM_DEFAULT;
    const double bw = cfg->bw_hz > 0.0 ? cfg->bw_hz : CM_COG_BW_DEFAULT;
    const double fs = (double)fs_hz;
    const double j = m->inertia_kgm2;
    if (!(j > 0.0) || !(rpm < 600.0) || !(bw < fs / 20.0)) {
        return -1;
    }
    const double w = CM_COG_TWO_PI * bw;
    const double kp = j * w * w;         /* N*m/rad */
    const double kd = 2.0 * 0.8 * j * w; /* N*m s/rad */
    const double ki = kp * w / 8.0;      /* N*m/(rad s) */
    const double rad_per_q16 = CM_COG_TWO_PI / (double)cpr / 65536.0;
    const double tb = b->torque_nm;
    const double w_mech_pu = b->w_rad_s / (double)m->pole_pairs; /* mechanical rad/s of 1 pu */
    if (!cm_cog_gain(kp * rad_per_q16 / tb * 16777216.0, &c->kp) ||
        !cm_cog_gain(kd * w_mech_pu / tb, &c->kd) ||
        !cm_cog_gain(ki / fs * rad_per_q16 / tb * 16777216.0, &c->ki) ||
        !cm_cog_gain(rad_per_q16 * fs / w_mech_pu * 16777216.0, &c->kw)) {
        return -1;
    }
    const double v = rpm / 60.0 * (double)cpr / fs * 65536.0;
    if (!(v >= 1.0) || v > 1.0e9) {
        return -1;
    }
    c->v_q16 = (int32_t)llround(v);
    /* the lag that makes the rated torque through Kp, at least 64 counts */
    const double e_rated = m->torque_rated_nm / kp / (CM_COG_TWO_PI) * (double)cpr;
    /* below 2^14 counts: e m < 2^61 in cm_cog_apply */
    c->e_max = (int64_t)llround(fmin(fmax(e_rated, 64.0), 16384.0) * 65536.0);
    c->t_lim = p->torque_rated;
    c->n_settle = (uint32_t)(0.2 * fs);
    c->n_ramp = (uint32_t)(0.1 * fs) + 1u;
    c->lead = cpr / 16u;
    c->revs = cfg->revs > 0u ? cfg->revs : 1u;
    /* periods of the whole step, for its progress */
    const double sweep = ((double)c->lead + (double)c->revs * (double)cpr) / (v / 65536.0);
    const double total = 2.0 * (c->n_settle + 2.0 * c->n_ramp + sweep +
                                (double)CTRL_COG_N / CM_COG_BINS_PER_PERIOD) +
                         (double)CTRL_COG_N / CM_COG_BINS_PER_PERIOD;
    c->progress_k = (uint64_t)(1000.0 * 4294967296.0 / total);
    c->ok = 1u;
    return 0;
}

/* ---- per period ---- */

static q24_t cm_cog_apply(const cm_cog_gain_t *g, int64_t x)
{
    return fx_round_sat(x * g->m, g->s);
}

/* round(num / den), den > 0, ties away from zero. */
static int64_t cm_cog_div(int64_t num, int64_t den)
{
    return num >= 0 ? (num + den / 2) / den : -((-num + den / 2) / den);
}

void cm_cogging_begin(cm_t *cm)
{
    cm_cog_t *c = cm->cog;
    if (c == NULL) {
        return;
    }
    c->valid = 0u; /* the table is rewritten */
    c->dir = 1;
    c->v = 0;
    c->integ = 0;
    c->pos = 0;
    c->pos_ref = 0;
    c->mark = 0;
    c->fin = 0u;
    c->mean_sum[0] = c->mean_sum[1] = 0;
    cm->detail[0] = cm->detail[1] = cm->detail[2] = 0;
    /* The sums are cleared during the hold (cm_cog_clear), not here: begin
     * runs in the interrupt, and clearing their 12 KiB at once costs more
     * than a whole period's budget (a deadline fault). */
    c->clr = 0u;
}

/* CM_COG_CLEAR_PER_PERIOD bins' sums and counts to 0 from c->clr on;
 * true once every bin is clear. */
static bool cm_cog_clear(cm_cog_t *c)
{
    uint32_t end = c->clr + CM_COG_CLEAR_PER_PERIOD;
    if (end > CTRL_COG_N) {
        end = CTRL_COG_N;
    }
    for (uint32_t i = c->clr; i < end; i++) {
        c->sum[i] = 0;
        c->cnt[i] = 0u;
    }
    c->clr = end;
    return end == CTRL_COG_N;
}

enum { COG_HOLD, COG_ACCEL, COG_LEAD, COG_MEASURE, COG_DECEL, COG_CONVERT, COG_CENTRE };

/* One direction's means into the table (forward) or averaged with it
 * (backward), CM_COG_BINS_PER_PERIOD bins a period; *done at the last. */
static int cm_cog_convert(cm_t *cm, cm_cog_t *c, bool *done)
{
    const int64_t den_t = (int64_t)c->map.torque_rated;
    uint32_t end = c->fin + CM_COG_BINS_PER_PERIOD;
    if (end > CTRL_COG_N) {
        end = CTRL_COG_N;
    }
    for (uint32_t i = c->fin; i < end; i++) {
        if (c->cnt[i] == 0u) {
            return cm_fail(cm, CM_E_COG_RANGE, (int32_t)i, 0, c->dir);
        }
        /* Q16 pu mean -> Q15 of the rated torque: sum 2^23 / (cnt T_rated,Q24);
         * |sum| <= CM_COG_CNT_MAX 2^16 < 2^28, so sum 2^23 < 2^51 */
        const int64_t q = cm_cog_div((int64_t)c->sum[i] * 8388608, (int64_t)c->cnt[i] * den_t);
        if (q >= CTRL_COG_ONE || q <= -CTRL_COG_ONE) {
            return cm_fail(cm, CM_E_COG_RANGE, (int32_t)i, (int32_t)fx_sat32(q), c->dir);
        }
        c->mean_sum[c->dir > 0 ? 0 : 1] += q;
        if (c->dir > 0) {
            c->table[i] = (int16_t)q;
        } else {
            c->table[i] = (int16_t)cm_cog_div((int64_t)c->table[i] + q, 2);
        }
        c->sum[i] = 0;
        c->cnt[i] = 0u;
    }
    c->fin = end;
    *done = end == CTRL_COG_N;
    return CM_RUN;
}

int cm_cogging_period(cm_t *cm, const cm_in_t *in, cm_out_t *out)
{
    cm_cog_t *const c = cm->cog;
    if (c == NULL || c->ok == 0u) {
        return cm_fail(cm, CM_E_COG_CONFIG, 0, 0, 0);
    }
    const uint32_t cpr = c->map.cpr;
    cm_out_off(cm, out);
    out->mode = CM_OUT_CTRL;
    if (cm->t_step == 0u) {
        out->ctrl_reset = 1u;
        c->last = in->enc_pos;
    }
    /* unwrapped position: the step between two periods is below half a turn */
    int64_t d = (int64_t)in->enc_pos - (int64_t)c->last;
    if (d > (int64_t)(cpr / 2u)) {
        d -= (int64_t)cpr;
    } else if (d < -(int64_t)(cpr / 2u)) {
        d += (int64_t)cpr;
    }
    c->last = in->enc_pos;
    c->pos += d;
    cm->progress = (uint16_t)(((uint64_t)cm->t_step * c->progress_k) >> 32);

    const int32_t vmax = c->dir > 0 ? c->v_q16 : -c->v_q16;
    bool measure = false;
    switch (cm->phase) {
    case COG_HOLD:
        c->v = 0;
        if (cm->t == 0u) {
            c->pos_ref = c->pos * 65536; /* hold where the rotor is */
        }
        /* the sweep measures once the sums are clear and the rotor settled */
        if (cm_cog_clear(c) && cm->t >= c->n_settle) {
            cm_next(cm);
        }
        break;
    case COG_ACCEL:
        c->v = (int32_t)(((int64_t)vmax * (int64_t)cm->t) / (int64_t)c->n_ramp);
        if (cm->t >= c->n_ramp) {
            c->v = vmax;
            c->mark = c->pos;
            cm_next(cm);
        }
        break;
    case COG_LEAD:
    case COG_MEASURE: {
        c->v = vmax;
        const int64_t moved = c->dir > 0 ? c->pos - c->mark : c->mark - c->pos;
        const int64_t span =
            cm->phase == COG_LEAD ? (int64_t)c->lead : (int64_t)c->revs * (int64_t)cpr;
        measure = cm->phase == COG_MEASURE;
        if (moved >= span) {
            c->mark = c->pos;
            cm_next(cm);
        }
        break;
    }
    case COG_DECEL:
        c->v = (int32_t)(((int64_t)vmax * (int64_t)(cm->t < c->n_ramp ? c->n_ramp - cm->t : 0u)) /
                         (int64_t)c->n_ramp);
        if (cm->t >= c->n_ramp) {
            c->v = 0;
            c->fin = 0u;
            cm_next(cm);
        }
        break;
    case COG_CONVERT: {
        c->v = 0;
        bool done = false;
        if (cm_cog_convert(cm, c, &done) == CM_FAIL) {
            return CM_FAIL;
        }
        if (done) {
            if (c->dir > 0) {
                c->dir = -1;
                cm->phase = COG_HOLD;
                cm->t = 0u;
                cm->t_fresh = 1u;
            } else {
                c->fin = 0u;
                cm_next(cm);
            }
        }
        break;
    }
    default: { /* COG_CENTRE: less the mean over the revolution */
        c->v = 0;
        const int64_t mean = cm_cog_div(c->mean_sum[0] + c->mean_sum[1], 2 * (int64_t)CTRL_COG_N);
        uint32_t end = c->fin + CM_COG_BINS_PER_PERIOD;
        if (end > CTRL_COG_N) {
            end = CTRL_COG_N;
        }
        for (uint32_t i = c->fin; i < end; i++) {
            const int64_t q = (int64_t)c->table[i] - mean;
            if (q >= CTRL_COG_ONE || q <= -CTRL_COG_ONE) {
                return cm_fail(cm, CM_E_COG_RANGE, (int32_t)i, (int32_t)q, 0);
            }
            c->table[i] = (int16_t)q;
            const int32_t a = q < 0 ? (int32_t)-q : (int32_t)q;
            cm->detail[0] = a > cm->detail[0] ? a : cm->detail[0];
        }
        c->fin = end;
        if (end == CTRL_COG_N) {
            /* detail: the peak and the friction at the sweep speed, pu */
            cm->detail[0] = fx_mul_qn(c->map.torque_rated, cm->detail[0], 15u);
            const int64_t fr = cm_cog_div(c->mean_sum[0] - c->mean_sum[1], 2 * (int64_t)CTRL_COG_N);
            cm->detail[1] = fx_round_sat(fr * c->map.torque_rated, 15u);
            cm->detail[2] = (int32_t)CTRL_COG_N;
            c->cal_cpr = cpr;
            c->valid = 1u;
            return CM_DONE;
        }
        break;
    }
    }

    /* position loop */
    c->pos_ref += c->v;
    const int64_t e = c->pos_ref - c->pos * 65536;
    if (e > c->e_max || e < -c->e_max) {
        return cm_fail(cm, CM_E_COG_FOLLOW, fx_sat32(cm_cog_div(e, 65536)),
                       fx_sat32(c->e_max / 65536), c->dir);
    }
    const q24_t w_ref = cm_cog_apply(&c->kw, c->v);
    const q24_t lim = c->t_lim;
    c->integ = fx_clamp(fx_add(c->integ, cm_cog_apply(&c->ki, e)), fx_neg(lim), lim);
    q24_t tq = fx_add(cm_cog_apply(&c->kp, e), cm_cog_apply(&c->kd, fx_sub(w_ref, in->omega_est)));
    tq = fx_clamp(fx_add(tq, c->integ), fx_neg(lim), lim);
    out->torque_ref = tq;
    if (measure) {
        /* the nearest entry: a bin's samples then average to its entry's
         * angle i / n, where the feed-forward reads it (flooring them into
         * [i, i + 1) put the table half a bin early: 23 degrees of a cogging
         * period at 7.8 entries per period) */
        const uint32_t half = 1u << (31u - c->map.n_log2);
        const uint32_t bin =
            ctrl_cogging_bin(&c->map, ctrl_cogging_turn(&c->map, in->enc_pos) + half);
        if (c->cnt[bin] < CM_COG_CNT_MAX) {
            c->sum[bin] += fx_rshift32_round(tq, 8u); /* Q16 pu, |.| <= 2^16 */
            c->cnt[bin]++;
        }
    }
    return CM_RUN;
}

#endif
