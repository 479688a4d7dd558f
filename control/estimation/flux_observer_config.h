/*
 * Configuration side of the stator-flux observer (flux_observer.h): SI values
 * (double) converted to its fixed-point gains. Included only by *_config.c
 * files, tests and the firmware's configuration code.
 */
#ifndef CONTROL_FLUX_OBSERVER_CONFIG_H
#define CONTROL_FLUX_OBSERVER_CONFIG_H

#include "ctrl_params.h"
#include "flux_observer.h"

typedef struct {
    unsigned mode;        /* CTRL_FOBS_SENSORLESS or CTRL_FOBS_ENCODER */
    double k0_rad_s;      /* sensorless gain at standstill, rad/s */
    double kappa;         /* sensorless speed-proportional gain: k = k0 + kappa |omega_e| */
    double kenc_rad_s;    /* encoder mode: corner of the current-model correction, rad/s */
    double pll_hz;        /* PLL natural frequency (critically damped), Hz */
    double dead_time_s;   /* inverter dead time to compensate, s (0 = none) */
    double v_fwd_v;       /* device forward drop to compensate, V (0 = none) */
    double band_a;        /* current band of the soft sign (the sign is unknown within), A */
    double psi_tau_s;     /* PM-flux estimate time constant, s (0 = off) */
    double psi_speed_min; /* PM-flux estimate runs above this share of the rated speed */
} ctrl_fobs_config_t;

/* Defaults for a machine (docs/algorithms.md, "Stator-flux observer"): sensorless,
 * k0 = 1 % and w_c = 5 % of the rated electrical speed, kappa = 0.5,
 * PLL 300 Hz, no inverter compensation (band 5 % of the rated current),
 * PM-flux estimate off (0.05 s above 20 % of the rated speed when on). */
void ctrl_fobs_config_default(ctrl_fobs_config_t *c, const ctrl_machine_t *m);

/* Validate c against the machine's fixed-point parameters and bases and set
 * the observer's gains; the state is cleared (not primed). Returns CTRL_OK,
 * or CTRL_EINVAL (a NULL pointer, or a value outside its range: *why names
 * the ctrl_fobs_config_t field, its value and the range; why may be NULL;
 * ctrl_diag_format words it) with *o untouched. */
int ctrl_fobs_init(ctrl_fobs_t *o, const ctrl_params_t *p, const ctrl_bases_t *b,
                   const ctrl_fobs_config_t *c, ctrl_diag_t *why);

#endif /* CONTROL_FLUX_OBSERVER_CONFIG_H */
