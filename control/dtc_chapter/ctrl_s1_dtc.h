/*
 * DTC controllers of the book chapter (S1): "hdtc" (§3, S1 Table 3 = thesis
 * Table 4.1), "svm_dtc" (§4, S1(17)-(20), Fig. 25) and "hpdtc" (§5, S1
 * Table 4, S1(40), §5.2.3); "hdtc_pred", this project's variant of hdtc.
 *
 * hdtc decides on the sampled errors (k), as the chapter does; the others on
 * the k+1 prediction. Flux reference: ref->psi, else the tunable
 * psi_ref (Wb), else the machine's psi_ref, else psi_pm (S1 §4, §6.1.4). Bands
 * of S1 §3.3 / §6.1.4: 0.01 Wb and 0.01 N*m (half widths, SI).
 *
 * svm_dtc: a PI on the torque error (pu of the torque base) gives the
 * load-angle increment Delta delta (rad) (S1 §4.1: Kp = 1, Ki = 0.03 per
 * sample), V_ref = (psi_ref e^{j(lambda_s + Delta delta)} - psi_s e^{j lambda_s})
 * / Ts + Rs i_s S1(19)-(20), by SVPWM; optional feed-forward omega_e Ts.
 * hpdtc: two adjacent vectors of S1 Table 4, on-times from a 5 x 5 timing
 * table (voltage level from |T_err|, reflected flux position S1(40)) generated
 * at init from space-vector geometry; the rest split between V0 and V7.
 * Gain units, default e_fs and the table's derivation: docs/algorithms.md.
 */
#ifndef CONTROL_CTRL_S1_DTC_H
#define CONTROL_CTRL_S1_DTC_H

#include <stdint.h>

#include "controller.h"
#include "fx.h"
#include "hysteresis.h"

/* The timing table's partition (S1 §5.2.3: 20 points, 5 levels, 5 sections).
 * POINTS and LEVELS may be overridden at build time (-DHPDTC_POINTS=...) for
 * the finer partitions S1 §5.3.2 mentions (tools/analyses.py --partitions; up
 * to about 10 levels fit the controller state); the sections are fixed by
 * ctrl_hpdtc_section's boundaries. */
#ifndef HPDTC_POINTS
#define HPDTC_POINTS 20 /* points per period */
#endif
#ifndef HPDTC_LEVELS
#define HPDTC_LEVELS 5 /* voltage levels */
#endif
#if HPDTC_POINTS < 1 || HPDTC_POINTS > 255 || HPDTC_LEVELS < 2
#error "HPDTC_POINTS must be 1..255 (uint8_t table), HPDTC_LEVELS at least 2"
#endif
#define HPDTC_SECTIONS 5 /* reflected-position sections of 12 deg */

typedef struct {
    q24_t psi_ref; /* Q24 pu, > 0 */
    /* flux regulator on |psi(k+1)|^2 (no square root), its limits formed
     * for the reference flux_lim_ref (Q24 pu; 0 after init: none yet) */
    ctrl_hyst2_sq_t flux;
    q24_t flux_lim_ref;
    ctrl_hyst3_t torque;
    uint8_t prev_vec;
} ctrl_hdtc_state_t;

typedef struct {
    q24_t psi_ref;         /* Q24 pu, > 0 */
    q24_t kp;              /* rad per pu torque, Q24 */
    int32_t ki;            /* rad per (pu torque * sample), Q30 */
    int64_t integ;         /* integrator, rad, Q40 */
    int32_t inv_ts;        /* 1 / Ts_pu, Q16 (Ts_pu >= 1e-3: up to 1000) */
    uint8_t ff;            /* omega_e Ts feed-forward on */
    uint8_t limited;       /* last voltage limited by the hexagon */
    q24_t dd;              /* last Delta delta, rad Q24 (telemetry/tests) */
    q24_t v_alpha, v_beta; /* last reference before limiting, Q24 pu (tests) */
} ctrl_svm_dtc_state_t;

typedef struct {
    q24_t psi_ref; /* Q24 pu, > 0 */
    /* phi, tau of Table 4 (two-level); phi on |psi(k+1)|^2 as hdtc's */
    ctrl_hyst2_sq_t flux;
    q24_t flux_lim_ref;
    ctrl_hyst2_t torque;
    q24_t lvl_thr[HPDTC_LEVELS - 1];              /* |T_err| thresholds l e_fs / 5, Q24 pu */
    uint8_t pts[HPDTC_LEVELS][HPDTC_SECTIONS][2]; /* (t_k1, t_k2) in points */
    q24_t dur[HPDTC_LEVELS][HPDTC_SECTIONS][2];   /* the same, Q24 fraction of Ts */
    uint8_t last_level, last_section;             /* telemetry/tests: 0..4 each */
} ctrl_hpdtc_state_t;

/* S1 Table 4: V_k1, V_k2 for flux regulator output phi (1 = increase, 0 =
 * decrease), torque tau (1 / 0) and sector n 1..6 (any int wraps); returns the
 * reflection sign s (+1 when phi == tau, else -1): the reflected position of
 * the flux seen from V_k1 is s * rho (README, "HP-DTC timing table"). */
int ctrl_hpdtc_vectors(int phi, int tau, int n, uint8_t *k1, uint8_t *k2);

/* Section -2..2 (12 deg each, centres 0, +-12, +-24 deg) of rho = the angle of
 * (psi_alpha, psi_beta) from the centre of its sector n (4.5), in [-30, 30) deg:
 * S1(40) with lambda_s measured from the start of the sector. */
int ctrl_hpdtc_section(q24_t psi_alpha, q24_t psi_beta, uint8_t n);

/* phi of hdtc and hpdtc: the flux regulator's output for the reference
 * psi_ref (> 0) and the predicted |psi(k+1)|^2 (ctrl_mstate_t.psi_amp_sq),
 * its limits formed again only when psi_ref moved. */
static inline int8_t ctrl_s1_flux_phi(ctrl_hyst2_sq_t *h, q24_t *lim_ref, q24_t psi_ref,
                                      uint64_t psi_amp_sq)
{
    if (psi_ref != *lim_ref) {
        ctrl_hyst2_sq_limits(h, psi_ref);
        *lim_ref = psi_ref;
    }
    return ctrl_hyst2_sq_update(h, psi_amp_sq);
}

extern const ctrl_desc_t ctrl_desc_hdtc;
extern const ctrl_desc_t ctrl_desc_hdtc_pred;
extern const ctrl_desc_t ctrl_desc_svm_dtc;
extern const ctrl_desc_t ctrl_desc_hpdtc;

/* ---- Internal: per-sample parts, shared with ctrl_s1_dtc_config.c. ---- */
void ctrl_hdtc_reset(void *state);
void ctrl_hdtc_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out);
void ctrl_hdtc_pred_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out);
void ctrl_svm_dtc_reset(void *state);
void ctrl_svm_dtc_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out);
void ctrl_hpdtc_reset(void *state);
void ctrl_hpdtc_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out);

#endif /* CONTROL_CTRL_S1_DTC_H */
