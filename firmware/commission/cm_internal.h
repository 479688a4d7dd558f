/*
 * Commissioning internals shared by the step modules (not for the pipeline).
 *
 * Timing of one period k (the pipeline's contract, hal.h): the samples are
 * taken at the start of k; the duties written at k act in [k+1, k+2). The
 * current change from k-1 to k therefore reflects the voltage commanded at
 * k-2 (cm_io_t.va_*[1]). Voltages are the ones the inverter was told to make
 * (compare values x measured DC link), not the reference: the duty grid is
 * part of the record, so averages over many periods are exact up to the
 * inverter's own error (dead time, device drops), which every step is built
 * to cancel.
 */
#ifndef FIRMWARE_COMMISSION_CM_INTERNAL_H
#define FIRMWARE_COMMISSION_CM_INTERNAL_H

#include "cm.h"

/* Step period results. */
enum { CM_RUN = 0, CM_DONE = 1, CM_FAIL = 2 };

typedef struct {
    const char *name;
    uint32_t gives, needs; /* CM_HAVE_* */
    void (*begin)(cm_t *cm);
    int (*period)(cm_t *cm, const cm_in_t *in, cm_out_t *out);
} cm_step_desc_t;

const cm_step_desc_t *cm_step_desc(uint8_t step);

/* Step entry points (one module each). */
void cm_vbus_begin(cm_t *cm);
int cm_vbus_period(cm_t *cm, const cm_in_t *in, cm_out_t *out);
void cm_probe_begin(cm_t *cm);
int cm_probe_period(cm_t *cm, const cm_in_t *in, cm_out_t *out);
void cm_encoder_begin(cm_t *cm);
int cm_encoder_period(cm_t *cm, const cm_in_t *in, cm_out_t *out);
void cm_rs_begin(cm_t *cm);
int cm_rs_period(cm_t *cm, const cm_in_t *in, cm_out_t *out);
void cm_ldq_begin(cm_t *cm);
int cm_ldq_period(cm_t *cm, const cm_in_t *in, cm_out_t *out);
void cm_flux_begin(cm_t *cm);
int cm_flux_period(cm_t *cm, const cm_in_t *in, cm_out_t *out);
void cm_gates_begin(cm_t *cm);
int cm_gates_period(cm_t *cm, const cm_in_t *in, cm_out_t *out);
void cm_sense_begin(cm_t *cm);
int cm_sense_period(cm_t *cm, const cm_in_t *in, cm_out_t *out);
void cm_run_begin(cm_t *cm);
int cm_run_period(cm_t *cm, const cm_in_t *in, cm_out_t *out);
#if CTRL_COGGING
void cm_cogging_begin(cm_t *cm);
int cm_cogging_period(cm_t *cm, const cm_in_t *in, cm_out_t *out);
#endif

/* ---- helpers (cm_core.c) ---- */

/* Ends the step with an error and up to three detail numbers; returns CM_FAIL. */
int cm_fail(cm_t *cm, uint8_t err, int32_t d0, int32_t d1, int32_t d2);
/* Next phase of the step (t restarts at 0). */
void cm_next(cm_t *cm);
void cm_out_off(cm_t *cm, cm_out_t *out);

/* Clear the scratch state and the unwrapped position (each step's begin). */
void cm_scratch_clear(cm_t *cm);

/* Current regulator: kp = L g / Ts, ki = kp g / 4 (crossover g / Ts, PI zero
 * a quarter of it: the loop does not depend on R); output and integrator
 * clamped to +-lim. */
void cm_pi_tune(cm_pi_t *c, q24_t l_pu, q24_t ts, q24_t g, q24_t lim);
void cm_pi_reset(cm_pi_t *c, q24_t integ);
q24_t cm_pi_step(cm_pi_t *c, q24_t err);
/* Tune both axes from one inductance (standstill) or from Ld and Lq. */
void cm_pi_tune_dq(cm_t *cm, q24_t ld, q24_t lq, q24_t lim);
/* The best inductance known: Ld/Lq mean, else the probe's, else configured. */
q24_t cm_l_best(const cm_t *cm);

/* Test currents within the voltage (cm_config.c, "rs"): i_hold at most
 * cap_st (standstill), the encoder scan's rising current and the flux
 * step's speed-loop limit i_spin at most cap_scan (what the spinning limit
 * drives through Rs: the scan turns slowly, the break-away is at rest; at
 * speed the flux step's voltage check holds), i_acc and i_fd at most cap_run
 * (at the speed the flux step's currents are sized for), each from its
 * configured level. */
void cm_fit_currents(cm_par_t *q, q24_t cap_st, q24_t cap_scan, q24_t cap_run);
/* The same with the measured Rs and inverter error (after "rs"). */
void cm_refit_currents(cm_t *cm);
/* Largest current (pu) a share CM_V_USE of v drives through r after the
 * inverter's error |v_inv| (measured, else 0) and e (a back-EMF); 0 if none. */
q24_t cm_i_within(const cm_t *cm, q24_t v, q24_t e, q24_t r);
/* End the step with CM_E_SUPPLY: i_min needs more than v_lim through r. */
int cm_fail_supply(cm_t *cm, q24_t r, q24_t v_lim);
/* The resistance known best: measured, else configured. */
q24_t cm_rs_best(const cm_t *cm);

/* f_dq = f_ab e^{-j ang} and back. */
void cm_to_frame(q24_t al, q24_t be, fx_angle_t ang, q24_t *d, q24_t *q);
void cm_from_frame(q24_t d, q24_t q, fx_angle_t ang, q24_t *al, q24_t *be);

/* alpha-beta voltage -> leg duties on the compare grid (min-max zero
 * sequence), recorded as applied (va_*[0]). */
void cm_modulate(cm_t *cm, q24_t v_al, q24_t v_be, cm_out_t *out);
/* Three leg duties (Q24) onto the compare grid; the applied voltage is not
 * recorded (these are not regulator outputs). */
void cm_legs(cm_t *cm, q24_t d0, q24_t d1, q24_t d2, cm_out_t *out);
/* Regulate the current to (d_ref, q_ref) in the frame at ang (measurement
 * angle of this period), with the command rotated by ang_cmd (the frame's
 * angle in the middle of [k+1, k+2)); extra_* is added to the command in the
 * frame (injection). Measured frame currents in *d, *q (may be NULL). */
void cm_regulate(cm_t *cm, fx_angle_t ang, fx_angle_t ang_cmd, q24_t d_ref, q24_t q_ref,
                 q24_t extra_d, q24_t extra_q, cm_out_t *out);

/* The voltage that acted in [k-1, k), in the frame at ang (its middle).
 * Returns false when it is not known (gates were off). */
bool cm_acted(const cm_t *cm, fx_angle_t ang, q24_t *vd, q24_t *vq);

/* Mean of a sum of Q24 values over n periods, rounded (n > 0). */
q24_t cm_mean(int64_t sum, uint32_t n);
/* num / den in Q24 when it fits and den != 0; else false. */
bool cm_ratio(int64_t num, int64_t den, q24_t *out);
/* num x mul / den for Q24 num, mul and den (num a sum of up to 2^14 Q24
 * values): round(num mul / den) as Q24 when it fits; else false. No
 * intermediate ratio, so num / den may exceed the Q24 range. */
bool cm_muldiv(int64_t num, q24_t mul, int64_t den, q24_t *out);
/* Linear ramp from 0 to x over n periods (t = 0 .. n). */
q24_t cm_ramp(q24_t x, uint32_t t, uint32_t n);

/* Encoder speed: moving average over CM_SPEED_AVG periods of the angle
 * increment (configured direction), as pu electrical speed. */
q24_t cm_speed(const cm_t *cm);
/* Rotor angle with the identified offset and direction (CM_HAVE_ENC). */
fx_angle_t cm_rotor_angle(const cm_t *cm);
/* Angle increments -> pu speed: sum over n periods. */
q24_t cm_speed_of(const cm_t *cm, int64_t dth_sum, uint32_t n);

/* Hold / scan frame with rotor damping: regulates |i| = i_mag along the
 * stationary or moving frame angle `ang` (ang = previous ang + inc: the
 * frame's motion over the same period as the encoder's) and a
 * q current opposing the rotor's slip speed against the frame, i_q = -i_mag
 * (slip / Omega) clamped to +-i_mag (Omega in cm_par_t.damp_k): it damps the
 * rotor's oscillation around the field, which nothing else damps when the
 * machine has no friction. Needs the encoder direction (CM_HAVE_ENC);
 * without it the damping is off. extra_* as in cm_regulate. */
void cm_hold(cm_t *cm, fx_angle_t ang, int32_t inc, q24_t i_mag, q24_t extra_d, q24_t extra_q,
             cm_out_t *out);
/* |slip speed| of the rotor against the frame of the last cm_hold calls, pu. */
q24_t cm_slip(const cm_t *cm);

#endif /* FIRMWARE_COMMISSION_CM_INTERNAL_H */
