/*
 * The host closed loop the recorders run (pil_gen here, bench_rec in
 * tools/bench_fw): the plant on a dynamometer (imposed speed), hal/sim and the
 * firmware, armed with a torque reference as soon as the firmware is READY.
 * Each period's ISR inputs are returned as a pil_in_t (what the replay HALs
 * feed back); the outputs are read from loop->hal / loop->fw between
 * rec_loop_isr and rec_loop_end.
 */
#ifndef TESTS_TARGET_PIL_REC_LOOP_H
#define TESTS_TARGET_PIL_REC_LOOP_H

#include <stdbool.h>
#include <stdint.h>

#include "controller.h"
#include "hal_sim.h"
#include "pil_data.h"
#include "pipeline.h"
#include "plant.h"
#include "sim_machine.h"
#include "sim_run.h" /* sim_ctrl_machine_from */

typedef struct {
    plant_t plant;
    hal_t hal;
    fw_t fw;
    hal_info_t info; /* what hal/sim reports (the replay HAL mirrors it) */
    int armed;
    q24_t torque_ref_armed; /* fw.torque_ref set at arm (before that ISR), Q24 pu */
} rec_loop_t;

/* Sets up the loop for controller d at fs on machine sm, the plant turning at
 * speed_rpm, calib_samples of current-offset calibration, the firmware with
 * its encoder (sensorless 0) or without (1: fw_config_t.sensorless; 2: with
 * the injection too, fw_config_t.hfi). Returns NULL or the
 * failing step ("plant_init failed for "; the caller appends d->name). */
const char *rec_loop_init(rec_loop_t *loop, const ctrl_desc_t *d, const sim_machine_t *sm,
                          uint32_t fs, double speed_rpm, uint32_t calib_samples,
                          unsigned sensorless);

/* Begins one period: arms at READY with torque_nm (in->cmd = PIL_CMD_TORQUE |
 * PIL_CMD_ARM in that period), samples the ISR inputs into *in, runs the ISR
 * and kicks the watchdog. */
void rec_loop_isr(rec_loop_t *loop, double torque_nm, pil_in_t *in);

/* Ends the period (the plant integrates it); PLANT_OK or the plant's error. */
int rec_loop_end(rec_loop_t *loop);

#endif /* TESTS_TARGET_PIL_REC_LOOP_H */
