/*
 * Step "flux": permanent-magnet flux linkage from the back-EMF while the
 * rotor spins, and (optional) inertia and friction.
 *
 * Method (VESC takes lambda = (|v| - R|i|)/omega - L|i| in an open-loop spin;
 * here in closed loop, since the encoder offset is known - the rotor-frame voltage equation (3.9) solved for psi_pm, "v_q -
 * Rs i_q - omega Ld i_d over omega"): in the rotor frame of the identified
 * offset,
 *   P1 accelerate with i_q = i_acc to w_flux (or until the voltage reaches
 *      80 % of the spinning limit); inertia J = T dt / d(omega_m) with
 *      T = 3/2 p (psi i_q + (Ld - Lq) i_d i_q), taken once psi is known;
 *   P2 coast with i_q = 0, i_d = +i_fd, P3 coast with i_d = -i_fd: over each
 *      window, psi_+- = mean(v_q) / mean(omega), since
 *          v_q = Rs i_q + omega (psi + Ld i_d) + Lq di_q/dt + e_q
 *      and i_q = 0. The inverter error e (dead time, device drops) follows
 *      the signs of the phase currents: a vector within +-30 deg of the
 *      current, whose q part is a saw-tooth of zero mean over every sixth of
 *      an electrical turn, so it averages out; the d current keeps the phase
 *      currents away from the ambiguous zero-current region.
 *          psi = (psi_+ + psi_-) / 2
 *      removes Ld i_d without needing Ld, and with it the first-order error
 *      of a small encoder-offset error (v_d, which leaks into v_q through it,
 *      changes sign with i_d). Rs is not needed either.
 *      The speed change over the two coasting windows gives the friction.
 *   P4 brake with i_q = -i_acc omega / (w_flux / 3) to rest, P5 hold the
 *      rotor where it stopped (hold_angle) for the next step.
 * Verdicts: speed below w_flux / 4 when accelerating stops: speed_low
 * (voltage limit or a load); psi <= 0: flux_range.
 */
#include "cm_internal.h"

enum { P_ENTER, P_ACC, P_POS, P_NEG, P_BRAKE, P_HOLD };

/* Scratch: a[0] rotor speed at the start of the inertia window, s[0] sum of
 * the measured i_q there, s[1] its periods; s[2] sum v_q, s[3] sum of rotor
 * angle increments, s[4] periods of a coasting window; a[3] speed of window
 * +, a[4] speed at its start; k[0] periods at rest (brake), k[1] periods
 * between the coasting speed readings. */

void cm_flux_begin(cm_t *cm)
{
    cm_pi_tune_dq(cm, cm->res.ld, cm->res.lq, cm->par.v_lim_run);
    if (!cm->hold_valid) {
        cm_pi_reset(&cm->pi_d, 0);
        cm_pi_reset(&cm->pi_q, 0);
    }
}

/* Rotor speed (identified direction), pu electrical. */
static q24_t cm_wr(const cm_t *cm)
{
    const q24_t w = cm_speed(cm);
    return cm->res.enc_dir < 0 ? fx_neg(w) : w;
}

static int32_t cm_rotor_inc(const cm_t *cm)
{
    return cm->res.enc_dir < 0 ? -cm->io.dth : cm->io.dth;
}

/* Regulate (d_ref, q_ref) in the rotor frame. */
static void cm_rotor_regulate(cm_t *cm, q24_t d_ref, q24_t q_ref, cm_out_t *out)
{
    const fx_angle_t th = cm_rotor_angle(cm);
    const int64_t s = cm->res.enc_dir < 0 ? -cm->io.dth_sum : cm->io.dth_sum;
    const int32_t inc = (int32_t)(s / (int64_t)CM_SPEED_AVG);
    cm_regulate(cm, th, th + (fx_angle_t)(inc + inc / 2), d_ref, q_ref, 0, 0, out);
}

/* v_q over one period (the acted voltage at the middle of [k-1, k)). */
static void cm_flux_sample(cm_t *cm)
{
    q24_t vd, vq;
    const int32_t inc = cm_rotor_inc(cm);
    if (cm_acted(cm, cm_rotor_angle(cm) - (fx_angle_t)(inc / 2), &vd, &vq)) {
        cm->x.s[2] += vq;
        cm->x.s[3] += inc;
        cm->x.s[4]++;
    }
}

static bool cm_flux_psi(cm_t *cm, q24_t *psi, q24_t *w)
{
    cm_scratch_t *x = &cm->x;
    const uint32_t n = (uint32_t)x->s[4];
    *w = cm_speed_of(cm, x->s[3], n);
    const q24_t vq = cm_mean(x->s[2], n);
    x->s[2] = x->s[3] = x->s[4] = 0;
    return cm_ratio(vq, *w, psi) && *psi > 0;
}

int cm_flux_period(cm_t *cm, const cm_in_t *in, cm_out_t *out)
{
    (void)in;
    cm_scratch_t *x = &cm->x;
    const cm_par_t *p = &cm->par;
    const q24_t wr = cm_wr(cm);
    cm->progress = (uint16_t)(cm->phase * 166u);
    switch (cm->phase) {
    case P_ENTER:
        if (p->i_acc < p->i_min) {
            return cm_fail_supply(cm, cm_rs_best(cm), p->v_lim_run);
        }
        x->a[1] = cm->hold_valid ? cm->hold_i : 0;
        cm_rotor_regulate(cm, x->a[1], 0, out);
        if (cm->t >= p->n_ramp) {
            cm->hold_valid = 0u;
            cm_next(cm);
        }
        return CM_RUN;
    case P_ACC: {
        /* A short ramp (CM_SPEED_AVG periods): a light rotor reaches the
         * speed within a few milliseconds. */
        const q24_t iq = cm_ramp(p->i_acc, cm->t, CM_SPEED_AVG);
        const q24_t id = fx_sub(x->a[1], cm_ramp(x->a[1], cm->t, CM_SPEED_AVG));
        cm_rotor_regulate(cm, id, iq, out);
        /* The inertia window starts once the speed average (CM_SPEED_AVG
         * periods, lagging by half of it) sees only the constant current. */
        const uint32_t t0 = 3u * CM_SPEED_AVG;
        if (cm->t == t0) {
            x->a[0] = wr;
        } else if (cm->t > t0) {
            q24_t d, q;
            cm_to_frame(cm->io.i_al, cm->io.i_be, cm_rotor_angle(cm), &d, &q);
            x->s[0] += q;
            x->s[1]++;
        }
        const bool volt = cm->pi_q.sat || fx_abs(cm->pi_q.integ) > p->v_lim_run - p->v_lim_run / 5;
        if (cm->t > t0 && (wr >= p->w_flux || volt || cm->t >= p->n_flux_max)) {
            if (wr < p->w_flux / 4) {
                return cm_fail(cm, CM_E_SPEED_LOW, wr, p->w_flux, volt ? 1 : 0);
            }
            /* J = T dt / dw: keep the accelerating current's sum and dw. */
            cm->res.acc_torque_sum = x->s[0]; /* times psi (pu) when known */
            cm->res.acc_dw = fx_sub(wr, x->a[0]);
            cm->res.acc_n = (uint32_t)x->s[1];
            x->s[0] = x->s[1] = 0;
            cm_next(cm);
        }
        return CM_RUN;
    }
    case P_POS:
    case P_NEG: {
        const bool pos = cm->phase == P_POS;
        const q24_t idr = pos ? p->i_fd : fx_neg(p->i_fd);
        /* i_q steps to zero (a ramp would keep accelerating a light rotor). */
        cm_rotor_regulate(cm, idr, 0, out);
        const uint32_t start = p->n_ramp + p->n_settle / 2u;
        if (cm->t == start && pos) {
            x->a[4] = wr;
        }
        if (cm->t > start) {
            cm_flux_sample(cm);
        }
        if (cm->t < start + p->n_flux_win) {
            return CM_RUN;
        }
        q24_t psi, w;
        if (!cm_flux_psi(cm, &psi, &w)) {
            return cm_fail(cm, CM_E_FLUX_RANGE, psi, w, pos ? 1 : -1);
        }
        if (pos) {
            cm->res.psi_pos = psi;
            x->a[3] = w;
        } else {
            cm->res.psi_neg = psi;
            cm->res.psi = (q24_t)(((int64_t)cm->res.psi_pos + psi) / 2);
            cm->res.omega_flux = (q24_t)(((int64_t)x->a[3] + w) / 2);
            cm->res.coast_w0 = x->a[4];
            cm->res.coast_w1 = wr;
            cm->res.coast_wm = cm->res.omega_flux;
            /* Periods between the two speed readings. */
            x->k[1] = (int32_t)(2u * (p->n_ramp + p->n_settle / 2u + p->n_flux_win) - start);
        }
        cm_next(cm);
        return CM_RUN;
    }
    case P_BRAKE: {
        q24_t k = 0;
        (void)cm_ratio(3 * (int64_t)wr, p->w_flux, &k);
        const q24_t iq = fx_clamp(fx_neg(fx_mul(p->i_acc, k)), fx_neg(p->i_acc), p->i_acc);
        cm_rotor_regulate(cm, 0, iq, out);
        x->k[0] = fx_abs(wr) < p->w_settle ? x->k[0] + 1 : 0;
        if (x->k[0] >= (int32_t)(p->n_settle / 2u)) {
            cm->hold_angle = cm_rotor_angle(cm);
            cm_pi_reset(&cm->pi_d, cm->pi_d.integ);
            cm_next(cm);
        } else if (cm->t >= p->n_flux_max) {
            return cm_fail(cm, CM_E_ENC_UNSTEADY, wr, p->w_settle, 1);
        }
        return CM_RUN;
    }
    case P_HOLD:
    default:
        cm_hold(cm, cm->hold_angle, 0, cm_ramp(p->i_hold, cm->t, p->n_ramp), 0, 0, out);
        if (cm->t < p->n_ramp) {
            return CM_RUN;
        }
        break;
    }
    cm->hold_valid = 1u;
    /* Inertia and friction data (SI in cm_config.c). */
    cm->res.coast_n = (uint32_t)x->k[1];
    return CM_DONE;
}
