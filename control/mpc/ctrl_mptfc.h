/*
 * Finite-set model predictive torque and flux control, FS-MPTFC (thesis §6.4.1,
 * cost (6.13)). Descriptor "mptfc".
 *
 * Each sample, with the k+1 state of the estimator (delay compensation §6.3.4),
 * the eight inverter vectors are predicted to k+2 for the whole period (D = 1)
 * and the one minimising g = |T_ref - Te| + zeta |psi_ref - |psi|| (6.13) is
 * applied all period. V0 and V7 give the same prediction: they are one
 * candidate, realised by the zero vector that switches one leg from the end
 * state of the applied plan. Ties keep the first in the order V0, V1 .. V6.
 * zeta defaults to 0 = T_rated/psi_pm (25.5 N*m/Wb for the thesis SPMSM; the
 * thesis gives no FS-MPTFC experiment): M1's 250 of Table 6.2 is above the
 * limit sqrt(3) (3p/2) psi_pm/Ls = 149.5 N*m/Wb derived in ctrl_m1.h and trips
 * over-current at 750 r/min in simulation. fs 10 kHz.
 */
#ifndef CONTROL_CTRL_MPTFC_H
#define CONTROL_CTRL_MPTFC_H

#include "controller.h"
#include "ctrl_m2ptfc_model.h"

/* State: the layout shared by m1, m3 and mptfc
 * (ctrl_m2ptfc_model.h); trace vec 0 (zero vector, duty 0), then V1..V6 (duty 1). */
typedef ctrl_mpc_wstate_t ctrl_mptfc_t;

extern const ctrl_desc_t ctrl_desc_mptfc;

void ctrl_mptfc_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out);

#endif /* CONTROL_CTRL_MPTFC_H */
