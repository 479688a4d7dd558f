/*
 * Field weakening: the operating limits of one PWM period from the voltage
 * available in it (integer-only; configuration in field_weak_config.h).
 *
 * Steady state of the dq model in pu (Te = psi x i, (3.6)), v = Rs i + j w psi:
 *   |v|^2 = Rs^2 |i|^2 + w^2 |psi|^2 + 2 Rs w Te
 * so with the usable phase-voltage amplitude V = k_mod Vdc / sqrt(3) (k_mod the
 * modulation's limit, Vdc measured this period and low-pass filtered) the
 * stator-flux amplitude the voltage allows at electrical speed w is
 *   psi_max = sqrt(V^2 - (Rs I)^2 - 2 Rs w T) / |w|
 * with T the torque reference of the last calls, low-pass filtered (T_f +=
 * (T - T_f) / 8 per call from the first call's T, ctrl_fieldweak_t_prev: the
 * limit depends on the torque it lets through, and taken from the last call
 * alone it alternated between full torque and none on a high-resistance
 * motor, where the Rs terms are a large part of V), and I the
 * current of T, |T| / psi_pm (the MTPA current is below it: Te = i_q (psi_pm
 * + (Lq - Ld) |i_d|) >= psi_pm |i_q| and |i_q| dominates |i|), at most I_max.
 * Motoring, w T > 0, leaves less flux; braking more. (With Rs I_max in place
 * of Rs I a motor whose Rs I_max approaches V was refused any torque at a
 * speed where the voltage suffices for the current its torque needs.) In deep
 * field weakening the d-axis current adds an Rs drop this leaves out: at most
 * (Rs I_max)^2 of V^2, 0.01 % on the 80 kW IPMSM and 0.1 % on the thesis
 * SPMSM, within the 8 % voltage margin of the limit (v_frac 0.92).
 *
 * Torque limit at the flux amplitude psi (psi = psi_max, or a fixed flux
 * reference below it), for Lq >= Ld:
 *   - MTPA mode and psi_max >= |psi_s| of MTPA at I_max: the current limit,
 *     T_mtpa(I_max) (below base speed);
 *   - otherwise the flux circle |psi_s| = psi in the current plane, an
 *     ellipse (Ld i_d + psi_pm)^2 + (Lq i_q)^2 = psi^2, meets the current circle
 *     |i| = I_max where
 *       (Ld^2 - Lq^2) i_d^2 + 2 Ld psi_pm i_d + psi_pm^2 + Lq^2 I_max^2 - psi^2 = 0,
 *     i_d = -2c / (b + sqrt(b^2 + 4 (Lq^2 - Ld^2) c)), b = 2 Ld psi_pm,
 *     c = psi_pm^2 + Lq^2 I_max^2 - psi^2 (the root without cancellation);
 *     the smaller root: |i|^2 on the ellipse is convex in i_d, so the arc
 *     inside the current circle starts there (the circle holds no point of
 *     the ellipse when even its least |i| exceeds I_max);
 *   - the largest torque on the flux circle (MTPV), with c1 = psi_pm / Ld,
 *     c2 = 1/Ld - 1/Lq: T = psi_q (c1 - c2 psi_d), maximal at
 *       psi_d = -2 c2 psi^2 / (c1 + sqrt(c1^2 + 8 c2^2 psi^2))  (SPMSM: 0);
 *   - T_lim = T_mtpv if the MTPV point lies inside the current circle (limit
 *     "mtpv"), else the torque at the intersection (limit "voltage": current
 *     circle and voltage ellipse), 0 if the flux circle has no point inside
 *     the current circle, and never above torque_margin * T_mtpv: a
 *     torque controller holding |psi_s| fixed loses the load angle at the
 *     MTPV point (dT/d delta = 0) and the torque collapses. Braking on a
 *     fixed flux reference (w T_req < 0) the margin is torque_margin_brake:
 *     there the zero vector turns the rotor away from a standing flux, which
 *     carries the load angle toward the pull-out, not away from it, and a
 *     step's overshoot or the flux's ripple (its sag) reaches the peak from a
 *     lower torque than motoring.
 * The flux reference is min(the controller's own (MTPA (4.15) / table, or the
 * fixed reference), psi_max) for the limited torque; every function of it is
 * continuous in speed, DC link and torque, so entering and leaving field
 * weakening is smooth.
 *
 * Formats: every q24_t is Q24 pu (bases in ctrl_params.h); squares and sums
 * of squares are formed in int64_t (Q48) and square-rooted exactly with
 * fx_isqrt64 (floor); at most three fx_div per period (psi_max, the
 * intersection, MTPV; psi_max at its ceiling and the SPMSM's MTPV point need
 * none). Error budget: docs/error-budget.md, "Field weakening".
 */
#ifndef CONTROL_FIELD_WEAK_H
#define CONTROL_FIELD_WEAK_H

#include <stdint.h>

#include "ctrl_params.h"
#include "fx.h"
#include "mtpa.h"

/* What bounds the torque at this speed and DC link. */
typedef enum {
    CTRL_FIELDWEAK_LIMIT_CURRENT = 0, /* current circle (MTPA at I_max): below base speed */
    CTRL_FIELDWEAK_LIMIT_VOLTAGE = 1, /* current circle and voltage ellipse: field weakening */
    CTRL_FIELDWEAK_LIMIT_MTPV = 2,    /* voltage alone (MTPV, IPMSM with psi_pm/Ld < I_max) */
    CTRL_FIELDWEAK_LIMIT_FLUX = 3,    /* a fixed flux reference below the voltage's limit */
    CTRL_FIELDWEAK_LIMIT_COUNT = 4
} ctrl_fieldweak_limit_t;

typedef struct {
    /* configuration (field_weak_config.c) */
    int32_t v_frac; /* usable phase-voltage amplitude per unit DC link, k_mod/sqrt(3), Q30 */
    q24_t i_max;    /* current limit */
    q24_t rs_imax;  /* Rs I_max */
    q24_t rs_ipsi;  /* Rs / psi_pm: the Rs drop per unit torque (Rs |T| / psi_pm) */
    q24_t two_rs;   /* 2 Rs */
    q24_t psi_pm, ld, ld_m_lq, inv_ld; /* psi_pm, Ld, Ld - Lq (<= 0), 1/Ld */
    q24_t inv_lq2;                     /* 1/Lq^2 */
    q24_t id_star;  /* Ld psi_pm / (Lq^2 - Ld^2): least |i| on a flux circle (FX_MAX: SPMSM) */
    q24_t psi_mtpa; /* |psi_s| of MTPA at I_max */
    q24_t t_mtpa;   /* torque of MTPA at I_max */
    q24_t psi_ceil; /* psi_max at standstill (psi_pm + Lq I_max: more flux is never used) */
    q24_t b;        /* 2 Ld psi_pm */
    q24_t dl2;      /* Lq^2 - Ld^2 (>= 0) */
    q24_t c0;       /* psi_pm^2 + Lq^2 I_max^2 */
    q24_t c1, c2;   /* psi_pm / Ld, 1/Ld - 1/Lq (>= 0) */
    q24_t c1_sq;    /* c1^2 */
    q24_t c2_sq8;   /* 8 c2^2 */
    q24_t t_margin; /* fraction of the MTPV torque allowed, Q24 in (0, 1] */
    q24_t t_margin_brake; /* the same braking (w T < 0) on a fixed flux, Q24 in (0, 1] */
    q24_t vdc_k;          /* DC-link EMA coefficient per period, Q24 */
    /* state */
    int64_t vdc_acc;      /* filtered DC link, Q48 */
    uint8_t primed;       /* vdc_acc holds a sample */
    q24_t t_prev;         /* torque reference of the last calls, low-passed (the Rs terms) */
    uint8_t t_primed;     /* t_prev holds a torque */
    q24_t psi_d;          /* ctrl_fieldweak_currents: psi_d of the last solution */
    q24_t vdc_r;          /* vdc_acc rounded to Q24 (saturated), as of the last period */
    ctrl_flux_memo_t own; /* the controller's flux reference of the last clamped torque */
    /* ctrl_fieldweak_step_lazy: a region of the filtered DC link and the
     * speed, vdc_r >= lz_vdc_min and 0 < |omega| <= lz_w_max, in which
     * psi_max >= psi_mtpa for every previous torque within +-t_mtpa (its
     * corner passed the test); lz_w_max = 0: none, lz_hold periods until the
     * next attempt after a corner failed */
    q24_t lz_vdc_min, lz_w_max;
    uint8_t lz_hold;
    uint8_t lz_xv; /* lz_x holds V^2 - (Rs I)^2 - 2 Rs w T of this period (Q48) */
    int64_t lz_x;
} ctrl_fieldweak_t;

typedef struct {
    q24_t vdc;         /* filtered DC link */
    q24_t psi_max;     /* flux amplitude the voltage allows at this speed */
    q24_t torque_max;  /* |torque| limit (> = 0) */
    q24_t torque;      /* request clamped to +-torque_max */
    q24_t psi_ref;     /* stator-flux amplitude reference for torque */
    uint8_t limit;     /* ctrl_fieldweak_limit_t: what bounds torque_max */
    uint8_t clipped;   /* 1 when the request was larger than torque_max */
    uint8_t weakening; /* 1 when psi_ref is below the controller's own reference */
} ctrl_fieldweak_out_t;

/* Clear the dynamic state (the next DC-link sample primes the filter). */
void ctrl_fieldweak_reset(ctrl_fieldweak_t *s);

/*
 * One period: vdc the measured DC link, omega the electrical speed, t_req the
 * torque request, psi_cmd a commanded flux amplitude (> 0) or 0 (then the
 * machine's fixed reference p->psi_ref if > 0, else MTPA, ctrl_flux_ref).
 */
void ctrl_fieldweak_step(ctrl_fieldweak_t *s, const ctrl_params_t *p, q24_t vdc, q24_t omega,
                         q24_t t_req, q24_t psi_cmd, ctrl_fieldweak_out_t *out);

/* ctrl_fieldweak_out_t.psi_max of ctrl_fieldweak_step_lazy where it was not
 * computed. */
#define CTRL_FIELDWEAK_PSI_MAX_NOT_BINDING ((q24_t)-1)

/* The DC link's first-order low pass of a period (the ADC's noise, not its
 * dips: vdc_k is set for ~1 kHz); returns it, >= 0. */
static inline q24_t ctrl_fieldweak_vdc_filter(ctrl_fieldweak_t *s, q24_t vdc)
{
    if (s->primed == 0u) {
        s->vdc_acc = (int64_t)vdc * FX_ONE;
        s->primed = 1u;
    } else {
        /* vdc_r: the accumulator rounded, as left by the last period */
        s->vdc_acc += (int64_t)fx_sub(vdc, s->vdc_r) * s->vdc_k; /* |.| < 2^31 * 2^24 */
    }
    s->vdc_r = fx_round_sat(s->vdc_acc, FX_QBITS);
    return fx_max(s->vdc_r, 0);
}

/* Inside the lazy step's region (lz_*; speed w = |omega| > 0): there
 * psi_max >= psi_mtpa (field_weak.c, fieldweak_lazy_region). */
static inline int ctrl_fieldweak_in_region(const ctrl_fieldweak_t *s, q24_t vdc_f, q24_t w)
{
    return w <= s->lz_w_max && vdc_f >= s->lz_vdc_min && fx_abs(s->t_prev) <= s->t_mtpa;
}

/* The torque of the Rs terms after a call that let t through: t itself
 * after a reset, then t_prev += (t - t_prev) / 8 per call (|t - t_prev| <=
 * 2^32: the quotient fits). The 1/8 is per call, not per unit time: it is
 * the step of the iteration limit -> torque -> limit, which converges
 * where the limit's slope in t_prev is above -15 (with t taken whole only
 * above -1: the limit alternated between full torque and none on a
 * high-resistance motor). Primed, because from 0 the calls of the medium
 * task (1 kHz) took some 20 ms to reach the torque: the flux limit of a
 * smaller torque all that time (FST, thesis SPMSM, 3000 r/min, 2.041 N*m:
 * its flux stayed 1 % high and the torque 6.9 % low). */
static inline void ctrl_fieldweak_t_prev(ctrl_fieldweak_t *s, q24_t t)
{
    if (s->t_primed == 0u) {
        s->t_prev = t;
        s->t_primed = 1u;
    } else {
        s->t_prev = fx_add(s->t_prev, (q24_t)(((int64_t)t - s->t_prev) / 8));
    }
}

/* The outputs below base speed: the current limit, torque t (t_req
 * clamped to +-t_mtpa), the controller's own flux reference psi_own, psi_max
 * not computed. */
static inline void ctrl_fieldweak_current_limit(ctrl_fieldweak_t *s, q24_t t, q24_t t_req,
                                                q24_t psi_own, ctrl_fieldweak_out_t *out)
{
    out->psi_max = CTRL_FIELDWEAK_PSI_MAX_NOT_BINDING;
    out->torque_max = s->t_mtpa;
    out->torque = t;
    out->psi_ref = psi_own;
    out->limit = CTRL_FIELDWEAK_LIMIT_CURRENT;
    out->clipped = t != t_req ? 1u : 0u;
    out->weakening = 0u;
    ctrl_fieldweak_t_prev(s, t);
}

/* ctrl_fieldweak_step_lazy after its DC-link filter (vdc_f): out of line. */
void ctrl_fieldweak_limits_lazy(ctrl_fieldweak_t *s, const ctrl_params_t *p, q24_t vdc_f,
                                q24_t omega, q24_t t_req, ctrl_fieldweak_out_t *out);

/*
 * ctrl_fieldweak_step for the interrupt, with psi_cmd = 0: the same outputs,
 * except that psi_max is CTRL_FIELDWEAK_PSI_MAX_NOT_BINDING where the comparison of
 * squares shows it at least the MTPA flux at the current limit and the flux
 * reference of the clamped torque (below base speed: then neither the
 * torque limit nor the flux reference depends on its value), which saves
 * its square root and division; the first comparison is skipped inside a
 * region of DC link and speed where its worst case has passed (lz_*).
 * Inline the usual period below base speed - inside the region, the flux
 * reference within the MTPA flux at the current limit - and out of line
 * the rest (ctrl_fieldweak_limits_lazy).
 */
static inline void ctrl_fieldweak_step_lazy(ctrl_fieldweak_t *s, const ctrl_params_t *p, q24_t vdc,
                                            q24_t omega, q24_t t_req, ctrl_fieldweak_out_t *out)
{
    const q24_t vdc_f = ctrl_fieldweak_vdc_filter(s, vdc);
    const q24_t w = fx_abs(omega);
    if (p->psi_ref <= 0 && w != 0 && ctrl_fieldweak_in_region(s, vdc_f, w)) {
        const q24_t t = fx_clamp(t_req, fx_neg(s->t_mtpa), s->t_mtpa);
        /* psi_ref <= 0, no command: ctrl_flux_ref is the MTPA flux of t */
        const q24_t psi_own = ctrl_flux_ref_memo(&s->own, p, 0, t);
        if (psi_own <= s->psi_mtpa) {
            out->vdc = vdc_f;
            ctrl_fieldweak_current_limit(s, t, t_req, psi_own, out);
            return;
        }
    }
    ctrl_fieldweak_limits_lazy(s, p, vdc_f, omega, t_req, out);
}

/* Torque limit and its kind at flux amplitude psi in field weakening (the
 * flux-circle part above), at most margin (Q24, s->t_margin or
 * s->t_margin_brake) of the MTPV torque; for tests and tools. */
q24_t ctrl_fieldweak_torque_at_flux(const ctrl_fieldweak_t *s, q24_t psi, q24_t margin,
                                    uint8_t *limit);

/*
 * Current references (FOC) for torque t at the flux reference psi_ref of
 * ctrl_fieldweak_step: the MTPA currents (ctrl_mtpa_current) when their flux
 * is within psi_ref, else the point of torque t on the flux circle psi_ref
 * between MTPV and zero torque, where T = psi_q (c1 - c2 psi_d) falls
 * strictly as psi_d rises: three bracketed Newton steps in psi_d per call
 * from the previous call's solution (kept in s; bisection when a step leaves
 * the bracket): i_d = (psi_d - psi_pm) / Ld, i_q = psi_q / Lq with the sign
 * of t. |t| above the arc's maximum gives the MTPV point.
 */
void ctrl_fieldweak_currents(ctrl_fieldweak_t *s, const ctrl_params_t *p, q24_t t, q24_t psi_ref,
                             q24_t *i_d, q24_t *i_q);

#endif /* CONTROL_FIELD_WEAK_H */
