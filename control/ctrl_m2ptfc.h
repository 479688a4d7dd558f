/*
 * Low-complexity two-candidate modulated model predictive torque and flux
 * control, M2PTFC (thesis §6.3, flowchart Fig. 6.5). Descriptor "m2ptfc".
 *
 * Each sample, with the k+1 state of the estimator (delay compensation §6.3.4):
 *   1. sector x of psi(k+1) (4.5), sigma_T EMA (6.8);
 *   2. two candidate active vectors (6.7):
 *        {V_{x+1}, V_{x+2}} if T_ref + sigma_T >= Te(k+1), else {V_{x+4}, V_{x+5}};
 *   3. per candidate: Te(k+2) at D = 1 (6.10)-(6.12), duty (6.5)
 *        D = (T_ref + sigma_T - Te(k+1)) / (dTe[x+n] + 2 sigma_T),
 *      with the clamp (6.6): D outside [0, 1] -> 1;
 *      then |psi(k+2)| with the vector on for D Ts (zero vector the rest);
 *   4. the candidate minimising the flux-only cost (6.9) |psi_ref - |psi(k+2)||
 *      is applied with its duty, followed by the zero vector that switches one leg.
 * No weighting factor. Per sample: one fx_sincos, three 32-bit divisions per
 * candidate, no square root (the cost is compared on squared amplitudes
 * exactly, ctrl_mpc_closer()).
 *
 * Choices the thesis leaves open (documented, also in the reference test):
 *   - sigma_T (6.8) and the torque of (6.5)/(6.7) use the k+1 estimate (the
 *     thesis' "k" variables moved one step ahead, §6.3.4);
 *   - (6.5) with a zero numerator gives D = 0 (also for a zero denominator);
 *   - equal costs keep the first candidate (V_{x+1} or V_{x+4}).
 * Defaults (Table 6.2): fs 10 kHz, lambda 0.03 at 750 r/min; the thesis runs
 * 11 kHz at 2250 r/min (same lambda).
 *
 * Mean torque with centre-aligned PWM: (6.2)-(6.5) put the torque at the
 * sample instants at T_ref - sigma_T, the bottom of the thesis' "active then
 * zero vector" ripple (Fig. 6.3), and (6.8) settles at sigma_T = -dTe[0]/2
 * (the relation (6.4) holds at equilibrium). This project's PWM centres the
 * active vector in the period, so the sample instants (mid zero vector) sit at
 * the period mean and the mean torque stays about sigma_T below T_ref
 * (closed loop, thesis SPMSM at 1.8 N*m: -0.14 N*m at 750 r/min, -0.36 N*m at
 * 2250 r/min; the ripple is unaffected). Implemented as the thesis states.
 */
#ifndef CONTROL_CTRL_M2PTFC_H
#define CONTROL_CTRL_M2PTFC_H

#include <stdint.h>

#include "controller.h"
#include "ctrl_m2ptfc_model.h"

/* SI configuration (tunables by name). */
typedef struct {
    double lambda;              /* "lambda": EMA coefficient of (6.8), 0 < lambda <= 1 */
    ctrl_mpc_model_cfg_t model; /* "rs_model", "ld_model", "lq_model", "psi_pm_model" */
} ctrl_m2ptfc_cfg_t;

typedef struct {
    ctrl_mpc_model_t model;
    q24_t lambda; /* Q24 */
    q24_t sigma;  /* sigma_T of (6.8), Q24 pu */
    ctrl_mpc_trace_t trace;
} ctrl_m2ptfc_t;

extern const ctrl_desc_t ctrl_desc_m2ptfc;

/* Candidate pair of (6.7) for sector x (1..6): out[0] = V_{x+1} or V_{x+4},
 * out[1] = V_{x+2} or V_{x+5}. */
void ctrl_m2ptfc_candidates(uint8_t sector, q24_t torque_upper, q24_t torque_est, uint8_t out[2]);

/* Duty (6.5) from its numerator and denominator with the clamp (6.6): num/den
 * if it lies in [0, 1], else FX_ONE; num == 0 gives 0. */
q24_t ctrl_m2ptfc_duty(q24_t num, q24_t den);

void ctrl_m2ptfc_reset(void *state);
void ctrl_m2ptfc_step(void *state, const ctrl_ctx_t *ctx, ctrl_plan_t *out);

#endif /* CONTROL_CTRL_M2PTFC_H */
