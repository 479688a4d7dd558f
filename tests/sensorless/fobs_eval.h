/*
 * Offline evaluation of the stator-flux observer (flux_observer.h) in a
 * closed loop that still runs on the encoder: the simulator's run (plant,
 * HAL, firmware pipeline) with the observer fed, after every interrupt, the
 * signals the firmware had - the measured currents and DC link and the leg
 * duties it wrote - and compared with the plant's true angle, speed, flux and
 * torque. The observer's machine parameters may be off (scales of Rs, L,
 * psi_pm); the plant may have dead time, forward drops and ADC noise.
 */
#ifndef TESTS_SENSORLESS_FOBS_EVAL_H
#define TESTS_SENSORLESS_FOBS_EVAL_H

#include <stdbool.h>
#include <stdio.h>

#include "flux_observer_config.h"
#include "sim_run.h"

typedef struct {
    const char *machine_path; /* machine file */
    const char *controller;   /* registry name */
    unsigned fs_hz;           /* 0 = the controller's default */
    const char *scenario;     /* text in the sim_scenario.h format, or NULL */
    double speed_ref_rpm;     /* speed mode, free rotor */
    double load_nm;           /* initial constant load */
    double load_passive_nm;   /* initial passive load */
    double duration_s, win_start_s, win_end_s;
    double rs_scale, l_scale, psi_scale; /* observer's parameters / the plant's */
    double dead_time_ns, v_fwd_v;        /* plant inverter */
    bool compensate;                     /* observer compensates them (configured values) */
    double noise_counts;                 /* ADC noise sigma (counts) */
    bool has_fobs;                       /* fobs overrides the observer defaults */
    ctrl_fobs_config_t fobs;
    double stat_min_speed;      /* statistics where |speed| >= this share of rated (0.1) */
    unsigned arm_delay_periods; /* periods ready before the arm (sim_run_cfg_t's) */
    FILE *csv;                  /* per-period record, may be NULL */
} fobs_eval_cfg_t;

typedef struct {
    bool ok;         /* the run completed without a fault */
    unsigned long n; /* samples in the statistics (window, |speed| >= 10 % rated) */
    double ang_rms_deg, ang_max_deg, ang_mean_deg; /* flux angle - true angle, electrical */
    double spd_rms_rpm, spd_max_rpm;               /* PLL speed - true speed, mechanical */
    double fw_spd_rms_rpm;                         /* the firmware's encoder speed - true */
    double tq_err_mean_nm, tq_err_rms_nm;          /* psi^ x i - true torque */
    double enc_tq_err_mean_nm, enc_tq_err_rms_nm;  /* the same, encoder-mode observer */
    double cm_tq_err_mean_nm;                      /* the firmware's current model */
    double psi_pm_est_wb;                          /* encoder-mode PM-flux estimate at the end */
    double speed_end_rpm;
} fobs_eval_res_t;

void fobs_eval_default(fobs_eval_cfg_t *c);
/* Run; returns 0, or -1 with a message in err. */
int fobs_eval_run(const fobs_eval_cfg_t *c, fobs_eval_res_t *res, char *err, size_t errlen);

#endif /* TESTS_SENSORLESS_FOBS_EVAL_H */
