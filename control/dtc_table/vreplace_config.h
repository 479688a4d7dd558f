/*
 * Configuration side of the voltage replacement: SI values (double) converted to the
 * fixed-point state of vreplace.h. Included only by *_config.c files, tests and
 * the firmware's configuration code; the per-sample code includes vreplace.h
 * alone and stays integer-only.
 */
#ifndef CONTROL_VREPLACE_CONFIG_H
#define CONTROL_VREPLACE_CONFIG_H

#include "ctrl_units.h"
#include "vreplace.h"

#define CTRL_VR_SIGMA_MAX (CTRL_PI / 6.0) /* subsectors I and II of (4.19) meet */

/*
 * Configuration (vreplace_config.c, uses double): sigma_rad in [0, pi/6]
 * ((4.19) takes [0, pi/12]; up to pi/6 the subsectors I and II stay apart);
 * sigma == 0 disables the replacement. Returns CTRL_OK, or
 * CTRL_EINVAL for NULL, a non-finite or out-of-range sigma (c is then left
 * disabled when not NULL).
 */
int ctrl_vreplace_config(ctrl_vreplace_t *c, double sigma_rad);

#endif /* CONTROL_VREPLACE_CONFIG_H */
