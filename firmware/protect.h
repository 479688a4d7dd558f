/*
 * Drive protections. Each check is a small integer-only function the
 * pipeline calls in a fixed order every PWM period; each returns 0 or a fault
 * code (FW_FAULT_*), which the pipeline latches through the state machine.
 *
 * Criteria (thresholds derived from the machine in protect_config.c):
 *  - over-current: |i_a|, |i_b| or |i_c| > i_max (machine current_max_a). The
 *    pipeline calls it first, right after the conversion, and switches the
 *    gates off in the same period (before the estimator runs).
 *  - hardware trip input (hal_trip_active): same reaction.
 *  - DC link: v_dc > vdc_max (default 1.25 Vdc_nom) or < vdc_min (0.70 Vdc_nom)
 *    on one sample (the link capacitor makes a one-sample excursion of 25 %
 *    implausible as noise: ADC noise is a few counts).
 *  - encoder stuck: the counter has not moved for enc_stuck_periods periods
 *    although the last measured rate was >= enc_rate_min. enc_rate_min is the
 *    rate from which the rotor, decelerated by the largest torque the drive and
 *    load can produce (a_max = (T(i_max) + T_rated) / J), still travels at
 *    least two counts before it can stop: r^2 / (2 a_max) >= 2 counts. Below it
 *    a stop cannot be told from a stuck sensor (documented limitation).
 *  - encoder jump: |delta_k - delta_{k-1}| > enc_jump_max counts (second
 *    difference of the count) with delta_k != 0. A real rotor changes its rate
 *    by at most a_max*Ts^2 counts per period; quantisation adds +-2 counts.
 *    delta_k == 0 is left to the stuck check (a frozen counter is "stuck").
 *  - deadline: the ISR entered while the previous one was still running
 *    (re-entry flag) or its duration measured with hal_cycles exceeded the
 *    period (cycle budget from hal_info_t.cycle_clock_hz).
 *  - watchdog: a counter incremented every period and cleared by the main
 *    loop (fw_watchdog_kick); more than wdg_periods periods without a kick
 *    is a fault.
 */
#ifndef FIRMWARE_PROTECT_H
#define FIRMWARE_PROTECT_H

#include <stdbool.h>
#include <stdint.h>

#include "ctrl_params.h"
#include "fx.h"

enum {
    FW_FAULT_NONE = 0,
    FW_FAULT_OVERCURRENT = 1,  /* phase current above i_max */
    FW_FAULT_HW_TRIP = 2,      /* hardware trip comparator */
    FW_FAULT_DC_OVERVOLT = 3,  /* DC link above vdc_max */
    FW_FAULT_DC_UNDERVOLT = 4, /* DC link below vdc_min */
    FW_FAULT_ENC_STUCK = 5,    /* encoder counter frozen while turning */
    FW_FAULT_ENC_JUMP = 6,     /* implausible encoder step */
    FW_FAULT_DEADLINE = 7,     /* ISR overrun or re-entry */
    FW_FAULT_WATCHDOG = 8,     /* main loop stopped kicking */
    FW_FAULT_CALIB = 9,        /* ADC offset outside the plausible range */
    FW_FAULT_COUNT = 10
};

/* Name of a fault code ("overcurrent", ...); "unknown" for others. */
const char *fw_fault_name(uint32_t code);

typedef struct {
    q24_t i_max;                /* phase-current trip level, Q24 pu (> 0) */
    q24_t vdc_max, vdc_min;     /* DC-link window, Q24 pu */
    int32_t enc_jump_max;       /* counts; max |second difference| per period */
    uint32_t enc_stuck_periods; /* periods without a count before "stuck" */
    int32_t enc_rate_min_q16;   /* counts per period, Q16.16; stuck check armed above */
    uint32_t deadline_cycles;   /* cycle budget per ISR; 0 disables the overrun check */
    uint32_t wdg_periods;       /* periods without a kick before the fault; 0 disables */
} fw_protect_cfg_t;

typedef struct {
    fw_protect_cfg_t cfg;
    uint32_t enc_last;      /* counter at the previous period */
    int32_t enc_last_delta; /* counts moved in the previous period */
    uint32_t enc_still;     /* periods since the counter last moved */
    int32_t enc_rate_q16;   /* |rate| at the last move, counts/period Q16.16 */
    uint8_t enc_primed;     /* 0: nothing, 1: enc_last valid, 2: enc_last_delta valid */
    uint32_t wdg_count;     /* periods since the last kick */
} fw_protect_t;

/*
 * Thresholds from SI data (protect_config.c, configuration time only):
 * machine (current_max_a, vdc_v, torque_rated_nm, inertia_kgm2, pole pairs),
 * the control frequency, the encoder resolution and the ADC-side bases.
 * Returns CTRL_OK or CTRL_EINVAL for missing or non-physical data.
 */
int fw_protect_config(fw_protect_cfg_t *cfg, const ctrl_machine_t *m, const ctrl_bases_t *b,
                      uint32_t fs_hz, uint32_t enc_counts_per_rev, uint32_t cycle_clock_hz);

void fw_protect_init(fw_protect_t *p, const fw_protect_cfg_t *cfg);
/* Forget the encoder history (on arm) and the watchdog count. */
void fw_protect_reset(fw_protect_t *p);

uint32_t fw_protect_current(const fw_protect_t *p, q24_t i_a, q24_t i_b);
uint32_t fw_protect_vdc(const fw_protect_t *p, q24_t vdc);
uint32_t fw_protect_encoder(fw_protect_t *p, uint32_t count);
uint32_t fw_protect_deadline(const fw_protect_t *p, uint32_t elapsed_cycles);
/* Called once per period; returns FW_FAULT_WATCHDOG when the kick is overdue. */
uint32_t fw_protect_watchdog_tick(fw_protect_t *p);
void fw_protect_watchdog_kick(fw_protect_t *p);

#endif /* FIRMWARE_PROTECT_H */
