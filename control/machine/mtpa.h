/*
 * Stator-flux amplitude reference for maximum torque per ampere.
 *
 * SPMSM (Ld == Lq), closed form (4.15): psi_s = sqrt(psi_pm^2 + (Lq T / psi_pm)^2)
 * in pu (T_base = 1.5 p psi_base i_base absorbs 2/(3p)); load angle (4.16).
 * IPMSM: the exact MTPA current locus is solved in ctrl_params_config.c and
 * tabulated as psi_s, i_d, i_q against |T| at CTRL_MTPA_N + 1 uniform torque
 * points (ctrl_params_t); per sample a linear interpolation (error budget:
 * docs/fixed-point.md).
 */
#ifndef CONTROL_MTPA_H
#define CONTROL_MTPA_H

#include "ctrl_params.h"
#include "fx.h"

/* MTPA flux amplitude for torque (Q24 pu, either sign); result Q24 pu > 0. */
q24_t ctrl_mtpa_psi(const ctrl_params_t *p, q24_t torque);

/* MTPA current references for torque (Q24 pu, either sign), |torque| limited
 * to p->mtpa_t_max (the torque at current_max): i_d (<= 0 for Lq > Ld), i_q
 * with the sign of torque. SPMSM: i_d = 0, i_q = T / psi_pm. */
void ctrl_mtpa_current(const ctrl_params_t *p, q24_t torque, q24_t *i_d, q24_t *i_q);

/* The stator-flux amplitude reference of the flux-regulating controllers:
 * the command psi_cmd if > 0, else the machine's fixed reference p->psi_ref
 * if > 0, else MTPA of torque (4.15). Q24 pu. */
static inline q24_t ctrl_flux_ref(const ctrl_params_t *p, q24_t psi_cmd, q24_t torque)
{
    if (psi_cmd > 0) {
        return psi_cmd;
    }
    if (p->psi_ref > 0) {
        return p->psi_ref;
    }
    return ctrl_mtpa_psi(p, torque);
}

#endif /* CONTROL_MTPA_H */
