/*
 * Discrete-duty M2PTFC, "M2" of thesis §6.4.2 / §6.6 (ref. [123]).
 * Descriptor "m2".
 *
 * Each sample, with the k+1 state of the estimator (delay compensation §6.3.4):
 *   1. predict Te and |psi| at k+2 with the zero vector;
 *   2. the active vector from the switching table (Table 4.1 with two-level
 *      torque) on the signs of the errors left by the zero vector:
 *        T up, psi up: V_{x+1};  T up, psi down: V_{x+2};
 *        T down, psi up: V_{x+5}; T down, psi down: V_{x+4}  (error >= 0 = up);
 *   3. the y + 1 candidates D_nu = nu / y, nu = 0..y (6.15), each predicted to
 *      k+2 and evaluated with g = |T_ref - Te| + phi (6.16), phi = 0 inside
 *      psi_ref +- eps_psi and infinite outside (6.17); the argmin (first on
 *      ties) is applied with D_nu (nu = 0: the zero vector all period).
 * If no candidate keeps |psi| in the band, (6.17) leaves every cost infinite;
 * then the candidate with the smallest flux error |psi_ref - |psi|| is taken.
 * The band test compares squared amplitudes (exact, no square root).
 * Table 6.2: eps_psi 6.60 mWb at 750 r/min (default), 9.42 mWb at 2250 r/min
 * (--set eps_psi=0.00942); fs 10 kHz; y = 4 (Table 6.1).
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
} ctrl_m2_t;

extern const ctrl_desc_t ctrl_desc_m2;

/* Active vector of step 2 for sector x and the error signs (1 = increase). */
uint8_t ctrl_m2_table(uint8_t sector, int torque_up, int flux_up);

void ctrl_m2_reset(void *state);
void ctrl_m2_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out);

#endif /* CONTROL_CTRL_M2_H */
