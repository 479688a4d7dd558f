/*
 * Commissioning: sequencer and the per-period machinery the steps share
 * (see cm.h, cm_internal.h). Integer-only.
 */
#include <stddef.h>
#include <string.h>

#include "cm_internal.h"
#include "svpwm.h"
#include "transforms.h"

/* ---- step table ---- */

static const cm_step_desc_t cm_steps[CM_STEP_COUNT] = {
    {"none", 0u, 0u, NULL, NULL},
    {"vbus", CM_HAVE_VBUS, 0u, cm_vbus_begin, cm_vbus_period},
    {"probe", CM_HAVE_LPROBE, 0u, cm_probe_begin, cm_probe_period},
    {"encoder", CM_HAVE_ENC, CM_HAVE_LPROBE, cm_encoder_begin, cm_encoder_period},
    {"rs", CM_HAVE_RS | CM_HAVE_BALANCE, CM_HAVE_ENC, cm_rs_begin, cm_rs_period},
    {"ldq", CM_HAVE_LDQ, CM_HAVE_ENC, cm_ldq_begin, cm_ldq_period},
    {"flux", CM_HAVE_FLUX | (CM_MECH ? CM_HAVE_MECH : 0u), CM_HAVE_ENC | CM_HAVE_LDQ, cm_flux_begin,
     cm_flux_period},
    {"gates", 0u, 0u, cm_gates_begin, cm_gates_period},
    {"sense", 0u, 0u, cm_sense_begin, cm_sense_period},
    {"run", 0u, 0u, cm_run_begin, cm_run_period},
#if CTRL_COGGING
    {"cogging", 0u, 0u, cm_cogging_begin, cm_cogging_period},
#endif
};

const cm_step_desc_t *cm_step_desc(uint8_t step)
{
    return (step > CM_STEP_NONE && step < CM_STEP_COUNT) ? &cm_steps[step] : NULL;
}

const char *cm_step_name(uint8_t step)
{
    return step < CM_STEP_COUNT ? cm_steps[step].name : "?";
}

uint8_t cm_step_find(const char *name)
{
    if (name == NULL) {
        return CM_STEP_NONE;
    }
    for (uint8_t s = 1u; s < CM_STEP_COUNT; s++) {
        if (strcmp(cm_steps[s].name, name) == 0) {
            return s;
        }
    }
    return CM_STEP_NONE;
}

uint32_t cm_step_gives(uint8_t step)
{
    return step < CM_STEP_COUNT ? cm_steps[step].gives : 0u;
}

uint32_t cm_step_needs(uint8_t step)
{
    return step < CM_STEP_COUNT ? cm_steps[step].needs : 0u;
}

static const char *const cm_err_names[CM_E_COUNT] = {
    "none",           "stopped",       "fault",       "vbus_low",      "vbus_high",
    "offset",         "noise",         "open_phase",  "shorted_phase", "unbalanced",
    "voltage_limit",  "current_limit", "rs_range",    "l_range",       "enc_no_motion",
    "enc_cpr",        "enc_unsteady",  "speed_low",   "overspeed",     "flux_range",
    "sense_polarity", "sense_gain",    "sense_sum",   "gates_current", "gates_vbus",
    "run_direction",  "run_no_accel",  "run_current", "needs",         "supply",
    "load",
#if CTRL_COGGING
    "cog_follow",     "cog_range",     "cog_config",
#endif
};

const char *cm_err_name(uint8_t err)
{
    return err < CM_E_COUNT ? cm_err_names[err] : "?";
}

/* ---- sequence ---- */

int cm_prepare(cm_t *cm, const uint8_t *steps, uint8_t n, uint8_t *missing)
{
    if (cm == NULL || steps == NULL || n == 0u || n > CM_STEP_COUNT) {
        return CM_E_NEEDS;
    }
    uint32_t have = cm->res.have;
    for (uint8_t i = 0; i < n; i++) {
        const cm_step_desc_t *d = cm_step_desc(steps[i]);
        if (d == NULL) {
            return CM_E_NEEDS;
        }
        const uint32_t lack = d->needs & ~have;
        if (lack != 0u) {
            if (missing != NULL) {
                /* The first step that gives a missing result. */
                *missing = CM_STEP_NONE;
                for (uint8_t s = 1u; s < CM_STEP_COUNT; s++) {
                    if ((cm_steps[s].gives & lack) != 0u) {
                        *missing = s;
                        break;
                    }
                }
            }
            return CM_E_NEEDS;
        }
        have |= d->gives;
        cm->plan[i] = steps[i];
    }
    cm->plan_n = n;
    cm->plan_i = 0u;
    return CM_E_NONE;
}

void cm_scratch_clear(cm_t *cm)
{
    memset(&cm->x, 0, sizeof cm->x);
    cm->io.pos = 0;
}

static void cm_step_start(cm_t *cm)
{
    cm->io.avg2 = 0u;
    cm->step = cm->plan[cm->plan_i];
    cm->last_step = cm->step;
    cm->phase = 0u;
    cm->t = 0u;
    cm->t_fresh = 1u;
    cm->t_step = 0u;
    cm->progress = 0u;
    cm_scratch_clear(cm);
    const cm_step_desc_t *d = cm_step_desc(cm->step);
    if (d != NULL && d->begin != NULL) {
        d->begin(cm);
    }
}

void cm_begin(cm_t *cm)
{
    cm->active = 1u;
    cm->done = 0u;
    cm->err = CM_E_NONE;
    cm->apply = 0u;
    cm->detail[0] = cm->detail[1] = cm->detail[2] = 0;
    cm->t_total = 0u;
    cm->i_peak = 0;
    memset(&cm->io, 0, sizeof cm->io);
    cm_pi_reset(&cm->pi_d, 0);
    cm_pi_reset(&cm->pi_q, 0);
    cm_step_start(cm);
    /* Called before the first period: that period is the step's t = 0. */
    cm->t_fresh = 0u;
}

static void cm_end(cm_t *cm, uint8_t err)
{
    if (err != CM_E_NONE) {
        /* A step that did not finish leaves none of its results valid. */
        cm->res.have &= ~cm_step_gives(cm->step);
    }
    cm->active = 0u;
    cm->done = 1u;
    cm->err = err;
    cm->step = CM_STEP_NONE;
    cm->hold_valid = 0u; /* the gates go off: the rotor is free */
}

int cm_fail(cm_t *cm, uint8_t err, int32_t d0, int32_t d1, int32_t d2)
{
    cm->err = err;
    cm->detail[0] = d0;
    cm->detail[1] = d1;
    cm->detail[2] = d2;
    return CM_FAIL;
}

void cm_next(cm_t *cm)
{
    cm->phase++;
    cm->t = 0u;
    cm->t_fresh = 1u;
}

void cm_out_off(cm_t *cm, cm_out_t *out)
{
    out->mode = CM_OUT_OFF;
    out->ctrl_reset = 0u;
    out->legs[0] = out->legs[1] = out->legs[2] = 0;
    out->torque_ref = 0;
    cm->io.va_valid[2] = 0u;
    cm->io.va_al[2] = cm->io.va_be[2] = 0;
    cm->mon_id = cm->mon_iq = 0;
}

void cm_abort_fault(cm_t *cm, uint32_t fault_code)
{
    if (cm == NULL || !cm->active) {
        return;
    }
    /* The probe drives the first currents into an unknown load: a current
     * that trips the over-current protection there rose faster than any
     * winding the probe's first, smallest pulses could explain. */
    const bool oc = fault_code == 1u || fault_code == 2u; /* overcurrent, hw trip */
    if (cm->step == CM_STEP_PROBE && oc) {
        (void)cm_fail(cm, CM_E_SHORTED_PHASE, cm->i_peak, 0, (int32_t)fault_code);
    } else {
        (void)cm_fail(cm, CM_E_FAULT, (int32_t)fault_code, 0, 0);
    }
    cm_end(cm, cm->err);
}

void cm_abort_stop(cm_t *cm)
{
    if (cm == NULL || !cm->active) {
        return;
    }
    (void)cm_fail(cm, CM_E_STOPPED, 0, 0, 0);
    cm_end(cm, CM_E_STOPPED);
}

/* ---- measurements ---- */

static void cm_io_update(cm_t *cm, const cm_in_t *in)
{
    cm_io_t *io = &cm->io;
    io->i_al_prev = io->i_al;
    io->i_be_prev = io->i_be;
    ctrl_clarke(in->i_a, in->i_b, &io->i_al, &io->i_be);
    io->vdc = in->vdc;
    if (!io->primed) {
        io->th = in->theta;
        io->i_al_prev = io->i_al;
        io->i_be_prev = io->i_be;
        io->primed = 1u;
    }
    io->th_prev = io->th;
    io->th = in->theta;
    io->dth = fx_u2i(io->th - io->th_prev);
    io->dth_sum += (int64_t)io->dth - io->dth_ring[io->ring_i];
    io->dth_ring[io->ring_i] = io->dth;
    io->ring_i = (io->ring_i + 1u) % CM_SPEED_AVG;
    io->pos += io->dth;
    /* A period has passed: k-1's command has acted, the last one acts now. */
    io->va_al[1] = io->va_al[0];
    io->va_be[1] = io->va_be[0];
    io->va_valid[1] = io->va_valid[0];
    io->va_al[0] = io->va_al[2];
    io->va_be[0] = io->va_be[2];
    io->va_valid[0] = io->va_valid[2];
    io->va_valid[2] = 0u;
}

static q24_t cm_absmax3(q24_t a, q24_t b, q24_t c)
{
    return fx_max(fx_abs(a), fx_max(fx_abs(b), fx_abs(c)));
}

bool cm_period(cm_t *cm, const cm_in_t *in, cm_out_t *out)
{
    if (cm == NULL || in == NULL || out == NULL) {
        return false;
    }
    if (!cm->active) {
        cm_out_off(cm, out);
        return false;
    }
    cm_io_update(cm, in);
    const q24_t i_c = cm->par.has_i_c ? in->i_c : fx_neg(fx_add(in->i_a, in->i_b));
    const q24_t ipk = cm_absmax3(in->i_a, in->i_b, i_c);
    cm->i_peak = fx_max(cm->i_peak, ipk);
    int rc;
    if (ipk > cm->par.i_guard) {
        rc = cm_fail(cm, CM_E_CURRENT_LIMIT, ipk, cm->par.i_guard, 0);
    } else if (fx_abs(cm_speed(cm)) > cm->par.w_guard && cm->step != CM_STEP_RUN) {
        rc = cm_fail(cm, CM_E_OVERSPEED, cm_speed(cm), cm->par.w_guard, 0);
    } else {
        const cm_step_desc_t *d = cm_step_desc(cm->step);
        rc = d != NULL ? d->period(cm, in, out) : cm_fail(cm, CM_E_NEEDS, 0, 0, 0);
    }
    /* A phase (or step) that began in this period starts counting at 0 in
     * its first period of its own. */
    if (cm->t_fresh != 0u) {
        cm->t_fresh = 0u;
    } else {
        cm->t++;
    }
    cm->t_step++;
    if (rc == CM_FAIL) {
        cm_out_off(cm, out);
        cm_end(cm, cm->err);
        return false;
    }
    if (out->mode != CM_OUT_OFF) {
        cm->t_total++;
    }
    if (rc == CM_DONE) {
        cm->res.have |= cm_step_gives(cm->step);
        cm->progress = 1000u;
        cm->plan_i++;
        if (cm->plan_i < cm->plan_n) {
            /* Keep this period's output: the next step continues from it. */
            cm_step_start(cm);
        } else {
            cm_out_off(cm, out);
            cm_end(cm, CM_E_NONE);
            /* A sequence that identified machine data: the main loop adopts it
             * (fw_commission_poll). */
            const uint32_t data = CM_HAVE_ENC | CM_HAVE_RS | CM_HAVE_LDQ | CM_HAVE_FLUX;
            for (uint8_t k = 0; k < cm->plan_n; k++) {
                if ((cm_step_gives(cm->plan[k]) & data) != 0u) {
                    cm->apply = 1u;
                }
            }
            return false;
        }
    }
    return true;
}

/* ---- arithmetic helpers ---- */

q24_t cm_mean(int64_t sum, uint32_t n)
{
    if (n == 0u) {
        return 0;
    }
    /* Round half away from zero without dividing a negative number's bias
     * into the wrong direction. */
    const int64_t h = (int64_t)(n / 2u);
    const int64_t q = sum >= 0 ? (sum + h) / (int64_t)n : -((-sum + h) / (int64_t)n);
    return fx_sat32(q);
}

bool cm_ratio(int64_t num, int64_t den, q24_t *out)
{
    if (den == 0) {
        return false;
    }
    /* |num| < 2^38 keeps num * 2^24 inside int64_t. */
    const int64_t lim = (int64_t)1 << 38;
    if (num >= lim || num <= -lim) {
        return false;
    }
    const int64_t n24 = num * (int64_t)FX_ONE;
    const int64_t h = den > 0 ? den / 2 : -den / 2;
    const int64_t an = n24 >= 0 ? n24 : -n24;
    const int64_t ad = den > 0 ? den : -den;
    const int64_t q = (an + h) / ad;
    if (q > (int64_t)INT32_MAX) {
        return false;
    }
    *out = ((n24 >= 0) == (den > 0)) ? (q24_t)q : -(q24_t)q;
    return true;
}

bool cm_muldiv(int64_t num, q24_t mul, int64_t den, q24_t *out)
{
    /* |num mul| must stay below 2^63 (checked, not assumed). */
    const int64_t am = mul >= 0 ? (int64_t)mul : -(int64_t)mul;
    const int64_t an = num >= 0 ? num : -num;
    if (den == 0 || (am != 0 && an > INT64_MAX / am)) {
        return false;
    }
    const int64_t p = an * am; /* |num mul| */
    const int64_t ad = den > 0 ? den : -den;
    const int64_t q = (p + ad / 2) / ad;
    if (q > (int64_t)INT32_MAX) {
        return false;
    }
    const bool neg = (num < 0) != (mul < 0) ? den > 0 : den < 0;
    *out = neg ? -(q24_t)q : (q24_t)q;
    return true;
}

q24_t cm_ramp(q24_t x, uint32_t t, uint32_t n)
{
    if (n == 0u || t >= n) {
        return x;
    }
    return (q24_t)(((int64_t)x * (int64_t)t) / (int64_t)n);
}

/* ---- frames ---- */

void cm_to_frame(q24_t al, q24_t be, fx_angle_t ang, q24_t *d, q24_t *q)
{
    q24_t s, c;
    fx_sincos(ang, &s, &c);
    ctrl_park(al, be, s, c, d, q);
}

void cm_from_frame(q24_t d, q24_t q, fx_angle_t ang, q24_t *al, q24_t *be)
{
    q24_t s, c;
    fx_sincos(ang, &s, &c);
    ctrl_inv_park(d, q, s, c, al, be);
}

/* ---- current regulator ---- */

void cm_pi_tune(cm_pi_t *c, q24_t l_pu, q24_t ts, q24_t g, q24_t lim)
{
    /* kp = L g / Ts: the loop's crossover is g / Ts (rad/s pu) whatever R is;
     * ki per period = kp g / 4 puts the PI zero at a quarter of it. */
    q24_t kp = 0;
    if (!cm_muldiv(l_pu, g, ts, &kp)) {
        kp = 127 * FX_ONE; /* beyond any machine the core accepts */
    }
    c->kp = kp;
    c->ki = fx_mul(kp, g) / 4;
    c->lim = lim;
    c->integ = fx_clamp(c->integ, fx_neg(lim), lim);
}

void cm_pi_reset(cm_pi_t *c, q24_t integ)
{
    c->integ = integ;
    c->sat = 0u;
}

q24_t cm_pi_step(cm_pi_t *c, q24_t err)
{
    const q24_t p = fx_mul(c->kp, err);
    q24_t in = fx_clamp(fx_add(c->integ, fx_mul(c->ki, err)), fx_neg(c->lim), c->lim);
    q24_t u = fx_add(p, in);
    c->sat = 0u;
    if (u > c->lim || u < fx_neg(c->lim)) {
        c->sat = 1u;
        /* Conditional integration: hold the integrator while it would push
         * further into the limit. */
        if ((u > c->lim && err > 0) || (u < fx_neg(c->lim) && err < 0)) {
            in = c->integ;
        }
        u = fx_clamp(u, fx_neg(c->lim), c->lim);
    }
    c->integ = in;
    return u;
}

q24_t cm_rs_best(const cm_t *cm)
{
    return (cm->res.have & CM_HAVE_RS) != 0u ? cm->res.rs : cm->par.rs_cfg;
}

q24_t cm_i_within(const cm_t *cm, q24_t v, q24_t e, q24_t r)
{
    const q24_t v_inv = (cm->res.have & CM_HAVE_RS) != 0u ? fx_abs(cm->res.v_inv) : 0;
    const q24_t num = fx_sub(fx_sub(fx_mul(CM_V_USE_Q24, v), v_inv), e);
    q24_t i = 0;
    if (num <= 0 || r <= 0 || !cm_ratio(num, r, &i)) {
        return num > 0 && r > 0 ? FX_MAX : 0;
    }
    return i;
}

int cm_fail_supply(cm_t *cm, q24_t r, q24_t v_lim)
{
    const q24_t v_inv = (cm->res.have & CM_HAVE_RS) != 0u ? fx_abs(cm->res.v_inv) : 0;
    const q24_t need = fx_add(fx_mul(cm->par.i_min, r), v_inv);
    return cm_fail(cm, CM_E_SUPPLY, cm->par.i_min, need, v_lim);
}

void cm_fit_currents(cm_par_t *q, q24_t cap_st, q24_t cap_scan, q24_t cap_run)
{
    q->i_hold = fx_min(q->i_hold_nom, cap_st);
    q->i_hold_max = fx_max(q->i_hold, fx_min(q->i_hold_max_nom, cap_scan));
    q->i_acc = fx_min(q->i_acc_nom, cap_run);
    q->i_fd = fx_min(q->i_fd_nom, cap_run);
    q->i_spin = fx_min(q->i_spin_nom, cap_scan); /* break-away at rest: no back-EMF */
}

void cm_refit_currents(cm_t *cm)
{
    const cm_par_t *p = &cm->par;
    const q24_t r = cm_rs_best(cm);
    /* spinning at 3/5 of w_flux: back-EMF w psi (configured), w L in series
     * (the flux step lowers its higher speed where the voltage reaches 80 %
     * of its limit; a machine with room goes up to w_flux) */
    const q24_t wc = p->w_flux / 5 * 3;
    const q24_t e = fx_mul(wc, p->psi_cfg);
    const q24_t r_run = fx_add(r, fx_mul(wc, fx_max(p->l_cfg_d, p->l_cfg_q)));
    cm_fit_currents(&cm->par, cm_i_within(cm, p->v_lim, 0, r), cm_i_within(cm, p->v_lim_run, 0, r),
                    cm_i_within(cm, p->v_lim_run, e, r_run));
}

q24_t cm_l_best(const cm_t *cm)
{
    if ((cm->res.have & CM_HAVE_LDQ) != 0u) {
        return (q24_t)(((int64_t)cm->res.ld + cm->res.lq) / 2);
    }
    if ((cm->res.have & CM_HAVE_LPROBE) != 0u) {
        return cm->res.l_probe;
    }
    return (q24_t)(((int64_t)cm->par.l_cfg_d + cm->par.l_cfg_q) / 2);
}

void cm_pi_tune_dq(cm_t *cm, q24_t ld, q24_t lq, q24_t lim)
{
    cm_pi_tune(&cm->pi_d, ld, cm->par.ts, cm->par.loop_g, lim);
    cm_pi_tune(&cm->pi_q, lq, cm->par.ts, cm->par.loop_g, lim);
}

/* ---- modulation and the applied-voltage record ---- */

void cm_modulate(cm_t *cm, q24_t v_al, q24_t v_be, cm_out_t *out)
{
    cm_io_t *io = &cm->io;
    /* Min-max zero sequence (the control core's space-vector modulation):
     * the steps keep within its linear range, |v| <= vdc / sqrt(3). */
    ctrl_legs_t legs;
    ctrl_svpwm_duties(v_al, v_be, io->vdc > (FX_ONE >> 4) ? io->vdc : (FX_ONE >> 4), &legs);
    cm_legs(cm, legs.duty[0], legs.duty[1], legs.duty[2], out);
    /* Leg voltages the duties on the compare grid make at this DC link. */
    q24_t vl[3];
    for (int x = 0; x < 3; x++) {
        vl[x] = fx_mul(out->legs[x], io->vdc);
    }
    const q24_t m = (q24_t)(((int64_t)vl[0] + vl[1] + vl[2]) / 3);
    ctrl_clarke(fx_sub(vl[0], m), fx_sub(vl[1], m), &io->va_al[2], &io->va_be[2]);
    io->va_valid[2] = 1u;
}

static q24_t cm_grid(const cm_t *cm, q24_t d)
{
    const q24_t c = fx_clamp(d, 0, FX_ONE);
    const uint32_t cmp = (uint32_t)(((uint64_t)(uint32_t)c * cm->par.pwm_n + (1u << 23)) >> 24);
    const uint64_t g = ((uint64_t)cmp * cm->par.inv_n_q32 + 128u) >> 8;
    return g > (uint64_t)FX_ONE ? FX_ONE : (q24_t)g;
}

void cm_legs(cm_t *cm, q24_t d0, q24_t d1, q24_t d2, cm_out_t *out)
{
    out->mode = CM_OUT_LEGS;
    out->ctrl_reset = 0u;
    out->torque_ref = 0;
    out->legs[0] = cm_grid(cm, d0);
    out->legs[1] = cm_grid(cm, d1);
    out->legs[2] = cm_grid(cm, d2);
    cm->io.va_valid[2] = 0u;
}

bool cm_acted(const cm_t *cm, fx_angle_t ang, q24_t *vd, q24_t *vq)
{
    if (!cm->io.va_valid[1]) {
        *vd = *vq = 0;
        return false;
    }
    cm_to_frame(cm->io.va_al[1], cm->io.va_be[1], ang, vd, vq);
    return true;
}

void cm_regulate(cm_t *cm, fx_angle_t ang, fx_angle_t ang_cmd, q24_t d_ref, q24_t q_ref,
                 q24_t extra_d, q24_t extra_q, cm_out_t *out)
{
    q24_t id, iq;
    q24_t al = cm->io.i_al, be = cm->io.i_be;
    if (cm->io.avg2) {
        al = (q24_t)(((int64_t)al + cm->io.i_al_prev) / 2);
        be = (q24_t)(((int64_t)be + cm->io.i_be_prev) / 2);
    }
    cm_to_frame(al, be, ang, &id, &iq);
    cm->mon_id = id;
    cm->mon_iq = iq;
    const q24_t vd = fx_add(cm_pi_step(&cm->pi_d, fx_sub(d_ref, id)), extra_d);
    const q24_t vq = fx_add(cm_pi_step(&cm->pi_q, fx_sub(q_ref, iq)), extra_q);
    cm_from_frame(vd, vq, ang_cmd, &al, &be);
    cm_modulate(cm, al, be, out);
}

/* ---- speed and damping ---- */

q24_t cm_speed_of(const cm_t *cm, int64_t dth_sum, uint32_t n)
{
    if (n == 0u) {
        return 0;
    }
    /* omega_pu = dtheta * dangle_to_omega / 2^28 per period (ctrl_params.h). */
    const int64_t per = dth_sum / (int64_t)n;
    return fx_round_sat(per * cm->par.dangle_to_omega, CTRL_DANGLE_SHIFT);
}

q24_t cm_speed(const cm_t *cm)
{
    return fx_round_sat((cm->io.dth_sum / (int64_t)CM_SPEED_AVG) * cm->par.dangle_to_omega,
                        CTRL_DANGLE_SHIFT);
}

fx_angle_t cm_rotor_angle(const cm_t *cm)
{
    const fx_angle_t th = cm->res.enc_dir < 0 ? (fx_angle_t)(0u - cm->io.th) : cm->io.th;
    return cm->res.enc_off + th;
}

void cm_monitor(const cm_t *cm, fx_angle_t theta_drive, q24_t *id, q24_t *iq, q24_t *w,
                q24_t *torque)
{
    const cm_results_t *r = &cm->res;
    *id = cm->mon_id;
    *iq = cm->mon_iq;
    *w = cm_speed(cm);
    /* the encoder step sets the direction before it has the offset */
    const bool enc = (r->have & CM_HAVE_ENC) != 0u && cm->step != CM_STEP_ENCODER;
    q24_t d, q;
    cm_to_frame(cm->io.i_al, cm->io.i_be, enc ? cm_rotor_angle(cm) : theta_drive, &d, &q);
    const bool ldq = (r->have & CM_HAVE_LDQ) != 0u;
    const q24_t psi = (r->have & CM_HAVE_FLUX) != 0u ? r->psi : cm->par.psi_cfg;
    const q24_t dl = ldq ? fx_sub(r->ld, r->lq) : fx_sub(cm->par.l_cfg_d, cm->par.l_cfg_q);
    /* (3.10) Te = i_q (psi_pm + (Ld - Lq) i_d), pu */
    *torque = fx_mul(fx_add(psi, fx_mul(dl, d)), q);
}

/* Slip: the rotor's angle increments (identified direction) against the
 * frame's, over the speed window, as pu speed. */
static q24_t cm_slip_signed(const cm_t *cm)
{
    const int64_t rot = cm->res.enc_dir < 0 ? -cm->io.dth_sum : cm->io.dth_sum;
    const int64_t slip = rot - cm->io.fr_sum;
    return fx_round_sat((slip / (int64_t)CM_SPEED_AVG) * cm->par.dangle_to_omega,
                        CTRL_DANGLE_SHIFT);
}

q24_t cm_slip(const cm_t *cm)
{
    return fx_abs(cm_slip_signed(cm));
}

void cm_hold(cm_t *cm, fx_angle_t ang, int32_t inc, q24_t i_mag, q24_t extra_d, q24_t extra_q,
             cm_out_t *out)
{
    cm_io_t *io = &cm->io;
    /* The frame's increment joins the window at the slot the encoder's took. */
    const uint32_t slot = (io->ring_i + CM_SPEED_AVG - 1u) % CM_SPEED_AVG;
    io->fr_sum += (int64_t)inc - io->fr_ring[slot];
    io->fr_ring[slot] = inc;
    q24_t iq = 0;
    if ((cm->res.have & CM_HAVE_ENC) != 0u) {
        /* i_q = -i_mag slip / Omega: damping ratio omega_n / (2 Omega) for the
         * rotor swinging at omega_n around the field. */
        const q24_t k = fx_mul_qn(cm_slip_signed(cm), cm->par.damp_k, 16u);
        iq = fx_clamp(fx_neg(fx_mul(i_mag, k)), fx_neg(i_mag), i_mag);
    }
    cm->hold_i = i_mag;
    /* The frame advances by 1.5 increments to the middle of [k+1, k+2). */
    const fx_angle_t ang_cmd = ang + (fx_angle_t)(inc + inc / 2);
    cm_regulate(cm, ang, ang_cmd, i_mag, iq, extra_d, extra_q, out);
}
