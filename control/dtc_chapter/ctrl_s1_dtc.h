/*
 * DTC controllers of the book chapter (S1): "hdtc" (§3, Table 3),
 * "svm_dtc" (§4, S1(17)-(20)) and "hpdtc" (§5, Table 4, S1(40), §5.2.3).
 *
 * Common to the three:
 *   - Delay compensation (REFERENCE §1): decisions use the state predicted for
 *     k+1 (est->next), the instant the chosen voltage starts to act.
 *   - Flux reference: ref->psi if > 0, else the tunable psi_ref (Wb) if > 0,
 *     else params->psi_ref if > 0, else psi_pm (S1 §4 and §6.1.4: "the
 *     reference value of the stator flux is ... equal to the permanent magnet
 *     flux").
 *   - Bands of S1 §3.3 / §6.1.4 ("Flux band = +-0.01; Torque Band = +-0.01"):
 *     the chapter's Simulink model is in SI units, so h_psi = 0.01 Wb and
 *     h_T = 0.01 N*m (half widths).
 *
 * hdtc: flux two-level and torque three-level hysteresis (hysteresis.h) and
 * the optimum switching table S1 Table 3, which is thesis Table 4.1
 * (st_lookup_bst); Table 3's fixed V0/V7 per sector is the one-leg-switching
 * zero vector ctrl_zero_after() of the previous active vector.
 *
 * svm_dtc: predictive controller of S1 Fig. 25. A PI on the torque error gives
 * the load-angle increment Delta delta; the reference voltage
 *   V_ref = (psi_ref e^{j(lambda_s + Delta delta)} - psi_s e^{j lambda_s}) / Ts + Rs i_s
 * S1(19)-(20) (S1(18) is its polar form), from the predicted flux psi_s(k+1)
 * and current i_s(k+1), synthesised by SVPWM (svpwm.h) with over-modulation
 * limiting. Gain units (S1 §4.1: Kp = 1, Ki = 0.03): torque error in per-unit
 * of the machine's torque base (T_base = 1.5 p psi_pm^2 / Ld), Delta delta in
 * rad, integrator per sample:
 *   Delta delta = Kp e_T + Ki sum_k e_T   [rad, rad/pu, rad/(pu*sample)].
 * (In N*m the chapter's Kp = 1 rad/(N*m) would be a loop gain of dT/d delta
 * = 8.3 N*m/rad per period on its IPMSM: unstable; in pu the loop gain is
 * 0.44 (chapter IPMSM) and 1.0 (thesis SPMSM).) Optional feed-forward
 * omega_e Ts (tunable omega_ff, default 1): the rotor advances omega_e Ts per
 * period, so the PI then supplies only the change of the load angle.
 * |Delta delta| <= pi/3, integrator within +-pi/6 and held while the voltage
 * is limited by the hexagon in the direction of the error (anti-windup).
 *
 * hpdtc: two adjacent active vectors from S1 Table 4 (phi, tau two-level,
 * sector n of (4.5), wrap 1..6), their on-times from a 5 x 5 timing table in
 * points of Ts/20 indexed by the voltage level (|T_err| quantised in 5 levels
 * of e_fs/5: level l = 1..5 when |T_err| in [(l-1), l) e_fs/5, 5 above) and
 * by the reflected flux position (S1(40), 5 sections of 12 deg); the rest of
 * the period split equally between V0 and V7. The table is generated at init
 * from space-vector geometry (control/README.md, "HP-DTC timing table").
 * Default e_fs (tunable 0): the level quantiser is a proportional controller
 * from |T_err| to the voltage; one level step (0.2 Vdc/sqrt(3)) changes the
 * torque by about 0.2 Ts Vdc psi_pm / (sqrt(3) Lq) x 1.5 p per period
 * (dT/d delta at delta = 0, S1(7)); e_fs = 5 x that step gives a loop gain
 * of 1 (0.24 N*m on the chapter IPMSM at 10 kHz). S1 §5.3.1's 0.1 N*m would
 * be a loop gain of 2.4: the level oscillates over the whole range.
 */
#ifndef CONTROL_CTRL_S1_DTC_H
#define CONTROL_CTRL_S1_DTC_H

#include <stdint.h>

#include "controller.h"
#include "fx.h"
#include "hysteresis.h"

#define HPDTC_POINTS 20  /* points per period (S1 §5.2.3) */
#define HPDTC_LEVELS 5   /* voltage levels */
#define HPDTC_SECTIONS 5 /* reflected-position sections of 12 deg */

typedef struct {
    q24_t psi_ref; /* Q24 pu, > 0 */
    ctrl_hyst2_t flux;
    ctrl_hyst3_t torque;
    uint8_t prev_vec;
} ctrl_hdtc_state_t;

typedef struct {
    q24_t psi_ref;         /* Q24 pu, > 0 */
    q24_t kp;              /* rad per pu torque, Q24 */
    int32_t ki;            /* rad per (pu torque * sample), Q30 */
    int64_t integ;         /* integrator, rad, Q40 */
    q24_t inv_ts;          /* 1 / Ts_pu, Q24 */
    uint8_t ff;            /* omega_e Ts feed-forward on */
    uint8_t limited;       /* last voltage limited by the hexagon */
    q24_t dd;              /* last Delta delta, rad Q24 (telemetry/tests) */
    q24_t v_alpha, v_beta; /* last reference before limiting, Q24 pu (tests) */
} ctrl_svm_dtc_state_t;

typedef struct {
    q24_t psi_ref;                                /* Q24 pu, > 0 */
    ctrl_hyst2_t flux, torque;                    /* phi, tau of Table 4 (two-level) */
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

extern const ctrl_desc_t ctrl_desc_hdtc;
extern const ctrl_desc_t ctrl_desc_svm_dtc;
extern const ctrl_desc_t ctrl_desc_hpdtc;

/* ---- Internal: per-sample parts, shared with ctrl_s1_dtc_config.c. ---- */
void ctrl_hdtc_reset(void *state);
void ctrl_hdtc_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out);
void ctrl_svm_dtc_reset(void *state);
void ctrl_svm_dtc_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out);
void ctrl_hpdtc_reset(void *state);
void ctrl_hpdtc_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out);

#endif /* CONTROL_CTRL_S1_DTC_H */
