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

/* A flux reference memoised by a controller whose references are piecewise
 * constant (a torque command; the speed loop holds its output between its
 * runs): the inputs it was formed from and its value. The keys are every
 * input of ctrl_flux_ref that can move at run time: the torque, the command,
 * the params, and in them psi_pm with mtpa_k (the pipeline tracks the PM
 * flux, fw_config_t.psi_adapt) and psi_ref; the MTPA table is fixed between
 * resets. valid == 0 (after reset): nothing memoised. */
typedef struct {
    const ctrl_params_t *p;
    q24_t torque, psi_cmd;         /* Q24 pu */
    q24_t psi_pm, mtpa_k, psi_ref; /* of *p, Q24 */
    int32_t value;                 /* the owner's function of the inputs */
    uint8_t valid;
} ctrl_flux_memo_t;

/* 1 when m holds the value of these inputs; else 0 with the inputs recorded
 * as the new keys (the caller then stores the value). */
static inline int ctrl_flux_memo_hit(ctrl_flux_memo_t *m, const ctrl_params_t *p, q24_t psi_cmd,
                                     q24_t torque)
{
    if (m->valid != 0u && m->p == p && m->torque == torque && m->psi_cmd == psi_cmd &&
        m->psi_pm == p->psi_pm && m->mtpa_k == p->mtpa_k && m->psi_ref == p->psi_ref) {
        return 1;
    }
    m->p = p;
    m->torque = torque;
    m->psi_cmd = psi_cmd;
    m->psi_pm = p->psi_pm;
    m->mtpa_k = p->mtpa_k;
    m->psi_ref = p->psi_ref;
    m->valid = 1u;
    return 0;
}

/* ctrl_flux_ref(p, psi_cmd, torque), formed only when an input moved (the
 * SPMSM's MTPA is a square root, fx_mag). */
static inline q24_t ctrl_flux_ref_memo(ctrl_flux_memo_t *m, const ctrl_params_t *p, q24_t psi_cmd,
                                       q24_t torque)
{
    if (ctrl_flux_memo_hit(m, p, psi_cmd, torque) == 0) {
        m->value = ctrl_flux_ref(p, psi_cmd, torque);
    }
    return m->value;
}

#endif /* CONTROL_MTPA_H */
