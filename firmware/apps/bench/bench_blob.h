/*
 * Recorded closed-loop inputs for the interrupt-cost benchmark (tools/bench).
 *
 * bench_host records, on the PC, a closed loop (plant + hal/sim + firmware) of
 * one controller at one speed from fw_init on (boot, ADC calibration, arm,
 * running) and writes every period's raw inputs (ADC counts, encoder, commands)
 * and the compare values the firmware wrote. The same file is replayed through
 * fw_isr on the PC (wall time, callgrind) and on the emulated Cortex-M4
 * (QEMU -device loader puts it at BENCH_BLOB_ADDR; instruction counts).
 *
 * Layout: one bench_hdr_t, then hdr.n bench_rec_t. Little-endian, fixed-size
 * fields with explicit padding, so x86-64 and ARM EABI agree (checked below).
 */
#ifndef TOOLS_BENCH_FW_BENCH_BLOB_H
#define TOOLS_BENCH_FW_BENCH_BLOB_H

#include <stddef.h>
#include <stdint.h>

#define BENCH_MAGIC 0x42534d50u /* "PMSB" */
#define BENCH_VERSION 2u
#ifndef BENCH_BLOB_ADDR             /* the build may place it elsewhere (bench_cm0) */
#define BENCH_BLOB_ADDR 0x20200000u /* QEMU RAM, 2 MB below the stack top */
#define BENCH_BLOB_MAX 0x00100000u  /* 1 MB */
#endif

#define BENCH_CMD_TORQUE 0x1u /* fw_set_torque_ref(hdr.torque_ref_q24) before the ISR */
#define BENCH_CMD_ARM 0x2u    /* fw_cmd_arm before the ISR */

typedef struct {
    uint32_t magic, version;
    uint32_t n;             /* records */
    uint32_t arm_index;     /* record whose ISR arms the drive (first running ISR) */
    uint32_t calib_samples; /* fw_config_t.calib_samples of the recording */
    int32_t torque_ref_q24; /* Q24 pu torque reference set at arm */
    uint32_t speed_rpm;     /* imposed (dynamometer) speed of the recording */
    uint32_t torque_mnm;    /* torque reference, mN*m */
    char ctrl_name[32];
    /* hal_info_t of the recording HAL */
    uint32_t pwm_freq_hz, period_counts, encoder_counts_per_rev, cycle_clock_hz;
    uint32_t adc_bits, has_i_c;
    uint32_t sensorless; /* fw_config_t.sensorless of the recording (0/1; 2: and .hfi) */
    uint32_t pad1;
    double adc_current_a_per_count, adc_vdc_v_per_count;
    /* ctrl_machine_t of the controller */
    int32_t pole_pairs;
    uint32_t pad2;
    double rs_ohm, ld_h, lq_h, psi_pm_wb, vdc_v, inertia_kgm2, torque_rated_nm, speed_rated_rpm,
        current_rated_a, current_max_a, psi_ref_wb;
    char machine_name[32];
    /* fw_config_t.dead_time_s and v_fwd_v of the recording (the plant's
     * inverter: the dead-time compensation runs with them) */
    double dead_time_s, v_fwd_v;
} bench_hdr_t;

typedef struct {
    uint16_t adc[4]; /* i_a, i_b, i_c, vdc counts */
    uint8_t cmd;     /* BENCH_CMD_* */
    uint8_t index_seen;
    uint8_t trip;
    uint8_t state_after; /* fw_state_id_t after the ISR */
    uint32_t enc_count, index_count;
    uint32_t cmp[3]; /* compare values written by the ISR */
} bench_rec_t;

_Static_assert(sizeof(bench_hdr_t) == 256u, "bench_hdr_t layout");
_Static_assert(offsetof(bench_hdr_t, adc_current_a_per_count) == 96u, "bench_hdr_t layout");
_Static_assert(offsetof(bench_hdr_t, machine_name) == 208u, "bench_hdr_t layout");
_Static_assert(sizeof(bench_rec_t) == 32u, "bench_rec_t layout");
_Static_assert(offsetof(bench_rec_t, cmp) == 20u, "bench_rec_t layout");

#endif /* TOOLS_BENCH_FW_BENCH_BLOB_H */
