/*
 * Finite-set model predictive torque and flux control, FS-MPTFC (thesis
 * §6.4.1, cost (6.13)). Descriptor "mptfc".
 *
 * Each period the eight vectors are predicted to k+2 for the whole period and
 * the one minimising (6.13) is applied all period; V0 and V7 are one
 * candidate, realised by the zero vector that switches one leg from the last
 * plan. Ties keep the first in the order V0, V1 .. V6. Default zeta
 * T_rated / psi_pm (docs/algorithms.md, "The weight zeta ...").
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
