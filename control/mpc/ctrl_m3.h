/*
 * Three-candidate M2PTFC, "M3" of thesis §6.4.2 / §6.6. Descriptor "m3".
 *
 * Each period: the set of (6.1) by the sign of T_ref - Te(k+1) ({V_{x+1},
 * V_{x+2}, ZVV} or {V_{x+5}, V_{x+4}, ZVV}), each active vector with the duty
 * D_f (5.18), the three evaluated with (6.13) on the k+2 model and the argmin
 * applied. Table 6.2: 12 kHz, zeta 440 at 750 r/min; 16 kHz, zeta 110 at
 * 2250 r/min; default zeta T_rated / psi_pm (limit and measured offsets:
 * docs/algorithms.md, "M3").
 */
#ifndef CONTROL_CTRL_M3_H
#define CONTROL_CTRL_M3_H

#include "controller.h"
#include "ctrl_m2ptfc_model.h"

/* State: the layout shared by m1, m3 and mptfc
 * (ctrl_m2ptfc_model.h); trace the two active vectors with D_f, then (0, 0). */
typedef ctrl_mpc_wstate_t ctrl_m3_t;

extern const ctrl_desc_t ctrl_desc_m3;

void ctrl_m3_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out);

#endif /* CONTROL_CTRL_M3_H */
