/*
 * Data generated on the host by pil_gen (tests/target_pil/pil_gen.c) into
 * pil_data.c and compiled into the host replay test and the QEMU images:
 *  - pil_recs: per registered controller, the pipeline's inputs (raw ADC,
 *    encoder, commands) and outputs (compare values, gate request, telemetry)
 *    of a host closed-loop run, from fw_init on (boot, calibration, arm,
 *    running);
 *  - pil_cl: the closed-loop scenarios of the PIL test (plant, HAL models,
 *    machine, references) with the host's metrics of the same run.
 */
#ifndef TESTS_TARGET_PIL_PIL_DATA_H
#define TESTS_TARGET_PIL_PIL_DATA_H

#include <stddef.h>
#include <stdint.h>

#include "ctrl_params.h"
#include "hal.h"

#define PIL_CMD_TORQUE 0x1u /* fw_set_torque_ref(rec->torque_ref_q24) before the ISR */
#define PIL_CMD_ARM 0x2u    /* fw_cmd_arm before the ISR */

typedef struct {
    uint16_t adc[4]; /* i_a, i_b, i_c, vdc counts */
    uint8_t cmd;     /* PIL_CMD_* */
    uint8_t index_seen;
    uint8_t trip; /* hardware trip comparator latched */
    uint32_t enc_count, index_count;
} pil_in_t;

typedef struct {
    uint32_t cmp[3]; /* last compare values written (shadow) */
    uint8_t gates;   /* gate request after the ISR (1 = enable requested) */
    uint8_t state, fault, vec;
    int32_t i_a, i_b, vdc, psi_amp, torque, omega_e, torque_ref, duty;
    int32_t legs[3];
    uint32_t theta_e, period, cycles;
} pil_out_t;

typedef struct {
    const char *name;
    hal_info_t info;        /* what the recording HAL reported */
    ctrl_machine_t machine; /* the controller's machine */
    uint32_t calib_samples;
    int32_t torque_ref_q24;
    uint32_t n; /* periods (ISR calls) */
    const pil_in_t *in;
    const pil_out_t *out;
} pil_rec_t;

extern const pil_rec_t pil_recs[];
extern const size_t pil_n_recs;

/* Metrics of one run (sim_host/metrics.h names). */
typedef struct {
    double torque_mean_nm, torque_ripple_nm, flux_mean_wb, flux_ripple_wb, torque_sse_nm;
    double f_av_hz, thd_i_pct;
    double torque_mean_ctrl_nm, torque_ripple_ctrl_nm, flux_mean_ctrl_wb, flux_ripple_ctrl_wb,
        torque_sse_ctrl_nm;
} pil_metrics_t;

/* Closed-loop scenario (dynamometer): plant_config_t fields of sim_host, the
 * HAL model settings of hal_sim_config_t, references and the host result. */
typedef struct {
    const char *ctrl_name;
    ctrl_machine_t machine;
    /* plant_config_t (linear model, imposed speed) */
    int pole_pairs;
    double rs_ohm, ld_h, lq_h, psi_pm_wb, vdc_v, dc_cap_f, dc_src_r_ohm, dead_time_s, v_fwd_v;
    double inertia_kgm2, friction_nms, speed_rpm;
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

#endif /* TESTS_TARGET_PIL_PIL_DATA_H */
