/*
 * Speed PI controller giving the torque reference (outer loop of the thesis
 * experiments, §4.6: Kp = 0.006843, Ki = 0.78046 for the SPMSM).
 *
 * u = Kp e + I, I += Ki Ts e, e = omega_ref - omega (electrical speed, Q24 pu).
 * Anti-windup by clamping (conditional integration): the integrator holds when
 * the output is saturated and the error drives it further into saturation, and
 * is itself kept within the output limit. Output limited to [-out_max, out_max].
 */
#ifndef CONTROL_SPEED_PI_H
#define CONTROL_SPEED_PI_H

#include <stdint.h>

#include "ctrl_params.h"
#include "fx.h"

typedef struct {
    int32_t kp;    /* proportional gain, Q(kp_shift): torque pu per speed pu */
    int32_t ki_ts; /* Ki * Ts of the loop, Q(ki_shift): torque pu per (speed pu * period) */
    uint8_t kp_shift, ki_shift; /* fractional bits of kp and ki_ts (chosen in config) */
    q24_t out_max;              /* output limit, Q24 pu torque (> 0) */
    int64_t integ;              /* integrator, Q(24 + ki_shift) pu torque */
} ctrl_speed_pi_t;

/* Set the integrator so that the output starts at out (bumpless start). */
void ctrl_speed_pi_reset(ctrl_speed_pi_t *pi, q24_t out);

/* One step: torque reference (Q24 pu) for speed reference and measurement (Q24 pu). */
q24_t ctrl_speed_pi_step(ctrl_speed_pi_t *pi, q24_t omega_ref, q24_t omega);

/*
 * New gains while the loop runs, bumpless: pi takes kp, ki_ts and their shifts
 * from to (ctrl_speed_pi_config of the new gains; its out_max and integrator
 * are not used) and keeps its output limit. The integrator keeps the torque
 * it holds (rescaled to the new ki_shift) plus (Kp_old - Kp_new) e, so that
 * the output for the error e is the same under both gains:
 *   u = Kp_new e + I_new = Kp_old e + I_old.
 * The next step after it differs from a step without the change only by
 * (Kp_new - Kp_old)(e' - e) + (Ki_new - Ki_old) Ts e' (e': that step's error)
 * and the rounding (2 LSB); the integrator stays within the output limit (a
 * change that needs more is clamped there). e: the latest speed error, Q24 pu.
 */
void ctrl_speed_pi_retune(ctrl_speed_pi_t *pi, const ctrl_speed_pi_t *to, q24_t e);

#endif /* CONTROL_SPEED_PI_H */
