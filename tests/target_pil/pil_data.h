/*
 * Data generated on the host by pil_gen (tests/target_pil/pil_gen.c) into
 * pil_data.c and compiled into the host replay test and the QEMU images:
 *  - pil_recs: per registered controller, the pipeline's inputs (raw ADC,
 *    encoder, commands) and outputs (compare values, gate request, telemetry)
 *    of a host closed-loop run, from fw_init on (boot, calibration, arm,
 *    running);
 *  - pil_cl, pil_machine (pil_cl.h): the closed-loop scenarios of the PIL
 *    test and the machine file.
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
    int32_t i_a, i_b, vdc, i_d, i_q, psi_d, psi_q, torque, omega_e, torque_ref, duty;
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
    uint8_t sensorless; /* fw_config_t.sensorless: no encoder, the observer's angle */
} pil_rec_t;

extern const pil_rec_t pil_recs[];
extern const size_t pil_n_recs;

#endif /* TESTS_TARGET_PIL_PIL_DATA_H */
