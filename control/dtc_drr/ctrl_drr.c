/*
 * DRR-DTC, thesis §5.3-§5.4, per sample (integer-only). See ctrl_drr.h.
 */
#include "ctrl_drr.h"

#include <stddef.h>

#include "mtpa.h"
#include "plan.h"
#include "st_tables.h"
#include "vectors.h"

/* Inputs of the duty formulas are clamped to [-4, 4) pu (rated torque is
 * ~0.3 pu and flux ~1 pu for the shipped machines; rated speed is 1 pu, the
 * speed base of ctrl_params.h): with
 * that bound every int64 intermediate below stays under 2^62. One SSAT. */
#define DRR_LIM (4 * FX_ONE)
_Static_assert(DRR_LIM == (q24_t)1 << 26, "FX_SAT(x, 27) is the +-DRR_LIM clamp");

static inline q24_t drr_lim(q24_t x)
{
    return FX_SAT(x, 27);
}

uint8_t ctrl_drr_select(uint8_t sector, q24_t t_err, q24_t psi_err)
{
    /* (5.1) is Table 4.4 (two-level torque, ">= 0" = increase): the
     * switching-table module's lookup; any sector is wrapped into 1..6 (4.14). */
    return st_lookup_ast(ctrl_vec_wrap((int)sector), psi_err >= 0 ? 1 : -1, t_err >= 0 ? 1 : -1);
}

q24_t ctrl_drr_ema(q24_t gamma, q24_t chi, q24_t lambda)
{
    /* (5.4) rewritten gamma[k] = gamma[k-1] + lambda (chi[k] - gamma[k-1]):
     * |chi - gamma| < 2^32, lambda < 2^25, product < 2^57; formed as
     * chi lambda - gamma lambda (two 32 x 32 products, each < 2^56). */
    const int64_t d = (int64_t)chi * lambda - (int64_t)gamma * lambda;
    return fx_sat32((int64_t)gamma + fx_rshift64_round(d, FX_QBITS));
}

int ctrl_drr_vreplace_active(const ctrl_drr_state_t *s, q24_t psi_err)
{
    return s != NULL && s->vr.enabled != 0u && fx_abs(psi_err) < s->half_dpsi;
}

void ctrl_drr_c_parts(const ctrl_drr_state_t *s, q24_t omega_e, q24_t *c_num, q24_t *dc)
{
    *c_num = s->c_num;
    if (s->dc_fixed != 0) {
        *dc = s->dc_fixed;
        return;
    }
    /* (5.13): C = 2 sqrt(3) A / (2 B |w| / w_rn - sqrt(3) A). The denominator
     * is < 0 below ~1.07 rated speed (thesis SPMSM) and crosses 0 above; it is
     * clamped to dc_max < 0, i.e. |C| <= CTRL_DRR_C_MAX. */
    /* 2 B |w| / w_rn generalised to twice the magnitude of the zero-vector
     * deviation with its resistive part, |kb w + rt| (s->rt = 0: the thesis). */
    const q24_t w = drr_lim(omega_e);
    const q24_t z = s->rt == 0 ? fx_mul(s->kb, fx_keep32(w < 0 ? -w : w)) /* |w| <= 2^26 */
                               : fx_abs(fx_add(fx_mul(s->kb, w), drr_lim(s->rt)));
    const q24_t d = fx_sub(fx_lshift_sat(z, 1u), s->sqrt3_a);
    *dc = fx_min(d, s->dc_max);
}

/* Bits needed for x > 0 (x < 2^62). */
static unsigned drr_bitlen(uint64_t x)
{
#if defined(__GNUC__)
    return 64u - (unsigned)__builtin_clzll(x); /* two CLZ on a Cortex-M4 */
#else
    unsigned n = 0;
    for (unsigned step = 32u; step > 0u; step /= 2u) {
        if ((x >> step) != 0u) {
            x >>= step;
            n += step;
        }
    }
    return n + (x != 0u ? 1u : 0u);
#endif
}

/*
 * num / den clamped to [0, FX_ONE] (Q24), with |num|, |den| < 2^62 in any
 * common scale. den == 0 counts as +0: the result is FX_ONE for num > 0, else 0.
 * Both are scaled by the same power of two so den lies in [2^25, 2^26]
 * (26 significant bits: each rounding of the scaling at most 2^-26 of den,
 * together at most half an LSB of the Q24 result), then the quotient is
 * exactly rounded: with the quotient's own rounding at most 1 LSB, as the
 * single fx_div on 30 bits this replaces. Long division in four 6-bit digits
 * (the remainder stays below d <= 2^26, so r 2^6 < 2^32): four UDIV, no
 * 64-bit division.
 */
static q24_t drr_ratio01(int64_t num, int64_t den)
{
    if (den < 0) {
        num = -num;
        den = -den;
    }
    if (num <= 0) {
        return 0;
    }
    if (den == 0 || num >= den) {
        return FX_ONE;
    }
    const unsigned bl = drr_bitlen((uint64_t)den);
    uint32_t ud;
    uint32_t r;
    if (bl > 26u) {
        /* Both positive: rounded half up by an unsigned shift (the value of
         * fx_rshift64_round), and the results below 2^27 are their low words. */
        const unsigned sh = bl - 26u;
        const uint64_t half = (uint64_t)1 << (sh - 1u);
        r = (uint32_t)(((uint64_t)num + half) >> sh);
        ud = (uint32_t)(((uint64_t)den + half) >> sh);
    } else {
        r = (uint32_t)num << (26u - bl); /* num < den < 2^bl: below 2^26 */
        ud = (uint32_t)den << (26u - bl);
    }
    /* 0 <= r <= ud (rounding keeps the order), 2^25 <= ud <= 2^26 */
    /* remainder >= d/2: round half up (fx_div's rounding for n, d > 0) */
    uint32_t q = fx_udiv_digits(0u, &r, ud, 6u, 4u);
    q = fx_udiv_round(q, r, ud);
    return q > (uint32_t)FX_ONE ? FX_ONE : (q24_t)q;
}

/* The zero vector's torque deviation per period, B w / w_rn + rt ((5.6), (5.7)). */
static q24_t drr_kbw(const ctrl_drr_state_t *s, q24_t omega_e)
{
    return fx_add(fx_mul(s->kb, drr_lim(omega_e)), drr_lim(s->rt));
}

/* ctrl_drr_duty with (cn, dc) = ctrl_drr_c_parts(s, omega_e), kbw = drr_kbw(s, omega_e). */
static q24_t drr_duty_c(const ctrl_drr_state_t *s, uint8_t vec, q24_t psi_alpha, q24_t psi_beta,
                        q24_t psi_amp, q24_t t_err, q24_t gamma, q24_t kbw, q24_t cn, q24_t dc)
{
    if (vec < 1u || vec > 6u || psi_amp <= 0) {
        return 0;
    }
    const q24_t e = drr_lim(t_err);
    const q24_t g = drr_lim(gamma);
    const q24_t pamp = fx_min(psi_amp, DRR_LIM);
    const q24_t ux = ctrl_vec_dir_q24[vec][0];
    const q24_t uy = ctrl_vec_dir_q24[vec][1];
    /* psi x v_hat = |psi| sin(theta_v - theta_s): positive for V_{x+1}, V_{x+2},
     * negative for V_{x+4}, V_{x+5} in sector x, so A (psi x v_hat) / |psi| is
     * the A |sin(.)| term of (5.6) with the sign of (5.7). */
    /* |psi| components within 2^26, the unit vector's within 2^24: the
     * difference of products below 2^51, no saturation */
    const q24_t cross = fx_cross_nosat(drr_lim(psi_alpha), drr_lim(psi_beta), ux, uy);

    /*
     * (5.14) with C = cn / dc and Delta T = A cross / |psi| - kb w, numerator and
     * denominator both multiplied by dc |psi| (one division, none for C or
     * |psi|):
     *   num = |psi| [ e dc - (2 dc + cn) gamma ]
     *   den = (A cross - kb w |psi|) dc - cn gamma |psi|
     * Magnitudes (|e|, |g|, |w|, |psi| <= 2^26 by the clamps; |A|, |kb| <= 2^26,
     * |dc| <= 2^27, |cn| <= 2^30 by init): every intermediate stays under 2^61.
     */
    const int64_t n48 = (int64_t)e * dc - ((int64_t)dc * 2 + cn) * g;
    const int64_t num = fx_rshift64_round(n48, FX_QBITS) * pamp;
    const int64_t d48 = (int64_t)s->a * cross - (int64_t)kbw * pamp;
    const int64_t cg = fx_rshift64_round((int64_t)cn * g, FX_QBITS);
    const int64_t den = fx_rshift64_round(d48, FX_QBITS) * dc - cg * pamp;

    /* Sign of the thesis' denominator Delta T -+ C gamma = den / (dc |psi|), dc < 0. */
    const int den_sign = (den < 0) - (den > 0);
    const int want = e >= 0 ? 1 : -1;
    if (den_sign != want) {
        return FX_ONE;
    }
    return drr_ratio01(num, den);
}

q24_t ctrl_drr_duty(const ctrl_drr_state_t *s, uint8_t vec, q24_t psi_alpha, q24_t psi_beta,
                    q24_t psi_amp, q24_t t_err, q24_t gamma, q24_t omega_e)
{
    if (s == NULL) {
        return 0;
    }
    q24_t cn;
    q24_t dc;
    ctrl_drr_c_parts(s, omega_e, &cn, &dc);
    return drr_duty_c(s, vec, psi_alpha, psi_beta, psi_amp, t_err, gamma, drr_kbw(s, omega_e), cn,
                      dc);
}

q24_t ctrl_drr_delta_t(const ctrl_drr_state_t *s, uint8_t vec, q24_t psi_alpha, q24_t psi_beta,
                       q24_t psi_amp, q24_t omega_e)
{
    if (s == NULL) {
        return 0;
    }
    const q24_t kbw = drr_kbw(s, omega_e);
    if (vec < 1u || vec > 6u || psi_amp <= 0) {
        return fx_neg(kbw); /* zero vector: (5.16) third term */
    }
    const q24_t ux = ctrl_vec_dir_q24[vec][0];
    const q24_t uy = ctrl_vec_dir_q24[vec][1];
    const q24_t cross = fx_cross(drr_lim(psi_alpha), drr_lim(psi_beta), ux, uy);
    return fx_sub(fx_div(fx_mul(s->a, cross), psi_amp), kbw);
}

void ctrl_drr_reset(void *state)
{
    ctrl_drr_state_t *s = state;
    s->gamma = 0;
    s->rt = 0;
    s->dt_sel = 0;
    s->vec_sel = 0u;
    s->last_tvref = 0;
    s->last_psiref = 0;
    s->last_terr = 0;
    s->last_psierr = 0;
    s->last_duty = 0;
    s->last_vec_51 = 0u;
}

/* ctrl_drr_t_start with (cn, dc) = ctrl_drr_c_parts(s, omega_e). */
static q24_t drr_t_start_c(const ctrl_drr_state_t *s, q24_t t_k1, q24_t cn, q24_t dc)
{
    /* (1 - D)/2 of zero vector precede the active vector in a centre-aligned
     * period; D: the last duty (steady state, D(k+1) ~ D(k)). */
    const uint32_t d0 = (uint32_t)(FX_ONE - fx_clamp(s->last_duty, 0, FX_ONE)); /* [0, 2^24] */
    const q24_t half_zero = fx_keep32((q24_t)((d0 + 1u) >> 1)); /* rounded half up */
    /* Zero-vector torque deviation per period by (5.12): C gamma = cn gamma / dc
     * (dc <= dc_max < 0: never a zero divisor). */
    const q24_t cg = fx_mul(cn, drr_lim(s->gamma));
    const q24_t dt0 = fx_keep32(s->dc_fixed != 0 ? fx_neg(cg) : fx_div(cg, dc));
    return fx_add(t_k1, fx_mul(half_zero, dt0));
}

q24_t ctrl_drr_t_start(const ctrl_drr_state_t *s, q24_t t_k1, q24_t omega_e)
{
    q24_t cn;
    q24_t dc;
    ctrl_drr_c_parts(s, omega_e, &cn, &dc);
    return drr_t_start_c(s, t_k1, cn, dc);
}

/* (5.16): T(k+1) = T(k) + D(k) Delta T(k) - (1 - D(k)) B w / w_rn, with D(k) and
 * the vector of the plan acting during [k, k+1) (this controller's choice at
 * k-1, none after reset) and its Delta T computed at k-1 for the state
 * predicted at k. */
static q24_t drr_predict_516(const ctrl_drr_state_t *s, const ctrl_ctx_t *ctx)
{
    q24_t d = 0;
    q24_t dt = 0;
    if (s->vec_sel >= 1u && s->vec_sel <= 6u) {
        d = fx_clamp(s->last_duty, 0, FX_ONE);
        dt = s->dt_sel;
    }
    const q24_t kbw = fx_add(fx_mul(s->kb, drr_lim(ctx->est->omega_e)),
                             fx_mul(s->r_ts, drr_lim(ctx->est->now.torque)));
    const q24_t t = fx_add(ctx->est->now.torque, fx_mul(d, dt));
    return fx_sub(t, fx_mul(FX_ONE - d, kbw));
}

/* A (5.9) and B (5.10) for the PM flux in use (they scale as psi_pm and
 * psi_pm^2), with what follows from A; only when params->psi_pm moved (the
 * pipeline tracks it from the voltage model, fw_config_t.psi_adapt). */
static void drr_track_psi(ctrl_drr_state_t *s, q24_t psi)
{
    s->psi_seen = psi;
    if (s->a_psi != 0) {
        s->a = fx_mul(s->a_psi, psi);
        s->sqrt3_a = fx_mul(2 * FX_Q24_SQRT3_2, s->a);
        if (s->dc_fixed == 0) {
            s->c_num = fx_lshift_sat(s->sqrt3_a, 1u);
            /* -c_num / CTRL_DRR_C_MAX (= 2^6), below zero */
            s->dc_max = fx_min(-fx_rshift32_round(s->c_num, 6u), -1);
        }
    }
    if (s->kb_psi2 != 0) {
        s->kb = fx_mul(s->kb_psi2, fx_mul(psi, psi));
    }
}

void ctrl_drr_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out)
{
    ctrl_drr_state_t *s = state;
    if (ctx->params->psi_pm != s->psi_seen) {
        drr_track_psi(s, ctx->params->psi_pm);
    }
    const ctrl_mstate_t *nx = &ctx->est->next;
    const q24_t w = ctx->est->omega_e;
    const q24_t t_k1 = s->pred_516 != 0u ? drr_predict_516(s, ctx) : nx->torque;
    /* Resistive zero-vector deviation (4.10) at the predicted torque. */
    s->rt = fx_mul(s->r_ts, drr_lim(t_k1));
    const q24_t tref = ctx->ref->torque;
    /* C of (5.13) once for the start torque and the duty (both after s->rt). */
    q24_t cn;
    q24_t dc;
    ctrl_drr_c_parts(s, w, &cn, &dc);
    const q24_t te = s->centre != 0u ? drr_t_start_c(s, t_k1, cn, dc) : t_k1;

    /* Virtual reference (5.3)-(5.4): gamma = EMA of T_ref - T_min, T_min being
     * the torque where the active vector starts (see ctrl_drr_t_start). The
     * EMA holds while the error exceeds one period's largest torque change,
     * gamma_max (default A (5.9)) plus the zero vector's |B w / w_rn + rt|:
     * such an error is a step's rise, not the offset gamma is for, and wound
     * up into T_ref + gamma it carries a fixed flux past its pull-out
     * (docs/algorithms.md, "Virtual-reference wind-up"). */
    const q24_t chi = fx_sub(tref, te);
    const q24_t kbw = drr_kbw(s, w);
    const q24_t band = fx_add(s->gamma_max, fx_abs(kbw));
    q24_t g = s->gamma;
    if (s->gamma_max == 0 || fx_abs(chi) <= band) {
        g = ctrl_drr_ema(g, chi, s->lambda);
        s->gamma = g;
    }
    const q24_t tv = fx_add(tref, g);

    /* Flux reference by MTPA (4.15) of the corrected demand (§5.4). */
    const q24_t psi_ref = ctrl_flux_ref(ctx->params, ctx->ref->psi, tv);
    const q24_t terr = fx_sub(tv, te);
    const q24_t psierr = fx_sub(psi_ref, nx->psi_amp);

    uint8_t vec = ctrl_drr_select(nx->sector, terr, psierr); /* (5.1), x by (4.5) */
    s->last_vec_51 = vec;
    if (ctrl_drr_vreplace_active(s, psierr)) {
        vec = ctrl_vreplace(&s->vr, vec, nx->sector, nx->psi_alpha, nx->psi_beta); /* §5.3.5 */
    }
    const q24_t duty = drr_duty_c(s, vec, nx->psi_alpha, nx->psi_beta, nx->psi_amp, terr, g, kbw,
                                  cn, dc); /* (5.14) */
    if (s->pred_516 != 0u) {
        s->dt_sel = ctrl_drr_delta_t(s, vec, nx->psi_alpha, nx->psi_beta, nx->psi_amp, w);
    }
    s->vec_sel = vec;
    s->last_tvref = tv;
    s->last_psiref = psi_ref;
    s->last_terr = terr;
    s->last_psierr = psierr;
    s->last_duty = duty;
    /* Active vector for D Ts, then V0 after V1/V3/V5, V7 after V2/V4/V6 (§5.4). */
    ctrl_out_active_zero(out, vec, duty);
}
