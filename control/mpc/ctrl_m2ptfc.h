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
 * exactly, ctrl_mpc_closer(), against the squared reference,
 * ctrl_mpc_psi_ref2(): MTPA (4.15) squared, cached in the state while the
 * references are unchanged); only V1..V3 are rotated into the rotor frame
 * (ctrl_mpc_basis3(), V_{i+3} = -V_i).
 *
 * Choices the thesis leaves open (documented, also in the reference test):
 *   - sigma_T (6.8) and the torque of (6.5)/(6.7) use the k+1 estimate (the
 *     thesis' "k" variables moved one step ahead, §6.3.4);
 *   - (6.5) with a zero numerator gives D = 0 (also for a zero denominator);
 *   - equal costs keep the first candidate (V_{x+1} or V_{x+4}).
 * Defaults (Table 6.2): fs 10 kHz, lambda 0.03 at 750 r/min; the thesis runs
 * 11 kHz at 2250 r/min (same lambda).
 *
 * Mean torque with centre-aligned PWM (tunable "centre", default 1).
 * The thesis applies the active vector first, then the zero vector (Fig. 6.3):
 * its sample instants are the bottoms of the ripple. (6.3) is exactly the
 * condition for the band T_ref +- sigma_T (bottom T_ref - sigma_T, top
 * T_ref + sigma_T, mean T_ref); (6.5) follows from it with (6.4). With
 * dT0 = dTe[0] and dTa = dTe[x+n] the per-period changes, a periodic steady
 * state needs D dTa + (1 - D) dT0 = 0, and (6.8) settles at sigma_T = Tref - Te,
 * so (6.5) gives 2 sigma_T / (dTa + 2 sigma_T) = -dT0 / (dTa - dT0), i.e.
 *   sigma_T = -dT0 / 2,   Te(sampled) = T_ref + dT0 / 2                   (*)
 * whatever instant of the period "Te" is taken at. plan.h realises every plan
 * centre-aligned: (1 - D)/2 zero vector, D active, (1 - D)/2 zero vector, so
 * the sample instants (mid zero vector) lie at the period mean (the triangle
 * rises dTa D = -dT0 (1 - D) and falls symmetrically about them), and the
 * literal equations leave the mean torque at T_ref + dT0/2, i.e. sigma_T low
 * (measured closed loop, thesis SPMSM, 1.8 N*m: 0.14 N*m at 750 r/min,
 * 0.36 N*m at 2250 r/min and 11 kHz; the thesis reports no offset).
 * centre = 1: Te of (6.5), (6.7) and (6.8) is replaced by
 *   Te_c = Te(k+1) + dT0 / 2,   dT0 = Te0(k+2) - Te(k+1)                 (**)
 * (Te0(k+2): the k+2 torque with the zero vector, already part of the k+2
 * basis: one subtraction and a halving, no division). By (*), Te_c settles at
 * T_ref + dT0/2, so the sampled torque Te(k+1) = the period mean settles at
 * T_ref: the thesis' band T_ref +- sigma_T centred on the reference. dTa of
 * (6.5) stays Te(k+2) - Te(k+1) (a per-period change). Shifting Te to the
 * active-vector start instead (as ctrl_drr does, Te + (1 - D)/2 dT0) leaves
 * the thesis' own residual of (6.4), a mean D sigma_T below T_ref (the ripple
 * rises from T_ref - sigma_T by dTa D = 2 sigma_T (1 - D)): estimated
 * 0.25 N*m at 2250 r/min (measured D ~ 0.70, sigma_T ~ 0.36 N*m).
 * Measured with centre = 1 (same runs): |T_sse| 0.0003 N*m at 750 r/min,
 * 0.007 N*m at 2250 r/min; ripple unchanged. centre = 0: the thesis' literal
 * equations.
 * (*) and (**) hold for either sign of dT0 (all four quadrants).
 */
#ifndef CONTROL_CTRL_M2PTFC_H
#define CONTROL_CTRL_M2PTFC_H

#include <stdint.h>

#include "controller.h"
#include "ctrl_m2ptfc_model.h"

typedef struct {
    ctrl_mpc_model_t model;
    q24_t lambda;   /* Q24 */
    q24_t sigma;    /* sigma_T of (6.8), Q24 pu */
    uint8_t centre; /* 1: Te_c (**) in (6.5), (6.7), (6.8); 0: Te(k+1) */
    ctrl_mpc_trace_t trace;
    /* Cache of ctrl_mpc_psi_ref2(params, ref), recomputed only when its inputs
     * change (the reference is piecewise constant): valid when params,
     * ref->torque and ref->psi equal the keys. The params pointed to are not
     * modified between init/reset and step (as for model). */
    const ctrl_params_t *psi2_params; /* key; NULL after init/reset: none cached */
    q24_t psi2_torque;                /* key: ref->torque, Q24 pu */
    q24_t psi2_psi;                   /* key: ref->psi, Q24 pu */
    int32_t psi2;                     /* psi_ref^2, Q24 pu^2 (ctrl_mpc_amp2 units) */
} ctrl_m2ptfc_t;

extern const ctrl_desc_t ctrl_desc_m2ptfc;

/* Candidate pair of (6.7) for sector x (1..6): out[0] = V_{x+1} or V_{x+4},
 * out[1] = V_{x+2} or V_{x+5}. */
void ctrl_m2ptfc_candidates(uint8_t sector, q24_t torque_upper, q24_t torque_est, uint8_t out[2]);

/* Duty (6.5) from its numerator and denominator with the clamp (6.6): num/den
 * if it lies in [0, 1], else FX_ONE; num == 0 gives 0. */
q24_t ctrl_m2ptfc_duty(q24_t num, q24_t den);

/* Torque the equations (6.5), (6.7), (6.8) use: Te_c (**) = t1 + (t0 - t1)/2
 * when s->centre, else t1 (Te(k+1)); t0 = Te0(k+2), Q24 pu. */
q24_t ctrl_m2ptfc_t_eval(const ctrl_m2ptfc_t *s, q24_t t1, q24_t t0);

void ctrl_m2ptfc_reset(void *state);
void ctrl_m2ptfc_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out);

#endif /* CONTROL_CTRL_M2PTFC_H */
