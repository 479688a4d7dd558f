/* The PWM-period interrupt (order and Q formats in pipeline.h). Integer-only. */
#include "pipeline.h"

#include <stdatomic.h>

#include "fw_pwm.h"
#include "plan.h"
#include "svpwm.h"

#if defined(__GNUC__)
#define FW_NOINLINE __attribute__((noinline))
#else
#define FW_NOINLINE
#endif

/* The main loop's side of the shared state (pipeline.h, fw_from_main_t): the
 * stores before this one are not moved after it by the compiler (the
 * Cortex-M core itself keeps its stores in order for an interrupt of the
 * same core). */
#define FW_RELEASE() atomic_signal_fence(memory_order_release)

/* The sensorless angle is its own (the observer's, or the injection's), not
 * the start's forced one: the speed loop runs, the torque estimate is
 * trusted. */
#if CTRL_SL_HFI
#define FW_SL_OWN_ANGLE(mode) ((mode) == CTRL_SL_OBSERVER || (mode) == CTRL_SL_INJECT)
#else
#define FW_SL_OWN_ANGLE(mode) ((mode) == CTRL_SL_OBSERVER)
#endif

static void fw_fault_now(fw_t *fw, uint32_t code)
{
    /* Gates off before anything else, then latch the code. */
    hal_gate_enable(fw->hal, false);
    (void)fw_state_event(&fw->sm, FW_EV_FAULT, code);
    fw->psi_due = 0u; /* the tracker restarts at the next arming */
    if (fw->cm.active != 0u) {
        cm_abort_fault(&fw->cm, code);
    }
    fw->cm_gates = 0u;
}

static void fw_pwm_off(fw_t *fw, fw_telemetry_t *tm)
{
    const hal_pwm_t off = {{0u, 0u, 0u}};
    hal_gate_enable(fw->hal, false);
    hal_pwm_write(fw->hal, &off);
    fw->applied.duty[0] = fw->applied.duty[1] = fw->applied.duty[2] = 0;
    fw->deadtime.high_prev = 0u;
    tm->legs[0] = tm->legs[1] = tm->legs[2] = 0;
}

/* A period without an estimate (not running, or a fault before it). */
static void fw_tm_no_estimate(fw_telemetry_t *tm)
{
    tm->vec = 0u;
    tm->duty = 0;
    tm->i_d = tm->i_q = 0;
    tm->psi_d = tm->psi_q = 0;
    tm->torque = tm->omega_e = tm->torque_ref = tm->torque_max = 0;
    tm->fieldweak_limit = 0u;
#if CTRL_SL_HFI
    /* no angle source with the gates off: not the last run's (a stale angle
     * error plotted after a stop) */
    tm->sl_state = 0u;
    tm->hfi_err = 0;
#endif
}

/* Q8 counts -> Q24 pu with a Q30 gain: round(d gain / 2^14), saturated. raw
 * < 2^16 and 0 <= off_q8 < 2^24 (an average of raw * 2^8), so |d| < 2^24 fits
 * 32 bits and d * gain (|.| < 2^55) is one 32x32 multiply; fx_round_sat is
 * fx_sat32(fx_rshift64_round(., 14)) on that range. */
static inline q24_t fw_current_pu(uint16_t raw, int32_t off_q8, int32_t gain_q30)
{
    const int32_t d = (int32_t)raw * 256 - off_q8;
    return fx_round_sat((int64_t)d * gain_q30, 14u);
}

/* DC link: raw * gain (< 2^16 * 2^31) / 2^6, rounded, saturated. */
static inline q24_t fw_vdc_pu(uint16_t raw, int32_t gain_q30)
{
    return fx_round_sat((int64_t)(int32_t)raw * gain_q30, 6u);
}

static void fw_calibrate(fw_t *fw, const hal_adc_raw_t *raw)
{
    fw->calib_sum[0] += raw->i_a;
    fw->calib_sum[1] += raw->i_b;
    fw->calib_sum[2] += raw->i_c;
    fw->calib_n++;
    if (fw->calib_n < fw->calib_samples) {
        return;
    }
    /* Average in Q8 counts, rounded (sum < 2^16 * 2^16, times 2^8 fits 64 bits). */
    const uint64_t n = fw->calib_n;
    /* Plausible offset: within adc_zero_tol of adc_zero (pipeline_config.c),
     * for every channel the HAL has (the third one's offset is used by the
     * commissioning steps' i_c: a broken sense path there faults too). */
    const int32_t tol = (int32_t)fw->adc_zero_tol * 256;
    const int n_ch = fw->info.has_i_c ? 3 : 2;
    bool ok = true;
    for (int x = 0; x < 3; x++) {
        const uint64_t avg = ((uint64_t)fw->calib_sum[x] * 256u + n / 2u) / n;
        fw->off_q8[x] = (int32_t)avg;
        const int32_t dev = fw->off_q8[x] - (int32_t)fw->adc_zero * 256;
        if (x < n_ch && (dev > tol || dev < -tol)) {
            ok = false;
        }
    }
    fw->calib_n = 0u;
    fw->calib_sum[0] = fw->calib_sum[1] = fw->calib_sum[2] = 0u;
    if (ok) {
        (void)fw_state_event(&fw->sm, FW_EV_CALIB_DONE, 0u);
    } else {
        fw_fault_now(fw, FW_FAULT_CALIB);
    }
}

/* A 32-bit counter value (or difference) read as two's complement. */
static int64_t fw_signed32(uint32_t u)
{
    return u <= (uint32_t)INT32_MAX ? (int64_t)u : (int64_t)u - (int64_t)4294967296;
}

/* A 32-bit counter difference u, read as two's complement, modulo m in
 * [0, m): fw_mod(fw_signed32(u), m), m <= 2^31. The index re-synchronisation
 * reduces the counts moved since the pulse, less than a turn: x in [-m, m)
 * takes no division (it was one in the worst period's path); any other x one
 * 32-bit division. */
static uint32_t fw_mod_u32(uint32_t u, uint32_t m)
{
    if (u < m) {
        return u; /* 0 <= x < m */
    }
    if (0u - u <= m) {
        return u + m; /* -m <= x < 0: x + m (modulo 2^32, which m = 2^31 needs at x = -m) */
    }
    if (u <= (uint32_t)INT32_MAX) {
        return u % m;
    }
    const uint32_t r = (0u - u) % m; /* |x| mod m for x = u - 2^32 < 0 */
    return r == 0u ? 0u : m - r;
}

/* x modulo m in [0, m) (C's % truncates towards zero). */
static uint32_t fw_mod(int64_t x, uint32_t m)
{
    int64_t r = x % (int64_t)m;
    if (r < 0) {
        r += (int64_t)m;
    }
    return (uint32_t)r;
}

/* Position tracking in full (first sample after (re)start, or a move out of
 * [0, cpr) in one step): the counter read as a signed offset or difference. */
static void fw_encoder_track(fw_t *fw, uint32_t count)
{
    if (!fw->enc_primed) {
        /* The counter is aligned (count 0 at the d axis on phase a) and read
         * as a signed offset from there: 2^32 is not a multiple of cpr, so a
         * counter below zero must not be reduced as an unsigned number. */
        fw->enc_last = count;
        fw->enc_pos = fw_mod_u32(count, fw->enc_cpr);
        fw->enc_primed = true;
    }
    /* Signed modulo-2^32 difference, then the position modulo cpr. */
    const int64_t delta = fw_signed32(count - fw->enc_last);
    fw->enc_last = count;
    const int64_t np = (int64_t)fw->enc_pos + delta;
    if (np >= 0 && np < (int64_t)fw->enc_cpr) {
        fw->enc_pos = (uint32_t)np;
    } else if (np >= (int64_t)fw->enc_cpr && np < 2 * (int64_t)fw->enc_cpr) {
        fw->enc_pos = (uint32_t)(np - (int64_t)fw->enc_cpr);
    } else if (np < 0 && np >= -(int64_t)fw->enc_cpr) {
        fw->enc_pos = (uint32_t)(np + (int64_t)fw->enc_cpr);
    } else {
        fw->enc_pos = fw_mod(np, fw->enc_cpr);
    }
}

/* Encoder counter -> position modulo cpr -> electrical angle. */
static inline fx_angle_t fw_encoder_angle(fw_t *fw, const hal_encoder_raw_t *enc)
{
    /* Direction -1: the counter negated, (c ^ ~0) - ~0 = -c (mod 2^32). */
    const uint32_t neg = fw->enc_neg;
    const uint32_t count = (enc->count ^ neg) - neg;
    const uint32_t index_count = (enc->index_count ^ neg) - neg;
    /* Usual period: the new position pos + delta stays in [0, cpr). With
     * delta in [-2^31, 2^31) and pos < cpr <= 2^31, pos + delta lies in that
     * range exactly when its value modulo 2^32 is below cpr (outside it, the
     * unsigned sum is >= cpr or wrapped to >= 2^31), so one unsigned sum and
     * compare decide it; everything else takes fw_encoder_track. */
    const uint32_t np = fw->enc_pos + (count - fw->enc_last);
    if (fw->enc_primed && np < fw->enc_cpr) {
        fw->enc_last = count;
        fw->enc_pos = np;
    } else {
        fw_encoder_track(fw, count);
    }
    /* A new index pulse marks position 0: re-synchronise. */
    if (enc->index_seen && (index_count != fw->enc_index_last || !fw->enc_index_valid)) {
        fw->enc_index_last = index_count;
        fw->enc_index_valid = true;
        fw->enc_pos = fw_mod_u32(count - index_count, fw->enc_cpr);
    }
    /* pos * p * 2^32 / cpr < p * 2^32: the low 32 bits are the angle modulo one
     * electrical turn (cpr * p < 2^31 checked at init). */
    if (fw->enc_cpr < 65536u) {
        /* pos p 2^32 / cpr = pos q + pos r / cpr; pos r < cpr^2 < 2^32. */
        const uint32_t e = fw->enc_pos * fw->enc_q32 + fw->enc_pos * fw->enc_r / fw->enc_cpr;
        return (fx_angle_t)e + fw->enc_offset;
    }
    const uint64_t num = (uint64_t)fw->enc_pos * (uint64_t)(uint32_t)fw->params.pole_pairs << 32;
    const uint64_t e = num / (uint64_t)fw->enc_cpr;
    return (fx_angle_t)(e & 0xFFFFFFFFu) + fw->enc_offset;
}

/* The medium task's state anew at its next run, which is this period's, inside
 * the interrupt (fw_control). */
static void fw_mid_restart(fw_t *fw)
{
    fw->mid_reset = 1u;
    fw->mid_bump = 0u;
    fw->mid_fresh = 0u;
    fw->mid_count = 1u;
    fw->mid_vdc_sum = 0;
    fw->mid_n = 0u;
}

/* The request k made since the last period: taken (its count copied). */
static bool fw_take(fw_t *fw, fw_req_t k)
{
    const uint32_t n = fw->ml.req[k];
    if (n == fw->isr.taken[k]) {
        return false;
    }
    fw->isr.taken[k] = n;
    return true;
}

#if PMSM_LIVE_PARAMS
/* A live change the main loop published (pipeline.h): the speed PI's new
 * gains handed to the medium task's next run (it applies them with that
 * run's speed error), the controller's retune from the state made for its
 * new configuration; taken and dropped when the main loop withdrew it
 * (fw_request_withdraw). Out of line: once per change. */
static FW_NOINLINE void fw_apply_tune(fw_t *fw)
{
    if (fw_take(fw, FW_REQ_SPEED_TUNE) && fw->ml.withdrawn[0] != fw->isr.taken[FW_REQ_SPEED_TUNE]) {
        /* for the medium task's next run, which steps the PI */
        fw->speed_pi_taken = fw->speed_pi_next;
        fw->mid_retune = 1u;
    }
    if (fw_take(fw, FW_REQ_CTRL_TUNE) && fw->ml.withdrawn[1] != fw->isr.taken[FW_REQ_CTRL_TUNE]) {
        fw->ctrl->retune(fw->ctrl_state.bytes, fw->ctrl_next.bytes);
    }
}
#endif

/* The main loop's requests, in this order (pipeline.h, fw_req_t). Out of
 * line: a period with a request is rare. */
static FW_NOINLINE void fw_apply_commands(fw_t *fw, fw_telemetry_t *tm, uint32_t sum)
{
    fw->isr.taken_sum = sum;
#if PMSM_LIVE_PARAMS
    fw_apply_tune(fw);
#endif
    if (fw_take(fw, FW_REQ_TM)) {
        /* a new stream: the records of the last one are not for it */
        fw->tm_every = fw->ml.tm_every;
        fw->tm_count = 1u;
        fw->isr.tm_drop = fw->isr.tm_head;
    }
    if (fw_take(fw, FW_REQ_CLEAR)) {
        if (fw_state_event(&fw->sm, FW_EV_CLEAR, 0u)) {
            hal_trip_clear(fw->hal);
            fw_protect_reset(&fw->prot);
            fw->enc_primed = false;
        }
    }
    if (fw_take(fw, FW_REQ_DISARM)) {
        fw->psi_due = 0u;
        const bool cm = fw->sm.state == FW_STATE_COMMISSION;
        if (fw_state_event(&fw->sm, FW_EV_DISARM, 0u) && cm) {
            /* Stop: the step ends, gates off now. */
            cm_abort_stop(&fw->cm);
            fw->cm_gates = 0u;
            fw_pwm_off(fw, tm);
        }
    }
    if (fw_take(fw, FW_REQ_CM)) {
        if (fw_state_event(&fw->sm, FW_EV_CM_START, 0u)) {
            /* The steps enable the gates when they first drive the legs. */
            fw->cm_gates = 0u;
            fw_pwm_off(fw, tm);
            cm_begin(&fw->cm);
        }
    }
    if (fw_take(fw, FW_REQ_ARM)) {
        if (fw_state_event(&fw->sm, FW_EV_ARM, 0u)) {
            /* Fresh dynamic state; the first gated period is k+1. */
            fw->ctrl->reset(fw->ctrl_state.bytes);
            ctrl_estimator_reset(&fw->est, &fw->params);
            ctrl_psi_track_reset(&fw->psi_track); /* from the current model at the first period */
            fw_mid_restart(fw);
            fw_torque_follow_reset(&fw->tqf);
#if CTRL_COGGING
            ctrl_cogging_restart(&fw->cog.map); /* no speed or read of the last run */
#endif
#if CTRL_SL_START_CHECK
            fw->sl_forced_n = fw->sl_obs_n = 0u;
#endif
            fw->trim = 0;
            fw->applied.duty[0] = fw->applied.duty[1] = fw->applied.duty[2] = 0;
            hal_gate_enable(fw->hal, true);
        }
    }
}

/* Over-current and hardware trip: checked right after the current conversion,
 * the gates go off before anything else is computed. Returns the fault or 0. */
static inline uint32_t fw_protect_fast(fw_t *fw, hal_t *hal, q24_t i_a, q24_t i_b)
{
    uint32_t f = fw_protect_current(&fw->prot, i_a, i_b);
    if (f == FW_FAULT_NONE && hal_trip_active(hal)) {
        f = FW_FAULT_HW_TRIP;
    }
    if (f != FW_FAULT_NONE) {
        fw_fault_now(fw, f);
    }
    return f;
}

/* DC link, then the encoder (not checked in a period whose DC link faults);
 * returns the first fault or 0. */
static inline uint32_t fw_protect_slow(fw_t *fw, q24_t vdc, uint32_t enc_count)
{
    uint32_t f = fw_protect_vdc(&fw->prot, vdc);
    if (f == FW_FAULT_NONE) {
        f = fw_protect_encoder(&fw->prot, enc_count);
    }
    return f;
}

/* DC link counts -> per unit and the encoder angle, into the measurements. */
static inline void fw_measure_rest(fw_t *fw, const hal_adc_raw_t *raw, const hal_encoder_raw_t *enc,
                                   ctrl_meas_t *m)
{
    m->vdc = fw_vdc_pu(raw->vdc, fw->vdc_gain_q30);
    m->theta_e = fw_encoder_angle(fw, enc);
}

/* Leg duties (each in [0, FX_ONE], so the compare values are in [0, N]) ->
 * limited to the HAL's largest duty (fw_legs_limit: a board keeps a zero
 * vector around the current sampling instant, hal_info_t.pwm_cmp_max), so
 * that what the estimator is told was applied is what the inverter applies
 * -> telemetry -> with est (the controller's periods) the dead-time
 * compensation (deadtime.h), limited again -> compare values ->
 * hal_pwm_write (effective at k+1). */
static inline void fw_pwm_out(fw_t *fw, hal_t *hal, fw_telemetry_t *tm, ctrl_legs_t *legs,
                              const ctrl_estimate_t *est)
{
    fw_legs_limit(legs->duty, fw->duty_max);
    tm->legs[0] = legs->duty[0];
    tm->legs[1] = legs->duty[1];
    tm->legs[2] = legs->duty[2];
    ctrl_legs_t w = *legs;
#if CTRL_DEAD_COMP
    if (fw->deadtime.dd != 0) {
        if (est != NULL) {
            ctrl_deadtime_apply(&fw->deadtime, est, &w);
            fw_legs_limit(w.duty, fw->duty_max);
        }
        ctrl_deadtime_written(&fw->deadtime, &w);
    }
#else
    (void)est;
#endif
    hal_pwm_t pwm;
    const uint32_t n8 = fw->pwm_n8;
    if (n8 != 0u) {
        pwm.cmp[0] = fw_pwm_compare8((uint32_t)w.duty[0], n8);
        pwm.cmp[1] = fw_pwm_compare8((uint32_t)w.duty[1], n8);
        pwm.cmp[2] = fw_pwm_compare8((uint32_t)w.duty[2], n8);
    } else {
        const uint32_t n = fw->info.period_counts;
        pwm.cmp[0] = fw_pwm_compare((uint32_t)w.duty[0], n);
        pwm.cmp[1] = fw_pwm_compare((uint32_t)w.duty[1], n);
        pwm.cmp[2] = fw_pwm_compare((uint32_t)w.duty[2], n);
    }
    hal_pwm_write(hal, &pwm);
}

/* PM flux from the voltage model (fw_config_t.psi_adapt): the encoder-mode
 * observer on the estimator's frame (psi_track.h), its integration here every
 * period; at period 0 of its N the correction's inputs go to the medium task
 * (fw_mid_trigger requests a run), whose correction, EMA and parameters
 * (medium.c) fw_psi_apply takes at the next period. */
static inline void fw_psi_track(fw_t *fw, const ctrl_meas_t *m, const ctrl_estimate_t *est)
{
    fw_mid_in_t *const in = &fw->mid_in[(fw->mid_req + 1u) & 1u]; /* the free slot */
    fw->psi_due = ctrl_psi_track_integrate(&fw->psi_track, &fw->params, est, &fw->applied, m->i_a,
                                           m->i_b, &in->psi)
                      ? 1u
                      : 0u;
}

/* The period after a tracker run (it has ended: checked at the period's
 * start), before the estimate: the flux's step (exact: the flux is a sum
 * between two corrections) and, when the estimate has moved out of the band,
 * the parameters every consumer reads. Out of line: once in N periods. */
static FW_NOINLINE void fw_psi_apply(fw_t *fw)
{
    fw->psi_due = 0u;
    const fw_mid_out_t *const mo = &fw->mid_out[fw->mid_done & 1u];
    ctrl_psi_track_add(&fw->psi_track, mo->psi_delta);
    if (mo->psi_new != 0u) {
        fw->params.psi_pm = mo->psi_pm;
        fw->params.inv_psi_pm = mo->inv_psi_pm;
        fw->params.mtpa_k = mo->mtpa_k;
    }
}

/* Sensorless (fw_config_t.sensorless): what the angle source needs before
 * the estimate of this period - the speed wanted (in torque mode one of the
 * torque's sign, so that the forced start turns the right way) and the
 * torque estimate of the last period. */
static inline void fw_sl_inputs(fw_t *fw, ctrl_angle_sl_t *sl, uint8_t mode, q24_t tref)
{
    q24_t w = fw->ml.speed_ref;
    if (mode != FW_REF_SPEED) {
        w = tref > 0 ? FX_ONE : (tref < 0 ? -FX_ONE : 0);
    }
    sl->speed_ref = w;
    sl->torque_est = fw->estimate.now.torque;
}

/* The sensorless angle's state in the record: its mode, the start's phase
 * and where its polarity came from (pipeline.h, fw_telemetry_t.sl_state),
 * and the injection's angle error. */
#if CTRL_SL_HFI
static inline void fw_sl_telemetry(fw_telemetry_t *tm, const ctrl_sl_t *s, const ctrl_sl_out_t *o)
{
    tm->sl_state = (uint8_t)((o->mode & 3u) | ((s->phase & 7u) << 2) | ((s->pol_src & 3u) << 5));
    tm->hfi_err = s->hfi.err;
}

/* The injection's voltage (hfi.h) added to the controller's leg duties for
 * the inverter only: what the estimator and the observer are told was
 * applied stays the controller's (limited as the written ones), so that they
 * see the fundamental; a clamp (the spread left no room) is counted. */
static FW_NOINLINE void fw_hfi_out(fw_t *fw, hal_t *hal, fw_telemetry_t *tm, ctrl_hfi_t *h,
                                   ctrl_legs_t *legs, const ctrl_estimate_t *est)
{
    ctrl_legs_t w = *legs;
    fw_legs_limit(w.duty, fw->duty_max);
    fw->hfi_clipped += ctrl_hfi_add_to_legs(h, w.duty, fw->duty_max);
    fw_pwm_out(fw, hal, tm, &w, est);
    fw_legs_limit(legs->duty, fw->duty_max);
}
#endif

/* The medium task's run of the PM-flux tracker alone (its inputs are in the
 * free slot, fw_psi_track): true. */
static inline bool fw_mid_track_request(fw_t *fw)
{
    const uint32_t req = fw->mid_req + 1u;
    fw_mid_in_t *const in = &fw->mid_in[req & 1u];
    in->track = 1u;
    in->run = 0u;
    in->first = 0u;
    FW_RELEASE(); /* the slot before its count */
    fw->mid_req = req;
    return true;
}

/* The DC link summed for the medium task; once in mid_div periods (or at
 * once, mid_count = 1) its inputs into the free slot, with the tracker's
 * correction when due: true, a run is due. */
static inline bool fw_mid_trigger(fw_t *fw, const ctrl_estimate_t *est, q24_t t_req, uint8_t hold,
                                  uint8_t mode)
{
    fw->mid_vdc_sum += est->vdc;
    fw->mid_n++;
    if (--fw->mid_count != 0u) {
        return fw->psi_due != 0u && fw_mid_track_request(fw);
    }
    fw->mid_count = fw->mid_div;
    const uint32_t req = fw->mid_req + 1u;
    fw_mid_in_t *const in = &fw->mid_in[req & 1u];
    in->track = fw->psi_due; /* its inputs are in the slot (fw_psi_track) */
    in->run = 1u;
    in->first = fw->mid_fresh == 0u ? 1u : 0u;
    in->vdc_sum = fw->mid_vdc_sum;
    in->n = fw->mid_n;
    in->omega_e = est->omega_e;
    in->tref = t_req;
    in->torque_now = fw->torque_ref_now;
    in->speed_ref = fw->ml.speed_ref;
    in->bump_torque = fw->mid_bump_t;
    in->ref_mode = mode;
    in->hold = hold;
    in->reset = fw->mid_reset;
    in->bump = fw->mid_bump;
#if PMSM_LIVE_PARAMS
    in->retune = fw->mid_retune;
    if (fw->mid_retune != 0u) {
        in->retune_pi = fw->speed_pi_taken;
        fw->mid_retune = 0u;
    }
#endif
    fw->mid_vdc_sum = 0;
    fw->mid_n = 0u;
    fw->mid_reset = 0u;
    fw->mid_bump = 0u;
    fw->mid_fresh = 1u;
    FW_RELEASE(); /* the slot before its count */
    fw->mid_req = req;
    return true;
}

/* The estimate, the torque reference within the medium task's limits, the
 * controller's step, the compare values; true when the medium task is due. */
static inline bool fw_control_out(fw_t *fw, fw_telemetry_t *tm, ctrl_angle_sl_t *sl, q24_t tref,
                                  uint8_t hold, uint8_t mode, const fw_mid_out_t *mo, q24_t *t_req);

/* The sensorless angle source's state (fw_config_t.sensorless), else NULL. */
static inline ctrl_angle_sl_t *fw_sl(fw_t *fw)
{
    return fw->cfg.sensorless ? (ctrl_angle_sl_t *)ctrl_estimator_angle_state(&fw->est) : NULL;
}

/* mode, tref0: the reference of this period (the main loop's, taken once;
 * a commissioning step's torque). */
static inline bool fw_control(fw_t *fw, fw_telemetry_t *tm, const ctrl_meas_t *m, uint8_t mode,
                              q24_t tref0)
{
    ctrl_estimate_t *const est = &fw->estimate;
    ctrl_angle_sl_t *const sl = fw_sl(fw);
    if (sl != NULL) {
        fw_sl_inputs(fw, sl, mode, tref0);
    } else if (fw->psi_due != 0u) {
        fw_psi_apply(fw);
    }
    ctrl_estimator_update(&fw->est, &fw->params, m, &fw->applied, est);
    if (sl != NULL) {
        /* the voltage of [k, k+1) for the observer's next period */
        ctrl_angle_sl_voltage(sl, &fw->applied, est, m->vdc, m->i_a, m->i_b);
    } else if (fw->cfg.psi_adapt && fw->sm.state == FW_STATE_RUNNING) {
        fw_psi_track(fw, m, est);
    }
    tm->omega_e = est->omega_e;
    tm->i_d = est->now.i_d;
    tm->i_q = est->now.i_q;
    tm->psi_d = est->now.psi_d;
    tm->psi_q = est->now.psi_q;
    tm->torque = est->now.torque;
#if CTRL_SL_HFI
    if (sl != NULL) {
        fw_sl_telemetry(tm, &sl->sl, &sl->out);
    }
#endif
    /* The torque reference without the speed loop: the sensorless start's
     * (forced angle or the initial angle's pulses: the start-up current along
     * the forced q axis, the speed loop waiting, sensorless.h), or torque
     * mode's (torque_ref clamped by fw_set_torque_ref). */
    const uint8_t hold = sl != NULL && !FW_SL_OWN_ANGLE(sl->out.mode) ? 1u : 0u;
    const q24_t tref = hold != 0u ? sl->out.torque_ref : tref0;
    q24_t t_req = tref;
    if (fw->mid_fresh == 0u) {
        /* The first period after a reset (arming, a commissioning step's
         * controller reset): the interrupt ends here; the medium task's run,
         * due now, is its first, and then does the rest of this period
         * (fw_mid_first_step: the torque reference, the controller's step, the
         * compare values) before the next period: the same outputs, in the
         * same period, as with all of it in the interrupt. The run comes
         * before the step so that this period already has the speed loop's
         * output and the limits of its own speed and DC link, as every later
         * one has (a drive started at its limit, the 80 kW IPMSM at its
         * fixed-flux torque limit under m2ptfc, lost the load angle after a
         * first period at zero torque and the limits of standstill). */
        fw->mid_count = 1u;
        fw->mid_first = tm;
    } else if (!fw_control_out(fw, tm, sl, tref, hold, mode, &fw->mid_out[fw->mid_done & 1u],
                               &t_req)) {
        return false; /* a fault: gates off */
    }
    return fw_mid_trigger(fw, est, t_req, hold, mode);
}

/* The rest of the period after the estimate (fw_control; in the first period
 * after a reset fw_mid_first_step): the protections on the estimate, the
 * torque reference within the medium task's limits (mo, its last run), the
 * controller's step, the compare values. False after a fault (gates off);
 * *t_req: the torque reference before the limits, for the medium task. */
static inline bool fw_control_out(fw_t *fw, fw_telemetry_t *tm, ctrl_angle_sl_t *sl, q24_t tref,
                                  uint8_t hold, uint8_t mode, const fw_mid_out_t *mo, q24_t *t_req)
{
    hal_t *const hal = fw->hal;
    const ctrl_meas_t *const m = &tm->meas;
    ctrl_estimate_t *const est = &fw->estimate;
    /* overspeed, or a slow protection of the medium task */
    uint32_t f = fw_protect_overspeed(&fw->prot, est->omega_e);
    if (f == FW_FAULT_NONE) {
        f = mo->fault;
    }
    if (f == FW_FAULT_NONE) {
        /* the estimate at k answers the reference applied at k-1; none to
         * trust on the sensorless start's forced angle */
        f = fw_torque_follow_step(&fw->tqf, fw->torque_ref_now, est->now.torque,
                                  sl == NULL || FW_SL_OWN_ANGLE(sl->out.mode));
    }
#if CTRL_SL_START_CHECK
    if (f == FW_FAULT_NONE && sl != NULL) {
        /* A start that does not end: periods off the observer while the
         * speed asked for is beyond the handover's (a rotor held by a load
         * or friction the start's torque cannot move falls back to the
         * forced angle again and again); forgotten once the observer has
         * held as long. The injection's tracking is no start: its angle
         * holds at any speed (docs/algorithms.md, "High-frequency injection"). */
        if (!FW_SL_OWN_ANGLE(sl->out.mode)) {
            fw->sl_obs_n = 0u;
            fw->sl_forced_n += fx_abs(sl->speed_ref) >= sl->sl.w_on ? 1u : 0u;
        } else if (++fw->sl_obs_n >= fw->sl_forced_max) {
            fw->sl_forced_n = 0u;
        }
        if (fw->sl_forced_n > fw->sl_forced_max) {
            f = FW_FAULT_SL_START;
        }
    }
#endif

    if (hold != 0u) {
        /* the sensorless start's reference (above) */
    } else if (mode == FW_REF_SPEED) {
        if (sl != NULL && sl->out.handover != 0u) {
            /* bumpless: the speed loop restarts from the torque it takes over,
             * in a run of the medium task now */
            tref = est->now.torque;
            fw->mid_bump = 1u;
            fw->mid_bump_t = tref;
            fw->mid_count = 1u;
        } else {
            /* the speed loop's output, held between the medium task's runs */
            tref = mo->speed_tref;
        }
    }
    if (f != FW_FAULT_NONE) {
        /* latched, gates off, no references in the record */
        fw_fault_now(fw, f);
        tm->vec = 0u;
        tm->duty = 0;
        tm->torque_ref = 0;
        tm->torque_max = 0;
        tm->fieldweak_limit = 0u;
        fw_pwm_off(fw, tm);
        return false;
    }
    /* Torque limited by the current and voltage limits, flux reference
     * weakened to what the voltage allows (0 = the controller's own below
     * base speed, so nothing changes there): the medium task's (field_weak.h). */
    const q24_t torque_max = mo->torque_max;
    *t_req = tref;
    tref = fx_clamp(*t_req, fx_neg(torque_max), torque_max);
    /* Mean-torque trim in field weakening: with the flux at the voltage's
     * limit the torque rises slowly (little voltage beyond the back-EMF) and
     * falls fast, so a hysteresis or duty-ratio controller settles below its
     * reference; an integrator of the estimated torque's error (corner
     * FW_TRIM_HZ, the DRR EMA's of thesis sec. 5.3.2) restores the mean.
     * Outside field weakening it decays with the same time constant (smooth
     * exit); bounded by a quarter of the torque limit. */
    const uint8_t weak = mo->weakening;
    if (weak != 0u || fw->trim != 0) { /* else it stays 0 */
        const q24_t trim_lim = fx_rshift32_round(torque_max, 2u);
        const q24_t trim_in = weak != 0u ? fx_sub(tref, est->now.torque) : fx_neg(fw->trim);
        fw->trim =
            fx_clamp(fx_add(fw->trim, fx_mul(fw->trim_k, trim_in)), fx_neg(trim_lim), trim_lim);
    }
    fw->refs.torque = fx_add(tref, fw->trim);
#if CTRL_COGGING
    if (fw->cog_on != 0u && fw->sm.state == FW_STATE_RUNNING) {
        /* anti-cogging: the table where the rotor will be when the torque
         * asked now is made (cogging_ff.h's lead), within the limit */
        const q24_t ff = ctrl_cogging_step(&fw->cog.map, fw->enc_pos, est->omega_e);
        const q24_t cmd = fw->refs.torque;
        fw->refs.torque = fx_clamp(fx_add(cmd, ff), fx_neg(torque_max), torque_max);
        fw->refs.torque_ff = fx_sub(fw->refs.torque, cmd); /* what the limit left of ff */
    } else {
        fw->refs.torque_ff = 0;
    }
#endif
    fw->refs.psi = weak != 0u ? mo->psi_ref : 0;
    fw->torque_ref_now = tref;
    tm->torque_max = torque_max;
    tm->fieldweak_limit =
        (uint8_t)(mo->limit + 4u * (tref != *t_req) + 8u * weak + 16u * fw->tqf.warn);

    const ctrl_ctx_t ctx = {&fw->params, est, &fw->refs};
    /* The descriptor and its state were validated when it was installed
     * (fw_select_controller): its step is called directly; it writes the leg
     * duties and, if it has one, the plan (ctrl_out_t). */
    ctrl_out_t out;
    out.plan.n_seg = 0u;
    fw->ctrl->step(fw->ctrl_state.bytes, &ctx, &out);
    if (sl != NULL && sl->out.mode == CTRL_SL_DETECT) {
        /* the initial angle's voltage pulse instead (initial_angle.h) */
        ctrl_svpwm_duties(sl->out.v_alpha, sl->out.v_beta, m->vdc, &out.legs);
        out.plan.n_seg = 0u;
    }
#if CTRL_SL_HFI
    if (sl != NULL && sl->sl.hfi.amp[0] != 0) {
        fw_hfi_out(fw, hal, tm, &sl->sl.hfi, &out.legs, est);
    } else
#endif
    {
        fw_pwm_out(fw, hal, tm, &out.legs, est);
    }
    /* The duties written now act during [k+1, k+2): they are "applied" for
     * the estimator's prediction at k+1 (the compensation makes them true). */
    fw->applied = out.legs;
    const int has_plan = out.plan.n_seg > 0u;
    tm->vec = has_plan ? out.plan.vec[0] : 0u;
    tm->duty = has_plan ? out.plan.dur[0] : 0;
    tm->torque_ref = tref;
    return true;
}

void fw_mid_first_step(fw_t *fw, const fw_mid_in_t *in, const fw_mid_out_t *mo)
{
    fw_telemetry_t *const tm = fw->mid_first;
    q24_t t_req;
    (void)fw_control_out(fw, tm, fw_sl(fw), in->tref, in->hold, in->ref_mode, mo, &t_req);
    /* the record's tail as the interrupt wrote it, after a fault here */
    tm->state = (uint8_t)fw->sm.state;
    tm->fault = (uint8_t)fw->sm.fault_code;
    tm->gates = fw->sm.state == FW_STATE_RUNNING || fw->cm_gates != 0u ? 1u : 0u;
}

/* A running period: measurements, protections, control. */
static inline bool fw_period_running(fw_t *fw, hal_t *hal, fw_telemetry_t *tm,
                                     const hal_adc_raw_t *raw, const hal_encoder_raw_t *enc)
{
    /* The measurements go straight into the telemetry record. */
    ctrl_meas_t *const m = &tm->meas;
    const q24_t i_a = fw_current_pu(raw->i_a, fw->off_q8[0], fw->gain_q30[0]);
    const q24_t i_b = fw_current_pu(raw->i_b, fw->off_q8[1], fw->gain_q30[1]);
    m->i_a = i_a;
    m->i_b = i_b;
    uint32_t f = fw_protect_fast(fw, hal, i_a, i_b);
    fw_measure_rest(fw, raw, enc, m);
    if (f == FW_FAULT_NONE) {
        f = fw->cfg.sensorless ? fw_protect_vdc(&fw->prot, m->vdc)
                               : fw_protect_slow(fw, m->vdc, enc->count);
        if (f != FW_FAULT_NONE) {
            fw_fault_now(fw, f);
        }
    }
    if (f == FW_FAULT_NONE) {
        return fw_control(fw, tm, m, fw->ml.ref_mode, fw->ml.torque_ref_lim);
    }
    fw_tm_no_estimate(tm);
    fw_pwm_off(fw, tm);
    return false;
}

/* ---- commissioning dispatch (firmware/commission; cm.h) ----
 * The same conversion and protections as every state; the active step then
 * decides the next period: gates off, leg duties, or the controller with a
 * torque reference. A protection or a failed step ends it with the gates off
 * (the step's reason stays in fw->cm.err, the fault latches). */
static bool fw_period_commission(fw_t *fw, hal_t *hal, fw_telemetry_t *tm, const hal_adc_raw_t *raw,
                                 const hal_encoder_raw_t *enc)
{
    ctrl_meas_t *const m = &tm->meas;
    m->i_a = fw_current_pu(raw->i_a, fw->off_q8[0], fw->gain_q30[0]);
    m->i_b = fw_current_pu(raw->i_b, fw->off_q8[1], fw->gain_q30[1]);
    /* The step's record of the largest current sees a tripping sample too. */
    fw->cm.i_peak = fx_max(fw->cm.i_peak, fx_max(fx_abs(m->i_a), fx_abs(m->i_b)));
    uint32_t f = fw_protect_fast(fw, hal, m->i_a, m->i_b);
    fw_measure_rest(fw, raw, enc, m);
    if (f == FW_FAULT_NONE) {
        f = fw_protect_slow(fw, m->vdc, enc->count);
        if (f != FW_FAULT_NONE) {
            fw_fault_now(fw, f);
        }
    }
    fw_tm_no_estimate(tm);
    if (f != FW_FAULT_NONE) {
        fw_pwm_off(fw, tm); /* fw_fault_now ended the step */
        return false;
    }
    cm_in_t in;
    in.i_a = m->i_a;
    in.i_b = m->i_b;
    in.i_c = fw->info.has_i_c ? fw_current_pu(raw->i_c, fw->off_q8[2], fw->gain_q30[2])
                              : fx_neg(fx_add(m->i_a, m->i_b));
    in.vdc = m->vdc;
    in.theta = m->theta_e - fw->enc_offset;
    in.omega_est = fw->estimate.omega_e;
    in.torque_est = fw->estimate.now.torque;
#if CTRL_COGGING
    in.enc_pos = fw->enc_pos;
#endif
    cm_out_t out;
    if (!cm_period(&fw->cm, &in, &out)) {
        fw->cm_gates = 0u;
        fw_pwm_off(fw, tm);
        if (fw->cm.err == CM_E_NONE) {
            (void)fw_state_event(&fw->sm, FW_EV_CM_END, 0u);
        } else {
            fw_fault_now(fw, FW_FAULT_COMMISSION);
        }
        return false;
    }
    if (out.mode == CM_OUT_OFF) {
        fw->cm_gates = 0u;
        fw_pwm_off(fw, tm);
        return false;
    }
    if (fw->cm_gates == 0u) {
        /* Effective at k+1, together with the compare values written now. */
        fw->applied.duty[0] = fw->applied.duty[1] = fw->applied.duty[2] = 0;
        hal_gate_enable(hal, true);
        fw->cm_gates = 1u;
    }
    if (out.mode == CM_OUT_CTRL) {
        if (out.ctrl_reset != 0u) {
            fw->ctrl->reset(fw->ctrl_state.bytes);
            ctrl_estimator_reset(&fw->est, &fw->params);
            fw_mid_restart(fw);
            fw->trim = 0;
            fw->applied.duty[0] = fw->applied.duty[1] = fw->applied.duty[2] = 0;
        }
        /* the step's torque, not the main loop's reference (which only the
         * main loop writes) */
        return fw_control(fw, tm, m, FW_REF_TORQUE,
                          fx_clamp(out.torque_ref, fw->torque_ref_min, fw->torque_ref_max));
    }
    /* What the step does, in the running drive's signals (telemetry, status) */
    cm_monitor(&fw->cm, m->theta_e, &tm->i_d, &tm->i_q, &tm->omega_e, &tm->torque);
    ctrl_legs_t legs = {{out.legs[0], out.legs[1], out.legs[2]}};
    /* uncompensated: the steps measure the inverter's error themselves */
    fw_pwm_out(fw, hal, tm, &legs, NULL);
    fw->applied = legs; /* acting in [k+1, k+2) */
    return false;
}

/* Every other state (boot, calibration, ready, fault): gates off. */
static void fw_period_idle(fw_t *fw, fw_telemetry_t *tm, const hal_adc_raw_t *raw,
                           const hal_encoder_raw_t *enc)
{
    fw_tm_no_estimate(tm);
    if (fw->sm.state == FW_STATE_BOOT) {
        (void)fw_state_event(&fw->sm, FW_EV_START, 0u);
    }
    if (fw->sm.state == FW_STATE_CALIB) {
        fw_pwm_off(fw, tm);
        fw_calibrate(fw, raw);
        return;
    }
    ctrl_meas_t *const m = &tm->meas;
    m->i_a = fw_current_pu(raw->i_a, fw->off_q8[0], fw->gain_q30[0]);
    m->i_b = fw_current_pu(raw->i_b, fw->off_q8[1], fw->gain_q30[1]);
    if (fw->sm.state != FW_STATE_FAULT) {
        (void)fw_protect_fast(fw, fw->hal, m->i_a, m->i_b);
    }
    fw_measure_rest(fw, raw, enc, m);
    if (fw->sm.state != FW_STATE_FAULT) {
        /* Sensorless: the encoder unchecked, as while running (fw_period_running),
         * whose periods leave its history behind: the first count after a stop
         * read as a jump (fault 6 encoder_jump at every stop of a turning rotor). */
        const uint32_t f = fw->cfg.sensorless ? fw_protect_vdc(&fw->prot, m->vdc)
                                              : fw_protect_slow(fw, m->vdc, enc->count);
        if (f != FW_FAULT_NONE) {
            fw_fault_now(fw, f);
        }
    }
    fw_pwm_off(fw, tm);
}

bool fw_isr_fast(fw_t *fw)
{
    if (fw == NULL || fw->hal == NULL || fw->ctrl == NULL) {
        return false;
    }
    /* The handle is fixed from fw_init on: kept in a register. */
    hal_t *const hal = fw->hal;
    const uint32_t t0 = hal_cycles(hal);
    if (fw->busy || fw->mid_done != fw->mid_req) {
        /* Entered while the previous period's ISR, or the medium task it
         * started, was still running. */
        fw_fault_now(fw, FW_FAULT_DEADLINE);
        return false;
    }
    fw->busy = true;
    fw->period++;
    /* This period's record: the ring slot after the published ones. */
    fw_telemetry_t *const tm = fw->tm_slot;

    hal_adc_raw_t raw;
    hal_encoder_raw_t enc;
    hal_adc_read(hal, &raw);
    hal_encoder_read(hal, &enc);

    const uint32_t req_sum = fw->ml.req_sum;
    if (req_sum != fw->isr.taken_sum) {
        fw_apply_commands(fw, tm, req_sum);
    }
    /* Running: one predictable branch to the straight path; boot,
     * calibration, ready and fault take the general one. */
    bool mid = false;
    if (fw->sm.state == FW_STATE_RUNNING) {
        mid = fw_period_running(fw, hal, tm, &raw, &enc);
    } else if (fw->sm.state == FW_STATE_COMMISSION) {
        mid = fw_period_commission(fw, hal, tm, &raw, &enc);
    } else {
        fw_period_idle(fw, tm, &raw, &enc);
    }

    const uint32_t wf = fw_protect_watchdog_tick(&fw->prot, fw->period - fw->ml.wdg_stamp);
    if (wf != FW_FAULT_NONE && fw->sm.state != FW_STATE_FAULT) {
        fw_fault_now(fw, wf);
    }

    tm->period = fw->period;
    tm->state = (uint8_t)fw->sm.state;
    tm->fault = (uint8_t)fw->sm.fault_code;
    tm->gates = fw->sm.state == FW_STATE_RUNNING || fw->cm_gates != 0u ? 1u : 0u;
    tm->cm_step = fw->cm.step;
    tm->cm_progress = fw->cm.progress;

    /* Deadline: duration of this ISR against the period's cycle budget. */
    const uint32_t elapsed = hal_cycles(hal) - t0;
    tm->cycles = elapsed;
    const uint32_t df = fw_protect_deadline(&fw->prot, elapsed);
    if (df != FW_FAULT_NONE && fw->sm.state != FW_STATE_FAULT) {
        fw_fault_now(fw, df);
        tm->state = (uint8_t)fw->sm.state;
        tm->fault = (uint8_t)fw->sm.fault_code;
        tm->gates = 0u;
    }
    /* Publish the record once in tm_every periods, unless the main loop is
     * a full ring behind (then it is dropped, counted). */
    fw->tm_last = tm;
    const uint32_t every = fw->tm_every;
    if (every != 0u && --fw->tm_count == 0u) {
        fw->tm_count = every;
        const uint32_t head = fw->isr.tm_head;
        if (head - fw->ml.tm_tail < FW_TM_RING - 1u) {
            fw->tm_slot = &fw->tm_ring[(head + 1u) & (FW_TM_RING - 1u)];
            FW_RELEASE(); /* the record before its publication */
            fw->isr.tm_head = head + 1u;
        } else {
            fw->isr.tm_dropped++;
        }
    }
    fw->busy = false;
    return mid;
}

void fw_isr(fw_t *fw)
{
    if (fw_isr_fast(fw)) {
        fw_medium(fw);
    }
}

void fw_request(fw_t *fw, fw_req_t k)
{
    FW_RELEASE();
    fw->ml.req[k] = fw->ml.req[k] + 1u;
    FW_RELEASE();
    fw->ml.req_sum = fw->ml.req_sum + 1u;
}

void fw_cmd_arm(fw_t *fw)
{
    if (fw != NULL) {
        fw_request(fw, FW_REQ_ARM);
    }
}

void fw_cmd_disarm(fw_t *fw)
{
    if (fw != NULL) {
        fw_request(fw, FW_REQ_DISARM);
    }
}

void fw_cmd_clear(fw_t *fw)
{
    if (fw != NULL) {
        fw_request(fw, FW_REQ_CLEAR);
    }
}

static inline bool fw_pending(const fw_t *fw, fw_req_t k)
{
    return fw->ml.req[k] != fw->isr.taken[k];
}

bool fw_cmd_pending(const fw_t *fw, fw_req_t k)
{
    return fw != NULL && (unsigned)k < FW_REQ_N && fw_pending(fw, k);
}

#if PMSM_LIVE_PARAMS
void fw_request_withdraw(fw_t *fw, fw_req_t k)
{
    const unsigned i = k == FW_REQ_CTRL_TUNE ? 1u : 0u;
    fw->ml.withdrawn[i] = fw->ml.req[k];
    FW_RELEASE(); /* withdrawn before its data is rewritten */
}

bool fw_tune_pending(const fw_t *fw, fw_req_t k)
{
    const unsigned i = k == FW_REQ_CTRL_TUNE ? 1u : 0u;
    return fw_pending(fw, k) && fw->ml.withdrawn[i] != fw->ml.req[k];
}
#endif

void fw_watchdog_kick(fw_t *fw)
{
    if (fw != NULL) {
        fw->ml.wdg_stamp = fw_period_count(fw);
    }
}

void fw_set_torque_ref(fw_t *fw, q24_t torque_pu)
{
    if (fw != NULL) {
        fw->ml.torque_ref = torque_pu;
        fw->ml.torque_ref_lim = fx_clamp(torque_pu, fw->torque_ref_min, fw->torque_ref_max);
        FW_RELEASE(); /* the reference before the mode */
        fw->ml.ref_mode = FW_REF_TORQUE;
    }
}

void fw_set_speed_ref(fw_t *fw, q24_t omega_e_pu)
{
    if (fw != NULL) {
        /* Bumpless: until the medium task's next run the speed loop's output
         * is the present torque reference, from which that run starts it. */
        fw->ml.speed_ref = omega_e_pu;
        FW_RELEASE(); /* the reference before the mode */
        fw->ml.ref_mode = FW_REF_SPEED;
    }
}

fw_ref_mode_t fw_ref_mode(const fw_t *fw)
{
    return fw != NULL && fw->ml.ref_mode == FW_REF_SPEED ? FW_REF_SPEED : FW_REF_TORQUE;
}

q24_t fw_torque_ref(const fw_t *fw)
{
    return fw != NULL ? fw->ml.torque_ref : 0;
}

q24_t fw_speed_ref(const fw_t *fw)
{
    return fw != NULL ? fw->ml.speed_ref : 0;
}

q24_t fw_speed_loop_torque(const fw_t *fw)
{
    const volatile fw_mid_out_t *mo = &fw->mid_out[fw->mid_done & 1u];
    return mo->speed_tref;
}

uint32_t fw_period_count(const fw_t *fw)
{
    return *(const volatile uint32_t *)&fw->period;
}

fw_state_id_t fw_state(const fw_t *fw)
{
    return fw != NULL ? *(const volatile fw_state_id_t *)&fw->sm.state : FW_STATE_FAULT;
}

const char *fw_gates_request_pending(const fw_t *fw, fw_state_id_t *state)
{
    const char *req = fw_pending(fw, FW_REQ_ARM)  ? "arm"
                      : fw_pending(fw, FW_REQ_CM) ? "commissioning start"
                                                  : NULL;
    /* the state after the requests (acquire): an interrupt that takes one in
     * between has set the state by then */
    atomic_signal_fence(memory_order_acquire);
    *state = *(const volatile fw_state_id_t *)&fw->sm.state;
    return req;
}

bool fw_gates_on_or_pending(const fw_t *fw)
{
    fw_state_id_t s;
    return fw_gates_request_pending(fw, &s) != NULL || s == FW_STATE_RUNNING ||
           s == FW_STATE_COMMISSION;
}

uint32_t fw_fault(const fw_t *fw)
{
    return fw != NULL ? *(const volatile uint32_t *)&fw->sm.fault_code : FW_FAULT_NONE;
}

const fw_telemetry_t *fw_telemetry(const fw_t *fw)
{
    return fw != NULL ? fw->tm_last : NULL;
}

void fw_tm_stream(fw_t *fw, uint32_t every)
{
    if (fw == NULL) {
        return;
    }
    fw->ml.tm_every = every;
    fw_request(fw, FW_REQ_TM);
}

/* The oldest record of the present stream not yet taken (main loop): none
 * while a stream request waits; records of an earlier stream skipped. */
const fw_telemetry_t *fw_tm_peek(fw_t *fw)
{
    if (fw == NULL || fw_pending(fw, FW_REQ_TM)) {
        return NULL;
    }
    const uint32_t drop = fw->isr.tm_drop;
    uint32_t tail = fw->ml.tm_tail;
    if (drop - tail - 1u < 0x7FFFFFFFu) { /* drop ahead of tail (modulo 2^32) */
        tail = drop;
        fw->ml.tm_tail = tail;
    }
    if (tail == fw->isr.tm_head) {
        return NULL;
    }
    atomic_signal_fence(memory_order_acquire); /* the record after its publication */
    return &fw->tm_ring[tail & (FW_TM_RING - 1u)];
}

void fw_tm_release(fw_t *fw)
{
    if (fw != NULL && fw->ml.tm_tail != fw->isr.tm_head) {
        FW_RELEASE(); /* the record read before its slot is handed back */
        fw->ml.tm_tail = fw->ml.tm_tail + 1u;
    }
}

uint32_t fw_tm_dropped(const fw_t *fw)
{
    return fw != NULL ? fw->isr.tm_dropped : 0u;
}

void *fw_ctrl_state(fw_t *fw)
{
    return fw != NULL ? fw->ctrl_state.bytes : NULL;
}
