/*
 * Configuration side of the PM-flux tracking (psi_track.h): the encoder-mode
 * observer's SI configuration and the highest speed, converted to its gains
 * and divider. Included only by *_config.c files, tests and the firmware's
 * configuration code.
 */
#ifndef CONTROL_PSI_TRACK_CONFIG_H
#define CONTROL_PSI_TRACK_CONFIG_H

#include "flux_observer_config.h"
#include "psi_track.h"

/* c: the observer's configuration (flux_observer_config.h), run in
 * CTRL_FOBS_ENCODER whatever c->mode says; its PLL's settings are validated
 * but unused; psi_tau_s = 0 leaves the estimate at p->psi_pm.
 * w_max_rad_s: the highest electrical speed the drive runs at, rad/s (> 0),
 * which sets the divider N (psi_track.h). Returns CTRL_OK, or CTRL_EINVAL (a NULL
 * pointer, or a value outside its range: *why names it, its value and the
 * range; why may be NULL) with *t untouched. The state is cleared (not
 * primed). */
int ctrl_psi_track_init(ctrl_psi_track_t *t, const ctrl_params_t *p, const ctrl_bases_t *b,
                        const ctrl_fobs_config_t *c, double w_max_rad_s, ctrl_diag_t *why);

#endif /* CONTROL_PSI_TRACK_CONFIG_H */
