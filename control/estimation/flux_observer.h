/*
 * Stator-flux observer: the rotor angle and speed without a position sensor,
 * and a torque estimate that does not depend on psi_pm at speed.
 *
 * Voltage model S1(13)-(14), S1(31)-(38) in the stationary frame, with a
 * correction towards the current model (3.9) - the "adaptive flux observer"
 * family the thesis cites for drift handling (§2.2) - per period k:
 *
 *   psi(k)  = psi(k-1) + Ts (v(k-1) - Rs (i(k-1) + i(k)) / 2) + corr(k-1)
 *   eta(k)  = psi(k) - Lq i(k)                                  active flux
 *   theta^  = atan2(eta)                                        rotor angle
 *
 * The active flux eta = (psi_pm + (Ld - Lq) i_d) e^{j theta} lies on the d
 * axis for any saliency (Boldea's active-flux concept, thesis ref. [71]), so
 * its angle is the rotor angle with no lag and no PLL in the angle path.
 *
 * Correction, in the frame of the reference angle theta_r (sin/cos given):
 *   sensorless (theta_r = theta^): only the magnitude of eta is pulled
 *     towards psi_a = psi_pm + (Ld - Lq) i_d, along the auxiliary-flux
 *     direction (psi_a, -(Ld - Lq) i_q):
 *       corr_dq = k Ts (psi_a - eta_d) (psi_a, -(Ld - Lq) i_q) / psi_pm,
 *       k = k0 + kappa |omega|.
 *     Linearised in the rotor frame (a, b = radial and tangential error of
 *     eta), this direction gives  s^2 + k (1 + c^2) s + omega^2 = 0,
 *     c = (Ld - Lq) i_q / psi_a: stable at every speed and load, motoring
 *     and braking, for SPMSM and IPMSM alike (a correction along d alone
 *     gives s^2 + k s + omega (omega + k c), unstable for an IPMSM motoring
 *     at |omega| < k |c|). It is the linear form of the nonlinear observer
 *     of Ortega et al. (gain gamma psi_pm^2 ~ k) and the direction of
 *     Hinkkanen et al.'s reduced-order observer gain (IEEE TIA 2018).
 *     A steady voltage error u_dq (rotor frame) leaves the angle error
 *     (kappa u_q - u_d) / (omega psi_a) and a psi_pm error Dpsi the angle
 *     error k Dpsi / (omega psi_pm); the magnitude of eta follows the
 *     voltage model above |omega| >> k (docs/algorithms.md, "Stator-flux observer").
 *   encoder (theta_r measured): the whole vector is pulled towards the
 *     current model at the measured angle with a fixed corner w_c, a
 *     complementary filter: current model below w_c, voltage model above,
 *     so the torque estimate psi x i carries a psi_pm error only as
 *     (w_c / omega)^2 at speed.
 *
 * Speed: a type-2 PLL on theta_r (critically damped, natural frequency
 * w_n): omega_i += w_n^2 Ts e, theta_pll += omega_i Ts + 2 w_n Ts e, e the
 * wrapped angle difference; the speed is the PLL's frequency
 * omega_i + 2 w_n e, which follows a constant acceleration without lag. The PM flux psi_d - Ld i_d
 * is tracked by a slow filter above a speed threshold (a PM-flux estimate where the voltage model
 * is reliable).
 *
 * The applied voltage is reconstructed from the leg duties and the measured
 * DC link (ctrl_fobs_voltage), corrected for the dead time and the device
 * forward drop by the sign of each phase current (a soft sign, linear in a
 * band around zero where the sign is unknown).
 *
 * Per period, with the rotor-frame path's one sin/cos:
 *   v = ctrl_fobs_voltage(legs of [k, k+1), vdc(k), i(k))    (also the k+1 prediction's)
 *   theta^ = ctrl_fobs_integrate(v of [k-1, k), i(k))
 *   sin/cos of theta_r (theta^ or the encoder), i_dq in that frame
 *   ctrl_fobs_correct(theta_r, sin, cos, i_d, i_q)
 * or ctrl_fobs_update (the three steps with its own fx_sincos).
 * Integer-only; Q formats at the fields; error budget in docs/error-budget.md.
 */
#ifndef CONTROL_FLUX_OBSERVER_H
#define CONTROL_FLUX_OBSERVER_H

#include <stdint.h>

#include "angle_source.h"
#include "ctrl_params.h"
#include "ctrl_types.h"
#include "fx.h"

#define CTRL_FOBS_SENSORLESS 0u /* reference angle = the flux angle */
#define CTRL_FOBS_ENCODER 1u    /* reference angle = the measured angle */

/* Shift of inv_band (Q16): 1 / band up to 2^15 per pu. */
#define CTRL_FOBS_BAND_SHIFT 16u

typedef struct {
    /* ---- configuration (ctrl_fobs_init, flux_observer_config.c) ---- */
    q24_t k0_ts;         /* sensorless gain at standstill x Ts, Q24 (k0 Ts per period) */
    q24_t kappa_ts;      /* sensorless speed-proportional gain: k Ts = k0_ts + kappa_ts |omega|,
                          * Q24 (kappa Ts_pu); k Ts capped at CTRL_FOBS_KTS_MAX */
    q24_t kenc_ts;       /* encoder-mode corner x Ts, Q24 (w_c Ts per period) */
    q24_t dl;            /* Ld - Lq, Q24 pu */
    int32_t pll_kp;      /* 2 zeta w_n Ts, Q24: share of the angle error added per period */
    int32_t pll_ki;      /* omega_acc (Q48 pu) += pll_ki e per period, e the angle error in
                          * fx_angle_t units: round(w_n^2 Ts 2 pi 2^16 / w_base) */
    q24_t dt_frac;       /* dead time x fs, Q24 fraction of the period */
    q24_t v_fwd;         /* device forward drop, Q24 pu */
    int32_t inv_band;    /* 1 / current band of the soft sign, Q16 per pu */
    q24_t psi_k;         /* PM-flux estimate: EMA coefficient per period, Q24 (0 = off) */
    q24_t psi_speed_min; /* PM-flux estimate runs where |omega| >= this, Q24 pu */
    uint8_t mode;        /* CTRL_FOBS_* */
    /* ---- state ---- */
    int64_t psi_alpha_acc, psi_beta_acc; /* stator flux, Q48 pu (24 guard bits) */
    q24_t i_alpha_prev, i_beta_prev;     /* i(k-1), Q24 pu */
    q24_t psi_alpha, psi_beta;           /* stator flux at k (before the correction), Q24 pu */
    q24_t eta_alpha, eta_beta;           /* active flux at k, Q24 pu */
    fx_angle_t theta;                    /* flux (rotor) angle at k */
    fx_angle_t pll_theta;                /* PLL angle (predicted for k) */
    int64_t pll_omega_acc;               /* PLL integrator (speed), Q48 pu electrical */
    q24_t omega;                         /* speed: the PLL's frequency, Q24 pu electrical */
    int64_t psi_pm_acc;                  /* PM-flux estimate, Q48 pu */
    ctrl_legs_t legs_prev;               /* duties of the period before (edges at its end) */
    ctrl_angle_frame_t frame;            /* ctrl_fobs_update's sin, cos of the reference angle */
    uint8_t primed;                      /* 0 until ctrl_fobs_reset */
} ctrl_fobs_t;

/* Largest correction per period (k Ts): a discrete first-order step stays
 * monotonic below 1; 0.5 leaves margin. */
#define CTRL_FOBS_KTS_MAX (FX_ONE / 2)

/* Start from the current model at angle theta (the active flux on the d
 * axis), the PLL at theta with speed omega (Q24 pu), the PM-flux estimate at
 * psi_pm; i(k) as the previous current. */
void ctrl_fobs_reset(ctrl_fobs_t *o, const ctrl_params_t *p, fx_angle_t theta, q24_t omega,
                     q24_t i_alpha, q24_t i_beta);
/* The same at the frame n of an estimate (its theta_e, sin_theta, cos_theta,
 * i_d, i_alpha, i_beta): no sine and cosine of its own; the same values where
 * n's are fx_sincos's and fx_dot's (the estimator's). */
void ctrl_fobs_reset_frame(ctrl_fobs_t *o, const ctrl_params_t *p, const ctrl_mstate_t *n,
                           q24_t omega);

/* Period-average alpha/beta voltage of the leg duties at the measured DC
 * link, Q24 pu, with the inverter's voltage error removed: per leg, dead
 * time (each low-to-high edge is t_d late when i > 0, each high-to-low edge
 * when i < 0; the edges from the duties of this period and of the one before,
 * kept in o->legs_prev) and forward drop (- v_fwd sign(i)); the sign is soft,
 * i / band clamped to [-1, 1]. Call once per period with the duties acting in
 * it; i_a, i_b: phase currents (i_c = -i_a - i_b), Q24 pu. */
void ctrl_fobs_voltage(ctrl_fobs_t *o, const ctrl_legs_t *legs, q24_t vdc, q24_t i_a, q24_t i_b,
                       q24_t *v_alpha, q24_t *v_beta);

/* Voltage model over [k-1, k) with the average voltage v of that period and
 * the current i(k) (alpha/beta, Q24 pu): the flux at k, its active flux and
 * angle (returned). Before ctrl_fobs_reset: only stores i(k) and returns the
 * last angle. */
fx_angle_t ctrl_fobs_integrate(ctrl_fobs_t *o, const ctrl_params_t *p, q24_t v_alpha, q24_t v_beta,
                               q24_t i_alpha, q24_t i_beta);

/* Correction and PLL at k. theta_r: the reference angle (the value
 * ctrl_fobs_integrate returned, or the encoder's in CTRL_FOBS_ENCODER), s, c
 * its sine and cosine (Q24), i_d, i_q the current at k in that frame. */
void ctrl_fobs_correct(ctrl_fobs_t *o, const ctrl_params_t *p, fx_angle_t theta_r, q24_t s, q24_t c,
                       q24_t i_d, q24_t i_q);

/* The encoder-mode correction of ctrl_fobs_correct alone (no PLL, no
 * PM-flux EMA), without the move: the flux at k, acc (Q48, alpha and beta; its
 * Q24 view in o->psi_alpha/beta), pulled towards the current model at the
 * measured angle (s, c its sine and cosine, i_d, i_q the current in that
 * frame); *delta (Q48) is what the pull adds (the clamped sum less acc, so that
 * acc + delta is the pulled flux). Reads o, writes nothing of it. Returns the
 * PM flux psi_d - Ld i_d of the flux at k, the EMA's input. */
q24_t ctrl_fobs_pull_delta(const ctrl_fobs_t *o, const ctrl_params_t *p, const int64_t acc[2],
                           q24_t s, q24_t c, q24_t i_d, q24_t i_q, int64_t delta[2]);

/* One step of the PM-flux EMA towards pm (Q24 pu) with coefficient k (Q24). */
void ctrl_fobs_psi_pm_step(ctrl_fobs_t *o, q24_t pm, q24_t k);

/* ctrl_fobs_integrate, fx_sincos of the reference angle (the flux angle, or
 * theta_enc in CTRL_FOBS_ENCODER), Park of i, ctrl_fobs_correct. Returns the
 * flux angle; the frame at the reference angle stays in frame (the
 * estimator's too, ctrl_angle_out_t). */
fx_angle_t ctrl_fobs_update(ctrl_fobs_t *o, const ctrl_params_t *p, q24_t v_alpha, q24_t v_beta,
                            q24_t i_alpha, q24_t i_beta, fx_angle_t theta_enc);

/* Speed (the PLL's frequency, Q24 pu electrical) and the PLL's angle. */
q24_t ctrl_fobs_omega(const ctrl_fobs_t *o);
fx_angle_t ctrl_fobs_pll_angle(const ctrl_fobs_t *o);
/* PM-flux estimate, Q24 pu. */
q24_t ctrl_fobs_psi_pm(const ctrl_fobs_t *o);

#endif /* CONTROL_FLUX_OBSERVER_H */
