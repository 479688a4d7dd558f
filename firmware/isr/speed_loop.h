/*
 * Sizing of the outer speed PI from the machine (configuration time only;
 * speed_loop_config.c, floating point).
 *
 * Loop: the PI acts on the mechanical speed error and gives the torque
 * reference; the inner torque control is fast, so the plant is the inertia,
 * J s w = T, and everything else is lumped into a dead time Td:
 *   - speed-loop sampling and hold: 1 / f_loop (half a period for the hold,
 *     half for the sample's age),
 *   - the encoder speed filter (first order at f_lpf): 1 / (2 pi f_lpf),
 *   - the torque response of the inner loop: FW_SPEED_TORQUE_DELAY_S
 *     (0.5 ms: the DTC/MPC controllers rise in 0.2-0.4 ms, FOC in 0.7 ms).
 * Open loop L(s) = Kp (1 + wz/s) e^{-s Td} / (J s). At the crossover wc
 * (|L| = 1) the phase margin is PM = 90 deg - atan(wz/wc) - wc Td, so
 *   wz = wc tan(90 deg - PM - wc Td),  Kp = J wc / sqrt(1 + (wz/wc)^2),  Ki = Kp wz
 * (N*m per mechanical rad/s and N*m per rad).
 * Choices: phase margin 60 deg (default); bandwidth = the crossover, by
 * default the highest that keeps the margin with the PI zero three octaves
 * below the crossover (wz = wc/8, atan(1/8) = 7.1 deg of the phase budget):
 *   wc = (90 deg - 7.13 deg - PM) / Td
 * (35 Hz at f_loop = 1 kHz, f_lpf = 500 Hz, Td = 1.82 ms). The zero that far
 * down keeps the overshoot of a step that stays linear (no torque limit) near
 * 6 % (a zero at wc/4 gave 16 % in simulation); a large step runs on the
 * torque limit and overshoots less (80 kW IPMSM, 0 -> 1000 r/min: 1 %,
 * tests/loop/test_loop_speed.c). The gains scale with J; the bandwidth does
 * not depend on the machine, only on the loop's dead time. The electrical
 * speed of the estimator is divided by the pole pairs for this mechanical
 * design (speed_pi_config.c). Output limit: fw_torque_limit_nm below.
 */
#ifndef FIRMWARE_SPEED_LOOP_H
#define FIRMWARE_SPEED_LOOP_H

#include <stddef.h>
#include <stdint.h>

#include "controller.h"
#include "ctrl_params.h"

#define FW_SPEED_PM_DEFAULT_DEG 60.0
#define FW_SPEED_TORQUE_DELAY_S 0.5e-3
#define FW_SPEED_ZERO_RATIO 0.125 /* wz / wc of the default bandwidth */

/* The design's inputs and result (SI). */
typedef struct {
    double bandwidth_hz;     /* crossover; 0 = the default above */
    double phase_margin_deg; /* 0 = FW_SPEED_PM_DEFAULT_DEG */
    /* results */
    double kp_nm_s_rad; /* N*m per mechanical rad/s */
    double ki_nm_rad;   /* N*m per mechanical rad */
    double zero_hz;     /* PI zero wz / 2 pi */
    double dead_time_s; /* Td */
} fw_speed_design_t;

/*
 * The drive's torque limit (outer-loop output and torque-reference clamp):
 * the rated torque, and with a fixed stator-flux reference (psi_ref_wb > 0)
 * held by controller ctrl (not flux_free; NULL counts as holding it)
 * at most FW_TORQUE_FLUX_MARGIN of the largest torque the linear model gives
 * at that flux, T_max(psi_ref) = max over i_d of 1.5 p i_q (psi_pm + (Ld - Lq) i_d)
 * on |psi| = psi_ref ((3.9), (3.10)): a DTC asked for more loses the load
 * angle and the torque collapses (the thesis 80 kW IPMSM at psi_ref =
 * 0.1837 Wb: T_max = 384 N*m < 400 N*m rated). *t_flux_max: T_max(psi_ref),
 * or 0 without a flux reference (may be NULL). Returns the limit in N*m.
 */
#define FW_TORQUE_FLUX_MARGIN 0.95
double fw_torque_limit_nm(const ctrl_machine_t *m, const ctrl_desc_t *ctrl, double *t_flux_max);

/*
 * The same limit in regenerative braking (w T < 0), with the braking margin
 * CTRL_FIELDWEAK_TORQUE_MARGIN_BRAKE_DEFAULT (field_weak_config.h) in place of
 * FW_TORQUE_FLUX_MARGIN; the field weakening's period limit applies it
 * (field_weak.h). 80 kW IPMSM at 0.1837 Wb: 0.88 x 383.7 = 337.7 N*m.
 */
double fw_torque_limit_brake_nm(const ctrl_machine_t *m, const ctrl_desc_t *ctrl,
                                double *t_flux_max);

/*
 * Gains for machine m (inertia), a speed loop at loop_hz and an encoder
 * speed filter at lpf_hz. Fills d's results (and the defaults it used).
 * Returns CTRL_OK, or CTRL_EINVAL with a message naming the quantity, its
 * value and the allowed range in why (may be NULL).
 */
int fw_speed_loop_design(fw_speed_design_t *d, const ctrl_machine_t *m, double loop_hz,
                         double lpf_hz, char *why, size_t why_len);

#endif /* FIRMWARE_SPEED_LOOP_H */
