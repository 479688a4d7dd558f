/*
 * Rotor-field-oriented control of the book chapter (S1 §2, Algorithm 1),
 * "foc", and its hysteresis-current variant "foc_hyst".
 *
 * Current references: T_ref -> (i_d, i_q) on the MTPA locus (IPMSM: the
 * machine's MTPA table, ctrl_mtpa_current) or with i_d = 0 (SPMSM, or tunable
 * mtpa = 0: Algorithm 1), |T_ref| limited to the torque at current_max; in
 * field weakening (a flux reference ref->psi > 0 from the pipeline's limits,
 * field_weak.h) the point of T_ref on the flux circle |psi_s| = ref->psi
 * (negative i_d from the voltage limit, MTPV at most), where that circle lies
 * inside the MTPA flux.
 * foc: d and q current PI with decoupling feed-forward (S1(1)),
 *   v_d = -omega psi_q + Kp_d e_d + I_d,  v_q = omega psi_d + Kp_q e_q + I_q,
 * gains Kp = L wc, Ki = R wc (default wc = 2 pi fs / 20), conditional
 * integration, integrators within +-Vdc (nominal); feedback on the k+1 prediction,
 * inverse Park at theta(k+1) + omega Ts / 2; output: leg duties by SVPWM
 * (svpwm.h), over-modulation limited onto the hexagon.
 * foc_hyst: per phase, e_x = i_x,ref - i_x at k+1; leg high if e_x >= h_i, low
 * if e_x <= -h_i, else unchanged; one vector per period.
 * Notes: docs/algorithms.md, "FOC".
 */
#ifndef CONTROL_CTRL_FOC_H
#define CONTROL_CTRL_FOC_H

#include <stdint.h>

#include "controller.h"
#include "field_weak.h"
#include "fx.h"

#define FOC_KP_QBITS 20u /* fractional bits of ctrl_foc_pi_t.kp */

/* One current PI (Q formats at the fields). */
typedef struct {
    int32_t kp;    /* V pu per A pu, Q20 (up to 2047: Kp ~ L wc / w_base grows with fs) */
    int32_t ki_ts; /* Ki Ts, V pu per (A pu * period), Q(ki_shift) */
    int64_t integ; /* integrator, V pu, Q(24 + ki_shift): the sum of err ki_ts, within +-lim */
    int64_t lim;   /* the integrator's limit, the nominal DC link, Q(24 + ki_shift), <= 2^59 */
    /* Fractional bits of ki_ts, 17..30: 30 while Ki Ts < 2 pu; fewer for a
     * machine whose Rs is many r_base (a gimbal motor: Rs ~ 16 pu, Ki Ts ~ 5). */
    uint8_t ki_shift;
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
    /* Field weakening (ref->psi > 0 below the MTPA flux): the currents of the
     * torque on that flux circle (ctrl_fieldweak_currents, MTPV at most). */
    ctrl_fieldweak_t fieldweak;
    ctrl_foc_pi_t pi_d, pi_q;
    q24_t v_d, v_q; /* last commanded voltage before the limit (telemetry/tests), Q24 pu */
#if PMSM_LIVE_PARAMS
    q24_t e_d, e_q; /* last current errors, Q24 pu (a gain changed while running) */
#endif
} ctrl_foc_state_t;

/* Current references for torque t (Q24 pu): i_d <= 0, i_q with the sign of t. */
void ctrl_foc_iref(const ctrl_params_t *p, const ctrl_foc_iref_t *r, q24_t t, q24_t *i_d,
                   q24_t *i_q);

/* PI output before limiting: Kp e + I (Q24 pu, saturated). */
q24_t ctrl_foc_pi_out(const ctrl_foc_pi_t *pi, q24_t err);

/* Integrator update after the limiter: integrates Ki Ts err unless limited and
 * err has the sign of the axis output v (it would drive further into the limit).
 * The integrator is kept within +-pi->lim. */
void ctrl_foc_pi_update(ctrl_foc_pi_t *pi, q24_t err, q24_t v, uint8_t limited);

extern const ctrl_desc_t ctrl_desc_foc;
extern const ctrl_desc_t ctrl_desc_foc_hyst;

/* ---- Internal: shared by ctrl_foc.c and ctrl_foc_config.c. ---- */
void ctrl_foc_reset(void *state);
void ctrl_foc_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out);

#endif /* CONTROL_CTRL_FOC_H */
