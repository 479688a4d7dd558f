/*
 * Field weakening, per-period part (integer-only). Equations and formats:
 * field_weak.h.
 */
#include "field_weak.h"

#define FIELDWEAK_NEWTON_STEPS 3 /* per call of ctrl_fieldweak_currents */

/* Forced inlining of the per-period body into its two entry points
 * (ctrl_fieldweak_step and the lazy step's remainder): an out-of-line call
 * costs the interrupt more than it saves in code (measured, tools/bench). */
#if defined(__GNUC__)
#define FIELDWEAK_ALWAYS_INLINE __attribute__((always_inline)) inline
#define FIELDWEAK_NOINLINE __attribute__((noinline))
#else
#define FIELDWEAK_ALWAYS_INLINE inline
#define FIELDWEAK_NOINLINE
#endif

void ctrl_fieldweak_reset(ctrl_fieldweak_t *s)
{
    s->vdc_acc = 0;
    s->primed = 0u;
    s->t_prev = 0;
    s->t_primed = 0u;
    s->psi_d = 0;
    s->own.valid = 0u;
    s->lz_w_max = 0;
    s->lz_hold = 0u;
    s->lz_xv = 0u;
}

/* floor(sqrt(x)) of a Q48 value >= 0 as Q24 (x < 2^62: the result < 2^31). */
static q24_t fieldweak_sqrt48(int64_t x)
{
    if (x <= 0) {
        return 0;
    }
    return (q24_t)fx_isqrt64((uint64_t)x);
}

static int64_t fieldweak_sq48(q24_t x)
{
    return (int64_t)x * x; /* < 2^62 */
}

/* psi_d of the MTPV point on the flux circle psi (field_weak.h):
 * -2 c2 psi^2 / (c1 + sqrt(c1^2 + 8 c2^2 psi^2)); 0 for c2 = 0. */
static q24_t fieldweak_mtpv_psid(const ctrl_fieldweak_t *s, q24_t psi)
{
    if (s->c2 == 0) {
        return 0; /* SPMSM: the expression is exactly 0 */
    }
    const q24_t psi2 = fx_mul(psi, psi);
    const int64_t rad = (int64_t)s->c1_sq * FX_ONE + (int64_t)s->c2_sq8 * psi2; /* Q48 */
    return fx_neg(fx_div(fx_mul(fx_add(s->c2, s->c2), psi2), fx_add(s->c1, fieldweak_sqrt48(rad))));
}

q24_t ctrl_fieldweak_torque_at_flux(const ctrl_fieldweak_t *s, q24_t psi, q24_t margin,
                                    uint8_t *limit)
{
    const int64_t psi2 = fieldweak_sq48(psi);
    const q24_t psid_v = fieldweak_mtpv_psid(s, psi);
    const q24_t psiq_v = fieldweak_sqrt48(psi2 - fieldweak_sq48(psid_v));
    const q24_t t_v = fx_mul(psiq_v, fx_sub(s->c1, fx_mul(s->c2, psid_v)));
    const q24_t id_v = fx_mul(fx_sub(psid_v, s->psi_pm), s->inv_ld);

    /* On the flux ellipse |i|^2 = i_d^2 + (psi^2 - (Ld i_d + psi_pm)^2) / Lq^2
     * is convex in i_d: largest at the left end -(psi + psi_pm)/Ld, smallest
     * at i_d* = Ld psi_pm / (Lq^2 - Ld^2) or at the right end (psi - psi_pm)/Ld
     * if that comes first. */
    uint8_t lim = CTRL_FIELDWEAK_LIMIT_MTPV;
    q24_t t = t_v;
    const q24_t id_right = fx_mul(fx_sub(psi, s->psi_pm), s->inv_ld);
    const q24_t id_left = fx_neg(fx_mul(fx_add(psi, s->psi_pm), s->inv_ld));
    const q24_t id_min = fx_min(id_right, s->id_star);
    const q24_t pd_min = fx_add(fx_mul(s->ld, id_min), s->psi_pm);
    const int64_t i2_min =
        fieldweak_sq48(id_min) +
        fx_mul(fx_round_sat(psi2 - fieldweak_sq48(pd_min), FX_QBITS), s->inv_lq2) *
            (int64_t)FX_ONE; /* Q48 */
    if (i2_min > fieldweak_sq48(s->i_max)) {
        /* No point of the flux circle inside the current circle (above the
         * speed the current limit reaches, or a fixed flux it cannot hold). */
        t = 0;
        lim = CTRL_FIELDWEAK_LIMIT_VOLTAGE;
    } else if (fx_abs(id_left) > s->i_max) {
        /* The circles meet: c = c0 - psi^2,
         * i_d = -2c / (b + sqrt(b^2 + 4 (Lq^2 - Ld^2) c)); the arc i_d >= it
         * is inside the current circle. */
        const int64_t c48 = (int64_t)s->c0 * FX_ONE - psi2; /* Q48 */
        const q24_t c = fx_round_sat(c48, FX_QBITS);
        const int64_t disc = fieldweak_sq48(s->b) + 4 * (int64_t)s->dl2 * c; /* Q48 */
        const q24_t id_x = fx_neg(fx_div(fx_add(c, c), fx_add(s->b, fieldweak_sqrt48(disc))));
        if (id_v < id_x) {
            /* MTPV lies outside the current circle: the intersection bounds T. */
            const q24_t iq_x = fieldweak_sqrt48(fieldweak_sq48(s->i_max) - fieldweak_sq48(id_x));
            t = fx_mul(fx_add(s->psi_pm, fx_mul(s->ld_m_lq, id_x)), iq_x);
            lim = CTRL_FIELDWEAK_LIMIT_VOLTAGE;
        }
    }
    if (limit != 0) {
        *limit = lim;
    }
    return fx_min(fx_max(t, 0), fx_mul(margin, t_v));
}

/* psi_max >= b (b > 0, w > 0) without the root and the division: when
 * x >= c^2, c = ceil(b w / 2^24) (< 2^31: c^2 < 2^62), floor(sqrt(x)) 2^24
 * >= b w, so the rounded quotient floor(sqrt(x)) / w is >= b. Sufficient
 * only: 0 leaves the question to the division. */
static int fieldweak_flux_at_least(int64_t x, q24_t w, q24_t b)
{
    const uint64_t c = ((uint64_t)(uint32_t)b * (uint32_t)w + (FX_ONE - 1u)) >> FX_QBITS;
    return c < ((uint64_t)1 << 31) && x >= (int64_t)(c * c);
}

/* V^2 - (Rs I)^2 - 2 Rs w T (Q48; psi_max = sqrt of it / |w|) with
 * V = k_mod vdc_f / sqrt(3), Rs I = min(Rs |T| / psi_pm, Rs I_max): every
 * term below 2^62 in magnitude. Nonincreasing in |T| for w T >= 0 and at
 * least its value at |T| for w T < 0 (the lazy region's corner). Out of
 * line: called from several places, not in the lazy path's usual period. */
static FIELDWEAK_NOINLINE int64_t fieldweak_volt_sq(const ctrl_fieldweak_t *s, q24_t vdc_f,
                                                    q24_t omega, q24_t t)
{
    const q24_t v = fx_mul_qn(vdc_f, s->v_frac, 30u);
    const q24_t rs_i = fx_min(fx_mul(fx_abs(t), s->rs_ipsi), s->rs_imax);
    return fieldweak_sq48(v) - fieldweak_sq48(rs_i) - (int64_t)s->two_rs * fx_mul(omega, t);
}

/* fieldweak_volt_sq of this period, formed once (lz_xv is cleared as the period
 * ends). */
static FIELDWEAK_ALWAYS_INLINE int64_t fieldweak_volt_sq_once(ctrl_fieldweak_t *s, q24_t vdc_f,
                                                              q24_t omega)
{
    if (s->lz_xv == 0u) {
        s->lz_x = fieldweak_volt_sq(s, vdc_f, omega, s->t_prev);
        s->lz_xv = 1u;
    }
    return s->lz_x;
}

/* Periods without a new region after a corner failed (near base speed). */
#define FIELDWEAK_LZ_HOLD 16u

/* A region of the lazy path around (vdc_f, w > 0), where psi_max >= psi_mtpa
 * has just been shown: the DC link down by 1/32, the speed up by 1/8. At
 * its corner - the least DC link, the highest speed, the largest motoring
 * torque t_mtpa - the test passes; everywhere inside it passes too: V is
 * nondecreasing in vdc_f, |fx_mul(omega, t)| <= fx_mul(|omega|, |t|) (rounding
 * half up never moves the magnitude past the exact product's rounding) is
 * nondecreasing in both, and so is c of fieldweak_flux_at_least in w. The speed
 * stays below FX_MAX, so that |omega| = FX_MAX (omega = FX_MIN saturated)
 * is never inside. */
static void fieldweak_lazy_region(ctrl_fieldweak_t *s, q24_t vdc_f, q24_t w)
{
    const q24_t w_hi = fx_min(fx_add(w, w >> 3), FX_MAX - 1); /* w > 0 */
    const q24_t vdc_lo = vdc_f - (vdc_f >> 5);                /* vdc_f >= 0 */
    if (fieldweak_flux_at_least(fieldweak_volt_sq(s, vdc_lo, w_hi, s->t_mtpa), w_hi, s->psi_mtpa)) {
        s->lz_vdc_min = vdc_lo;
        s->lz_w_max = w_hi;
    } else {
        s->lz_hold = FIELDWEAK_LZ_HOLD;
    }
}

/* The lazy path's first test outside its region: psi_max >= psi_mtpa, and
 * if so a new region around this point (at most once in FIELDWEAK_LZ_HOLD periods
 * after one failed). */
static int fieldweak_lazy_enter(ctrl_fieldweak_t *s, q24_t vdc_f, q24_t omega, q24_t w)
{
    if (!fieldweak_flux_at_least(fieldweak_volt_sq_once(s, vdc_f, omega), w, s->psi_mtpa)) {
        return 0;
    }
    if (s->lz_hold == 0u) {
        fieldweak_lazy_region(s, vdc_f, w);
    } else {
        s->lz_hold--;
    }
    return 1;
}

/* Everything of a period after the DC-link filter (vdc_f, >= 0). */
static FIELDWEAK_ALWAYS_INLINE void fieldweak_limits(ctrl_fieldweak_t *s, const ctrl_params_t *p,
                                                     q24_t vdc_f, q24_t omega, q24_t t_req,
                                                     q24_t psi_cmd, ctrl_fieldweak_out_t *out,
                                                     int lazy)
{
    out->vdc = vdc_f;

    /* Flux the voltage allows: psi_max = sqrt(V^2 - (Rs I)^2 - 2 Rs w T) / |w|. */
    const q24_t w = fx_abs(omega);
    const q24_t psi_fix = psi_cmd > 0 ? psi_cmd : p->psi_ref;
    if (lazy != 0 && psi_fix <= 0 && w != 0 &&
        (ctrl_fieldweak_in_region(s, vdc_f, w) || fieldweak_lazy_enter(s, vdc_f, omega, w))) {
        /* psi_max >= the MTPA flux at I_max (inside the region, or by the
         * test): the current limit, whatever psi_max is; if it is also >=
         * the flux reference of the clamped torque, neither the reference
         * nor "weakening" depends on it. */
        const q24_t t = fx_clamp(t_req, fx_neg(s->t_mtpa), s->t_mtpa);
        /* psi_fix <= 0: ctrl_flux_ref is the MTPA flux of t */
        const q24_t psi_own = ctrl_flux_ref_memo(&s->own, p, psi_cmd, t);
        if (psi_own <= s->psi_mtpa ||
            (psi_own <= s->psi_ceil &&
             fieldweak_flux_at_least(fieldweak_volt_sq_once(s, vdc_f, omega), w, psi_own))) {
            ctrl_fieldweak_current_limit(s, t, t_req, psi_own, out);
            s->lz_xv = 0u;
            return;
        }
    }
    const int64_t x = fieldweak_volt_sq_once(s, vdc_f, omega);
    q24_t psi_max = s->psi_ceil;
    if (w != 0 && !fieldweak_flux_at_least(x, w, s->psi_ceil)) {
        /* (at the ceiling - low speed - without the root and the division) */
        psi_max = fx_min(fx_div(fieldweak_sqrt48(x), w), s->psi_ceil);
    }
    out->psi_max = psi_max;

    /* Torque limit at the flux the controller will hold. */
    q24_t t_lim;
    uint8_t lim;
    if (psi_fix <= 0 && psi_max >= s->psi_mtpa) {
        t_lim = s->t_mtpa;
        lim = CTRL_FIELDWEAK_LIMIT_CURRENT;
    } else {
        const q24_t psi_lim = psi_fix > 0 ? fx_min(psi_fix, psi_max) : psi_max;
        /* braking (w T_req < 0) on a fixed flux: the braking margin (header) */
        const int brake = psi_fix > 0 && ((omega > 0 && t_req < 0) || (omega < 0 && t_req > 0));
        t_lim = ctrl_fieldweak_torque_at_flux(s, psi_lim, brake ? s->t_margin_brake : s->t_margin,
                                              &lim);
        if (psi_lim < psi_max) {
            lim = CTRL_FIELDWEAK_LIMIT_FLUX; /* the fixed reference, not the voltage */
        }
    }
    const q24_t t = fx_clamp(t_req, fx_neg(t_lim), t_lim);
    const q24_t psi_own = ctrl_flux_ref_memo(&s->own, p, psi_cmd, t);
    out->torque_max = t_lim;
    out->torque = t;
    out->psi_ref = fx_min(psi_own, psi_max);
    out->limit = lim;
    out->clipped = t != t_req ? 1u : 0u;
    out->weakening = psi_max < psi_own ? 1u : 0u;
    ctrl_fieldweak_t_prev(s, t);
    s->lz_xv = 0u;
}

void ctrl_fieldweak_step(ctrl_fieldweak_t *s, const ctrl_params_t *p, q24_t vdc, q24_t omega,
                         q24_t t_req, q24_t psi_cmd, ctrl_fieldweak_out_t *out)
{
    fieldweak_limits(s, p, ctrl_fieldweak_vdc_filter(s, vdc), omega, t_req, psi_cmd, out, 0);
}

void ctrl_fieldweak_limits_lazy(ctrl_fieldweak_t *s, const ctrl_params_t *p, q24_t vdc_f,
                                q24_t omega, q24_t t_req, ctrl_fieldweak_out_t *out)
{
    fieldweak_limits(s, p, vdc_f, omega, t_req, 0, out, 1);
}

void ctrl_fieldweak_currents(ctrl_fieldweak_t *s, const ctrl_params_t *p, q24_t t, q24_t psi_ref,
                             q24_t *i_d, q24_t *i_q)
{
    q24_t md;
    q24_t mq;
    ctrl_mtpa_current(p, t, &md, &mq);
    const q24_t psi_d = fx_add(fx_mul(p->ld, md), s->psi_pm);
    if (psi_ref <= 0 || fx_mag(psi_d, fx_mul(p->lq, mq)) <= psi_ref) {
        s->psi_d = psi_d; /* MTPA is within the voltage: where weakening starts */
        *i_d = md;
        *i_q = mq;
        return;
    }
    /* On the flux circle psi, T(psi_d) = psi_q (c1 - c2 psi_d) falls strictly
     * from T_mtpv at psi_d = psi_d,mtpv to 0 at psi_d = min(psi, c1/c2):
     * bracketed Newton steps from the previous solution. */
    const q24_t psi = psi_ref;
    const int64_t psi2 = fieldweak_sq48(psi);
    const q24_t lo_v = fieldweak_mtpv_psid(s, psi);
    q24_t lo = lo_v;
    q24_t hi = psi;
    if (s->c2 > 0 && fx_mul(s->c2, psi) > s->c1) {
        hi = fx_div(s->c1, s->c2);
    }
    const q24_t ta = fx_abs(t);
    q24_t x = fx_clamp(s->psi_d, lo, hi);
    for (int k = 0; k < FIELDWEAK_NEWTON_STEPS; k++) {
        const q24_t pq = fieldweak_sqrt48(psi2 - fieldweak_sq48(x));
        const q24_t kk = fx_sub(s->c1, fx_mul(s->c2, x));
        const q24_t r = fx_sub(fx_mul(pq, kk), ta);
        if (r > 0) {
            lo = x; /* too much torque: psi_d must rise */
        } else {
            hi = x;
        }
        /* dT/dpsi_d = -(psi_d k + c2 psi_q^2) / psi_q: Newton step
         * r psi_q / (psi_d k + c2 psi_q^2). */
        const q24_t den = fx_add(fx_mul(x, kk), fx_mul(s->c2, fx_mul(pq, pq)));
        q24_t xn = x;
        if (den > 0) {
            xn = fx_add(x, fx_div(fx_mul(r, pq), den));
        }
        /* When the step leaves the bracket, or stays at psi_q = 0 off the
         * torque (psi_d = psi: the step is 0 there): the point of the flux
         * circle whose psi_q gives t at this k, sqrt(psi^2 - (t / k)^2) -
         * exact where k hardly moves (small torques, near psi_d = psi, where
         * T(psi_d) is a square root's flank and Newton converges slowly) -
         * if it is inside the bracket, else the bracket's midpoint. */
        if (den <= 0 || xn < lo || xn > hi || (pq == 0 && r != 0)) {
            xn = fx_add(lo, fx_rshift32_round(fx_sub(hi, lo), 1u)); /* bisect */
            if (kk > ta) {
                const q24_t pq_t = fx_div(ta, kk); /* < 1 pu */
                const q24_t xg = fieldweak_sqrt48(psi2 - fieldweak_sq48(pq_t));
                if (xg > lo && xg < hi) {
                    xn = xg;
                }
            }
        }
        x = xn;
    }
    s->psi_d = x;
    const q24_t id = fx_mul(fx_sub(x, s->psi_pm), s->inv_ld);
    /* i_q from the torque, T = (psi_pm + (Ld - Lq) i_d) i_q: exact in T even
     * where psi_q = sqrt(psi^2 - psi_d^2) resolves a small torque poorly (near
     * psi_d = psi one LSB of psi_d is sqrt(2 psi) LSB^(1/2) of psi_q); never
     * beyond the flux circle (|t| above the arc's maximum: the MTPV point). */
    const q24_t q_f = fx_mul(fieldweak_sqrt48(psi2 - fieldweak_sq48(x)), p->inv_lq);
    const q24_t q_t = fx_div(ta, fx_add(s->psi_pm, fx_mul(s->ld_m_lq, id)));
    const q24_t q = x == lo_v ? fx_min(q_t, q_f) : q_t;
    *i_d = id;
    *i_q = t < 0 ? fx_neg(q) : q;
}
