/*
 * Configuration side of the speed PI: SI values (double) converted to the
 * fixed-point state of speed_pi.h. Included only by *_config.c files, tests and
 * the firmware's configuration code; the per-sample code includes speed_pi.h
 * alone and stays integer-only.
 */
#ifndef CONTROL_SPEED_PI_CONFIG_H
#define CONTROL_SPEED_PI_CONFIG_H

#include <stdint.h>

#include "ctrl_params.h"
#include "speed_pi.h"

/* Unit of the speed in which the SI gains are given. */
typedef enum {
    CTRL_SPEED_UNIT_RAD_S_MECH = 0, /* N*m per (mechanical rad/s), N*m per rad */
    CTRL_SPEED_UNIT_RPM = 1,        /* N*m per (r/min), N*m per (r/min * s) */
    CTRL_SPEED_UNIT_RAD_S_ELEC = 2  /* N*m per (electrical rad/s) */
} ctrl_speed_unit_t;

/* SI gains -> fixed point (speed_pi_config.c). kp in N*m per speed unit, ki in
 * N*m per (speed unit * s), out_limit_nm > 0, loop_hz = rate at which
 * ctrl_speed_pi_step is called. Clears the integrator. Returns CTRL_OK,
 * CTRL_EINVAL (NULL, non-finite, negative) or CTRL_ERANGE (does not fit). */
int ctrl_speed_pi_config(ctrl_speed_pi_t *pi, const ctrl_bases_t *bases, int pole_pairs, double kp,
                         double ki, ctrl_speed_unit_t unit, double out_limit_nm, uint32_t loop_hz);
/* The same; a CTRL_ERANGE names the per-unit quantity, its value and the
 * range in *why (may be NULL). */
int ctrl_speed_pi_config_diag(ctrl_speed_pi_t *pi, const ctrl_bases_t *bases, int pole_pairs,
                              double kp, double ki, ctrl_speed_unit_t unit, double out_limit_nm,
                              uint32_t loop_hz, ctrl_diag_t *why);

#endif /* CONTROL_SPEED_PI_CONFIG_H */
