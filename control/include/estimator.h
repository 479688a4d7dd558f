/*
 * State estimator run once per control period, in the rotor frame (thesis
 * §5.4, §6.3.4; docs/architecture.md, "One period").
 *
 * At sample k:
 *   - Clarke (3.3) of the measured currents; theta(k), omega(k) from the
 *     angle source (angle_source.h: encoder by default);
 *   - one fx_sincos(theta(k)); Park (3.7) of the current, current model
 *     (3.9) psi_d = Ld i_d + psi_pm, psi_q = Lq i_q, torque (3.10);
 *   - prediction to k+1 in the rotor frame, (5.15)/(6.10)-(6.12): the leg
 *     duties acting in [k, k+1) as a voltage in the frame at theta(k),
 *     psi' = psi + Ts v - Ts Rs i, then the frame turned by
 *     delta = omega Ts: psi(k+1) = psi' e^{-j delta} (fx_rot_q30, no second
 *     table look-up), i(k+1) from (3.9) inverted, torque (3.10).
 * Stator-frame values, amplitudes and sectors only where a consumer reads
 * them (CTRL_EST_* below).
 */
#ifndef CONTROL_ESTIMATOR_H
#define CONTROL_ESTIMATOR_H

#include <stddef.h>
#include <stdint.h>

#include "angle_source.h"
#include "ctrl_params.h"
#include "ctrl_types.h"
#include "fx.h"

/* Optional outputs (bit set = computed). Always computed: now and next
 * i_d, i_q, psi_d, psi_q, torque, theta_e; now.sin_theta, now.cos_theta,
 * now.i_alpha, now.i_beta; omega_e, vdc, dtheta, rot_c, rot_s, u_alpha, u_beta. A field not
 * computed is not written (it keeps the caller's value, zero from an
 * initialised ctrl_estimate_t). Costs on a Cortex-M4: a square root ~60
 * instructions, a sector ~20, a rotation ~10, a square ~5. */
#define CTRL_EST_AMP_NOW 0x01u      /* now.psi_amp (4.3) */
#define CTRL_EST_SECTOR_NOW 0x02u   /* now.sector (4.5), with now.psi_alpha/beta */
#define CTRL_EST_PSI_AB_NOW 0x04u   /* now.psi_alpha, now.psi_beta */
#define CTRL_EST_AMP_NEXT 0x08u     /* next.psi_amp */
#define CTRL_EST_SECTOR_NEXT 0x10u  /* next.sector, with next.psi_alpha/beta */
#define CTRL_EST_PSI_AB_NEXT 0x20u  /* next.psi_alpha, next.psi_beta */
#define CTRL_EST_SC_NEXT 0x40u      /* next.sin_theta, next.cos_theta */
#define CTRL_EST_I_AB_NEXT 0x80u    /* next.i_alpha, next.i_beta, with next sin/cos */
#define CTRL_EST_AMP_SQ_NEXT 0x100u /* next.psi_amp_sq (two multiplies, no root) */
#define CTRL_EST_ALL 0x1FFu
/* For a descriptor's est_unused (controller.h): it reads no optional output but x. */
#define CTRL_EST_ONLY(x) ((uint16_t)(CTRL_EST_ALL & ~(unsigned)(x)))

/* Range of the phase currents the estimator takes (beyond: taken as the
 * limit): 32 pu, twice the largest trip level the core accepts
 * (current_max <= 16 pu), so the over-current protection acts first; it
 * bounds every product of the period (no saturation needed in the Park
 * transform and the voltage terms). Leg duties are taken in [0, FX_ONE],
 * the DC link in [0, 64 pu]. */
#define CTRL_EST_I_LIM ((q24_t)1 << 29)

typedef struct {
    const ctrl_angle_src_t *src; /* angle source; init: ctrl_angle_encoder */
    uint16_t outputs;            /* CTRL_EST_* (with what they imply), set by
                                  * ctrl_estimator_set_outputs; init: all */
    ctrl_angle_in_t in;          /* what the source sees; v_alpha, v_beta: the
                                  * mean voltage of the last period (for a
                                  * source with uses_voltage), Q24 pu */
    union {
        max_align_t align;
        unsigned char bytes[CTRL_ANGLE_STATE_MAX];
    } src_state; /* the source's state */
} ctrl_estimator_t;

/* Encoder angle source, every output. */
void ctrl_estimator_init(ctrl_estimator_t *e, const ctrl_params_t *p);

/* Forget the history (the source's, the last voltage); keep the settings. */
void ctrl_estimator_reset(ctrl_estimator_t *e, const ctrl_params_t *p);

/* Select the angle source (its state cleared and reset). Returns CTRL_OK,
 * or CTRL_EINVAL (NULL, no update function, state larger than
 * CTRL_ANGLE_STATE_MAX) with the previous source kept. */
int ctrl_estimator_set_angle_src(ctrl_estimator_t *e, const ctrl_params_t *p,
                                 const ctrl_angle_src_t *src);

/* The selected source's state (e.g. for ctrl_angle_forced_set); inline, as
 * the interrupt reads the sensorless source's every period. */
static inline void *ctrl_estimator_angle_state(ctrl_estimator_t *e)
{
    return e != NULL ? e->src_state.bytes : NULL;
}

/* Choose the optional outputs (CTRL_EST_*; a sector implies the stator-frame
 * flux it is taken from, I_AB_NEXT the sine and cosine at k+1). */
void ctrl_estimator_set_outputs(ctrl_estimator_t *e, unsigned outputs);

/* Estimate at k and predict k+1; applied: the leg duties acting during
 * [k, k+1) (NULL: a zero vector). */
void ctrl_estimator_update(ctrl_estimator_t *e, const ctrl_params_t *p, const ctrl_meas_t *m,
                           const ctrl_legs_t *applied, ctrl_estimate_t *est);

#endif /* CONTROL_ESTIMATOR_H */
