/*
 * Torque supervision: does the machine give the torque the drive applies?
 *
 * Over windows of n = 2^shift PWM periods (the power of two nearest above
 * 50 ms, the window of speed following, protect.h) the mean estimated torque
 * against the mean applied reference (the reference of the previous period
 * after the static clamp and the field-weakening limit: the torque estimate
 * at k answers it). A window misses when
 *     |mean(T_est - T_ref)| > max(|mean T_ref| / 20, tol_rated)
 * (5 % of the reference, with a floor of 2 % of the rated torque for small
 * references whose mean the ripple resolves no better); compared on the sums
 * (|sum e| 20 > sum |T_ref| and |sum e| > n tol_rated): no division.
 * A missed window sets the warning (fw_telemetry_t.fieldweak_limit + 16) until a
 * window meets the reference; with fault_windows > 0, that many consecutive
 * misses are a fault (FW_FAULT_TORQUE_FOLLOW: gates off). Periods without a
 * trustworthy estimate (the sensorless start's forced angle) restart the
 * window. What it cannot see: an estimate that is wrong the same way as the
 * torque (a wrong psi_pm in the current model); the simulator, which knows
 * the true torque, checks that (sim_run.c).
 *
 * Integer-only; |T| < 2^31 Q24 and n <= 2^15: the sums stay below 2^47.
 * The check is one call per period with the period's two values, and keeps
 * its state here, so that it can run at a lower rate unchanged (a window is
 * a count of calls).
 */
#ifndef FIRMWARE_TORQUE_FOLLOW_H
#define FIRMWARE_TORQUE_FOLLOW_H

#include <stdbool.h>
#include <stdint.h>

#include "fx.h"
#include "protect.h"

typedef struct {
    uint8_t shift;          /* window = 2^shift calls, 1..15 */
    q24_t tol_rated;        /* 2 % of the rated torque, Q24 pu (> 0) */
    uint32_t fault_windows; /* consecutive missed windows that fault; 0: warning only */
} fw_torque_follow_cfg_t;

typedef struct {
    fw_torque_follow_cfg_t cfg;
    int64_t sum_err; /* sum of T_est - T_ref over the window, Q24 */
    int64_t sum_ref; /* sum of |T_ref| over the window, Q24 */
    uint32_t n;      /* calls in the window */
    uint32_t missed; /* consecutive missed windows */
    uint8_t warn;    /* 1 after a missed window, until a window meets */
} fw_torque_follow_t;

/* Window from the call rate (the power of two >= rate_hz / 20, at most 2^15)
 * and the tolerance floor from the rated torque (Q24 pu); fault_windows as
 * configured. CTRL_OK or CTRL_EINVAL (rate 0, rated torque <= 0). */
int fw_torque_follow_config(fw_torque_follow_cfg_t *cfg, uint32_t rate_hz, q24_t torque_rated,
                            uint32_t fault_windows);

/* Copies cfg, clears the state. */
void fw_torque_follow_init(fw_torque_follow_t *s, const fw_torque_follow_cfg_t *cfg);

/* A fresh window, the warning and the miss count cleared (on arm). */
void fw_torque_follow_reset(fw_torque_follow_t *s);

/* The window's end (fw_torque_follow_step, once in 2^shift calls): the
 * criterion on the sums, a fresh window. */
uint32_t fw_torque_follow_window(fw_torque_follow_t *s);

/* One call: the applied reference t_ref and the estimate t_est that answers
 * it; valid = false restarts the window. Returns FW_FAULT_TORQUE_FOLLOW or
 * FW_FAULT_NONE (protect.h). Inline: the sums, once per period; the
 * window's end out of line (inlined whole by the board image's link-time
 * optimisation it took 1 384 B, where the image with the settings store had
 * 1 104 B left). */
static inline uint32_t fw_torque_follow_step(fw_torque_follow_t *s, q24_t t_ref, q24_t t_est,
                                             bool valid)
{
    if (!valid) {
        s->sum_err = 0;
        s->sum_ref = 0;
        s->n = 0u;
        return FW_FAULT_NONE;
    }
    s->sum_err += (int64_t)t_est - t_ref;
    s->sum_ref += t_ref < 0 ? -(int64_t)t_ref : (int64_t)t_ref;
    if (++s->n < ((uint32_t)1 << s->cfg.shift)) {
        return FW_FAULT_NONE;
    }
    return fw_torque_follow_window(s);
}

#endif /* FIRMWARE_TORQUE_FOLLOW_H */
