/*
 * Low-complexity two-candidate modulated model predictive torque and flux
 * control, M2PTFC (thesis §6.3, Fig. 6.5). Descriptor "m2ptfc".
 *
 * Each period, on the k+1 state (delay compensation §6.3.4) and the k+2 model
 * of ctrl_m2ptfc_model.h: sector x of psi(k+1) (4.5), sigma_T (6.8), the two
 * candidates (6.7), their duties (6.5) with the clamp (6.6), the candidate
 * closer to psi_ref by the flux-only cost (6.9) (squared amplitudes, exact,
 * no square root), applied with its duty and then the zero vector that
 * switches one leg. Tunable "centre" (default 1): Te of (6.5), (6.7), (6.8)
 * shifted by half the zero-vector change, so that the mean torque of a
 * centre-aligned period sits on T_ref (**); 0: the thesis' literal equations.
 * Derivation, measured offsets and the choices the thesis leaves open:
 * docs/algorithms.md, "M2PTFC".
 */
#ifndef CONTROL_CTRL_M2PTFC_H
#define CONTROL_CTRL_M2PTFC_H

#include <stdint.h>

#include "controller.h"
#include "ctrl_m2ptfc_model.h"

typedef struct {
    ctrl_mpc_model_t model;
    q24_t lambda;    /* Q24 */
    q24_t sigma;     /* sigma_T of (6.8), Q24 pu */
    q24_t sigma_max; /* A (5.9), Q24 pu: (6.8) holds while |error| > A + |dTe0| */
    uint8_t centre;  /* 1: Te_c (**) in (6.5), (6.7), (6.8); 0: Te(k+1) */
    ctrl_mpc_trace_t trace;
    /* ctrl_mpc_psi_ref2(params, ref), psi_ref^2 in Q24 pu^2 (ctrl_mpc_amp2
     * units), formed only when its inputs move (mtpa.h: the references, the
     * params and the PM flux tracked in them). */
    ctrl_flux_memo_t psi2;
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
