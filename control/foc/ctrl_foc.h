/*
 * Rotor-field-oriented control of the book chapter (S1 §2, Algorithm 1),
 * "foc", and its hysteresis-current variant "foc_hyst".
 *
 * Current references: T_ref -> (i_d, i_q) on the MTPA locus (IPMSM: the
 * machine's MTPA table, ctrl_mtpa_current) or with i_d = 0 (SPMSM, or tunable
 * mtpa = 0: the chapter's Algorithm 1, alpha_sref = pi/2). |T_ref| is limited
 * to the torque at current_max on that locus (current limit).
 *
 * foc: d and q current PI regulators with decoupling feed-forward
 *   v_d = -omega psi_q + Kp_d e_d + I_d,  v_q = omega psi_d + Kp_q e_q + I_q,
 * where psi_d = Ld i_d + psi_pm, psi_q = Lq i_q (= omega L i and omega psi_pm
 * terms of S1(1)). Gains by pole-zero cancellation for a first-order current
 * loop of bandwidth wc: Kp = L wc, Ki = R wc (default wc = 2 pi fs / 20 rad/s,
 * i.e. fs/20 Hz: 500 Hz at 10 kHz, rise time 2.2/wc = 0.70 ms).
 * Anti-windup: conditional integration - an axis integrates only if the
 * voltage is not limited by the hexagon or its error drives its output away
 * from the limit; integrators clamped to +-1 pu.
 * Delay compensation (REFERENCE §1): the voltage computed at k acts during
 * [k+1, k+2). The feedback currents and fluxes are the prediction for k+1
 * (est->next), and the inverse Park uses the mean rotor angle of the
 * application interval, theta(k+1) + omega Ts / 2 (= theta(k) + 1.5 omega Ts).
 * Output: leg duties by space-vector PWM (svpwm.h; V_k1, V_k2 and the zero
 * time split between V0 and V7), over-modulation limited onto the hexagon
 * keeping the angle.
 *
 * foc_hyst (S1 §2: current-controlled inverter with hysteresis controllers):
 * per phase x, e_x = i_x,ref - i_x at k+1 (predicted); leg x high if
 * e_x >= h_i, low if e_x <= -h_i, else unchanged. One vector per period
 * (state changes only at sampling instants).
 */
#ifndef CONTROL_CTRL_FOC_H
#define CONTROL_CTRL_FOC_H

#include <stdint.h>

#include "controller.h"
#include "fx.h"

/* One current PI (Q formats at the fields). */
typedef struct {
    q24_t kp;      /* V pu per A pu, Q24 */
    int32_t ki_ts; /* Ki Ts, V pu per (A pu * period), Q30 */
    int64_t integ; /* integrator, V pu, Q40 */
} ctrl_foc_pi_t;

/* Torque -> current references (both controllers). */
typedef struct {
    uint8_t mtpa; /* 1: ctrl_mtpa_current (salient machine); 0: i_d = 0 */
    q24_t t_max;  /* i_d = 0: |T| limit psi_pm i_max, Q24 pu */
} ctrl_foc_iref_t;

typedef struct {
    uint8_t hyst;    /* 0: foc (PI + SVPWM), 1: foc_hyst */
    uint8_t legs;    /* foc_hyst: leg states, bit 0 = a */
    uint8_t limited; /* foc: the last voltage was limited by the hexagon */
    q24_t h_i;       /* foc_hyst band, Q24 pu */
    ctrl_foc_iref_t iref;
    ctrl_foc_pi_t pi_d, pi_q;
    q24_t v_d, v_q; /* last commanded voltage before the limit (telemetry/tests), Q24 pu */
} ctrl_foc_state_t;

/* Current references for torque t (Q24 pu): i_d <= 0, i_q with the sign of t. */
void ctrl_foc_iref(const ctrl_params_t *p, const ctrl_foc_iref_t *r, q24_t t, q24_t *i_d,
                   q24_t *i_q);

/* PI output before limiting: Kp e + I (Q24 pu, saturated). */
q24_t ctrl_foc_pi_out(const ctrl_foc_pi_t *pi, q24_t err);

/* Integrator update after the limiter: integrates Ki Ts err unless limited and
 * err has the sign of the axis output v (it would drive further into the limit).
 * The integrator is kept within +-1 pu. */
void ctrl_foc_pi_update(ctrl_foc_pi_t *pi, q24_t err, q24_t v, uint8_t limited);

extern const ctrl_desc_t ctrl_desc_foc;
extern const ctrl_desc_t ctrl_desc_foc_hyst;

/* ---- Internal: shared by ctrl_foc.c and ctrl_foc_config.c. ---- */
void ctrl_foc_reset(void *state);
void ctrl_foc_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out);

#endif /* CONTROL_CTRL_FOC_H */
