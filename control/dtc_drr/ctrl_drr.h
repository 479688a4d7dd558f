/*
 * Duty-ratio-regulated DTC (thesis chapter 5) and the duty-ratio baselines of
 * §5.5, each period an active vector for D Ts, then the zero vector (§5.3.1):
 *
 *   drr     multiobjective DRR-DTC (§5.3-§5.4): active vector (5.1), virtual
 *           reference with the EMA (5.3)-(5.5), MTPA flux reference (4.15) of
 *           T_vref, voltage replacement (4.19)-(4.21) while |psi_err| <
 *           dpsi_max / 2 (§5.3.5), optimised duty (5.14) with (5.6)-(5.10),
 *           (5.13), zero vector of §5.4;
 *   drr_d1  D1 (5.19);  drr_d2  D2 (5.21);  drr_pi  D_PI (5.20);
 *   drr_df  D_f (5.18) or D_RMS (5.17) with the deviations of (4.10).
 *
 * Decisions on the k+1 prediction; torque at k+1 from the estimator's model
 * (tunable pred_516 = 1: (5.16)); with centre-aligned PWM (5.3) and (5.8)-(5.14)
 * are evaluated at the active-vector start (tunable centre, default 1). The
 * zero-vector deviation of (5.6), (5.7), (5.13) and (5.16) is
 * -(B/w_rn) w - (Rs Ts/Ls) T_e: the speed term of the thesis plus the resistive
 * term of (4.10) that (5.10) drops ("T_e = 0"), s->rt = (Rs Ts/Ls) T_e of the
 * sample (tunable rs_dt, default 1; 0 = the thesis' load-free model). One
 * division per period for the duty, one more for C gamma when C follows the
 * speed (5.13). Units: Q24 per-unit throughout; A (5.9) = (2/3) Vdc psi_pm Ts
 * / Ls, B (5.10) / w_rn = psi_pm^2 Ts / Ls in pu. Reasoning and measured
 * effects: docs/algorithms.md, "Duty-ratio-regulated DTC".
 */
#ifndef CONTROL_CTRL_DRR_H
#define CONTROL_CTRL_DRR_H

#include <stdint.h>

#include "controller.h"
#include "ctrl_params.h"
#include "ctrl_types.h"
#include "fx.h"
#include "mtpa.h"
#include "vreplace.h"

#define CTRL_DRR_FS_HZ 10000u /* thesis §5.6: DRR methods at 10 kHz */
#define CTRL_DRR_C_MAX 64     /* |C| of (5.13) is clamped to this (see ctrl_drr.c) */

/* ---------------- drr: runtime state ---------------- */
typedef struct {
    /* configuration, fixed point */
    q24_t a;         /* A, pu torque */
    q24_t kb;        /* B / w_rn, pu torque per pu electrical speed */
    q24_t sqrt3_a;   /* sqrt(3) A: (5.13) denominator term */
    q24_t c_num;     /* (5.13) numerator 2 sqrt(3) A; with a fixed C: -C */
    q24_t dc_fixed;  /* 0: C = c_num / (2 kb |w| - sqrt(3) A); else -FX_ONE (C = -c_num) */
    q24_t dc_max;    /* (5.13) denominator clamp, < 0: |C| <= CTRL_DRR_C_MAX */
    q24_t lambda;    /* (5.4), Q24 */
    q24_t half_dpsi; /* dpsi_max / 2, pu flux */
    q24_t gamma_max; /* pu torque: (5.4) holds while |error| > gamma_max + |kb w + rt| */
    q24_t r_ts;      /* Rs Ts / Ls, per period (Q24): resistive ZVV deviation; 0 = off */
    ctrl_vreplace_t vr;
    uint8_t pred_516;
    uint8_t centre; /* T_e taken at the active-vector start of a centre-aligned period */

    /* A (5.9) and B (5.10) scale as psi_pm and psi_pm^2: per pu of PM flux,
     * Q24 (0: given as tunables, fixed), and the params->psi_pm they were
     * formed for; recomputed when the pipeline's PM-flux estimate moves. */
    q24_t a_psi, kb_psi2, psi_seen;

    /* dynamic */
    q24_t rt;        /* r_ts T_e of this sample, pu torque (set by ctrl_drr_step) */
    q24_t gamma;     /* EMA output gamma[k-1] -> gamma[k], pu torque (5.4) */
    q24_t dt_sel;    /* Delta T of the vector chosen at k-1 (for (5.16)), pu */
    uint8_t vec_sel; /* vector chosen at k-1 (0 after reset) */
    /* last decision, for telemetry and tests */
    q24_t last_tvref;             /* virtual reference T_vref (5.3), Q24 pu torque */
    q24_t last_psiref;            /* flux reference, Q24 pu flux */
    q24_t last_terr, last_psierr; /* T_vref - Te, Q24 pu torque; psi_ref - |psi|, Q24 pu flux */
    q24_t last_duty;              /* duty (5.14), Q24 fraction of the period */
    uint8_t last_vec_51;          /* vector by (5.1) before replacement */
} ctrl_drr_state_t;

/* ---------------- baselines: runtime state (SI configuration in ctrl_drr_config.h) ------ */
typedef enum {
    CTRL_DRR_BASE_D1 = 0,
    CTRL_DRR_BASE_D2,
    CTRL_DRR_BASE_PI,
    CTRL_DRR_BASE_DF
} ctrl_drr_base_kind_t;

typedef struct {
    uint8_t kind;                 /* ctrl_drr_base_kind_t */
    uint8_t rms;                  /* D_f: 1 = D_RMS (5.17) */
    q24_t inv_ct;                 /* D1: 1 / C_T, Q24 per pu torque */
    q24_t inv_cpsi;               /* D1: 1 / C_psi, Q24 per pu flux */
    q24_t ka;                     /* D2: K_a, pu torque */
    q24_t kb;                     /* D2: K_b, pu torque per pu electrical speed */
    q24_t kp;                     /* D_PI: K_P, per pu torque */
    q24_t ki_ts;                  /* D_PI: K_I Ts, per pu torque */
    q24_t ff;                     /* D_PI: 3 psi_pm / (2 Vdc), per pu electrical speed */
    q24_t ts_l;                   /* D_f: Ts / Ls (pu) */
    q24_t rs_l;                   /* D_f: Rs / Ls (pu) */
    q24_t integ;                  /* D_PI integrator (duty units, clamped to [-1, 1]) */
    q24_t last_duty;              /* last duty, Q24 fraction of the period */
    q24_t last_terr, last_psierr; /* T_ref - Te, Q24 pu torque; psi_ref - |psi|, Q24 pu flux */
    ctrl_flux_memo_t flux_ref;    /* the flux reference of T_ref (mtpa.h) */
} ctrl_drr_base_state_t;

/* ---------------- per-sample building blocks (ctrl_drr.c, integer-only) ---------------- */

/* Active vector by (5.1) for sector x (1..6): V_{x+1} (T_err >= 0, psi_err >= 0),
 * V_{x+2} (T_err >= 0, psi_err < 0), V_{x+4} (< 0, < 0), V_{x+5} (< 0, >= 0).
 * A sector outside 1..6 is wrapped by ctrl_vec_wrap arithmetic. */
uint8_t ctrl_drr_select(uint8_t sector, q24_t t_err, q24_t psi_err);

/* One step of the EMA (5.4): gamma + lambda (chi - gamma), rounded, saturated. */
q24_t ctrl_drr_ema(q24_t gamma, q24_t chi, q24_t lambda);

/* Is the voltage replacement of §5.3.5 allowed: |psi_err| < dpsi_max / 2. */
int ctrl_drr_vreplace_active(const ctrl_drr_state_t *s, q24_t psi_err);

/* (5.13) as the pair (C numerator, denominator) used by ctrl_drr_duty:
 * C = *c_num / *dc, with dc clamped to <= s->dc_max (< 0). */
void ctrl_drr_c_parts(const ctrl_drr_state_t *s, q24_t omega_e, q24_t *c_num, q24_t *dc);

/*
 * Optimised duty (5.14) of active vector vec (1..6) for the flux (psi_alpha,
 * psi_beta) of amplitude psi_amp, torque error t_err = T_vref - T_e, EMA
 * output gamma and electrical speed omega_e (all Q24 pu), with
 * Delta T = A (psi x v_hat) / |psi| - (B / w_rn) w - s->rt  ((5.6)/(5.7), s->rt the
 * resistive term of (4.10) set by ctrl_drr_step, 0 with rs_dt off: psi x v_hat =
 * |psi| |sin(theta_s - theta_v)| with the sign of the vector's family).
 * The branch (numerator/denominator pair) is chosen by the sign of t_err (5.8).
 * Result in [0, FX_ONE]; one fx_div. If the denominator has the sign opposite
 * to the branch (C gamma overstates the zero-vector deviation, possible while
 * gamma settles), the result is FX_ONE: by (5.6)/(5.7) the active vector always
 * moves the torque further in the wanted direction than a zero vector.
 */
q24_t ctrl_drr_duty(const ctrl_drr_state_t *s, uint8_t vec, q24_t psi_alpha, q24_t psi_beta,
                    q24_t psi_amp, q24_t t_err, q24_t gamma, q24_t omega_e);

/*
 * Torque where the active vector starts, for a plan realised centre-aligned
 * (plan.h): the thesis' period begins with the active vector (Fig. 5.4), so
 * T_e of (5.8)-(5.14) and T_min of (5.3) are taken there; in a centre-aligned
 * period (1 - D)/2 of zero vector comes first:
 *   T_start = T(k+1) + (1 - D)/2 C gamma    (zero-vector deviation (5.12)),
 * D = s->last_duty (steady state), gamma = s->gamma. Without it the sampled
 * torque sits half-way down the zero-vector slope (at the mean) and the
 * virtual reference leaves a mean error of about gamma. One fx_div (C).
 */
q24_t ctrl_drr_t_start(const ctrl_drr_state_t *s, q24_t t_k1, q24_t omega_e);

/* Delta T of (5.6)/(5.7) for vector vec at flux psi and speed omega_e, pu (one fx_div;
 * used by the (5.16) prediction and by tests). */
q24_t ctrl_drr_delta_t(const ctrl_drr_state_t *s, uint8_t vec, q24_t psi_alpha, q24_t psi_beta,
                       q24_t psi_amp, q24_t omega_e);

/* Duty of each baseline for the already selected vector (tests use these). */
q24_t ctrl_drr_duty_d1(const ctrl_drr_base_state_t *s, q24_t t_err, q24_t psi_err);
q24_t ctrl_drr_duty_d2(const ctrl_drr_base_state_t *s, q24_t t_err, q24_t omega_e);
/* D_PI with the integrator value after this sample's update (s->integ not changed). */
q24_t ctrl_drr_duty_pi(const ctrl_drr_base_state_t *s, q24_t t_err, q24_t integ, q24_t omega_e);
/* D_f / D_RMS with (4.10) at the predicted state m (flux, rotor angle sin/cos). */
q24_t ctrl_drr_duty_df(const ctrl_drr_base_state_t *s, const ctrl_params_t *p,
                       const ctrl_mstate_t *m, uint8_t vec, q24_t vdc, q24_t t_err, q24_t omega_e);

/* The descriptors. */
extern const ctrl_desc_t ctrl_desc_drr;
extern const ctrl_desc_t ctrl_desc_drr_d1;
extern const ctrl_desc_t ctrl_desc_drr_d2;
extern const ctrl_desc_t ctrl_desc_drr_pi;
extern const ctrl_desc_t ctrl_desc_drr_df;

/* ---- Internal: shared by ctrl_drr*.c and ctrl_drr_config.c. ---- */
void ctrl_drr_reset(void *state);
void ctrl_drr_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out);
void ctrl_drr_base_reset(void *state);
void ctrl_drr_base_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out);

#endif /* CONTROL_CTRL_DRR_H */
