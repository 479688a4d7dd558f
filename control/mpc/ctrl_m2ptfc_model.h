/*
 * k+2 prediction model shared by the modulated predictive controllers of
 * thesis chapter 6 (m2ptfc, m1, mptfc, m3, m2).
 *
 * The estimator hands over the state at k+1; a vector chosen now acts during
 * [k+1, k+2), so every candidate is evaluated at k+2 (§6.3.4). With
 * psi(k+2) = psi0 + D Ts V_i, psi0 = psi(k+1) - Ts Rs i(k+1) (6.10), linear in
 * the duty D, psi0 and every Ts V_i are rotated once into the rotor frame at
 * theta(k+2); there Te = psi_q (a + b psi_d) (3.10)/(6.11) with a = psi_pm/Ld,
 * b = 1/Lq - 1/Ld, and |psi|^2 = psi_d^2 + psi_q^2: one rotation, no square
 * root per period (docs/algorithms.md, "The k+2 model").
 *
 * All q24_t values are Q24 per-unit (bases in ctrl_params.h).
 */
#ifndef CONTROL_CTRL_M2PTFC_MODEL_H
#define CONTROL_CTRL_M2PTFC_MODEL_H

#include <stdint.h>

#include "controller.h"
#include "ctrl_params.h"
#include "ctrl_types.h"
#include "fx.h"
#include "mtpa.h"
#include "plan.h"
#include "vectors.h"

/* Model constants, computed once from the machine (ctrl_m2ptfc_model_config.c). */
typedef struct {
    q24_t a;       /* psi_pm / Ld, Q24 pu */
    q24_t b;       /* 1/Lq - 1/Ld, Q24 pu (0 for an SPMSM, < 0 for an IPMSM) */
    q24_t ts_rs;   /* Ts Rs, Q24 pu */
    q24_t ts_v;    /* Ts * 2/3: |V_i| Ts per pu of DC link, Q24 pu */
    q24_t vdc_max; /* DC-link clamp of the basis, 2 x nominal, Q24 pu
                    * (ts_v vdc_max <= CTRL_MPC_TSV_MAX) */

    /* a per pu of PM flux (1/Ld), Q24, 0: a fixed (psi_pm_model given); the
     * params->psi_pm a was formed for (ctrl_mpc_model_track). */
    q24_t a_psi, psi_seen;
} ctrl_mpc_model_t;

/* Per-sample prediction basis in the rotor frame at theta(k+2). Ranges (the
 * bounds the fast arithmetic below relies on): |d0|, |q0| <= 8 sqrt(2) pu
 * (psi0 clamped to [-8, 8) pu per rotor-frame component), |wd|, |wq| <= 16 pu. */
typedef struct {
    q24_t d0, q0;       /* psi(k+2) with a zero vector, rotor frame, Q24 pu */
    q24_t wd[6], wq[6]; /* Ts V_1 .. Ts V_6 in the same frame (index i - 1), Q24 pu */
    q24_t t0;           /* Te(k+2) with a zero vector, Q24 pu */
} ctrl_mpc_basis_t;

/* The same basis with only V1..V3 (V_{i+3} = -V_i): for controllers that use
 * two candidates (m2ptfc), ctrl_mpc_vec3_dq() gives any V_i. Same ranges and
 * the same values as ctrl_mpc_basis_t (bit-identical arithmetic). */
typedef struct {
    q24_t d0, q0;       /* psi(k+2) with a zero vector, rotor frame, Q24 pu */
    q24_t wd[3], wq[3]; /* Ts V_1 .. Ts V_3, rotor frame (index i - 1), Q24 pu */
    q24_t t0;           /* Te(k+2) with a zero vector, Q24 pu */
} ctrl_mpc_basis3_t;

/* Model limits checked by ctrl_mpc_model_init (CTRL_ERANGE outside). */
#define CTRL_MPC_AB_MAX (2 * FX_ONE)    /* |a|, |b| <= 2 pu */
#define CTRL_MPC_TSV_MAX (16 * FX_ONE)  /* |Ts V_i| at the DC-link clamp <= 16 pu */
#define CTRL_MPC_TS_RS_MAX FX_ONE       /* Ts Rs <= 1 pu */
#define CTRL_MPC_PSI_CLAMP (8 * FX_ONE) /* psi0 components within [-8, 8) pu */
#define CTRL_MPC_I_CLAMP (64 * FX_ONE)  /* i(k+1) components within [-64, 64) pu */
#define CTRL_MPC_PSI_MAX 7.0            /* |psi| at current_max, pu: inside the clamp */

/* Candidate trace of the last step (for tests and telemetry). */
#define CTRL_MPC_TRACE_MAX 17
typedef struct {
    uint8_t n;                       /* number of candidates evaluated */
    uint8_t vec[CTRL_MPC_TRACE_MAX]; /* candidate vector 0..7 (0/7: zero vector) */
    q24_t duty[CTRL_MPC_TRACE_MAX];  /* its duty, Q24 fraction of the period */
} ctrl_mpc_trace_t;

/* State shared by the weighted-cost controllers m1, m3 and mptfc (cost
 * (6.13) with one weight zeta and the k+2 model); their SI configuration,
 * ctrl_mpc_wcfg_t, is in ctrl_m2ptfc_model_config.h. */
typedef struct {
    ctrl_mpc_model_t model;
    q24_t zeta;             /* Q24 pu (T_base / psi_base) */
    uint8_t last_vec;       /* segment 0 of the last plan (0 after reset) */
    ctrl_mpc_trace_t trace; /* candidates of the last step (see each controller) */
    ctrl_flux_memo_t flux;  /* the flux reference (ctrl_mpc_in) */
} ctrl_mpc_wstate_t;

/* ---- per sample (ctrl_m2ptfc_model.c, integer only) ---- */

/* ctrl_desc_t.reset of m1, m3, mptfc (ctrl_mpc_wstate_t): clears the trace
 * and the last vector; the controllers keep no other dynamic state. */
void ctrl_mpc_wreset(void *state);

/* a = psi_pm / Ld for the PM flux in use: when the pipeline tracks psi_pm
 * from the voltage model (fw_config_t.psi_adapt) params->psi_pm moves and the
 * k+2 model follows it (unless its psi_pm is fixed by psi_pm_model). Called
 * at the start of each step; nothing changes while psi_pm does not. */
static inline void ctrl_mpc_model_track(ctrl_mpc_model_t *m, const ctrl_params_t *p)
{
    if (p->psi_pm != m->psi_seen && m->a_psi != 0) {
        m->psi_seen = p->psi_pm;
        m->a = fx_mul(m->a_psi, p->psi_pm);
    }
}

/* Basis for the candidates of this sample from the k+1 state of est (rotor
 * frame, with next.sin_theta/cos_theta: CTRL_EST_SC_NEXT) and its rotation
 * over one period (rot_c, rot_s). */
void ctrl_mpc_basis(const ctrl_mpc_model_t *m, const ctrl_estimate_t *est, ctrl_mpc_basis_t *b);

/* What the six-candidate steps (M1, M2, M3, FS-MPTFC) start from: the model
 * following psi_pm (ctrl_mpc_model_track), the basis and the references, the flux one from
 * ctrl_flux_ref (MTPA (4.15) when the command is 0), memoised in flux. */
typedef struct {
    ctrl_mpc_basis_t b;
    q24_t t_ref;   /* torque reference, Q24 pu */
    q24_t psi_ref; /* flux reference, Q24 pu */
} ctrl_mpc_in_t;

static inline void ctrl_mpc_in(ctrl_mpc_model_t *m, ctrl_flux_memo_t *flux, const ctrl_ctx_t *ctx,
                               ctrl_mpc_in_t *in)
{
    ctrl_mpc_model_track(m, ctx->params);
    ctrl_mpc_basis(m, ctx->est, &in->b);
    in->t_ref = ctx->ref->torque;
    in->psi_ref = ctrl_flux_ref_memo(flux, ctx->params, ctx->ref->psi, ctx->ref->torque);
}

/* ctrl_mpc_basis() with V1..V3 only (no V4..V6): the same d0, q0, t0 and
 * wd/wq[0..2] bit for bit. */
void ctrl_mpc_basis3(const ctrl_mpc_model_t *m, const ctrl_estimate_t *est, ctrl_mpc_basis3_t *b);

/* The flux reference ctrl_flux_ref (mtpa.h) of the torque reference, squared, in ctrl_mpc_amp2
 * units (Q24 pu^2), for the amplitude comparisons on squares: for the SPMSM MTPA, (4.15) squared,
 * psi_pm^2 + (Lq T / psi_pm)^2, needs no square root (saves 69 of the
 * m2ptfc step's 697 Cortex-M4 instructions, tests/mpc/bench_mpc_qemu.c); the
 * other cases square the amplitude. */
int32_t ctrl_mpc_psi_ref2(const ctrl_params_t *p, const ctrl_refs_t *ref);

/* A zero vector for the whole period after a plan whose segment 0 was
 * last_vec (the one that switches one leg), recorded as the new last vector. */
static inline void ctrl_mpc_out_zero(ctrl_out_t *out, uint8_t *last_vec)
{
    const uint8_t z = *last_vec <= 7u ? ctrl_vec_zero_after[*last_vec] : 0u;
    ctrl_out_single(out, z);
    *last_vec = z;
}

/* n / d as a Q24 fraction for 0 <= n <= d, d > 0, rounded (<= FX_ONE). Three
 * 32-bit divisions (one UDIV each on a Cortex-M4), no 64-bit division; inline
 * (one call site per step). */
static inline q24_t ctrl_mpc_ratio(uint32_t n, uint32_t d)
{
    if (d == 0u || n >= d) {
        return FX_ONE;
    }
    /* Keep d below 2^24 so that r * 2^8 < 2^32 below (never taken for
     * realistic torque deviations, which are far below 1 pu = 2^24). */
    while (d >= ((uint32_t)1 << 24)) {
        d >>= 1;
        n >>= 1;
    }
    /* Long division in three 8-bit digits: q = n 2^24 / d, n < d. Then
     * q < 2^24 and the rounded q <= 2^24 = FX_ONE: no clamp. */
    uint32_t r = n;
    const uint32_t q = fx_udiv_digits(0u, &r, d, 8u, 3u);
    return (q24_t)fx_udiv_round(q, r, d);
}

/* num / den clamped to [0, FX_ONE] (duty of (5.18)); den == 0 gives FX_ONE for
 * num > 0, else 0. Inline: per candidate of the six-vector searches. */
static inline q24_t ctrl_mpc_duty_sat(q24_t num, q24_t den)
{
    if (den == 0) {
        return num > 0 ? FX_ONE : 0;
    }
    if (num == 0 || (num < 0) != (den < 0)) {
        return 0; /* num / den <= 0 */
    }
    /* Magnitudes as uint32_t (exact also for INT32_MIN); n >= d gives FX_ONE. */
    const uint32_t n = num < 0 ? 0u - (uint32_t)num : (uint32_t)num;
    const uint32_t d = den < 0 ? 0u - (uint32_t)den : (uint32_t)den;
    return ctrl_mpc_ratio(n, d);
}

/* ---- bounded fast arithmetic of the k+2 model ----
 * With the ranges of ctrl_mpc_basis_t and the model limits every product
 * below is below 2^55 in magnitude, so its Q24 result fits an int32_t without
 * saturation: a rounding multiply is a 32x32->64 multiply, an add and a
 * shift: fx_mul_nosat / fx_dot_nosat of fx.h (fx_mul's saturation costs
 * more on a Cortex-M4). Same rounding as fx_mul (to nearest, ties up). */

/* Ts V_i (i = 1..6) in the rotor frame at k+2. */
static inline void ctrl_mpc_vec_dq(const ctrl_mpc_basis_t *b, uint8_t i, q24_t *vd, q24_t *vq)
{
    *vd = b->wd[i - 1u];
    *vq = b->wq[i - 1u];
}

/* Ts V_i (i = 1..6) from a ctrl_mpc_basis3_t: V_i for i <= 3, else -V_{i-3}
 * (equal to ctrl_mpc_vec_dq of the full basis; |w| <= 16 pu, no overflow). */
static inline void ctrl_mpc_vec3_dq(const ctrl_mpc_basis3_t *b, uint8_t i, q24_t *vd, q24_t *vq)
{
    if (i > 3u) {
        *vd = -b->wd[i - 4u];
        *vq = -b->wq[i - 4u];
    } else {
        *vd = b->wd[i - 1u];
        *vq = b->wq[i - 1u];
    }
}

/* Te = psi_q (a + b psi_d), (3.6)/(6.11) with (6.12) in the rotor frame, for a
 * flux of the basis' range (|psi_d| <= 28 pu): |b psi_d| < 2^55 (|b| <= 2 pu);
 * the last product saturates. */
static inline q24_t ctrl_mpc_torque(const ctrl_mpc_model_t *m, q24_t psi_d, q24_t psi_q)
{
    /* b = 0 (SPMSM): b psi_d is 0, the same value without the product */
    return fx_mul(psi_q, m->b != 0 ? m->a + fx_mul_nosat(m->b, psi_d) : m->a);
}

/* Ceiling of ctrl_mpc_amp2: 64 pu^2 in Q24. */
#define CTRL_MPC_AMP2_MAX ((int32_t)1 << 30)

/* |psi|^2 in Q24 pu^2, rounded, clamped to [0, CTRL_MPC_AMP2_MAX] (|psi| <= 8 pu,
 * far beyond any reachable flux; the clamp keeps ctrl_mpc_closer's products in range). */
static inline int32_t ctrl_mpc_amp2(q24_t psi_d, q24_t psi_q)
{
    const uint64_t sq = (uint64_t)((int64_t)psi_d * psi_d) + (uint64_t)((int64_t)psi_q * psi_q);
    const uint64_t a2 = (sq + ((uint64_t)1 << 23)) >> 24;
    return a2 > (uint64_t)CTRL_MPC_AMP2_MAX ? CTRL_MPC_AMP2_MAX : (int32_t)a2;
}

/* -1 when |r - a| < |r - b|, +1 when greater, 0 when equal, for amplitudes
 * a, b >= 0 and reference r >= 0 given by their squares, Q24 pu^2 as
 * ctrl_mpc_amp2 returns them: a2, b2 in [0, CTRL_MPC_AMP2_MAX], r2 >= 0 (taken
 * at most 16 pu^2). Exact integer test of sign((a - b)(a + b - 2r)) =
 * sign(|r - a| - |r - b|): no square root. a + b > 2r <=> A + B + 2 sqrt(AB)
 * > 4R <=> S = 4R - A - B < 0 or 4AB > S^2; with these ranges S lies in
 * [-2^31, 2^30] (an int32_t) and 4AB = (2A)(2B) <= 2^62, S^2 <= 2^60 are
 * unsigned 32x32->64 products (one UMULL each on a Cortex-M4). */
static inline int ctrl_mpc_closer(int32_t a2, int32_t b2, int32_t r2)
{
    const int32_t r = r2 < ((int32_t)1 << 28) ? r2 : ((int32_t)1 << 28); /* r <= 4 pu */
    const int sab = (a2 > b2) - (a2 < b2);                               /* sign(a - b) */
    const int32_t sum = 4 * r - a2 - b2;
    if (sab == 0 || sum < 0) {
        return sab; /* sign(a + b - 2r) = +1 when S < 0 */
    }
    const uint64_t lhs = (uint64_t)(2u * (uint32_t)a2) * (2u * (uint32_t)b2);
    const uint64_t rhs = (uint64_t)(uint32_t)sum * (uint32_t)sum;
    return lhs > rhs ? sab : (lhs < rhs ? -sab : 0);
}

/* Flux of a candidate: psi0 + D Ts V, rotor frame, for 0 <= duty <= FX_ONE
 * and (vd, vq) from ctrl_mpc_vec_dq (or 0): |psi| components <= 27.4 pu. */
static inline void ctrl_mpc_flux(const ctrl_mpc_basis_t *b, q24_t vd, q24_t vq, q24_t duty,
                                 q24_t *psi_d, q24_t *psi_q)
{
    *psi_d = b->d0 + fx_mul_nosat(duty, vd);
    *psi_q = b->q0 + fx_mul_nosat(duty, vq);
}

/* Weighted cost (6.13) of a candidate whose flux psi(k+2) = (pd, pq) and
 * torque te = Te(k+2) are known: |T_ref - te| + zeta |psi_ref - |psi||, Q24 pu
 * (64-bit, no overflow); the amplitude needs one fx_mag (square root).
 * INT64_MAX instead when the torque term alone is at least bound: the flux
 * term is >= 0 (zeta >= 0), so that cost is not below bound and a search
 * that keeps the strictly smallest cost (bound = the best so far) decides
 * exactly as with the full cost, without the square root. */
static inline int64_t ctrl_mpc_cost_at(q24_t pd, q24_t pq, q24_t te, q24_t t_ref, q24_t psi_ref,
                                       q24_t zeta, int64_t bound)
{
    const int64_t e_t = (int64_t)t_ref - te;
    const int64_t g_t = e_t < 0 ? -e_t : e_t;
    if (g_t >= bound) {
        return INT64_MAX; /* g_t + zeta e_psi >= bound: no square root needed */
    }
    const q24_t e_psi = fx_abs(fx_sub(psi_ref, fx_mag(pd, pq)));
    return g_t + fx_mul(zeta, e_psi);
}

/* ctrl_mpc_cost_at of a candidate: the active vector with Ts V = (vd, vq) on
 * for duty, the zero vector the rest (flux ctrl_mpc_flux, torque
 * ctrl_mpc_torque). Inline: per candidate of the searches. */
static inline int64_t ctrl_mpc_cost_weighted(const ctrl_mpc_model_t *m, const ctrl_mpc_basis_t *b,
                                             q24_t vd, q24_t vq, q24_t duty, q24_t t_ref,
                                             q24_t psi_ref, q24_t zeta, int64_t bound)
{
    q24_t pd;
    q24_t pq;
    ctrl_mpc_flux(b, vd, vq, duty, &pd, &pq);
    return ctrl_mpc_cost_at(pd, pq, ctrl_mpc_torque(m, pd, pq), t_ref, psi_ref, zeta, bound);
}

/* ctrl_mpc_cost_weighted of the candidate (vd, vq) with duty (5.18), t_full
 * its Te(k+2) with the duty 1: a duty of 0 or FX_ONE takes the flux and torque
 * already formed (psi0 and t0, or psi0 + Ts V and t_full: what ctrl_mpc_flux
 * and ctrl_mpc_torque give for them, bit for bit). */
static inline int64_t ctrl_mpc_cost_duty(const ctrl_mpc_model_t *m, const ctrl_mpc_basis_t *b,
                                         q24_t vd, q24_t vq, q24_t duty, q24_t t_full, q24_t t_ref,
                                         q24_t psi_ref, q24_t zeta, int64_t bound)
{
    if (duty == 0) {
        return ctrl_mpc_cost_at(b->d0, b->q0, b->t0, t_ref, psi_ref, zeta, bound);
    }
    if (duty == FX_ONE) {
        return ctrl_mpc_cost_at(b->d0 + vd, b->q0 + vq, t_full, t_ref, psi_ref, zeta, bound);
    }
    return ctrl_mpc_cost_weighted(m, b, vd, vq, duty, t_ref, psi_ref, zeta, bound);
}

#endif /* CONTROL_CTRL_M2PTFC_MODEL_H */
