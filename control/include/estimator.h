/*
 * State estimator run once per control period (thesis §5.4, §6.3.4).
 *
 * At sample k, from the measured phase currents and the encoder angle:
 *   - current model (3.4)/(4.1), in the rotor frame (3.9):
 *       psi_d = Ld i_d + psi_pm, psi_q = Lq i_q (SPMSM and IPMSM);
 *   - torque (3.6) = psi x i, amplitude (4.3), sector (4.5);
 *   - electrical speed from the angle difference per period, low-pass filtered
 *     (first-order EMA with coefficient p->speed_lpf_k; the default cut-off is
 *     CTRL_SPEED_LPF_HZ_DEFAULT, see ctrl_params.h);
 *   - prediction to k+1 (5.15)/(6.10)-(6.12) with the period-average voltage of
 *     the leg duties applied during [k, k+1).
 * One fx_sincos for the measured angle and one for the predicted angle.
 */
#ifndef CONTROL_ESTIMATOR_H
#define CONTROL_ESTIMATOR_H

#include <stdint.h>

#include "ctrl_params.h"
#include "ctrl_types.h"
#include "flux_vm.h"
#include "fx.h"

/* Optional outputs (ctrl_estimator_t.outputs, a bit set = computed). The rest
 * of ctrl_estimate_t is always computed. A field not computed is set to 0
 * (psi_amp 0, sector 0 = "none"). Default CTRL_EST_ALL: clear bits only when no
 * consumer (controller, telemetry) reads the field; each square root costs
 * ~75 Cortex-M4 instructions, the sector ~20 (tests/perf). */
#define CTRL_EST_AMP_NOW 0x01u    /* est->now.psi_amp (4.3) */
#define CTRL_EST_AMP_NEXT 0x02u   /* est->next.psi_amp */
#define CTRL_EST_SECTOR_NOW 0x04u /* est->now.sector (4.5); next.sector is always computed */
#define CTRL_EST_ALL 0x07u

#define CTRL_FLUX_CURRENT_MODEL 0u /* default: (3.4) from the encoder angle */
#define CTRL_FLUX_VOLTAGE_MODEL 1u /* flux_vm.h, drift-compensated */

typedef struct {
    fx_angle_t theta_prev;           /* encoder angle at k-1 */
    int64_t omega_acc;               /* filtered electrical speed, Q48 pu */
    q24_t v_prev_alpha, v_prev_beta; /* average voltage applied during [k-1, k), Q24 pu */
    uint8_t primed;                  /* 0 before the first update after reset */
    uint8_t flux_source;             /* CTRL_FLUX_*; set after init, kept by reset */
    ctrl_flux_vm_t vm;               /* voltage model (used if flux_source says so) */
    uint8_t outputs;                 /* CTRL_EST_* optional outputs; init: CTRL_EST_ALL,
                                      * set after init, kept by reset */
} ctrl_estimator_t;

/* Current model, default flux source, every output, voltage model configured
 * without correction (call ctrl_flux_vm_init on e->vm to choose another). */
void ctrl_estimator_init(ctrl_estimator_t *e, const ctrl_params_t *p);

/* Forget the history (speed, previous angle, voltage model), keep the settings. */
void ctrl_estimator_reset(ctrl_estimator_t *e);

/* Estimate at k and predict k+1; applied: the leg duties acting during [k, k+1)
 * (NULL: a zero vector). */
void ctrl_estimator_update(ctrl_estimator_t *e, const ctrl_params_t *p, const ctrl_meas_t *m,
                           const ctrl_legs_t *applied, ctrl_estimate_t *est);

/* Current model (3.9) for a measured alpha/beta current at angle theta_e with
 * its sin/cos (Q24): fills every field of out. */
void ctrl_mstate_from_current(const ctrl_params_t *p, q24_t i_alpha, q24_t i_beta,
                              fx_angle_t theta_e, q24_t sin_theta, q24_t cos_theta,
                              ctrl_mstate_t *out);

#endif /* CONTROL_ESTIMATOR_H */
