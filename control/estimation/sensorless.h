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
 *   OBSERVER the observer's angle and speed. Passing through zero in a
 *           reversal keeps it (the flux integral holds the angle for the
 *           few milliseconds the rotor spends at low speed); if |omega^| stays
 *           below w_off for low_n periods (a low speed reference, a stall),
 *           the forced angle takes over again at theta_f = theta^ - gamma,
 *           omega_f = omega^, with cos(gamma) = T^/t_start so that the torque
 *           does not jump.
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

#define CTRL_SL_FORCED 0u   /* forced angle (start-up, low speed) */
#define CTRL_SL_OBSERVER 1u /* the observer's angle */

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
    int64_t kd; /* damping of the forced start: the forced angle shifted by
                 * -kd (omega^ - omega_f) >> 24, fx_angle_t units per pu of
                 * speed (0: off); the shift within +-45 deg */
    /* ---- state ---- */
    uint8_t mode;       /* CTRL_SL_* */
    uint8_t ramping;    /* the forced ramp has started (observer restarted) */
    uint32_t count;     /* periods at w_on (forced) or under w_off (observer) */
    fx_angle_t theta_f; /* forced angle at the next update */
    q24_t omega_f;      /* forced speed, Q24 pu */
} ctrl_sl_t;

/* What the sensorless angle gives at sample k. */
typedef struct {
    fx_angle_t theta;     /* the angle for the estimator */
    q24_t omega;          /* the speed for the estimator and the speed loop, Q24 pu */
    uint8_t mode;         /* CTRL_SL_* */
    uint8_t handover;     /* 1 in the period the observer took over */
    q24_t torque_ref;     /* forced mode: the torque reference to apply, Q24 pu */
    fx_angle_t theta_obs; /* the observer's angle (also while forced) */
} ctrl_sl_out_t;

/* Back to the forced start: theta_f = theta0, omega_f = 0, observer not
 * primed (it is restarted when the ramp starts). Keeps the configuration. */
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

/* After the period's estimate: the voltage the leg duties acting in [k, k+1)
 * give at the DC link vdc(k) with the phase currents i_a, i_b at k (Q24 pu),
 * for the next update. */
void ctrl_angle_sl_voltage(ctrl_angle_sl_t *s, const ctrl_legs_t *legs, q24_t vdc, q24_t i_a,
                           q24_t i_b);

#endif /* CONTROL_SENSORLESS_H */
