/*
 * Sensorless angle: the stator-flux observer (flux_observer.h) and the
 * start-up that brings the rotor to a speed where the observer sees it.
 *
 * A back-EMF observer has no angle information at standstill under load, so
 * the drive starts on a forced angle, current-frequency style (VESC's and
 * ODrive's open-loop start, docs/algorithms.md "Sensorless start-up"):
 *
 *   FORCED  the angle the estimator uses is theta_f, turning at omega_f; the
 *           torque reference is t_start in the forced frame, i.e. a current of
 *           fixed amplitude along its q axis. The rotor locks on with its d
 *           axis between the forced d axis and the current (the angle gamma
 *           with t_start cos(gamma) = the torque the rotor needs) and follows
 *           omega_f, which ramps at ramp_dw per period towards the speed
 *           reference, limited to +-w_on. The observer runs all the while
 *           (restarted at theta_f + 90 deg, where an unloaded rotor lines up,
 *           when the ramp starts) with the fast gain kappa_start.
 *   HANDOVER when |omega_f| has been at w_on for settle_n periods (the
 *           observer's error has decayed by e^-6: settle_n = 6 / (w_on Ts)
 *           at critical damping): the angle switches to the observer's, the
 *           caller's speed loop takes over, its integrator set to the
 *           torque estimate of that period (bumpless: the current does not
 *           jump, only the frame it is described in), and the observer's
 *           gain falls to kappa.
 *   OBSERVER the observer's angle, and its speed through the encoder
 *           speed's first-order filter (params speed_lpf_k). Passing through zero in a
 *           reversal keeps it (the flux integral holds the angle for the
 *           few milliseconds the rotor spends at low speed); if |omega^| stays
 *           below w_off for low_n periods (a low speed reference, a stall),
 *           the forced angle takes over again at theta_f = theta^ - gamma,
 *           omega_f = omega^, with cos(gamma) = T^/t_start so that the torque
 *           does not jump.
 *
 * A salient machine (|Lq - Ld| large enough, ia_on) starts instead from its
 * measured angle (docs/algorithms.md, "Initial angle"):
 *   DETECT  the angle modulo pi from voltage pulses (initial_angle.h), the
 *           caller applying the pulses instead of its controller's output;
 *   POLARITY forced mode on that axis (turned back by the MTPA current's
 *           angle: the current on the measured q axis), no ramp: t_start for pol_n periods,
 *           -t_start for pol_n (the rotor turns by about a t^2 and stops),
 *           no torque for zero_n; then the angle modulo pi again. The rotor
 *           turned the way the torque pushed it: the measured d axis is the
 *           magnet's north if it turned forwards (dir = the speed
 *           reference's sign, + at 0), its south if backwards. A displacement
 *           under pol_min leaves the polarity unknown: the blind forced start.
 *   OBSERVER primed at that angle at standstill, the speed loop from the
 *           start (handover = 1 in that period); the low-speed fallback
 *           waits until the filtered |omega^| (w_f) has once reached w_on.
 *
 * Integer-only per period; the configuration in sensorless_config.h.
 */
#ifndef CONTROL_SENSORLESS_H
#define CONTROL_SENSORLESS_H

#include <stdint.h>

#include "angle_source.h"
#include "ctrl_params.h"
#include "flux_observer.h"
#include "fx.h"
#include "hfi.h"
#include "initial_angle.h"

/* 0: the initial angle left out (a flash-tight image, CMake option
 * PMSM_SL_INITIAL_ANGLE): every machine takes the forced start. */
#ifndef CTRL_SL_INITIAL_ANGLE
#define CTRL_SL_INITIAL_ANGLE 1
#endif

#define CTRL_SL_FORCED 0u   /* forced angle (start-up, low speed) */
#define CTRL_SL_OBSERVER 1u /* the observer's angle */
#define CTRL_SL_DETECT 2u   /* initial angle: the caller applies out.v_alpha, v_beta */
#define CTRL_SL_INJECT 3u   /* the injection's angle (hfi.h): the caller's speed loop runs */

/* Start of a salient machine (ia_on): the phases before the observer. */
#define CTRL_SL_PH_NONE 0u /* the blind forced start (or started) */
#define CTRL_SL_PH_D1 1u   /* angle modulo pi (initial_angle.h) */
#define CTRL_SL_PH_POL 2u  /* polarity pulse: +t_start, -t_start, 0 on that axis */
#define CTRL_SL_PH_D2 3u   /* angle modulo pi again: the displacement's sign */
#define CTRL_SL_PH_LOCK 4u /* injection: the tracking settles on the measured axis */
#define CTRL_SL_PH_SAT 5u  /* polarity by d-axis saturation pulses (hfi.h) */

/* Where the polarity of the start came from (ctrl_sl_t.pol_src). */
#define CTRL_SL_POL_UNKNOWN 0u /* not yet, or the blind forced start */
#define CTRL_SL_POL_SAT 1u     /* d-axis saturation pulses */
#define CTRL_SL_POL_MOTION 2u  /* the first motion (polarity pulse) */

typedef struct {
    ctrl_fobs_t obs; /* the observer (CTRL_FOBS_SENSORLESS) */
    /* ---- configuration (sensorless_config.c) ---- */
    q24_t t_start;     /* torque reference in the forced mode, Q24 pu (> 0) */
    q24_t ramp_dw;     /* forced speed change per period, Q24 pu */
    q24_t w_on;        /* |omega_f| of the handover, Q24 pu */
    q24_t w_off;       /* |omega^| under which the forced angle may take over, Q24 pu */
    uint32_t settle_n; /* periods at w_on before the handover */
    uint32_t low_n;    /* periods under w_off before the forced angle takes over */
    q24_t kappa_ts;    /* observer gain in the observer mode (obs.kappa_ts then) */
    q24_t kappa_start; /* observer gain while forced, Q24 (kappa Ts_pu) */
    fx_angle_t theta0; /* forced angle at the start */
#define CTRL_SL_KD_MAX ((int64_t)1 << 38) /* bound on kd (the product in 64 bits) */
    int64_t kd;           /* damping of the forced start: the forced angle shifted by
                           * -kd (omega^ - omega_f) >> 24, fx_angle_t units per pu of
                           * speed (0: off); the shift within +-45 deg */
    uint8_t ia_on;        /* salient machine: the start from the measured angle */
    uint32_t pol_n;       /* periods of each half of the polarity pulse */
    uint32_t zero_n;      /* periods without torque after it */
    fx_angle_t pol_min;   /* smallest displacement that tells the polarity */
    fx_angle_t pol_shift; /* the pulse's frame behind the measured axis: current on q */
    ctrl_ia_t ia;         /* the angle modulo pi */
    /* ---- state ---- */
    uint8_t mode;       /* CTRL_SL_* */
    uint8_t ramping;    /* the forced ramp has started (observer restarted) */
    uint32_t count;     /* periods at w_on (forced) or under w_off (observer) */
    fx_angle_t theta_f; /* forced angle at the next update */
    q24_t omega_f;      /* forced speed, Q24 pu */
    uint8_t phase;      /* CTRL_SL_PH_* */
    int8_t dir;         /* polarity pulse's sign */
    uint8_t reached;    /* the filtered |omega^| (w_f) reached w_on: fallback armed */
    fx_angle_t th1;     /* first angle modulo pi */
    q24_t w_f;          /* observer mode: the observer's speed through the encoder
                         * speed's filter (params speed_lpf_k), Q24 pu - what the
                         * speed loop gets (the PLL's own is too noisy for it) */
#if CTRL_SL_HFI
    uint8_t pol_src; /* CTRL_SL_POL_* of the start */
    /* High-frequency injection at and near standstill (hfi_on; hfi.h): the
     * start's angle modulo pi, LOCK, SAT (or the motion's polarity), then
     * the injection's angle below w_hi (for hfi_low_n periods above it: the
     * observer's), back below w_lo at once. */
    ctrl_hfi_t hfi;
    uint8_t hfi_on;     /* configured (ctrl_sl_init with an injection configuration) */
    q24_t hfi_w_hi;     /* |speed| of the hand-over to the observer, Q24 pu */
    q24_t hfi_w_lo;     /* |speed| under which the injection takes over again, Q24 pu */
    uint32_t lock_n;    /* periods of LOCK */
    uint32_t hfi_low_n; /* periods above hfi_w_hi before the observer takes over */
#endif
} ctrl_sl_t;

/* What the sensorless angle gives at sample k. */
typedef struct {
    fx_angle_t theta;      /* the angle for the estimator */
    q24_t omega;           /* the speed for the estimator and the speed loop, Q24 pu */
    uint8_t mode;          /* CTRL_SL_* */
    uint8_t handover;      /* 1 in the period the observer took over */
    uint8_t obs_frame;     /* 1: theta is the observer's angle (obs.frame is its frame) */
    q24_t torque_ref;      /* forced mode: the torque reference to apply, Q24 pu */
    fx_angle_t theta_obs;  /* the observer's angle (also while forced) */
    q24_t v_alpha, v_beta; /* CTRL_SL_DETECT: the voltage to apply, Q24 pu */
#if CTRL_SL_HFI
    uint8_t i_fund; /* 1: i_ab is the current without the injection's ripple, for the
                     * estimator (hfi.h) */
    q24_t i_ab[2];  /* alpha, beta, Q24 pu */
#endif
} ctrl_sl_out_t;

/* Back to the start: theta_f = theta0, omega_f = 0, observer not primed
 * (restarted when the ramp starts); a salient machine measures its angle
 * first (ia_on). Keeps the configuration. */
void ctrl_sl_reset(ctrl_sl_t *s);

/*
 * One period at sample k: v the mean voltage of [k-1, k) (ctrl_fobs_voltage),
 * i the current at k (alpha/beta), speed_ref the speed the caller wants (Q24
 * pu electrical; in torque mode a speed of the torque's sign beyond w_on),
 * torque_est the torque estimate of the previous period (Q24 pu, for a
 * bumpless return to the forced angle).
 */
void ctrl_sl_update(ctrl_sl_t *s, const ctrl_params_t *p, q24_t v_alpha, q24_t v_beta,
                    q24_t i_alpha, q24_t i_beta, q24_t speed_ref, q24_t torque_est,
                    ctrl_sl_out_t *out);

/*
 * The sensorless angle as the estimator's angle source (angle_source.h):
 * ctrl_estimator_set_angle_src(e, p, &ctrl_angle_sensorless), then
 * ctrl_sl_init on ((ctrl_angle_sl_t *)ctrl_estimator_angle_state(e))->sl.
 * Its voltage is the observer's own reconstruction (dead time and forward
 * drop removed, ctrl_fobs_voltage), not the estimator's plain duties x Vdc:
 * the caller hands it over after each period with ctrl_angle_sl_voltage,
 * together with the speed it wants and the torque estimate (speed_ref,
 * torque_est), and reads the mode, the handover and the forced torque
 * reference from out.
 */
typedef struct {
    ctrl_sl_t sl;
    q24_t v_alpha, v_beta; /* mean voltage of the last period, Q24 pu (ctrl_angle_sl_voltage) */
    q24_t speed_ref;       /* caller: the speed it wants, Q24 pu electrical */
    q24_t torque_est;      /* caller: the torque estimate of the last period, Q24 pu */
    ctrl_sl_out_t out;     /* the last update's output */
} ctrl_angle_sl_t;

extern const ctrl_angle_src_t ctrl_angle_sensorless;

/* After the period's estimate est: the voltage the leg duties acting in
 * [k, k+1) (legs, each in [0, FX_ONE], those est was formed with) give at the
 * DC link vdc(k) with the phase currents i_a, i_b at k (Q24 pu), for the
 * next update. */
void ctrl_angle_sl_voltage(ctrl_angle_sl_t *s, const ctrl_legs_t *legs, const ctrl_estimate_t *est,
                           q24_t vdc, q24_t i_a, q24_t i_b);

#endif /* CONTROL_SENSORLESS_H */
