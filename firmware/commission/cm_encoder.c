/*
 * Step "encoder": direction, counts per revolution and electrical offset of
 * the encoder, and the phase-balance harmonic, from a slow open-loop scan.
 *
 * Method (ODrive's offset calibration: turn the field slowly forward, then
 * backward, and average the two, so that the lag behind the field cancels):
 * a current of i_hold is regulated along a field angle theta* that
 *   P0 ramps up at theta* = theta_0, P1 waits (the rotor aligns),
 *   P2 turns one electrical turn forward  -> direction (sign of the count
 *      change; under 1/8 of the expected change: enc_no_motion),
 *   P3 holds, P4 turns two turns backward, P5 holds, P6 two turns forward,
 *   P7 holds until the rotor is at rest (enc_unsteady after n_hold_max).
 * From P3 on the rotor's swinging around the field is damped (cm_hold):
 * without friction nothing else would damp it.
 *  - counts per revolution: the mean encoder angle over P3 and over P5 (rotor
 *    at rest on the field, damped) differ by two electrical turns times
 *    (true counts / configured counts) x (configured p / true p); more than
 *    cpr_tol away from 1: enc_cpr;
 *  - offset: the circular mean over the constant-speed parts of P4 and P6
 *    (equal lengths, opposite directions) of theta* - dir * theta_enc, so that
 *    theta_e = offset + dir * theta_enc.
 * The field starts and ends at theta* = 0 (phase a's axis): the step ends
 * with the rotor at rest there (hold_angle), so the next steps start
 * without a jolt.
 */
#include "cm_internal.h"

/* Scratch use:
 *   ang[0] theta* (field angle), ang[1] offset reference (first sample)
 *   s[0] offset sum, s[1] offset samples, s[5] move distance left (angle
 *   units, signed), s[6] pos sum (hold), s[7] pos at P3 mean (A), s[8] pos
 *   at P2 start, s[9] hold samples
 *   k[0] move sub-phase (0 accel, 1 cruise, 2 decel), k[1] inc (signed),
 *   k[2] periods in the sub-phase, k[3] settled periods (holds)
 */

enum { P_RAMP, P_ALIGN, P_FWD1, P_HOLD1, P_BACK2, P_HOLD2, P_FWD2, P_HOLD3 };

#define CM_TURN ((int64_t)1 << 32)

void cm_encoder_begin(cm_t *cm)
{
    /* Re-measured: the damping uses the direction once P2 has found it. */
    cm->res.have &= ~(uint32_t)CM_HAVE_ENC;
    cm->x.ang[0] = 0u;
    cm->x.a[0] = cm->hold_valid ? cm->hold_i : 0;
    cm_pi_reset(&cm->pi_d, 0);
    cm_pi_reset(&cm->pi_q, 0);
    cm_pi_tune_dq(cm, cm_l_best(cm), cm_l_best(cm), cm->par.v_lim);
}

/* Start a move of `turns` electrical turns (sign = direction). */
static void cm_move_start(cm_t *cm, int32_t turns)
{
    cm->x.s[5] = (int64_t)turns * CM_TURN;
    cm->x.k[0] = 0;
    cm->x.k[1] = 0;
    cm->x.k[2] = 0;
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

static void cm_offset_sample(cm_t *cm)
{
    cm_scratch_t *x = &cm->x;
    const fx_angle_t th = cm->res.enc_dir < 0 ? (fx_angle_t)(0u - cm->io.th) : cm->io.th;
    const fx_angle_t off = x->ang[0] - th;
    if (x->s[1] == 0) {
        x->ang[1] = off;
    }
    x->s[0] += fx_u2i(off - x->ang[1]);
    x->s[1]++;
}

int cm_encoder_period(cm_t *cm, const cm_in_t *in, cm_out_t *out)
{
    (void)in;
    cm_scratch_t *x = &cm->x;
    const cm_par_t *p = &cm->par;
    int32_t inc = 0;
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
                fx_add(x->a[0], cm_ramp(fx_sub(p->i_hold, x->a[0]), cm->t, p->n_hold)), 0, 0, out);
        if (cm->t >= p->n_hold) {
            cm_next(cm);
        }
        return CM_RUN;
    case P_ALIGN:
        cm_hold(cm, x->ang[0], 0, p->i_hold, 0, 0, out);
        if (cm->t >= p->n_hold) {
            cm_next(cm);
            cm_move_start(cm, 1);
            x->s[8] = cm->io.pos;
        }
        return CM_RUN;
    case P_FWD1:
    case P_BACK2:
    case P_FWD2:
        inc = cm_move_step(cm, &cruise, &done);
        x->ang[0] += (fx_angle_t)inc;
        cm_hold(cm, x->ang[0], inc, p->i_hold, 0, 0, out);
        if (cruise && cm->phase != P_FWD1) {
            cm_offset_sample(cm);
        }
        if (!done) {
            return CM_RUN;
        }
        if (cm->phase == P_FWD1) {
            const int64_t moved = cm->io.pos - x->s[8];
            const int64_t amoved = moved >= 0 ? moved : -moved;
            if (amoved < CM_TURN / 8) {
                /* Per mille of one electrical turn the encoder reported. */
                return cm_fail(cm, CM_E_ENC_NO_MOTION, (int32_t)((amoved * 1000) / CM_TURN), 1000,
                               0);
            }
            cm->res.enc_dir = moved > 0 ? 1 : -1;
            cm->res.have |= CM_HAVE_ENC; /* direction only, for the damping */
        }
        cm_next(cm);
        x->s[6] = 0;
        x->s[9] = 0;
        return CM_RUN;
    case P_HOLD1:
    case P_HOLD2:
        cm_hold(cm, x->ang[0], 0, p->i_hold, 0, 0, out);
        /* Wait until the rotor rests on the field (damped), then average its
         * position over half a hold. */
        if (x->s[9] == 0) {
            x->k[3] = cm_slip(cm) < p->w_settle ? x->k[3] + 1 : 0;
            if (x->k[3] < (int32_t)(p->n_settle / 2u)) {
                if (cm->t >= p->n_hold_max) {
                    return cm_fail(cm, CM_E_ENC_UNSTEADY, cm_slip(cm), p->w_settle, 0);
                }
                return CM_RUN;
            }
        }
        x->s[6] += cm->io.pos;
        x->s[9]++;
        if (x->s[9] < (int64_t)(p->n_hold / 2u)) {
            return CM_RUN;
        }
        x->k[3] = 0;
        if (cm->phase == P_HOLD1) {
            x->s[7] = x->s[6] / x->s[9];
            cm_next(cm);
            cm_move_start(cm, -2);
            return CM_RUN;
        }
        {
            const int64_t b = x->s[6] / x->s[9];
            const int64_t d = b - x->s[7];
            const int64_t ad = d >= 0 ? d : -d;
            /* ratio = |B - A| / (2 turns), Q24: |d| 2^24 / 2^33. */
            const q24_t ratio = fx_sat32((ad + 256) / 512);
            const uint32_t cpr =
                (uint32_t)(((uint64_t)p->enc_cpr * (uint32_t)ratio + (1u << 23)) >> 24);
            cm->res.enc_cpr_ratio = ratio;
            cm->res.enc_cpr = cpr;
            if (fx_abs(fx_sub(ratio, FX_ONE)) > p->cpr_tol) {
                return cm_fail(cm, CM_E_ENC_CPR, (int32_t)cpr, (int32_t)p->enc_cpr, ratio);
            }
        }
        cm_next(cm);
        cm_move_start(cm, 2);
        return CM_RUN;
    case P_HOLD3:
    default:
        cm_hold(cm, x->ang[0], 0, p->i_hold, 0, 0, out);
        if (cm_slip(cm) < p->w_settle) {
            x->k[3]++;
        } else {
            x->k[3] = 0;
        }
        if (x->k[3] < (int32_t)(p->n_settle / 2u)) {
            if (cm->t >= p->n_hold_max) {
                return cm_fail(cm, CM_E_ENC_UNSTEADY, cm_slip(cm), p->w_settle, 0);
            }
            return CM_RUN;
        }
        break;
    }
    /* Results. */
    if (x->s[1] == 0) {
        return cm_fail(cm, CM_E_ENC_NO_MOTION, 0, 1000, 1);
    }
    const int64_t mean = x->s[0] / x->s[1];
    cm->res.enc_off = x->ang[1] + (fx_angle_t)(int32_t)mean;
    cm->hold_angle = x->ang[0];
    cm->hold_valid = 1u;
    return CM_DONE;
}
