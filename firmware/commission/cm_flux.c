/*
 * Step "flux": permanent-magnet flux linkage from the back-EMF at two
 * speeds, and the mechanics: Coulomb and viscous friction (a passive load
 * counts as Coulomb friction) and the inertia, on a rotor that friction and
 * a load slow down as soon as the torque goes.
 *
 * Method (VESC takes lambda = (|v| - R|i|)/omega - L|i| in an open-loop spin
 * and checks it coasting; a rotor with friction does not coast long, so here
 * the speed is held): in the rotor frame of the identified offset, a speed
 * loop (i_q from the speed error; crossover w_loop with the configured
 * inertia) holds the rotor at w_lo and at w_hi, with i_d = +i_fd and
 * -i_fd. Over windows of whole electrical half turns the means of v_q, i_q and
 * the speed are taken (the rotor-frame voltage equation (3.9)):
 *     v_q = Rs i_q + omega (psi + Ld i_d) + Lq di_q/dt + e_q
 * so at one i_d, between the two speeds,
 *     psi + Ld i_d = (dv_q - Rs di_q - de_q) / d(omega)
 * with e_q the inverter's error (dead time, device drops) along q. Its mean
 * over whole half turns is a vector along the current, so each window
 * measures it from v_d: e_q = (v_d - Rs i_d + w Lq i_q) i_q / i_d
 * (cm_window_store). Whole half turns: the inverter error's sixth-of-a-turn saw-tooth and
 * cogging (harmonics of lcm(slots, 2p) per mechanical turn, an even
 * multiple of p) have zero mean over them. Then
 *     psi = (psi_+ + psi_-) / 2
 * removes Ld i_d without needing Ld, and with it the first-order error of a
 * small offset error (v_d leaking into v_q changes sign with i_d).
 * Mechanics (SI in cm_config.c): the windows' torque T = 3/2 p (psi +
 * D) i_q (D the reluctance term (Ld - Lq) i_d, found from the windows
 * themselves: at one speed the +i_d and -i_d windows carry the same
 * friction) against the speed gives the friction F + B w (the
 * torque the speed loop needs in the steady state, less J dw/dt over the
 * window: the loop is not quite settled); between the windows at
 * w_lo and w_hi the rotor is accelerated (and later braked) with a constant
 * q current d_i_q above (below) the friction's, and over that transition
 *     J (w_end - w_start) = integral (T - F - B w) dt
 * with the speeds at its ends from the windows' means and changes; the two
 * transitions are averaged, so an error in F enters them with opposite
 * signs. J and the friction depend on each other (each through a small
 * correction): three rounds in cm_results_si.
 * Phases: P0 into the rotor frame at i_d = +i_fd; P1 to w_lo (break-away:
 * until the rotor turns the speed loop's integrator rises steadily, past
 * stiction); P2 window A (w_lo, +); P3 accelerate to w_hi; P4 settle at w_hi
 * (voltage: w_hi is lowered to the speed where the q regulator reaches 80 %
 * of its limit); P5 window B (w_hi, +); P6 i_d to -i_fd; P7 window C (w_hi,
 * -); P8 brake to w_lo; P9 settle; P10 window D (w_lo, -); P11 brake to
 * rest; P12 hold.
 * Verdicts: the rotor does not turn at the largest q current, or does not
 * reach a speed (speed loop at its current limit): speed_low (speed,
 * target, the q current); psi <= 0: flux_range; not at rest after braking:
 * enc_unsteady.
 */
#include "cm_internal.h"

enum {
    P_ENTER,
    P_TO_LO,
    P_WIN_A,
    P_ACC,
    P_TO_HI,
    P_WIN_B,
    P_FLIP,
    P_WIN_C,
    P_DEC,
    P_BACK_LO,
    P_WIN_D,
    P_BRAKE,
    P_HOLD
};

/* Scratch: s[0..3] window sums (v_q, rotor angle increments, i_q,
 * periods), s[4] position at the window's start, s[5] window sum of v_d, s[6..8] transition sums
 * (i_q, angle increments, periods), s[9] the last turn's end (also the
 * position at the last settling check), s[10] the first block's end, s[11]
 * the last block's start (Q8 periods); a[0] speed target, a[1] i_d
 * reference, a[2] transition q current, a[3] w_hi, a[4] the break-away's
 * integrator step, a[6] the speed loop's integrator at the last settling
 * check;
 * k[0] successive settled checks, k[1] half turns completed in the window,
 * k[2] half turns of a block (m), k[3] of the window (K), k[4] the filtered speed,
 * k[5] periods the q regulator has been near its limit. */

void cm_flux_begin(cm_t *cm)
{
    cm_pi_tune_dq(cm, cm->res.ld, cm->res.lq, cm->par.v_lim_run);
    if (!cm->hold_valid) {
        cm_pi_reset(&cm->pi_d, 0);
        cm_pi_reset(&cm->pi_q, 0);
    }
    cm->pi_w.kp = cm->par.w_kp;
    cm->pi_w.ki = cm->par.w_ki;
    cm->pi_w.lim = cm->par.i_spin;
    cm_pi_reset(&cm->pi_w, 0);
    cm->x.a[3] = cm->par.w_flux;
    cm->x.a[4] = cm->par.i_spin / (int32_t)(cm->par.n_flux_max / 2u + 1u);
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

/* Regulate (d_ref, q_ref) in the rotor frame; the measured i_q in *iq. */
static void cm_rotor_regulate(cm_t *cm, q24_t d_ref, q24_t q_ref, cm_out_t *out, q24_t *iq)
{
    const fx_angle_t th = cm_rotor_angle(cm);
    const int64_t s = cm->res.enc_dir < 0 ? -cm->io.dth_sum : cm->io.dth_sum;
    const int32_t inc = (int32_t)(s / (int64_t)CM_SPEED_AVG);
    q24_t id;
    cm_to_frame(cm->io.i_al, cm->io.i_be, th, &id, iq);
    cm_regulate(cm, th, th + (fx_angle_t)(inc + inc / 2), d_ref, q_ref, 0, 0, out);
}

/* A current regulator at its limit or beyond 80 % of it (the spinning
 * voltage limit, per axis: at speed the d axis carries w Lq i_q) for
 * CM_SPEED_AVG periods in a row (not a current step's moment). */
static bool cm_volt(cm_t *cm)
{
    const q24_t l = cm->par.v_lim_run;
    const bool v = cm->pi_q.sat || cm->pi_d.sat || fx_abs(cm->pi_q.integ) > l - l / 5 ||
                   fx_abs(cm->pi_d.integ) > l - l / 5;
    cm->x.k[5] = v ? cm->x.k[5] + 1 : 0;
    return cm->x.k[5] >= (int32_t)CM_SPEED_AVG;
}

/* The speed loop at the target a[0], i_d = a[1]; its feedback the speed
 * window's average through a first-order filter of 8 periods (k[4]): at a
 * low speed the window holds few encoder counts. Until the rotor turns
 * (stiction) its integrator rises by i_spin over n_flux_max / 2. */
static void cm_spin(cm_t *cm, q24_t wr, cm_out_t *out, q24_t *iq)
{
    cm_pi_t *w = &cm->pi_w;
    cm->x.k[4] = fx_add(cm->x.k[4], fx_sub(wr, cm->x.k[4]) / 8);
    if (wr < cm->x.a[0] / 4) {
        w->integ = fx_min(w->lim, fx_add(w->integ, cm->x.a[4]));
    }
    const q24_t iq_ref = cm_pi_step(w, fx_sub(cm->x.a[0], cm->x.k[4]));
    cm_rotor_regulate(cm, cm->x.a[1], iq_ref, out, iq);
}

/* Settled: at two successive checks, one every n_settle periods, the mean
 * speed since the last check (from the encoder's position: a slow rotor's
 * speed window holds few counts) within 1/16 of the target and the speed
 * loop's integrator changed by less than 1/32 of itself (and 4 ADC counts);
 * or the speed near the target at two checks after 6 n_settle (a loop that
 * the encoder's resolution keeps jittering: the windows measure the rest of
 * the drift). */
static bool cm_settled(cm_t *cm)
{
    cm_scratch_t *x = &cm->x;
    const uint32_t n = cm->par.n_settle;
    if (cm->t == 0u || cm->t % n != 0u) {
        if (cm->t == 0u) {
            x->s[9] = cm->io.pos;
            x->k[0] = 0;
        }
        return false;
    }
    const int64_t d = cm->io.pos - x->s[9];
    const q24_t w = cm_speed_of(cm, cm->res.enc_dir < 0 ? -d : d, n);
    const q24_t i = cm->pi_w.integ;
    const bool near = fx_abs(fx_sub(w, x->a[0])) < x->a[0] / 16;
    /* without the mechanics the windows need only a near speed */
    const bool still = !CM_MECH || cm->t >= 6u * n ||
                       fx_abs(fx_sub(i, x->a[6])) < fx_add(fx_abs(i) / 32, 4 * cm->par.i_lsb);
    x->s[9] = cm->io.pos;
    x->a[6] = i;
    x->k[0] = near && still ? x->k[0] + 1 : 0;
    return x->k[0] >= 2;
}

#if CM_MECH
/* One window period: v_q (acted at the middle of [k-1, k)), the rotor's
 * angle increment, i_q; and the speed's change over the window from the
 * mean speeds of its first and last blocks of m half turns (cogging's
 * ripple and the inverter error's saw-tooth have zero mean over each: an
 * integer number of their periods, lcm(slots, 2p) / p per electrical turn
 * is even; m: the half turns of the first quarter of n_flux_win). True
 * when the window is complete: K half turns, K at least 2 m and about
 * n_flux_win long. */
#else
/* One window period: v_q (acted at the middle of [k-1, k)), the rotor's
 * angle increment, i_q. True when the window is complete: at least
 * n_flux_win periods, then whole half turns (cogging's ripple and the
 * inverter error's saw-tooth have zero mean over each: an integer number of
 * their periods, lcm(slots, 2p) / p per electrical turn is even). */
#endif
static bool cm_window(cm_t *cm, q24_t iq)
{
    cm_scratch_t *x = &cm->x;
    q24_t vd, vq;
    const int32_t inc = cm_rotor_inc(cm);
    if (x->s[3] == 0) {
        x->s[4] = cm->io.pos;
        x->s[10] = 0;
        x->k[1] = x->k[2] = x->k[3] = 0;
    }
    if (cm_acted(cm, cm_rotor_angle(cm) - (fx_angle_t)(inc / 2), &vd, &vq)) {
        x->s[0] += vq;
        x->s[5] += vd;
        x->s[1] += inc;
        x->s[2] += iq;
        x->s[3]++;
    }
    const int64_t d = cm->io.pos - x->s[4];
    const int64_t ad = d >= 0 ? d : -d;
    const int32_t j = (int32_t)(ad >> 31); /* half turns */
    if (j <= x->k[1] || inc <= 0) {
        return false;
    }
    x->k[1] = j;
#if CM_MECH
    /* Half turn j completed in this period, at the fraction of it the rotor
     * needed for the rest of the turn (t: Q8 periods from the window's first
     * period, where the position was taken: s[3] = 1 then). */
    const int64_t t = ((x->s[3] - 1) << 8) - ((ad - ((int64_t)j << 31)) << 8) / inc;
    const int64_t nb = (int64_t)cm->par.n_flux_win << 6; /* a quarter, Q8 */
    if (x->k[2] == 0 && t >= nb) {
        x->k[2] = j; /* m */
        x->s[10] = t;
        const int64_t k = ((int64_t)j * (nb << 2) + t - 1) / t;
        x->k[3] = (int32_t)(k > 2 * j ? k : 2 * j);
    }
    if (x->k[2] != 0 && j == x->k[3] - x->k[2]) {
        x->s[11] = t;
    }
    x->s[9] = t;
    return x->k[2] != 0 && j >= x->k[3];
#else
    return x->s[3] >= (int64_t)cm->par.n_flux_win;
#endif
}

/* Window w (0..3) into the results; the sums cleared. */
static void cm_window_store(cm_t *cm, int w)
{
    cm_scratch_t *x = &cm->x;
    const uint32_t n = (uint32_t)x->s[3];
    const q24_t vq = cm_mean(x->s[0], n);
    q24_t iq = cm_mean(x->s[2], n);
    cm->res.fw_vq[w] = vq;
    cm->res.fw_w[w] = cm_speed_of(cm, x->s[1], n);
    /* The current samples' offset: the dead time moves every leg's pulse by
     * t_d / 2, and the sample at the zero vector's middle sees the current
     * the back-EMF e_q = v_q - Rs i_q lets fall there, (t_d / 2) e_q / Lq: i_q
     * read high in proportion to the speed (a viscous friction's look-alike:
     * +35 % on a 44 uH drone motor with 1 us; psi_pm 0.6 % low on the 64 uH
     * outrunner). */
    q24_t off = 0;
    (void)cm_ratio(fx_mul(cm->par.td / 2, fx_sub(vq, fx_mul(cm->res.rs, iq))), cm->res.lq, &off);
    iq = fx_sub(iq, off);
    cm->res.fw_iq[w] = iq;
    /* The inverter's error: its mean over whole half turns is a vector along
     * the current (the six sectors' error vectors, each within 30 deg of it,
     * symmetric about it), so e_q = e_d i_q / i_d, and e_d is what v_d has
     * beyond (3.9): v_d - Rs i_d + w Lq i_q. Measured here, under the
     * window's own current ripple and speed (the standstill error of the rs
     * step, taken as (3/pi) |v_inv| i_q / |i|, came out twice the real one on
     * the 24 V outrunner: psi -2.4 %). */
    const q24_t e_d = fx_add(fx_sub(cm_mean(x->s[5], n), fx_mul(cm->res.rs, x->a[1])),
                             fx_mul(fx_mul(cm->res.fw_w[w], cm->res.lq), iq));
    q24_t e_q = 0;
    (void)cm_ratio(fx_mul(e_d, iq), x->a[1], &e_q);
    cm->res.fw_eq[w] = e_q;
#if CM_MECH
    const int64_t m = (int64_t)x->k[2] << 39;
    const int64_t last = x->s[9] - x->s[11];
    cm->res.fw_dw[w] =
        fx_sub(cm_speed_of(cm, m, (uint32_t)last), cm_speed_of(cm, m, (uint32_t)x->s[10]));
    cm->res.fw_n[w] = (uint32_t)((x->s[9] - (x->s[10] + last) / 2) >> 8);
    cm->res.fw_len[w] = n;
#endif
    x->s[0] = x->s[1] = x->s[2] = x->s[3] = x->s[5] = 0;
}

/* psi + Ld i_d from windows lo and hi: (dv_q - Rs di_q - de_q) / dw. */
static bool cm_flux_psi(const cm_t *cm, int lo, int hi, q24_t *psi)
{
    const cm_results_t *r = &cm->res;
    const int64_t dv = (int64_t)r->fw_vq[hi] - r->fw_vq[lo] -
                       fx_mul(r->rs, fx_sub(r->fw_iq[hi], r->fw_iq[lo])) -
                       fx_sub(r->fw_eq[hi], r->fw_eq[lo]);
    return cm_ratio(dv, (int64_t)r->fw_w[hi] - r->fw_w[lo], psi) && *psi > 0;
}

/* The transition sums (CM_MECH). */
static void cm_transit(cm_t *cm, q24_t iq)
{
#if CM_MECH
    cm->x.s[6] += iq;
    cm->x.s[7] += cm_rotor_inc(cm);
    cm->x.s[8]++;
#else
    (void)cm;
    (void)iq;
#endif
}

/* t: 0 acceleration, 1 braking */
static void cm_transit_store(cm_t *cm, int t)
{
#if CM_MECH
    cm_scratch_t *x = &cm->x;
    cm->res.jx_iq[t] = x->s[6];
    cm->res.jx_th[t] = x->s[7];
    cm->res.jx_n[t] = (uint32_t)x->s[8];
    x->s[6] = x->s[7] = x->s[8] = 0;
#else
    (void)cm;
    (void)t;
#endif
}

int cm_flux_period(cm_t *cm, const cm_in_t *in, cm_out_t *out)
{
    (void)in;
    cm_scratch_t *x = &cm->x;
    const cm_par_t *p = &cm->par;
    const q24_t wr = cm_wr(cm);
    const q24_t w_lo = x->a[3] / 3;
    q24_t iq = 0;
    cm->progress = (uint16_t)(cm->phase * 71u);
    if (cm->phase > P_ENTER && cm->phase < P_BRAKE && cm->t >= p->n_flux_max) {
        /* a speed the loop does not reach within its current */
        return cm_fail(cm, CM_E_SPEED_LOW, wr, x->a[0], cm->pi_w.integ);
    }
    switch (cm->phase) {
    case P_ENTER:
        if (p->i_spin < p->i_min) {
            return cm_fail_supply(cm, cm_rs_best(cm), p->v_lim_run);
        }
        {
            const q24_t h = cm->hold_valid ? cm->hold_i : 0;
            x->a[1] = fx_add(h, cm_ramp(fx_sub(p->i_fd, h), cm->t, p->n_ramp));
        }
        cm_rotor_regulate(cm, x->a[1], 0, out, &iq);
        if (cm->t >= p->n_ramp) {
            cm->hold_valid = 0u;
            x->a[0] = w_lo;
            cm_next(cm);
        }
        return CM_RUN;
    case P_TO_LO:
    case P_TO_HI:
    case P_FLIP:
    case P_BACK_LO:
        if (cm->phase == P_FLIP) {
            /* i_d from +i_fd to -i_fd: the torque per ampere changes (a
             * salient machine's), the speed loop settles anew */
            x->a[1] = fx_sub(p->i_fd, cm_ramp(2 * p->i_fd, cm->t, p->n_ramp));
        }
        cm_spin(cm, wr, out, &iq);
        if (cm->phase == P_TO_HI || cm->phase == P_BACK_LO) {
            cm_transit(cm, iq);
        }
        if (cm->phase == P_TO_HI && cm_volt(cm)) {
            /* the voltage: w_hi is the speed reached */
            x->a[0] = x->a[3] = fx_min(x->a[3], wr);
        }
        if (cm_settled(cm)) {
            if (cm->phase == P_BACK_LO) {
                cm_transit_store(cm, 1);
            } else if (cm->phase == P_TO_HI) {
                cm_transit_store(cm, 0);
            }
            cm_next(cm);
        }
        return CM_RUN;
    case P_WIN_A:
    case P_WIN_B:
    case P_WIN_C:
    case P_WIN_D: {
        cm_spin(cm, wr, out, &iq);
        if (!cm_window(cm, iq)) {
            return CM_RUN;
        }
        static const uint8_t slot[P_WIN_D + 1] = {
            [P_WIN_A] = 0, [P_WIN_B] = 1, [P_WIN_C] = 2, [P_WIN_D] = 3};
        cm_window_store(cm, slot[cm->phase]);
        if (cm->phase == P_WIN_A || cm->phase == P_WIN_C) {
#if CM_MECH
            /* the transition's constant q current: the friction's and d_i_q */
            const q24_t di = p->i_acc / 2;
            const q24_t base = cm->res.fw_iq[cm->phase == P_WIN_A ? 0 : 2];
            x->a[2] = fx_clamp(cm->phase == P_WIN_A ? fx_add(base, di) : fx_sub(base, di),
                               fx_neg(p->i_spin), p->i_spin);
#else
            /* no transition: the speed loop takes the rotor to the next speed */
            x->a[0] = cm->phase == P_WIN_A ? x->a[3] : w_lo;
            cm->phase++;
#endif
        }
        cm_next(cm);
        return CM_RUN;
    }
#if CM_MECH
    case P_ACC:
    case P_DEC: {
        const bool acc = cm->phase == P_ACC;
        cm_rotor_regulate(cm, x->a[1], x->a[2], out, &iq);
        cm_transit(cm, iq);
        if (acc && cm_volt(cm)) {
            /* the voltage ends the acceleration: w_hi here, at least 3/2 w_lo
             * (a smaller step leaves psi to the error of the two windows) */
            if (wr < w_lo + w_lo / 2) {
                return cm_fail(cm, CM_E_SPEED_LOW, wr, x->a[3], x->a[2]);
            }
            x->a[3] = wr;
        }
        if (acc ? wr >= x->a[3] : wr <= w_lo) {
            /* the speed loop from the friction's current of the last window */
            x->a[0] = acc ? x->a[3] : w_lo;
            cm_pi_reset(&cm->pi_w, cm->res.fw_iq[acc ? 0 : 2]);
            cm_next(cm);
        }
        return CM_RUN;
    }
#endif
    case P_BRAKE: {
        q24_t k = 0;
        (void)cm_ratio(3 * (int64_t)wr, x->a[3], &k);
        const q24_t i = fx_clamp(fx_neg(fx_mul(p->i_acc, k)), fx_neg(p->i_acc), p->i_acc);
        cm_rotor_regulate(cm, 0, i, out, &iq);
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
    /* psi_+ from windows A (lo) and B (hi), psi_- from D (lo) and C (hi) */
    q24_t pp, pn;
    if (!cm_flux_psi(cm, 0, 1, &pp)) {
        return cm_fail(cm, CM_E_FLUX_RANGE, pp, cm->res.fw_w[1], 1);
    }
    if (!cm_flux_psi(cm, 3, 2, &pn)) {
        return cm_fail(cm, CM_E_FLUX_RANGE, pn, cm->res.fw_w[2], -1);
    }
    cm->res.psi_pos = pp;
    cm->res.psi_neg = pn;
    cm->res.psi = (q24_t)(((int64_t)pp + pn) / 2);
    cm->res.omega_flux = x->a[3];
    cm->res.i_fd = p->i_fd;
    cm->hold_valid = 1u;
    return CM_DONE;
}
