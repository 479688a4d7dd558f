/*
 * Configuration side of the sensorless angle (sensorless.h): SI values
 * (double) converted to its fixed-point settings. Included only by
 * *_config.c files, tests and the firmware's configuration code.
 */
#ifndef CONTROL_SENSORLESS_CONFIG_H
#define CONTROL_SENSORLESS_CONFIG_H

#include "ctrl_params.h"
#include "flux_observer_config.h"
#include "hfi_config.h"
#include "sensorless.h"

typedef struct {
    ctrl_fobs_config_t obs; /* the observer (mode forced to sensorless) */
    double t_start_nm;      /* torque reference while forced, N*m (> 0) */
    double ramp_rad_s2;     /* forced speed ramp, electrical rad/s^2 (> 0) */
    double w_on_frac;       /* handover speed, share of the rated speed */
    double w_off_frac;      /* forced again under this share of the rated speed ... */
    double low_s;           /* ... for this long, s */
    double settle_s;        /* time at the handover speed before the handover, s */
    double kappa_start;     /* observer gain while forced (obs.kappa afterwards) */
    double theta0_rad;      /* forced angle at the start, electrical rad */
    double damp_zeta;       /* damping ratio of the forced start's swing (0: off) */
    double inertia_kgm2;    /* rotor (and load) inertia the damping is sized for (0: off) */
    /* Salient machines: the start from the measured angle (sensorless.h) when
     * 2 |Lq - Ld| / (Lq + Ld) >= ia_saliency_min (> 2: never). */
    double ia_saliency_min;
    double ia_i_frac;    /* current change of one pulse, share of the rated current */
    double ia_rounds;    /* rounds of the six pulse directions per measurement */
    double pol_deg;      /* polarity pulse: displacement of the bare rotor, electrical deg */
    double pol_min_frac; /* displacement under which the polarity is unknown, share of pol_deg */
#if CTRL_SL_HFI
    /* High-frequency injection at and near standstill (hfi.h; an image built
     * with it, CMake option PMSM_SL_HFI): 0 off (the forced start and
     * fallback), 1 on. */
    unsigned hfi;
    ctrl_hfi_config_t hfi_cfg;
    double hfi_low_s; /* time above the upper hand-over speed before the hand-over, s */
#endif
} ctrl_sl_config_t;

/*
 * Defaults for a machine (docs/algorithms.md, "Sensorless start-up"):
 * t_start = half the rated torque; the ramp a quarter of what t_start
 * accelerates the bare rotor with (t_start p / (4 J)), leaving the rest for a
 * load; handover at 5 % of the rated speed after 6 time constants of the
 * observer at critical damping (kappa_start = 2: 6 / w_on); forced again
 * under 2.5 % for 50 ms (the time a 10 % resistance error at rated current
 * takes to turn the thesis SPMSM's flux by 10 deg). Salient machines
 * (saliency >= 0.1) measure their angle: pulses of 10 % of the rated
 * current, 2 rounds; a polarity pulse that turns the bare rotor by 10 deg
 * electrical, a quarter of which tells the polarity.
 */
void ctrl_sl_config_default(ctrl_sl_config_t *c, const ctrl_machine_t *m);

/* Validate and set everything (the observer through ctrl_fobs_init, the
 * injection through ctrl_hfi_init); the state is reset (ctrl_sl_reset).
 * Returns CTRL_OK or CTRL_EINVAL with *why naming the field (why may be
 * NULL) and *s untouched. */
int ctrl_sl_init(ctrl_sl_t *s, const ctrl_params_t *p, const ctrl_bases_t *b,
                 const ctrl_sl_config_t *c, ctrl_diag_t *why);

#endif /* CONTROL_SENSORLESS_CONFIG_H */
