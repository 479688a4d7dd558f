/*
 * Three-candidate M2PTFC, "M3" of thesis §6.4.2 / §6.6 (ref. [124]).
 * Descriptor "m3".
 *
 * Each sample, with the k+1 state of the estimator (delay compensation §6.3.4):
 * the set of (6.1) chosen by the sign of the torque error T_ref - Te(k+1):
 *   >= 0: Set I  {V_{x+1}, V_{x+2}, ZVV},   < 0: Set II {V_{x+5}, V_{x+4}, ZVV};
 * each active vector gets the duty D_f (5.18) saturated to [0, 1] (the same
 * duty controller as M1, so a vector that cannot reach the reference gets
 * D = 0, i.e. a zero vector all period, §6.6.2); the three candidates are
 * evaluated with (6.13) and the argmin (first on ties) is applied.
 * Table 6.2: 750 r/min fs 12 kHz (default), zeta 440 N*m/Wb; 2250 r/min
 * fs 16 kHz, zeta 110 N*m/Wb (--set zeta=110 and fs 16000: works).
 * Default zeta = 0 = T_rated/psi_pm (25.5 N*m/Wb for the thesis SPMSM): 440 is
 * above the limit zeta_max = sqrt(3) (3p/2) psi_pm/Ls = 149.5 N*m/Wb derived
 * in ctrl_m1.h and trips over-current in simulation (the zero vector wins
 * every period once the flux sits mid-sector at its reference).
 * Mean torque: D_f (5.18) puts the torque at the sample instants on T_ref, and
 * with centre-aligned PWM (plan.h) a sample lies at the period mean, so the
 * duty itself leaves no offset (unlike m2ptfc's (6.5), ctrl_m2ptfc.h); but
 * whenever Te(k+1) > T_ref, Set II's vectors get D = 0 and the zero vector
 * runs a whole period (38 % of periods at 750 r/min), a dip of up to |dTe[0]|
 * that (5.18) only repairs at the next sample: measured T_sse 0.09 N*m at
 * 750 r/min / 12 kHz and 0.19 N*m at 2250 r/min / 16 kHz (thesis SPMSM,
 * 1.8 N*m). This is M3's own behaviour (§6.6.2: "M3 sometimes selects
 * V_{x+4} or V_{x+5} ... applying a ZVV for the entire control period") and
 * is left as the thesis describes it.
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
