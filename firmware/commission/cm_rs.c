/*
 * Step "rs": stator resistance by DC injection at two current levels, along
 * each phase's axis in turn, and the phase-balance check.
 *
 * Method (VESC and ODrive lock the field and take R = V / I at one current;
 * here two levels and the slope, which cancels the inverter's voltage drop): the current is
 * regulated along the axis of phase a (0 deg), then of phase b (120 deg),
 * then of phase c (240 deg). On each axis the rotor is pulled towards the
 * field at i_rs1 and let come to rest (cm_hold damps its swing), the current
 * rises to i_rs2 and the rotor rests again, and over a window the applied
 * voltage along the axis and the measured current are averaged; then the
 * same at i_rs1. The larger level first: a rotor that stiction, cogging or a
 * load hold short of the field stays where it is when the torque falls,
 * where it would creep on when it rose. (The field turns to the next axis
 * at the smaller level: a free rotor swings less.) A window in which the rotor moved on by more
 * than two encoder counts (its back-EMF would enter the voltage) runs again after the wait. The
 * inverter's error along the axis - dead time (Vdc t_d / Ts per leg) and the devices' forward drops
 * - depends only on the signs of the phase currents, the same at both
 * levels, so the slope
 *     R_k = (V2 - V1) / (I2 - I1)
 * is free of it; the intercept V1 - R_k I1 is that error (v_inv, reported
 * for axis a). With the rotor at rest there is no back-EMF, and L di/dt
 * averages out over a window of constant current.
 * Rs is the mean of the three slopes. Phase balance: along phase x's axis
 * the slope is (2 R_x + (R_y + R_z) / 2) / 3, so the slopes differ by half
 * the differences of the phase resistances; unbalance = (max - min) / Rs
 * above unbalance_max: unbalanced (one phase's resistance off by about
 * twice that fraction).
 * Test levels: i_rs1, i_rs2 within the voltage (cm_configure: what 80 % of
 * v_lim drives through the configured Rs, the ratio kept); below i_min:
 * supply (the motor cannot be identified on this supply).
 * Verdicts: a slope <= 0: rs_range; the regulator at its voltage limit in a
 * window: voltage_limit (resistance above the configured one, or an open
 * phase); the rotor not settling: enc_unsteady.
 * The rotor ends at rest near phase c's axis (hold_angle).
 */
#include "cm_internal.h"

enum { P_ALIGN, P_RAISE, P_WIN2, P_LOWER, P_WIN1 };

static const fx_angle_t cm_rs_axis[3] = {0u, 0x55555555u, 0xAAAAAAABu};

/* Scratch: k[1] axis 0..2, a[0] start current of the align ramp, k[0]
 * periods at rest, s[0]/s[1] sum v / i of window 1, s[2]/s[3] of window 2,
 * s[4] n1, s[5] n2, s[6] encoder position at the window's start; a[1..3]
 * slopes of the axes, a[4] v_inv of axis a. */

void cm_rs_begin(cm_t *cm)
{
    if (!cm->hold_valid) {
        cm_pi_reset(&cm->pi_d, 0);
        cm_pi_reset(&cm->pi_q, 0);
        cm->x.a[0] = 0;
    } else {
        cm->x.a[0] = cm->hold_i;
    }
    cm->hold_angle = cm_rs_axis[0];
    cm_pi_tune_dq(cm, cm_l_best(cm), cm_l_best(cm), cm->par.v_lim);
}

static void cm_rs_window(cm_t *cm, int64_t *sv, int64_t *si, int64_t *n)
{
    q24_t vd, vq, id, iq;
    if (cm_acted(cm, cm->hold_angle, &vd, &vq)) {
        cm_to_frame(cm->io.i_al, cm->io.i_be, cm->hold_angle, &id, &iq);
        *sv += vd;
        *si += id;
        (*n)++;
    }
}

/* Slope of the axis just measured; false (with the error set) if implausible. */
static int cm_rs_axis_done(cm_t *cm)
{
    cm_scratch_t *x = &cm->x;
    const q24_t v1 = cm_mean(x->s[0], (uint32_t)x->s[4]);
    const q24_t i1 = cm_mean(x->s[1], (uint32_t)x->s[4]);
    const q24_t v2 = cm_mean(x->s[2], (uint32_t)x->s[5]);
    const q24_t i2 = cm_mean(x->s[3], (uint32_t)x->s[5]);
    q24_t r = 0;
    if (!cm_ratio((int64_t)v2 - v1, (int64_t)i2 - i1, &r) || r <= 0) {
        return cm_fail(cm, CM_E_RS_RANGE, fx_sub(v2, v1), fx_sub(i2, i1), x->k[1]);
    }
    x->a[1 + x->k[1]] = r;
    if (x->k[1] == 0) {
        x->a[4] = fx_sub(v1, fx_mul(r, i1));
    }
    for (int k = 0; k < 6; k++) {
        x->s[k] = 0;
    }
    return CM_RUN;
}

int cm_rs_period(cm_t *cm, const cm_in_t *in, cm_out_t *out)
{
    (void)in;
    cm_scratch_t *x = &cm->x;
    const cm_par_t *p = &cm->par;
    const fx_angle_t h = cm->hold_angle;
    const bool two = cm->phase == P_RAISE || cm->phase == P_WIN2;
    const q24_t lvl = two ? p->i_rs2 : p->i_rs1;
    cm->progress = (uint16_t)((uint32_t)x->k[1] * 333u + cm->phase * 66u);
    if (cm->phase == P_ALIGN && p->i_rs2 < p->i_min) {
        return cm_fail_supply(cm, p->rs_cfg, p->v_lim);
    }
    if (cm->phase != P_WIN2 && cm->phase != P_WIN1) {
        /* ramp to the level, then wait until the rotor rests for n_settle */
        cm_hold(cm, h, 0, fx_add(x->a[0], cm_ramp(fx_sub(lvl, x->a[0]), cm->t, p->n_ramp)), 0, 0,
                out);
        x->k[0] = cm->t >= p->n_ramp && cm_slip(cm) < p->w_settle ? x->k[0] + 1 : 0;
        if (x->k[0] >= (int32_t)p->n_settle) {
            cm->hold_valid = 1u;
            x->s[6] = cm->io.pos;
            x->a[0] = lvl;
            x->k[0] = 0;
            cm_next(cm);
        } else if (cm->t >= p->n_hold_max) {
            return cm_fail(cm, CM_E_ENC_UNSTEADY, cm_slip(cm), p->w_settle, 0);
        }
        return CM_RUN;
    }
    /* P_WIN2, P_WIN1 */
    cm_hold(cm, h, 0, lvl, 0, 0, out);
    if (cm->pi_d.sat) {
        return cm_fail(cm, CM_E_VOLTAGE_LIMIT, lvl, p->v_lim, 0);
    }
    cm_rs_window(cm, &x->s[two ? 2 : 0], &x->s[two ? 3 : 1], &x->s[two ? 5 : 4]);
    if (cm->t < p->n_win) {
        return CM_RUN;
    }
    /* A rotor that moved on in the window (the back-EMF of a rotor that
     * creeps after the field enters the voltage; an aligned rotor's swing
     * adds only a second-order term): the window again, from the wait. */
    const int64_t mv = cm->io.pos - x->s[6];
    if (mv > 2 * (int64_t)p->enc_count || mv < -2 * (int64_t)p->enc_count) {
        x->s[two ? 2 : 0] = x->s[two ? 3 : 1] = x->s[two ? 5 : 4] = 0;
        x->a[0] = lvl;
        x->k[0] = 0;
        cm->phase--;
        cm->t = 0u;
        cm->t_fresh = 1u;
        return CM_RUN;
    }
    x->a[0] = lvl;
    x->k[0] = 0;
    if (two) {
        cm_next(cm);
        return CM_RUN;
    }
    if (cm_rs_axis_done(cm) == CM_FAIL) {
        return CM_FAIL;
    }
    if (x->k[1] < 2) {
        /* Next axis: the field turns by 120 deg, the rotor follows. */
        x->k[1]++;
        cm->hold_angle = cm_rs_axis[x->k[1]];
        cm->phase = P_ALIGN;
        cm->t = 0u;
        cm->t_fresh = 1u;
        return CM_RUN;
    }
    const q24_t r0 = x->a[1], r1 = x->a[2], r2 = x->a[3];
    const q24_t rs = (q24_t)(((int64_t)r0 + r1 + r2) / 3);
    const q24_t spread = fx_sub(fx_max(r0, fx_max(r1, r2)), fx_min(r0, fx_min(r1, r2)));
    q24_t u = 0;
    if (!cm_ratio(spread, rs, &u)) {
        u = FX_MAX;
    }
    cm->res.rs = rs;
    cm->res.v_inv = x->a[4];
    cm->res.unbalance = u;
    cm->res.have |= CM_HAVE_BALANCE;
    if (u > p->unbalance_max) {
        return cm_fail(cm, CM_E_UNBALANCED, u, p->unbalance_max, 0);
    }
    /* the later steps' currents from the measured Rs and inverter error
     * (the step table marks Rs as had on CM_DONE; the same now) */
    cm->res.have |= CM_HAVE_RS;
    cm_refit_currents(cm);
    return CM_DONE;
}
