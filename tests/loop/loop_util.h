/* Helpers of the closed-loop tests: the thesis SPMSM and a configured run. */
#ifndef TESTS_LOOP_LOOP_UTIL_H
#define TESTS_LOOP_LOOP_UTIL_H

#include <stdbool.h>
#include <stdint.h>

#include "sim_run.h"

/* Thesis SPMSM (sim_host/machines/thesis_spmsm.ini); aborts the test on error. */
const sim_machine_t *loop_spmsm(void);
/* Thesis 80 kW IPMSM (thesis_ipmsm_80kw.ini, as shipped); aborts the test on error. */
const sim_machine_t *loop_ipmsm80(void);

/* Machine file `file` of sim_host/machines; fails the test on error. */
sim_machine_t loop_machine_file(const char *file);
/* Dynamometer run of controller `name` on machine m at fs (0: the
 * controller's default) and speed_rpm with a torque reference; duration and
 * window (to the end) in seconds, 64 calibration samples. */
void loop_cfg_machine(sim_run_cfg_t *c, const sim_machine_t *m, const char *name, uint32_t fs,
                      double speed_rpm, double torque_nm, double duration_s, double win_start_s);
/* The same on the thesis SPMSM at the controller's default rate. */
void loop_cfg(sim_run_cfg_t *c, const char *name, double speed_rpm, double torque_nm,
              double duration_s, double win_start_s);

/* Parse a scenario given as text (sim_scenario.h format); fails the test on error. */
void loop_scenario(sim_scenario_t *s, const char *text, const char *name);

/* Initialise the run; fails the test with the message on error. */
void loop_start(sim_run_t *r, const sim_run_cfg_t *c);
/* Initialise, run to the end and take the plant-grid metrics; fails the test
 * with the message on error. */
void loop_run_metrics(sim_run_t *r, const sim_run_cfg_t *c, metrics_result_t *mp);

/* Result of a speed-reversal run (thesis Figs. 4.14, 5.12, 6.17). */
typedef struct {
    bool reached;         /* the reversal command (the scenario's third line) fired */
    double min_rpm_after; /* lowest speed after the reversal command */
    double t_rise_ms;     /* T >= 90 % of 2 N*m after the step at 2 ms */
    double t_fall_ms;     /* T <= fall_nm after the reversal command */
    double tq_back_mean;  /* mean torque over the last 10 ms of backward motoring */
    double tq_back_rip;   /* its standard deviation */
    uint32_t fault;
} loop_reversal_t;

/*
 * Run `base` with free mechanics under `scenario` (text in the sim_scenario.h
 * format; its third line must be the reversal command). The run stops at the
 * configured duration, at a fault, or back_s after the speed first reaches
 * -1000 r/min; the backward torque statistics cover the last 10 ms of that
 * span. Prints one line under `label`.
 */
loop_reversal_t loop_reversal(sim_run_t *run, const sim_run_cfg_t *base, const char *scenario,
                              double fall_nm, double back_s, const char *label);

#endif /* TESTS_LOOP_LOOP_UTIL_H */
