/*
 * Step "encoder": direction, counts per revolution and electrical offset of
 * the encoder from a slow open-loop scan, on a rotor that friction, a load
 * and cogging hold back.
 *
 * Method (ODrive's offset calibration: turn the field slowly forward, then
 * backward, and average the two, so that the lag behind the field cancels;
 * and a current that rises until the rotor follows): a current i_enc is
 * regulated along a field angle theta* that
 *   P0 ramps up at theta* = 0, P1 waits (the rotor aligns as far as its
 *      friction lets it),
 *   P2 turns three electrical turns forward: the direction is the sign of
 *      the count change. The rotor went along when the encoder moved 1 1/2
 *      to 4 1/2 turns (a lag under half a turn at each end, the counts
 *      within a quarter of the configured); a rotor that slips poles moves
 *      far less (one held by stiction, a load or cogging above what the
 *      field can pull: no count at all, or a jolt per turn). Then the
 *      counts per turn it implies must be within a quarter of the
 *      configured (the damping below needs the scale; else a slipped pole
 *      or wrong counts: the current rises as below, and at i_hold_max
 *      enc_cpr), and the rotor's swinging around the field is damped from
 *      then on (cm_hold).
 *   P3 waits until the rotor rests, P4 turns three turns backward, P5
 *      waits, P6 three turns forward, P7 waits until the rotor rests.
 * In the constant-speed part of P4 and P6 the rotor's lag behind the field is
 * a periodic function of the field angle with the period of one electrical
 * turn: friction and a load are constant at constant speed, cogging is a sum
 * of harmonics of lcm(slots, 2p) per mechanical turn, an even multiple of p,
 * so half a turn holds an integer number of its periods. After a settling
 * distance of 5/8 of a turn (the damped swing's slow mode decays at Omega,
 * 1 / Omega = 33 ms; a rotor held by stiction starts only when the field has
 * passed it by twice its lag):
 *  - the rotor followed steadily when it moved the same distance over half
 *    a turn of the field and over the same half turn one field turn later
 *    (within 2 %): a rotor that stiction, a load or cogging hold near the
 *    field's largest torque creeps after the field and fails this, and so
 *    does one that slips a pole. Not followed (in P2 or here): the current
 *    rises by half (at most i_hold_max) and the scan starts again at P0;
 *    at i_hold_max, no count at all: enc_no_motion (an encoder that does
 *    not count, or a rotor that does not turn), some: load (the shaft
 *    needs more torque than the field gives: the largest current and the
 *    torque it makes are named);
 *  - counts per revolution: the encoder position summed over those two
 *    windows (n_turn / 2 periods each) differ by n_w x (one field turn) x
 *    (true / configured counts) x (configured p / true p): the lag is the
 *    same at both ends of each pair and drops out. Forward and backward
 *    averaged; more than cpr_tol away from 1: enc_cpr;
 *  - offset: the circular mean of theta* - dir theta_enc over exactly one
 *    field turn in each direction: the lag's periodic part (cogging) has
 *    zero mean over it, its constant part (friction, load) changes sign with
 *    the direction and cancels in the sum of the two.
 * The field ends at theta* = 0 (phase a's axis, a whole number of turns on):
 * the step ends with the rotor at rest there (hold_angle), so the next steps
 * start without a jolt.
 */
#include "cm_internal.h"

/* Scratch use:
 *   ang[0] theta* (field angle), ang[1] offset reference (first sample)
 *   s[0] offset sum, s[1] offset samples, s[2] window 1 sum, s[3] window 2
 *   sum, s[4] sum of |window 2 - window 1| over the moves, s[5] move
 *   distance left (angle units, signed), s[6] / s[7] the rotor's travel
 *   over window 1 / 2, s[8] pos at the move's start
 *   a[0] ramp start current, a[1] scan current i_enc
 *   k[0] move sub-phase (0 accel, 1 cruise, 2 decel), k[1] inc (signed),
 *   k[2] periods in the sub-phase, k[3] settled periods, k[4] cruise periods
 */

enum { P_RAMP, P_ALIGN, P_FWD1, P_HOLD1, P_BACK2, P_HOLD2, P_FWD2, P_HOLD3 };

#define CM_TURN ((int64_t)1 << 32)
#define CM_SCAN_TURNS 3 /* electrical turns of each move */

void cm_encoder_begin(cm_t *cm)
{
    /* Re-measured: the damping uses the direction once P2 has found it. */
    cm->res.have &= ~(uint32_t)CM_HAVE_ENC;
    cm->x.ang[0] = 0u;
    cm->x.a[0] = cm->hold_valid ? cm->hold_i : 0;
    cm->x.a[1] = cm->par.i_hold;
    cm_pi_reset(&cm->pi_d, 0);
    cm_pi_reset(&cm->pi_q, 0);
    /* the spinning limit: the rising current may need more than the
     * standstill's (cm_fit_currents) */
    cm_pi_tune_dq(cm, cm_l_best(cm), cm_l_best(cm), cm->par.v_lim_run);
}

/* Start a move of `turns` electrical turns (sign = direction). */
static void cm_move_start(cm_t *cm, int32_t turns)
{
    cm->x.s[5] = (int64_t)turns * CM_TURN;
    cm->x.s[8] = cm->io.pos;
    cm->x.k[0] = 0;
    cm->x.k[1] = 0;
    cm->x.k[2] = 0;
    cm->x.k[4] = 0;
}

/* One period of a trapezoidal move: returns the increment of theta* and
 * whether the move is in its constant-speed part; *done at the end. */
static int32_t cm_move_step(cm_t *cm, bool *cruise, bool *done)
{
    cm_scratch_t *x = &cm->x;
    const int64_t left = x->s[5];
    const int32_t sgn = left >= 0 ? 1 : -1;
    const int64_t aleft = left >= 0 ? left : -left;
    const int32_t w = (int32_t)cm->par.scan_inc;
    const int32_t na = (int32_t)cm->par.n_scan_acc;
    int32_t inc;
    *cruise = false;
    *done = false;
    /* Distance a linear ramp from speed a to 0 over na periods covers. */
    const int64_t a = x->k[1] >= 0 ? x->k[1] : -x->k[1];
    const int64_t brake = a * (int64_t)(na + 1) / 2;
    if (x->k[0] == 0) {
        x->k[2]++;
        inc = (int32_t)(((int64_t)w * x->k[2]) / na);
        if (x->k[2] >= na) {
            x->k[0] = 1;
            x->k[2] = 0;
        }
    } else if (x->k[0] == 1 && aleft > brake + w) {
        inc = w;
        *cruise = true;
    } else {
        x->k[0] = 2;
        x->k[2]++;
        inc = (int32_t)(((int64_t)w * (na - x->k[2])) / na);
        if (x->k[2] >= na || inc < 1) {
            /* The ramp's rounding leaves less than one cruise increment. */
            inc = (int32_t)(aleft < (int64_t)w ? aleft : w);
        }
    }
    if ((int64_t)inc >= aleft) {
        inc = (int32_t)aleft;
        *done = true;
    }
    inc *= sgn;
    x->k[1] = inc;
    x->s[5] = left - inc;
    return inc;
}

/* The cruise of P4 / P6: offset over one field turn, the two count windows
 * (position sums and the rotor's travel over each). */
static void cm_cruise_sample(cm_t *cm)
{
    cm_scratch_t *x = &cm->x;
    const uint32_t nt = cm->par.n_turn;
    const uint32_t c = (uint32_t)x->k[4]++;
    const uint32_t s0 = nt / 8u * 5u; /* settling: 5/8 of a turn */
    if (c < s0) {
        return;
    }
    const uint32_t u = c - s0;
    if (u < nt) {
        const fx_angle_t th = cm->res.enc_dir < 0 ? (fx_angle_t)(0u - cm->io.th) : cm->io.th;
        const fx_angle_t off = x->ang[0] - th;
        if (x->s[1] == 0) {
            x->ang[1] = off;
        }
        x->s[0] += fx_u2i(off - x->ang[1]);
        x->s[1]++;
    }
    const int64_t pos = cm->io.pos;
    if (u == 0u || u == nt) {
        x->s[u == 0u ? 6 : 7] = -pos;
    } else if (u == nt / 2u || u == nt + nt / 2u) {
        x->s[u == nt / 2u ? 6 : 7] += pos;
    }
    if (u < nt / 2u) {
        x->s[2] += pos;
    } else if (u >= nt && u < nt + nt / 2u) {
        x->s[3] += pos;
    }
}

/* The rotor at rest on the field (damped): true once settled; fails after
 * n_hold_max. */
static int cm_enc_settle(cm_t *cm, q24_t i, cm_out_t *out)
{
    cm_scratch_t *x = &cm->x;
    cm_hold(cm, x->ang[0], 0, i, 0, 0, out);
    x->k[3] = cm_slip(cm) < cm->par.w_settle ? x->k[3] + 1 : 0;
    if (x->k[3] >= (int32_t)(cm->par.n_settle / 2u)) {
        x->k[3] = 0;
        return CM_DONE;
    }
    if (cm->t >= cm->par.n_hold_max) {
        return cm_fail(cm, CM_E_ENC_UNSTEADY, cm_slip(cm), cm->par.w_settle, 0);
    }
    return CM_RUN;
}

/* Counts per revolution from the measured / configured ratio (Q24): kept;
 * more than tol away from 1: enc_cpr. */
static int cm_enc_ratio(cm_t *cm, q24_t ratio, q24_t tol)
{
    const uint32_t cpr =
        (uint32_t)(((uint64_t)cm->par.enc_cpr * (uint32_t)ratio + (1u << 23)) >> 24);
    cm->res.enc_cpr_ratio = ratio;
    cm->res.enc_cpr = cpr;
    if (fx_abs(fx_sub(ratio, FX_ONE)) > tol) {
        return cm_fail(cm, CM_E_ENC_CPR, (int32_t)cpr, (int32_t)cm->par.enc_cpr, ratio);
    }
    return CM_RUN;
}

/* The rotor did not follow over a move that moved it `amoved`: the scan
 * again at a current raised by half, or the verdict at i_hold_max. */
static int cm_not_followed(cm_t *cm, int64_t amoved)
{
    cm_scratch_t *x = &cm->x;
    const q24_t i = x->a[1];
    cm->res.have &= ~(uint32_t)CM_HAVE_ENC;
    if (i < cm->par.i_hold_max) {
        x->a[0] = i;
        x->a[1] = fx_min(fx_add(i, i / 2), cm->par.i_hold_max);
        x->s[0] = x->s[1] = x->s[4] = 0;
        cm->phase = P_RAMP;
        cm->t = 0u;
        cm->t_fresh = 1u;
        return CM_RUN;
    }
    /* Per mille of one electrical turn the encoder reported. */
    const int32_t pm = (int32_t)((amoved * 1000) / CM_TURN);
    if (amoved < (int64_t)cm->par.enc_count * 2) {
        return cm_fail(cm, CM_E_ENC_NO_MOTION, pm, i, fx_mul(i, cm->par.psi_cfg));
    }
    return cm_fail(cm, CM_E_LOAD, pm, i, fx_mul(i, cm->par.psi_cfg));
}

int cm_encoder_period(cm_t *cm, const cm_in_t *in, cm_out_t *out)
{
    (void)in;
    cm_scratch_t *x = &cm->x;
    const cm_par_t *p = &cm->par;
    const q24_t i_enc = x->a[1];
    bool cruise = false, done = false;
    cm->progress = (uint16_t)(cm->phase * 125u);

    switch (cm->phase) {
    case P_RAMP:
        if (p->i_hold < p->i_min) {
            return cm_fail_supply(cm, cm_rs_best(cm), p->v_lim);
        }
        /* A slow ramp: the rotor, wherever it rests, is pulled in gently (the
         * swing it keeps is smaller the slower the field grows). */
        cm_hold(cm, x->ang[0], 0,
                fx_add(x->a[0], cm_ramp(fx_sub(i_enc, x->a[0]), cm->t, p->n_hold)), 0, 0, out);
        if (cm->t >= p->n_hold) {
            cm_next(cm);
        }
        return CM_RUN;
    case P_ALIGN:
        cm_hold(cm, x->ang[0], 0, i_enc, 0, 0, out);
        if (cm->t >= p->n_hold) {
            cm_next(cm);
            cm_move_start(cm, CM_SCAN_TURNS);
        }
        return CM_RUN;
    case P_FWD1:
    case P_BACK2:
    case P_FWD2: {
        const int32_t inc = cm_move_step(cm, &cruise, &done);
        x->ang[0] += (fx_angle_t)inc;
        cm_hold(cm, x->ang[0], inc, i_enc, 0, 0, out);
        if (cruise && cm->phase != P_FWD1) {
            cm_cruise_sample(cm);
        }
        if (!done) {
            return CM_RUN;
        }
        const int64_t moved = cm->io.pos - x->s[8];
        const int64_t amoved = moved >= 0 ? moved : -moved;
        if (amoved < CM_TURN * 3 / 2 || amoved > CM_TURN * 9 / 2) {
            return cm_not_followed(cm, amoved);
        }
        if (cm->phase == P_FWD1) {
            /* within a quarter of the configured counts: the damping's
             * slip measure holds (a wrong scale reads as a slip) */
            if (cm_enc_ratio(cm, fx_sat32(amoved / (CM_SCAN_TURNS << 8)), FX_ONE / 4) == CM_FAIL) {
                /* a pole slipped, or the counts are wrong: a larger current
                 * first (a wrong count stays wrong at every current) */
                if (x->a[1] < p->i_hold_max) {
                    cm->err = CM_E_NONE;
                    return cm_not_followed(cm, amoved);
                }
                return CM_FAIL;
            }
            cm->res.enc_dir = moved > 0 ? 1 : -1;
            cm->res.have |= CM_HAVE_ENC; /* direction only, for the damping */
        } else {
            /* steady: the same travel over the two windows (2 %) */
            const int64_t t1 = x->s[6] >= 0 ? x->s[6] : -x->s[6];
            const int64_t t2 = x->s[7] >= 0 ? x->s[7] : -x->s[7];
            const int64_t dt = t1 - t2;
            if (x->k[4] < (int32_t)(p->n_turn / 8u * 5u + p->n_turn + p->n_turn / 2u) ||
                (dt >= 0 ? dt : -dt) > t2 / 50) {
                return cm_not_followed(cm, amoved);
            }
            const int64_t d = x->s[3] - x->s[2];
            x->s[4] += d >= 0 ? d : -d;
            x->s[2] = x->s[3] = 0;
        }
        if (cm->phase == P_FWD2) {
            /* ratio = mean |window 2 - window 1| / (n_w n_turn scan_inc): the
             * two moves' sums over n_w = n_turn / 2 periods each (the mean
             * difference per sample below 2^33), Q24. */
            const uint64_t q = (uint64_t)x->s[4] / (uint64_t)(p->n_turn & ~1u);
            const uint64_t den = (uint64_t)p->n_turn * p->scan_inc;
            if (cm_enc_ratio(cm, fx_sat32((int64_t)(((q << 24) + den / 2u) / den)), p->cpr_tol) ==
                CM_FAIL) {
                return CM_FAIL;
            }
        }
        cm_next(cm);
        return CM_RUN;
    }
    case P_HOLD1:
    case P_HOLD2: {
        const int rc = cm_enc_settle(cm, i_enc, out);
        if (rc != CM_DONE) {
            return rc;
        }
        cm_next(cm);
        cm_move_start(cm, cm->phase == P_BACK2 ? -CM_SCAN_TURNS : CM_SCAN_TURNS);
        return CM_RUN;
    }
    case P_HOLD3:
    default: {
        const int rc = cm_enc_settle(cm, i_enc, out);
        if (rc != CM_DONE) {
            return rc;
        }
        break;
    }
    }
    /* Results. */
    if (x->s[1] == 0) {
        return cm_fail(cm, CM_E_ENC_NO_MOTION, 0, i_enc, fx_mul(i_enc, p->psi_cfg));
    }
    const int64_t mean = x->s[0] / x->s[1];
    cm->res.enc_off = x->ang[1] + (fx_angle_t)(int32_t)mean;
    cm->hold_angle = x->ang[0];
    cm->hold_i = i_enc;
    cm->hold_valid = 1u;
    return CM_DONE;
}
