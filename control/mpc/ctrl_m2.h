/*
 * Discrete-duty M2PTFC, "M2" of thesis §6.4.2 / §6.6. Descriptor "m2".
 *
 * Each period, on the k+2 model: the active vector of Table 4.1 (two-level
 * torque) on the error signs the zero vector leaves; the y + 1 duties
 * D_nu = nu / y (6.15) evaluated with g = |T_ref - Te| + phi (6.16), phi = 0
 * inside psi_ref +- eps_psi and infinite outside (6.17), compared on squared
 * amplitudes; if no candidate keeps |psi| in the band the smallest flux error
 * wins. Table 6.2: eps_psi 6.60 mWb (750 r/min), 9.42 mWb (2250 r/min); y = 4
 * (Table 6.1).
 */
#ifndef CONTROL_CTRL_M2_H
#define CONTROL_CTRL_M2_H

#include "controller.h"
#include "ctrl_m2ptfc_model.h"

#define CTRL_M2_Y_MAX 16

typedef struct {
    ctrl_mpc_model_t model;
    q24_t eps_psi; /* Q24 pu */
    uint8_t y;
    q24_t d_nu[CTRL_M2_Y_MAX + 1]; /* nu / y, Q24 */
    uint8_t last_vec;              /* segment 0 of the last plan (0 after reset) */
    ctrl_mpc_trace_t trace;        /* y + 1 entries: the table vector with D_nu */
    ctrl_flux_memo_t flux;         /* the flux reference (ctrl_mpc_in) */
} ctrl_m2_t;

extern const ctrl_desc_t ctrl_desc_m2;

/* Active vector of step 2 for sector x and the error signs (1 = increase). */
uint8_t ctrl_m2_table(uint8_t sector, int torque_up, int flux_up);

void ctrl_m2_reset(void *state);
void ctrl_m2_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out);

#endif /* CONTROL_CTRL_M2_H */
