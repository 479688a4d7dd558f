/* Helpers of the closed-loop tests: the thesis SPMSM and a configured run. */
#ifndef TESTS_LOOP_LOOP_UTIL_H
#define TESTS_LOOP_LOOP_UTIL_H

#include "sim_run.h"

/* Thesis SPMSM (sim_host/machines/thesis_spmsm.ini); aborts the test on error. */
const sim_machine_t *loop_spmsm(void);

/* Dynamometer run of controller `name` at speed_rpm with a torque reference,
 * ADC noise off unless noise > 0; duration and window in seconds. */
void loop_cfg(sim_run_cfg_t *c, const char *name, double speed_rpm, double torque_nm,
              double duration_s, double win_start_s);

/* Initialise the run; fails the test with the message on error. */
void loop_start(sim_run_t *r, const sim_run_cfg_t *c);

#endif /* TESTS_LOOP_LOOP_UTIL_H */
