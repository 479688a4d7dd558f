/* Sensorless angle: observer and forced-angle start-up (sensorless.h). */
#include "sensorless.h"

#include "angle_source.h"

#define SL_QUARTER_TURN 0x40000000u /* 90 deg */
#define SL_HALF_TURN 0x80000000u    /* 180 deg */

void ctrl_sl_reset(ctrl_sl_t *s)
{
    s->mode = CTRL_SL_FORCED;
    s->ramping = 0u;
    s->count = 0u;
    s->theta_f = s->theta0;
    s->omega_f = 0;
    s->obs.primed = 0u;
    s->obs.kappa_ts = s->kappa_start;
    s->phase = (uint8_t)(s->ia_on != 0u ? CTRL_SL_PH_D1 : CTRL_SL_PH_NONE);
    s->mode = (uint8_t)(s->ia_on != 0u ? CTRL_SL_DETECT : CTRL_SL_FORCED);
    s->reached = (uint8_t)(s->ia_on != 0u ? 0u : 1u);
    s->dir = 1;
    s->th1 = 0u;
#if CTRL_SL_INITIAL_ANGLE
    ctrl_ia_start(&s->ia);
#endif
#if CTRL_SL_HFI
    s->pol_src = CTRL_SL_POL_UNKNOWN;
    ctrl_hfi_halt(&s->hfi);
#endif
}

/* omega_f one step towards target (at most ramp_dw). */
static q24_t sl_ramp(q24_t omega_f, q24_t target, q24_t dw)
{
    if (omega_f < target) {
        return fx_min(fx_add(omega_f, dw), target);
    }
    return fx_max(fx_sub(omega_f, dw), target);
}

/* The angle gamma of the rotor's d axis ahead of the forced d axis at which a
 * current along the forced q axis that gives t_start in its own frame gives
 * the torque T on the rotor: t_start cos(gamma) = T, gamma in [0, pi],
 * = atan2(sqrt(t_start^2 - T^2), T) (T clamped to +-t_start). */
static fx_angle_t sl_gamma(q24_t t_start, q24_t torque)
{
    const q24_t t = fx_clamp(torque, fx_neg(t_start), t_start);
    const int64_t d = (int64_t)t_start * t_start - (int64_t)t * t; /* >= 0, < 2^62 */
    const q24_t sn = (q24_t)fx_isqrt64((uint64_t)d);               /* <= t_start */
    return fx_atan2(sn, t);
}

/* The forced angle shifted against the rotor's speed error (the observer's
 * speed against the forced one): a rotor that runs ahead of the current sees
 * its torque reduced by t_start sin(gamma) delta, one that lags it increased,
 * which damps its swing about the forced current (critical damping with the
 * configured kd; nothing else does in a drive without friction). Speed error
 * taken within +-1 pu, the shift within +-45 deg. */
static fx_angle_t sl_damp(const ctrl_sl_t *s, q24_t w_obs)
{
    if (s->kd == 0 || s->obs.primed == 0u) {
        return 0u;
    }
    const q24_t dw = fx_clamp(fx_sub(w_obs, s->omega_f), -FX_ONE, FX_ONE);
    /* |dw kd| <= 2^24 CTRL_SL_KD_MAX = 2^62; rounded, saturated to 32 bits, then
     * to +-45 deg */
    const int32_t d = fx_round_sat((int64_t)dw * s->kd, FX_QBITS);
    const int32_t lim = (int32_t)1 << 29;
    const int32_t dc = fx_clamp(fx_neg(d), -lim, lim);
    return (fx_angle_t)(uint32_t)dc;
}

static void sl_forced_out(ctrl_sl_t *s, ctrl_sl_out_t *out, q24_t w_obs)
{
    out->mode = CTRL_SL_FORCED;
    out->theta = s->theta_f + sl_damp(s, w_obs);
    out->omega = s->omega_f;
    out->torque_ref = s->t_start;
    out->v_alpha = 0;
    out->v_beta = 0;
}

#if CTRL_SL_INITIAL_ANGLE
/* The observer from angle theta at standstill, its angle from this period
 * on; the caller's speed loop takes over (handover). */
static void sl_observe_from(ctrl_sl_t *s, const ctrl_params_t *p, fx_angle_t theta, q24_t i_alpha,
                            q24_t i_beta, ctrl_sl_out_t *out)
{
    ctrl_fobs_reset(&s->obs, p, theta, 0, i_alpha, i_beta);
    s->obs.kappa_ts = s->kappa_ts;
    s->mode = CTRL_SL_OBSERVER;
    s->phase = CTRL_SL_PH_NONE;
    s->count = 0u;
    s->w_f = 0;
    out->mode = CTRL_SL_OBSERVER;
    out->theta = theta;
    out->omega = 0;
    out->torque_ref = 0;
    out->handover = 1u;
}

#if CTRL_SL_HFI
/* The injection's tracking from angle theta (the north the polarity told, or
 * the observer's angle below w_lo) at speed omega, its angle from this period
 * on; the observer waits (it is started anew at the hand-over); the caller's
 * speed loop takes over (handover) or runs on. */
static void sl_inject_from(ctrl_sl_t *s, fx_angle_t theta, q24_t omega, q24_t torque, q24_t i_alpha,
                           q24_t i_beta, ctrl_sl_out_t *out)
{
    ctrl_hfi_start(&s->hfi, theta, omega, torque, i_alpha, i_beta);
    s->mode = CTRL_SL_INJECT;
    s->phase = CTRL_SL_PH_NONE;
    s->count = 0u;
    s->w_f = omega;
    s->reached = 1u;
    out->mode = CTRL_SL_INJECT;
    out->theta = theta;
    out->omega = omega;
    out->torque_ref = 0;
    out->handover = 1u;
}
#endif

/* The salient machine's start (sensorless.h): angle modulo pi, polarity
 * pulse, angle again, then the observer from the measured angle. */
static void sl_initial(ctrl_sl_t *s, const ctrl_params_t *p, q24_t v_alpha, q24_t v_beta,
                       q24_t i_alpha, q24_t i_beta, q24_t speed_ref, ctrl_sl_out_t *out)
{
    out->theta = s->theta_f;
    out->omega = 0;
    out->torque_ref = 0;
    out->v_alpha = 0;
    out->v_beta = 0;
#if CTRL_SL_HFI
    if (s->phase == CTRL_SL_PH_LOCK) {
        /* the injection settles on the measured axis; no torque */
        out->mode = CTRL_SL_FORCED;
        out->theta = s->hfi.theta;
        if (++s->count >= s->lock_n) {
            ctrl_hfi_halt(&s->hfi);
            ctrl_hfi_pol_start(&s->hfi, s->hfi.theta);
            s->phase = CTRL_SL_PH_SAT;
            s->mode = CTRL_SL_DETECT;
            s->count = 0u;
        }
        return;
    }
    if (s->phase == CTRL_SL_PH_SAT) {
        out->mode = CTRL_SL_DETECT;
        out->theta = s->hfi.pol_theta;
        if (ctrl_hfi_pol_step(&s->hfi, i_alpha, i_beta, &out->v_alpha, &out->v_beta) != 0u) {
            return;
        }
        const uint8_t r = s->hfi.pol_result;
        if (r == CTRL_HFI_POL_NORTH || r == CTRL_HFI_POL_SOUTH) {
            s->pol_src = CTRL_SL_POL_SAT;
            const fx_angle_t north =
                r == CTRL_HFI_POL_NORTH ? s->hfi.pol_theta : s->hfi.pol_theta + SL_HALF_TURN;
            sl_inject_from(s, north, 0, 0, i_alpha, i_beta, out);
            return;
        }
        /* no saturation to read: the polarity from the first motion, on the
         * axis the injection found */
        s->th1 = s->hfi.pol_theta & (SL_HALF_TURN - 1u);
        s->theta_f = s->th1;
        s->dir = speed_ref < 0 ? -1 : 1;
        s->phase = CTRL_SL_PH_POL;
        s->mode = CTRL_SL_FORCED;
        s->count = 0u;
        return;
    }
#endif
    if (s->phase == CTRL_SL_PH_POL) {
        out->mode = CTRL_SL_FORCED;
        const q24_t t = s->dir > 0 ? s->t_start : fx_neg(s->t_start);
        out->torque_ref = s->count < s->pol_n ? t : (s->count < 2u * s->pol_n ? fx_neg(t) : 0);
        /* the MTPA current's angle from q turns with the torque's sign */
        out->theta = out->torque_ref < 0 ? s->th1 + s->pol_shift : s->th1 - s->pol_shift;
        s->count++;
        if (s->count >= 2u * s->pol_n + s->zero_n) {
            s->phase = CTRL_SL_PH_D2;
            s->mode = CTRL_SL_DETECT;
            s->count = 0u;
            ctrl_ia_start(&s->ia);
        }
        return;
    }
    out->mode = CTRL_SL_DETECT;
    if (ctrl_ia_step(&s->ia, v_alpha, v_beta, i_alpha, i_beta, &out->v_alpha, &out->v_beta) != 0u) {
        return;
    }
    const fx_angle_t th = ctrl_ia_angle(&s->ia);
#if CTRL_SL_HFI
    if (s->phase == CTRL_SL_PH_D1 && s->hfi_on != 0u) {
        /* the injection tracks the axis found, then the saturation pulses */
        ctrl_hfi_start(&s->hfi, th, 0, 0, i_alpha, i_beta);
        s->phase = CTRL_SL_PH_LOCK;
        s->mode = CTRL_SL_FORCED;
        s->count = 0u;
        return;
    }
#endif
    if (s->phase == CTRL_SL_PH_D1) {
        /* the polarity pulse on the measured axis, the way the speed is wanted */
        s->th1 = th;
        s->theta_f = th;
        s->dir = speed_ref < 0 ? -1 : 1;
        s->phase = CTRL_SL_PH_POL;
        s->mode = CTRL_SL_FORCED;
        s->count = 0u;
        return;
    }
    /* Displacement within +-90 deg (both angles modulo pi): in doubled angles
     * the wrap is the integer one; halved without shifting a negative value. */
    const int32_t d2 = (int32_t)(uint32_t)((th << 1) - (s->th1 << 1));
    const int32_t disp = d2 / 2;
    const uint32_t mag = disp < 0 ? (uint32_t)0 - (uint32_t)disp : (uint32_t)disp;
    if (mag < s->pol_min) {
        /* polarity unknown (a load as large as t_start, a blocked rotor):
         * the blind forced start */
        s->phase = CTRL_SL_PH_NONE;
        s->mode = CTRL_SL_FORCED;
        s->reached = 1u;
        s->theta_f = s->theta0;
        s->count = 0u;
        return;
    }
    /* th1 moved on by the displacement (th itself may have wrapped across
     * the ends of [0, pi)), or turned by pi if the rotor went backwards */
    const fx_angle_t moved = s->th1 + (fx_angle_t)(uint32_t)disp;
    const fx_angle_t north = ((disp < 0) == (s->dir < 0)) ? moved : moved + SL_HALF_TURN;
#if CTRL_SL_HFI
    s->pol_src = CTRL_SL_POL_MOTION;
    if (s->hfi_on != 0u) {
        sl_inject_from(s, north, 0, 0, i_alpha, i_beta, out);
        return;
    }
#endif
    sl_observe_from(s, p, north, i_alpha, i_beta, out);
}
#endif

#if CTRL_SL_HFI
/* The injection's angle and speed (its tracking observer's, through the
 * encoder speed's filter); above w_hi for hfi_low_n periods (a torque step on
 * a load the tracking does not know moves its speed for a few ms) the
 * hand-over to the flux observer: the injection stops (its half pulse back
 * to the centre next) and the observer starts anew from the current model at
 * the injection's angle and speed (no angle step; its PLL without an error,
 * which its speed, 2 w_n e, would pass), its angle the output from the next
 * period on. */
static void sl_inject_track(ctrl_sl_t *s, const ctrl_params_t *p, q24_t i_alpha, q24_t i_beta,
                            ctrl_sl_out_t *out)
{
    s->w_f = fx_add(s->w_f, fx_mul(p->speed_lpf_k, fx_sub(s->hfi.omega, s->w_f)));
    out->mode = CTRL_SL_INJECT;
    out->theta = s->hfi.theta;
    out->theta_obs = s->hfi.theta;
    out->torque_ref = 0;
    out->v_alpha = 0;
    out->v_beta = 0;
    out->omega = s->w_f;
    s->count = fx_abs(s->w_f) >= s->hfi_w_hi ? s->count + 1u : 0u;
    if (s->count >= s->hfi_low_n) {
        ctrl_hfi_stop(&s->hfi);
        ctrl_fobs_reset(&s->obs, p, s->hfi.theta, s->w_f, i_alpha, i_beta);
        s->obs.kappa_ts = s->kappa_ts;
        s->mode = CTRL_SL_OBSERVER;
        s->count = 0u;
    }
}

/* Observer mode with the injection configured: below w_lo (the speed through
 * the encoder speed's filter) the injection takes over again at once, at the
 * observer's angle and that speed (the observer's angle is the one not to
 * trust there; the hysteresis w_lo .. w_hi keeps the two from alternating),
 * with the load its tracking learnt before (a load that lasts: through a
 * reversal the torque is far from it, and taken as steady the tracking would
 * lag the acceleration until it learnt it again). */
static void sl_observer_inject(ctrl_sl_t *s, fx_angle_t th_obs, q24_t torque, q24_t i_alpha,
                               q24_t i_beta, ctrl_sl_out_t *out)
{
    if (fx_abs(s->w_f) >= s->hfi_w_lo) {
        return;
    }
    const int64_t load = s->hfi.load_acc;
    sl_inject_from(s, th_obs, s->w_f, torque, i_alpha, i_beta, out);
    s->hfi.load_acc = load;
    out->handover = 0u; /* the speed loop runs on */
}
#endif

void ctrl_sl_update(ctrl_sl_t *s, const ctrl_params_t *p, q24_t v_alpha, q24_t v_beta,
                    q24_t i_alpha, q24_t i_beta, q24_t speed_ref, q24_t torque_est,
                    ctrl_sl_out_t *out)
{
    ctrl_fobs_t *const o = &s->obs;
#if CTRL_SL_HFI
    out->handover = 0u;
    out->obs_frame = 0u;
    out->i_fund = 0u;
    if (s->hfi.on != 0u || s->hfi.pos[0] != 0 || s->hfi.pos[1] != 0) {
        /* injecting, or its last pulses still in the samples: the current
         * without the ripple, for the observer and the estimator */
        ctrl_hfi_update(&s->hfi, p, v_alpha, v_beta, i_alpha, i_beta, torque_est, &i_alpha,
                        &i_beta);
        out->i_fund = 1u;
        out->i_ab[0] = i_alpha;
        out->i_ab[1] = i_beta;
    }
    if (s->mode == CTRL_SL_INJECT) {
        /* the injection's angle: the observer waits */
        sl_inject_track(s, p, i_alpha, i_beta, out);
        return;
    }
    const fx_angle_t th_obs = ctrl_fobs_update(o, p, v_alpha, v_beta, i_alpha, i_beta, 0u);
#else
    const fx_angle_t th_obs = ctrl_fobs_update(o, p, v_alpha, v_beta, i_alpha, i_beta, 0u);
    out->handover = 0u;
    out->obs_frame = 0u;
#endif
    const q24_t w_obs = o->omega; /* ctrl_fobs_omega without the call */
    out->theta_obs = th_obs;

#if CTRL_SL_INITIAL_ANGLE
    if (s->phase != CTRL_SL_PH_NONE) {
        sl_initial(s, p, v_alpha, v_beta, i_alpha, i_beta, speed_ref, out);
        return;
    }
#endif
    if (s->mode == CTRL_SL_OBSERVER) {
        out->mode = CTRL_SL_OBSERVER;
        out->theta = th_obs;
        out->obs_frame = 1u;
        s->w_f = fx_add(s->w_f, fx_mul(p->speed_lpf_k, fx_sub(w_obs, s->w_f)));
        out->omega = s->w_f;
        out->torque_ref = 0;
        out->v_alpha = 0;
        out->v_beta = 0;
#if CTRL_SL_HFI
        if (s->hfi_on != 0u) {
            sl_observer_inject(s, th_obs, torque_est, i_alpha, i_beta, out);
            return;
        }
#endif
        if (fx_abs(s->w_f) >= s->w_on) {
            s->reached = 1u; /* on the filtered speed: the PLL's noise near standstill
                              * reaches w_on */
        }
        s->count = fx_abs(w_obs) < s->w_off && s->reached != 0u ? s->count + 1u : 0u;
        if (s->count < s->low_n) {
            return;
        }
        /* Too slow for too long: the forced angle again, placed so that the
         * torque stays what it was (t_start cos(gamma) = T^). */
        s->mode = CTRL_SL_FORCED;
        s->ramping = 1u;
        s->count = 0u;
        s->theta_f = th_obs - sl_gamma(s->t_start, torque_est);
        s->omega_f = w_obs;
        o->kappa_ts = s->kappa_start;
    }

    /* Forced: the ramp towards the speed reference, at most +-w_on. */
    const q24_t target = fx_clamp(speed_ref, fx_neg(s->w_on), s->w_on);
    if (o->primed == 0u) {
        /* From the first forced period: the observer from where an unloaded
         * rotor lines up with the current (the forced q axis). Its error
         * decays as soon as the rotor moves - in the swing the forced current
         * starts, which its speed then damps (sl_damp). */
        ctrl_fobs_reset(o, p, s->theta_f + SL_QUARTER_TURN, s->omega_f, i_alpha, i_beta);
        o->kappa_ts = s->kappa_start;
    }
    if (s->ramping == 0u && (target != 0 || s->omega_f != 0)) {
        s->ramping = 1u;
    }
    sl_forced_out(s, out, w_obs);
    s->theta_f += ctrl_angle_step(p, s->omega_f);
    const q24_t w_next = sl_ramp(s->omega_f, target, s->ramp_dw);
    if ((w_next > 0 && s->omega_f < 0) || (w_next < 0 && s->omega_f > 0) ||
        (w_next == 0 && s->omega_f != 0)) {
        s->ramping = 0u; /* through or to zero */
    }
    s->omega_f = w_next;
    s->count = fx_abs(s->omega_f) >= s->w_on ? s->count + 1u : 0u;
    if (s->count >= s->settle_n) {
        /* Handover: the observer's angle from this period on. */
        s->mode = CTRL_SL_OBSERVER;
        s->count = 0u;
        o->kappa_ts = s->kappa_ts;
        out->mode = CTRL_SL_OBSERVER;
        out->theta = th_obs;
        out->obs_frame = 1u;
        out->omega = w_obs;
        out->torque_ref = 0;
        out->handover = 1u;
        s->reached = 1u;
        s->w_f = w_obs;
    }
}

/* ---- the angle source (sensorless.h) ---- */

static void angle_sl_reset(void *state, const ctrl_params_t *p)
{
    (void)p;
    ctrl_angle_sl_t *s = state;
    ctrl_sl_reset(&s->sl);
    s->v_alpha = 0;
    s->v_beta = 0;
    s->out.mode = s->sl.mode;
    s->out.handover = 0u;
    s->out.torque_ref = 0;
    s->out.v_alpha = 0;
    s->out.v_beta = 0;
#if CTRL_SL_HFI
    s->out.i_fund = 0u;
#endif
}

static void angle_sl_update(void *state, const ctrl_params_t *p, const ctrl_angle_in_t *in,
                            ctrl_angle_out_t *out)
{
    ctrl_angle_sl_t *s = state;
    ctrl_sl_update(&s->sl, p, s->v_alpha, s->v_beta, in->i_alpha, in->i_beta, s->speed_ref,
                   s->torque_est, &s->out);
    out->theta = s->out.theta;
    out->omega = s->out.omega;
    /* In the observer's mode its angle (the reference angle of its
     * correction, CTRL_FOBS_SENSORLESS as ctrl_sl_init sets it) is the
     * estimator's: the frame it formed is the estimator's too. */
    if (s->out.obs_frame != 0u) {
        out->frame = &s->sl.obs.frame;
    }
#if CTRL_SL_HFI
    if (s->out.i_fund != 0u) {
        out->i_fund = s->out.i_ab;
    }
#endif
}

const ctrl_angle_src_t ctrl_angle_sensorless = {
    .name = "sensorless",
    .state_size = sizeof(ctrl_angle_sl_t) +
                  0 * sizeof(struct {
                      _Static_assert(sizeof(ctrl_angle_sl_t) <= CTRL_ANGLE_STATE_MAX, "state");
                      int ok;
                  }),
    .uses_voltage = 0u, /* its own reconstruction: ctrl_angle_sl_voltage */
    .reset = angle_sl_reset,
    .update = angle_sl_update,
};

void ctrl_angle_sl_voltage(ctrl_angle_sl_t *s, const ctrl_legs_t *legs, const ctrl_estimate_t *est,
                           q24_t vdc, q24_t i_a, q24_t i_b)
{
    ctrl_fobs_t *const o = &s->sl.obs;
    if (o->dt_frac == 0 && o->v_fwd == 0) {
        /* No inverter error to remove: ctrl_fobs_voltage's ctrl_legs_voltage,
         * vdc times (4.4) of the duties, which the estimator formed with the
         * same rounding (est->u_alpha, u_beta; duties in [0, 1], where
         * ctrl_plan_dur and the clamp to [-2, 2) change nothing). */
        o->legs_prev = *legs;
        s->v_alpha = fx_mul(vdc, est->u_alpha);
        s->v_beta = fx_mul(vdc, est->u_beta);
        return;
    }
    ctrl_fobs_voltage(o, legs, vdc, i_a, i_b, &s->v_alpha, &s->v_beta);
}
