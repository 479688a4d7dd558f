/*
 * High-frequency injection: the rotor angle of a salient machine at and near
 * standstill, where a back-EMF observer sees nothing (docs/algorithms.md,
 * "High-frequency injection").
 *
 * Injection: a square wave on the estimated d axis at half the control rate,
 * +u_h, -u_h, +u_h, ... one period each (the first a half pulse, so that the
 * ripple's samples alternate about the fundamental: +h/2, -h/2, ...). Held
 * for one period at sample k-2, the voltage changes the current by
 *   h = Ts L^-1 v,  in the injection frame at an angle error e (estimated
 *   d axis minus the rotor's):  h_d = Ts V (S + D cos 2e),
 *                               h_q = -Ts V D sin 2e,
 *   S = (1/Ld + 1/Lq)/2,  D = (1/Ld - 1/Lq)/2
 * (resistance and back-EMF change little over one period; they are part of
 * the fundamental). Demodulation, per period, no filter in the signal path:
 *   dq(k) = R(-theta_inj(k-2)) (i(k) - i(k-1))   the last change in its own
 *                                                  injection's frame
 *   y(k)  = sgn(k-2) (dq(k) - dq(k-1)) / 2       = h: the fundamental's change
 *                                                  (almost the same in two
 *                                                  consecutive periods) cancels
 * so y_q = -Ts V D sin 2e carries the angle error. The change the
 * controller's own voltage v of the period makes, Ts L^-1 v at the tracked
 * angle, is taken from dq first (a modulated controller's voltage jumps from
 * one period to the next; at the right angle the model removes it whole, off
 * by e it leaves -2 Ts D e v_d: a gain, not a noise), and the error is
 * weighted by the d voltage's actual change w (the injection's, what a clamp
 * left of it, and the controller's, in units of 2 V) over the mean of w^2
 * (at least 1): a controller alternating with the injection adds to the
 * information instead of cancelling it. The tracking observer drives the
 * error to zero: the rotor's mechanics with the torque estimate as its input
 * (Lorenz's tracking observer),
 *   theta' = omega + l1 e,  omega' = p (T^ - T_L^) / J + l2 e,
 *   (p T_L^ / J)' = -l3 e,
 * a triple pole at -w_o (l1 = 3 w_o, l2 = 3 w_o^2, l3 = w_o^3): the speed
 * follows the torque without lag and the loop only corrects for the load and
 * the model's errors, so its bandwidth (and its noise) can be low. The
 * ripple model hm = y through an EMA (time constant h_tau) gives the
 * injection's share of the sampled current, pos(k-2) hm / 2 in the injection
 * frame (pos = +-1: the ripple's side), which the current handed to the
 * controllers has removed: no filter, hence no delay, in the controllers'
 * current path; the EMA only sets how fast the removal follows a change of
 * the saliency.
 *
 * Polarity (the d axis modulo pi of the saliency): d-axis pulses, +v_pol for
 * n_pol periods and -v_pol back, then the same in the other direction
 * (pol_rounds times). The magnet's flux saturates the iron along +d: the
 * same volt-seconds drive a larger current towards north. The asymmetry
 * a = (I+ - I-) / (I+ + I-) of the peaks tells north (a > 0: the axis is
 * north) when |a| >= pol_min; below it the machine gives no saturation to
 * read and the polarity is left unknown (ctrl_hfi_pol_result).
 *
 * Integer-only per period; the configuration in hfi_config.h.
 */
#ifndef CONTROL_HFI_H
#define CONTROL_HFI_H

#include <stdint.h>

#include "ctrl_params.h"
#include "fx.h"

/* 0: the injection left out (a flash-tight image, CMake option PMSM_SL_HFI). */
#ifndef CTRL_SL_HFI
#define CTRL_SL_HFI 1
#endif

/* Polarity results (ctrl_hfi_pol_result). */
#define CTRL_HFI_POL_RUNNING 0u /* pulses under way */
#define CTRL_HFI_POL_NORTH 1u   /* the tracked axis is north */
#define CTRL_HFI_POL_SOUTH 2u   /* the tracked axis is south: turn it by pi */
#define CTRL_HFI_POL_NONE 3u    /* |a| < pol_min: no saturation to read */

typedef struct {
    /* ---- configuration (ctrl_hfi_init, hfi_config.c) ---- */
    q24_t u_h;     /* injection amplitude per unit of the DC link (duty), Q24 */
    int32_t k_err; /* angle error (fx_angle_t units) per Q24 pu of y_q: 1 / (2 Ts V D),
                    * signed with D, Q(k_err_shift) */
    uint8_t k_err_shift;
    q24_t h0;        /* the ripple step along d at zero error, Ts V / Ld, Q24 pu (the
                      * model's start) */
    q24_t ts_inv_ld; /* Ts / Ld, Ts / Lq: the current change per unit of voltage held for */
    q24_t ts_inv_lq; /* one period, Q24 pu */
    q24_t inv_2vh;   /* 1 / (2 V), V the amplitude at the nominal DC link, Q24 per pu */
    q24_t v_nom;     /* the nominal DC link, Q24 pu */
    q24_t h_k;       /* ripple model's EMA coefficient per period, Q24 */
    q24_t l1;        /* 3 w_o Ts, Q24: share of the angle error added to the angle */
    int32_t l2;      /* omega (Q48 pu) += l2 e per period, e in fx_angle_t units */
    int32_t l3;      /* load (Q48 pu speed per period) -= l3 e / 2^16 per period */
    q24_t k_acc;     /* speed change per period per pu of torque, Ts p T_base / (J w_base),
                      * Q24 (0: no torque feed-forward) */
    int32_t err_max; /* the angle error the observer takes, within +-err_max (45 deg) */
    q24_t v_pol;     /* polarity pulse voltage, Q24 pu */
    uint16_t n_pol;  /* periods of each pulse */
    uint8_t pol_rounds;
    q24_t pol_min; /* smallest |asymmetry| that tells the polarity, Q24 */
    /* ---- state ---- */
    uint8_t on;       /* 1: the square wave runs (0: stopped, or the stop's half pulse) */
    uint8_t stopping; /* 1: the next decision is the half pulse back to the centre */
    int8_t pos[2];    /* ripple's side after the decisions of k-1 [0] and k-2 [1]: -1, 0, +1 */
    int8_t amp[2];    /* their amplitude in half steps: -2..2 (+-1: a half pulse) */
    uint8_t clip[2];  /* 1: applied clamped (ctrl_hfi_add_to_legs): not demodulated */
    q24_t cs[2][2];   /* cos, sin of their injection angles, Q24 */
    uint8_t dq_ok;    /* dq_prev answers a full pulse */
    q24_t i_prev_a, i_prev_b;   /* current at k-1, Q24 pu */
    q24_t dq_prev_d, dq_prev_q; /* the last change in its injection's frame, Q24 pu */
    q24_t vt_prev;     /* the d voltage of the period before (controller's and injection's, in
                        * its injection's frame), Q24 pu */
    q24_t rq_prev;     /* its q change less the model's, Q24 pu */
    uint8_t r_ok;      /* those hold a period */
    q24_t w_sq;        /* mean square of the excitation w (hfi.c), Q24 */
    q24_t ua_act[2];   /* the injection the legs applied of the decisions of k-1 [0], k-2 [1], */
    q24_t ub_act[2];   /* alpha, beta, duty per unit of DC link (ctrl_hfi_add_to_legs) */
    q24_t hm_d, hm_q;  /* ripple model: the step of one full pulse, injection frame, Q24 pu */
    fx_angle_t theta;  /* tracked angle at k */
    int64_t omega_acc; /* speed, Q48 pu electrical */
    int64_t load_acc;  /* load's speed change per period, p T_L Ts / J, Q48 pu */
    q24_t omega;       /* speed, Q24 pu electrical */
    int32_t err;       /* the last angle error estimate (rotor minus tracked), fx_angle_t
                        * units, within +-err_max; 0 without a demodulated sample */
    q24_t u_alpha, u_beta; /* injection decided at k for [k+1, k+2), duty per unit of DC link */
    /* polarity */
    uint16_t pol_n;       /* periods into the pulse sequence */
    fx_angle_t pol_theta; /* the axis pulsed */
    int64_t pol_acc[2];   /* peak currents along +d, -d summed, Q24 pu */
    q24_t pol_i_last;     /* the current along the axis at the last quarter's end, Q24 pu */
    uint8_t pol_result;   /* CTRL_HFI_POL_* */
    q24_t pol_asym;       /* measured asymmetry, Q24 */
} ctrl_hfi_t;

/* Track from theta at speed omega (Q24 pu), the load taken as what the
 * torque estimate torque (Q24 pu) holds (no acceleration), the current at
 * the start i: the square wave starts with its half pulse at the next
 * decision, the ripple model at its nominal value. */
void ctrl_hfi_start(ctrl_hfi_t *h, fx_angle_t theta, q24_t omega, q24_t torque, q24_t i_alpha,
                    q24_t i_beta);

/* Stop: the next decision is the half pulse back to the centre, then none. */
void ctrl_hfi_stop(ctrl_hfi_t *h);

/* Stop at once (the caller applies something else from the next period on:
 * the pulses in flight are left to it): nothing injected, nothing removed. */
void ctrl_hfi_halt(ctrl_hfi_t *h);

/*
 * One period at sample k: v the mean voltage of [k-1, k) without the
 * injection (the controller's: the caller's reconstruction of what it
 * applied), i the measured current at k (alpha/beta, Q24 pu), p the
 * machine's parameters (Ts). Demodulates the response to the injection of
 * k-2, moves the tracked angle and speed (torque: the torque estimate of
 * the period before, Q24 pu, the observer's input), decides the injection for
 * [k+1, k+2) (h->u_alpha, u_beta) and writes the fundamental current (the
 * injection's ripple removed) to *if_alpha, *if_beta.
 */
void ctrl_hfi_update(ctrl_hfi_t *h, const ctrl_params_t *p, q24_t v_alpha, q24_t v_beta,
                     q24_t i_alpha, q24_t i_beta, q24_t torque, q24_t *if_alpha, q24_t *if_beta);

/* Polarity pulses on the axis theta (the tracked one): starts the sequence
 * (ctrl_hfi_pol_step per period until it returns 0). */
void ctrl_hfi_pol_start(ctrl_hfi_t *h, fx_angle_t theta);
/* Number of periods the sequence takes. */
uint32_t ctrl_hfi_pol_periods(const ctrl_hfi_t *h);
/*
 * One period of the polarity pulses: i the current at k (alpha/beta); the
 * voltage to apply in [k+1, k+2) (Q24 pu alpha/beta) into *v_alpha,
 * *v_beta. Returns 1 while running, 0 when the result is in
 * h->pol_result (and the asymmetry in h->pol_asym).
 */
uint8_t ctrl_hfi_pol_step(ctrl_hfi_t *h, q24_t i_alpha, q24_t i_beta, q24_t *v_alpha,
                          q24_t *v_beta);

/* The injection decided at the last update added to leg duties (each in
 * [0, dmax], dmax <= FX_ONE the largest the inverter applies): per leg (the
 * inverse of (4.4), no common mode), then the three moved together to stay
 * within [0, dmax] where the spread allows. Records what the legs apply of
 * it (the demodulation's excitation). Returns 1 if a leg had to be clamped
 * (the injection not applied in full: the ripple model leaves it out), else
 * 0. Nothing when the injection is off. */
uint8_t ctrl_hfi_add_to_legs(ctrl_hfi_t *h, q24_t duty[3], q24_t dmax);

#endif /* CONTROL_HFI_H */
