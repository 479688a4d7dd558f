/*
 * Conventional M2PTFC, "M1" of thesis §6.4.2 / §6.6. Descriptor "m1".
 *
 * Each period, on the k+2 model (ctrl_m2ptfc_model.h): for each active vector
 * the duty D_f (5.18) that cancels the torque error at k+2, saturated to
 * [0, 1]; the weighted cost (6.13) g = |T_ref - Te| + zeta |psi_ref - |psi||;
 * the argmin (first on ties) applied with its duty, then the zero vector that
 * switches one leg. Default zeta = T_rated / psi_pm (§6.5): Table 6.2's values
 * exceed the stability limit sqrt(3) (3p/2) psi_pm / Ls of the linear cost
 * (docs/algorithms.md, "The weight zeta and its stability limit").
 */
#ifndef CONTROL_CTRL_M1_H
#define CONTROL_CTRL_M1_H

#include "controller.h"
#include "ctrl_m2ptfc_model.h"

/* State: the layout shared by m1, m3 and mptfc
 * (ctrl_m2ptfc_model.h); trace the six active vectors with D_f (5.18). */
typedef ctrl_mpc_wstate_t ctrl_m1_t;

extern const ctrl_desc_t ctrl_desc_m1;

void ctrl_m1_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out);

#endif /* CONTROL_CTRL_M1_H */
