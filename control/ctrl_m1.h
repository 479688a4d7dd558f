/*
 * Conventional M2PTFC, "M1" of thesis §6.4.2 / §6.6 (ref. [47]). Descriptor "m1".
 *
 * Each sample, with the k+1 state of the estimator (delay compensation §6.3.4):
 * for each of the six active vectors V_i the duty D_f (5.18) that cancels the
 * torque error at k+2,
 *   D_f = (T_err - dTe[0]) / (dTe[i] - dTe[0]) = (T_ref - Te0(k+2)) / (Te_i(k+2) - Te0(k+2)),
 * saturated to [0, 1] (den = 0: 1 if the zero vector leaves torque below the
 * reference, else 0); then Te(k+2) and |psi(k+2)| with V_i on for D_f Ts and
 * the weighted cost (6.13) g = |T_ref - Te| + zeta |psi_ref - |psi||. The
 * argmin (first on ties) is applied with its duty, then the zero vector that
 * switches one leg. Six duty divisions and six square roots per sample.
 *
 * zeta (Table 6.2): 250 N*m/Wb at 750 r/min (default), 640 N*m/Wb at 2250 r/min
 * (pass --set zeta=640); fs 10 kHz at both speeds. zeta = 0 gives T_rated/psi_pm
 * (the equal-importance value of §6.5: 25.5 N*m/Wb for the thesis SPMSM,
 * 2133 N*m/Wb for the 80 kW IPMSM).
 * Caution: with the Table 6.2 weights the simulated SPMSM drive loses torque
 * control after a torque step (tests/mpc/test_mpc_loop.c): once D_f saturates
 * at 1, the torque gained by V_{x+1} / V_{x+2} in one period (~1.1 N*m) is less
 * than zeta times their flux-amplitude change (~250 x 6 mWb), so the zero
 * vector wins every period while the rotor turns away from the flux. zeta = 0
 * (equal importance) works at both speeds.
 */
#ifndef CONTROL_CTRL_M1_H
#define CONTROL_CTRL_M1_H

#include "controller.h"
#include "ctrl_m2ptfc_model.h"

typedef struct {
    double zeta;                /* "zeta", N*m/Wb, (6.13) */
    ctrl_mpc_model_cfg_t model; /* model overrides, see ctrl_m2ptfc_model.h */
} ctrl_m1_cfg_t;

typedef struct {
    ctrl_mpc_model_t model;
    q24_t zeta; /* Q24 pu (T_base / psi_base) */
    ctrl_mpc_trace_t trace;
} ctrl_m1_t;

extern const ctrl_desc_t ctrl_desc_m1;

void ctrl_m1_reset(void *state);
void ctrl_m1_step(void *state, const ctrl_ctx_t *ctx, ctrl_plan_t *out);

#endif /* CONTROL_CTRL_M1_H */
