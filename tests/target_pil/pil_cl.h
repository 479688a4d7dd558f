/*
 * The closed-loop part of pil_data.c (pil_gen, see pil_data.h), apart from the
 * replay recordings because it carries the machine file (sim_machine.h):
 *  - pil_cl: the closed-loop scenarios of the PIL test (plant, HAL models,
 *    machine, references) with the host's metrics of the same run;
 *  - pil_machine: the machine file the recordings and scenarios use (the
 *    interactive image runs it).
 */
#ifndef TESTS_TARGET_PIL_PIL_CL_H
#define TESTS_TARGET_PIL_PIL_CL_H

#include <stddef.h>
#include <stdint.h>

#include "ctrl_params.h"
#include "sim_machine.h"

/* Metrics of one run (sim_host/metrics.h names). */
typedef struct {
    double torque_mean_nm, torque_ripple_nm, flux_mean_wb, flux_ripple_wb, torque_sse_nm;
    double f_av_hz, thd_i_pct;
    double torque_mean_ctrl_nm, torque_ripple_ctrl_nm, flux_mean_ctrl_wb, flux_ripple_ctrl_wb,
        torque_sse_ctrl_nm;
} pil_metrics_t;

/* Closed-loop scenario (dynamometer): the machine file as the engine reads it
 * (sim_run_config_default), the HAL model settings of hal_sim_config_t,
 * references and the host result. */
typedef struct {
    const char *ctrl_name;
    ctrl_machine_t machine; /* the controller's (sim_ctrl_machine_from of plant) */
    sim_machine_t plant;
    double speed_rpm;
    /* hal_sim_config_t */
    uint32_t fs_hz, timer_clock_hz;
    uint8_t adc_bits;
    double i_fullscale_a, vdc_fullscale_v, adc_noise_counts, trip_level_a;
    uint32_t enc_lines;
    uint8_t enc_index;
    /* run */
    uint32_t calib_samples;
    double torque_ref_nm, duration_s, win_start_s, win_end_s;
    pil_metrics_t host; /* the host run of exactly this scenario */
    /* Tolerance of each metric: 3 x the largest deviation from `host` among
     * tol_runs host runs whose imposed speed differs by k * 1e-12 (relative):
     * a rounding-level perturbation, like the last-bit differences of libm
     * between glibc and newlib, that the closed loop turns into another (but
     * statistically equivalent) switching sequence. */
    pil_metrics_t tol;
    uint32_t tol_runs;
    double host_wall_s;
} pil_cl_t;

extern const pil_cl_t pil_cl[];
extern const size_t pil_n_cl;

/* The machine of the recordings (the thesis SPMSM), for the interactive image. */
extern const sim_machine_t pil_machine;

#endif /* TESTS_TARGET_PIL_PIL_CL_H */
