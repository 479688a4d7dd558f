/*
 * Voltage-model stator-flux estimator, S1(13)-(14) and S1(31)-(38):
 *   psi(m) = psi(m-1) + Ts (v(m-1) - Rs (i(m-1) + i(m)) / 2)
 * (trapezoidal resistive drop: the average of the currents at both ends of the
 * period over which the average voltage v(m-1) acted).
 *
 * A pure integrator drifts with any current/voltage offset (thesis §2.2), so a
 * drift handling is selectable:
 *   CTRL_VM_CORR_NONE     pure integrator (for tests);
 *   CTRL_VM_CORR_LOWPASS  the integrator replaced by a low-pass filter with
 *                         corner w_c: psi += Ts (v - Rs i) - k psi, k = w_c Ts;
 *   CTRL_VM_CORR_CM       slow correction towards the current-model flux:
 *                         psi += Ts (v - Rs i) + k (psi_cm - psi). Below the
 *                         corner the current model dominates, above it the
 *                         voltage model (complementary filter).
 * Not in the estimator's path (it runs the current model from the angle
 * source's theta, as the thesis experiments do, §6.3.4): a building block
 * for a sensorless angle source (angle_source.h, uses_voltage).
 */
#ifndef CONTROL_FLUX_VM_H
#define CONTROL_FLUX_VM_H

#include <stdint.h>

#include "ctrl_params.h"
#include "fx.h"

#define CTRL_VM_CORR_NONE 0u
#define CTRL_VM_CORR_LOWPASS 1u
#define CTRL_VM_CORR_CM 2u

typedef struct {
    int64_t psi_alpha_acc, psi_beta_acc; /* flux, Q48 pu (Q24 with 24 guard bits) */
    q24_t i_alpha_prev, i_beta_prev;     /* i(m-1), Q24 pu */
    q24_t k_corr;                        /* correction gain per period, Q24 (w_c Ts) */
    uint8_t mode;                        /* CTRL_VM_CORR_* */
    uint8_t primed;                      /* 0 until the first reset/update */
} ctrl_flux_vm_t;

/* Set mode and gain; the state is cleared (not primed). */
void ctrl_flux_vm_init(ctrl_flux_vm_t *vm, uint8_t mode, q24_t k_corr);

/* Start from a known flux and current (e.g. the current model at standstill). */
void ctrl_flux_vm_reset(ctrl_flux_vm_t *vm, q24_t psi_alpha, q24_t psi_beta, q24_t i_alpha,
                        q24_t i_beta);

/* One period: v_* is the average voltage applied during [m-1, m), i_* the
 * current sampled at m, psi_cm_* the current-model flux at m (used only in
 * CTRL_VM_CORR_CM). If not primed, the state is reset to psi_cm and i. */
void ctrl_flux_vm_update(ctrl_flux_vm_t *vm, const ctrl_params_t *p, q24_t v_alpha, q24_t v_beta,
                         q24_t i_alpha, q24_t i_beta, q24_t psi_cm_alpha, q24_t psi_cm_beta);

/* Current estimate, Q24 pu. */
void ctrl_flux_vm_get(const ctrl_flux_vm_t *vm, q24_t *psi_alpha, q24_t *psi_beta);

#endif /* CONTROL_FLUX_VM_H */
