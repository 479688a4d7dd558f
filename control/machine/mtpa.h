/*
 * Stator-flux amplitude reference for maximum torque per ampere.
 *
 * SPMSM (Ld == Lq), closed form (4.15): psi_s = sqrt(psi_pm^2 + (Lq T / psi_pm)^2)
 * in pu (T_base = 1.5 p psi_base i_base absorbs 2/(3p)); load angle (4.16).
 * IPMSM: the exact MTPA current locus is solved in ctrl_params_config.c and
 * tabulated as psi_s(|T|) at CTRL_MTPA_N + 1 uniform torque points
 * (p->mtpa_psi); per sample a linear interpolation (error in control/README.md).
 */
#ifndef CONTROL_MTPA_H
#define CONTROL_MTPA_H

#include "ctrl_params.h"
#include "fx.h"

/* MTPA flux amplitude for torque (Q24 pu, either sign); result Q24 pu > 0. */
q24_t ctrl_mtpa_psi(const ctrl_params_t *p, q24_t torque);

#endif /* CONTROL_MTPA_H */
