/*
 * The closed-loop engine: plant (sim_host) + the HAL back-end that carries it
 * (engine_port.h: hal/sim on the host, hal/qemu_mps2 in the QEMU images) + the
 * firmware pipeline (firmware/), period by period. The same code runs the
 * host simulator (./tools/sim, the tests) and the PIL images in QEMU.
 *
 * Time line: the firmware boots and calibrates its ADC offsets with the gates
 * off (calib_samples periods, plant running: imposed speed or coasting), waits
 * arm_delay_periods periods ready (0 by default: a test moves the arm instant
 * against the rotor, the noise and the switching with it), then it is armed;
 * scenario time t = 0 is the arm instant. Traces and metrics use
 * scenario time. In free mechanics the load torque is applied from t = 0 (a
 * constant load on the unpowered rotor would spin it backwards meanwhile).
 *
 * Metrics (sim_host/metrics.h): true plant signals on a grid of Ts/10 over the
 * window (plant sampling), and the true signals at the control instants
 * (control sampling, the *_ctrl keys). The torque reference of T_sse is the
 * reference the firmware used (output of the speed PI in speed mode); the
 * reference asked for is kept beside it (torque_ref_requested_nm in the JSON)
 * and a reference outside the drive's torque limit raises a warning.
 *
 * Validation before the run (sim_run_init): the scenario against the run
 * (load steps need free mechanics, speed steps a dynamometer, a reference
 * must match the run's mode: errors; events after the end and references the
 * firmware clamps: warnings). A configuration the firmware refuses is
 * explained by the single values (machine data, fs) that would make it
 * acceptable. Warnings go to stderr and to cfg.warnings (the JSON).
 *
 * Faults: with stop_on_fault the run ends in the period the firmware latched
 * a fault (fault_time_s, metrics over the samples before it).
 *
 * Output filter (machine [filter], sim_host/plant_filter.h): the firmware's
 * current sensors sit at the inverter output or the motor terminals (the
 * machine's current_sense, or cfg.hal.sense_motor_side); the active filter's
 * reference generator gets the firmware's torque reference every period (its
 * "control setting", S1 (50)); the metrics add the filter's losses, branch
 * currents and the active filter's storage capacitors over the window.
 */
#ifndef FIRMWARE_HOST_SIM_RUN_H
#define FIRMWARE_HOST_SIM_RUN_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "engine_port.h"
#include "metrics.h"
#include "pipeline.h"
#include "plant.h"
#include "sim_diag.h"
#include "sim_machine.h"
#include "sim_scenario.h"

#define SIM_MAX_SETS 32u
/* The longest wait between the calibration and the arm (one second at 64 kHz). */
#define SIM_ARM_DELAY_MAX 65536u

typedef struct sim_run sim_run_t;

/*
 * A target that runs the same firmware period by period (processor in the
 * loop over a link, host_sim/sim_pil.h). setup: after the host's fw_init,
 * before the first period (fc: the configuration fw_init got). send: after
 * the period's samples, before the host's fw_isr (the samples and the main
 * loop's commands). receive: after the host's fw_isr: the target's outputs
 * replace the host's at the HAL (they drive the plant), and must equal them.
 * Each returns 0, or -1 for a link fault (named by error()): gates off, the
 * run stops.
 */
typedef struct {
    void *ctx;
    int (*setup)(void *ctx, sim_run_t *r, const fw_config_t *fc, char *err, size_t errlen);
    int (*send)(void *ctx, sim_run_t *r);
    int (*receive)(void *ctx, sim_run_t *r);
    const char *(*error)(void *ctx);
} sim_link_t;
#define SIM_SET_NAME_MAX 48u

/* A controller tunable set by name (--set NAME=VALUE). */
typedef struct {
    char name[SIM_SET_NAME_MAX];
    double value;
} sim_set_t;

typedef struct {
    sim_machine_t plant_machine; /* the simulated drive */
    ctrl_machine_t ctrl_machine; /* what the controller is configured with */
    const ctrl_desc_t *ctrl;
    const void *ctrl_cfg; /* NULL = desc->cfg_default(ctrl_machine) + sets */
    sim_set_t sets[SIM_MAX_SETS];
    size_t n_sets;
    uint32_t fs_hz;
    bool free_mech;         /* false: dynamometer at speed_rpm */
    double speed_rpm;       /* imposed speed, or initial speed (free) */
    double load_nm;         /* free mechanics: constant (active) load torque, from arm on
                               (default: the machine file's [mechanics] constant load) */
    double load_passive_nm; /* free mechanics: passive load magnitude (opposes motion;
                               default: the machine file's [mechanics] passive load) */
    bool speed_mode;        /* speed reference (outer PI) instead of torque */
    double torque_ref_nm, speed_ref_rpm;
    double duration_s;             /* after arm */
    double win_start_s, win_end_s; /* metrics window (scenario time) */
    uint64_t seed;
    const sim_scenario_t *scenario;    /* may be NULL */
    FILE *trace;                       /* may be NULL */
    uint32_t trace_decimation;         /* every n-th sample of the Ts/10 grid, >= 1 */
    double trace_start_s, trace_end_s; /* rows written in [start, end] (scenario time) */
    engine_hal_config_t hal;           /* filled by sim_run_config_default, adjustable */
    uint32_t calib_samples;
    /* Speed loop and overspeed (fw_config_t; from the machine file by default). */
    double speed_bw_hz, speed_pm_deg;     /* sizing (0 = firmware defaults) */
    double speed_kp, speed_ki;            /* explicit gains, N*m s/rad, N*m/rad (0 = sized) */
    double overspeed_rpm;                 /* 0 = 1.05 x the machine's maximum speed (protect.h) */
    uint32_t torque_follow_fault_windows; /* fw_config_t's (0: warning only) */
    bool stop_on_fault;                   /* end the run at a fault (default false) */
    bool psi_adapt;                       /* fw_config_t.psi_adapt (default true) */
    bool dead_comp;                       /* fw_config_t.dead_comp (default true) */
    bool sensorless;                      /* fw_config_t.sensorless (default false) */
    /* The dead time the firmware's compensation assumes, s; < 0 (default): the
     * plant's, a perfectly known inverter. A production spread sets the plant's
     * and keeps this at the nominal value. */
    double comp_dead_time_s;
    bool hfi; /* fw_config_t.hfi (default false); its settings as sets "hfi.<field>" */
    /* Driving the periods (defaults: the host simulator). */
    bool defer_start;             /* sim_run_init stops before boot: the caller runs every period */
    bool auto_arm;                /* arm with the references above once calibrated (default) */
    uint32_t arm_delay_periods;   /* auto_arm: periods the drive stays ready before the arm (0) */
    bool kick_watchdog;           /* kick after each ISR (default; a target's main loop does it) */
    void (*after_isr)(void *ctx); /* called right after fw_isr, may be NULL */
    void *after_isr_ctx;
    bool skip_thd; /* no THD (the QEMU images: its sums cost ~10^10 soft-float ops) */
    /* The firmware's encoder configuration (the control machine's [sensors];
     * default: the plant machine's, i.e. a perfectly known encoder). */
    int ctrl_enc_lines;
    double ctrl_enc_offset_deg;
    int ctrl_enc_dir;
    double theta0_e_rad;      /* initial electrical rotor angle of the plant */
    sim_warnings_t *warnings; /* may be NULL (warnings printed only) */
    const sim_link_t *link;   /* PIL target, NULL: the host firmware alone */
} sim_run_cfg_t;

struct sim_run {
    sim_run_cfg_t cfg;
    plant_t plant;
    plant_fluxmap_t fluxmap; /* the machine file's [fluxmap], when it names one */
    hal_t hal;
    fw_t fw;
    sim_scenario_t scn;
    bool has_scn;
    bool armed;   /* the run's arm instant has passed */
    double t_arm; /* plant time of the arm instant */
    /* Periods ended in the ready state before the arm (cfg.arm_delay_periods). */
    uint32_t ready_periods;
    double t_end;
    double obs_dt;
    metrics_acc_t m_plant, m_ctrl;
    uint64_t tr_win_start; /* plant transitions at the window start */
    double t_win_start;    /* scenario time of that period boundary */
    bool win_started, win_done;
    uint64_t obs_count;
    bool obs_on;          /* plant observer installed */
    double speed_sum_rpm; /* mean speed in the window (free-mode THD) */
    uint64_t speed_n;
    /* Speed mode: the true speed against the firmware's speed reference on the
     * plant grid of the window (sum of squares, largest magnitude, r/min). */
    double speed_err_sum2, speed_err_max;
    int plant_rc;
    uint8_t vec_now;                /* vector acting in the present period (chosen at k-1) */
    double duty_now;                /* its on-time fraction */
    double torque_limit_nm;         /* the firmware's torque-reference clamp */
    double torque_limit_brake_nm;   /* its braking limit (w T < 0, field_weak.h) */
    double torque_ref_requested_nm; /* last torque reference asked for (torque mode) */
    double fault_time_s;            /* scenario time of the first fault, NaN if none */
    /* Estimator against the plant at the control instants of the window where
     * |speed| >= 10 % of rated (sim_run_est_errors). */
    double est_ang_sum2, est_ang_max, est_spd_sum2;
    uint64_t est_n;
    /* the same below 10 % of rated speed (sim_run_est_errors_low) */
    double est_lo_sum2, est_lo_max;
    uint64_t est_lo_n;
    double scn_fired_s[SIM_SCN_MAX_EVENTS]; /* scenario time each event fired, NaN if not */
    unsigned char ctrl_cfg_buf[CTRL_CFG_MAX] __attribute__((aligned(16)));
    /* output filter (plant_machine.filter): cumulative statistics at the
     * window's start and end (losses, branch currents, AF capacitors) */
    plant_filter_stats_t flt_w0, flt_w1;
    double flt_t0, flt_t1;
    bool flt_w1_set;
    /* non-ideal mechanics (plant_mech_stats) at the window's start and end */
    plant_mech_stats_t mech_w0, mech_w1;
    double mech_t0, mech_t1;
    /* The torque limit of field weakening over the metrics window (torque
     * mode): periods, periods the request was clipped, the smallest limit and
     * the sum of the reference the controller got (before the trim). */
    uint64_t lim_n, lim_clipped_n;
    double lim_min_nm, tref_sum_nm;
    uint8_t lim_last; /* fw_telemetry_t.fieldweak_limit of the last clipped period */
    bool lim_warned;
    bool link_failed;    /* the PIL link reported a fault (cfg.link->error) */
    uint64_t lim_weak_n; /* periods of the window with the flux weakened (fieldweak_limit bit 3) */
};

/* The pipeline configuration of a run (the controller's aside). */
void sim_run_fw_config(const sim_run_cfg_t *c, const ctrl_machine_t *m, fw_config_t *fc);

/* Convert a machine file into the controller's machine description. */
void sim_ctrl_machine_from(const sim_machine_t *m, ctrl_machine_t *out);
/* The control machine's encoder settings ([sensors]) into the run's firmware
 * configuration. */
void sim_run_ctrl_sensors_from(sim_run_cfg_t *c, const sim_machine_t *m);

/* Defaults: fs = machine fs (the caller sets the controller's), dynamometer
 * at 0 r/min, torque mode 0 N*m, 0.3 s, window 0.1 s .. end, seed 1. */
void sim_run_config_default(sim_run_cfg_t *c, const sim_machine_t *m, const ctrl_desc_t *ctrl);

/* Build everything and run boot + calibration + arm (unless cfg.defer_start).
 * Returns 0 or -1 with a message. */
int sim_run_init(sim_run_t *r, const sim_run_cfg_t *cfg, char *err, size_t errlen);
/* One PWM period: before the arm, boot/calibration (arming at the end of
 * it with auto_arm); after it, scenario and metrics bookkeeping at the period
 * start, then HAL begin, fw_isr, after_isr, watchdog kick, plant through the
 * period. The host calls it in a loop, a QEMU image from its Timer0
 * interrupt. Returns 0, or -1 if the plant failed. */
int sim_run_period(sim_run_t *r);
/* Armed and the duration reached. */
bool sim_run_done(const sim_run_t *r);
/* Scenario time of the next period start (seconds since arm). */
double sim_run_time(const sim_run_t *r);
/* Run until the end of the duration (or the fault, with stop_on_fault). */
int sim_run_all(sim_run_t *r, char *err, size_t errlen);
/* Metrics of the window (plant and control sampling). */
int sim_run_metrics(sim_run_t *r, metrics_result_t *plant, metrics_result_t *ctrl);

/* The non-ideal mechanics over the metrics window (free mechanics on a machine
 * with Coulomb friction, stiction, cogging or a load; else 0 and NaN): time at
 * rest held by friction, its fraction of the window, break-aways, stops,
 * reversals, the mean bearing friction and load torque against the motion
 * (their work over the angle turned) and the friction's power. */
typedef struct {
    int present;
    double stuck_s, stuck_frac;
    uint64_t breakaways, stops, reversals;
    double friction_nm, load_nm, friction_w;
} sim_mech_summary_t;
void sim_run_mech_summary(const sim_run_t *r, sim_mech_summary_t *m);
/* {...} with the keys of the CLI's --metrics. */
void sim_run_write_metrics_json(FILE *f, const sim_run_t *r, const metrics_result_t *mp,
                                const metrics_result_t *mc);
void sim_run_free(sim_run_t *r);

/* The estimator's errors (rotor angle used for control and electrical speed
 * against the plant's, at the control instants of the metrics window where
 * |speed| >= 10 % of rated): rms and largest angle error (electrical deg),
 * rms speed error (mechanical r/min); NaN without such instants. */
void sim_run_est_errors(const sim_run_t *r, double *ang_rms_deg, double *ang_max_deg,
                        double *spd_rms_rpm);

/* The estimator's angle error where |speed| < 10 % of rated (standstill
 * included: the injection's range), over the same window: rms and largest,
 * electrical deg; NaN without such instants. */
void sim_run_est_errors_low(const sim_run_t *r, double *ang_rms_deg, double *ang_max_deg);

/* True when the run ended at a fault or the firmware is in the fault state. */
bool sim_run_faulted(const sim_run_t *r);

/* The speed reference, N*m limit and mode in SI for reports. */
double sim_run_speed_rpm(const sim_run_t *r);
/* The speed reference in force (r/min, after the drive's clamp), NaN in torque mode. */
double sim_run_speed_ref_now(const sim_run_t *r);

#endif /* FIRMWARE_HOST_SIM_RUN_H */
