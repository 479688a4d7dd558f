/*
 * Step "ldq": Ld and Lq at standstill, dead-time compensated, and saliency.
 *
 * Method (ODrive alternates +-V every period and takes L = V / (di/dt); VESC
 * separates Ld and Lq by injecting along the rotor axes): the rotor is held
 * by alignment - a DC bias i_hold along a phase axis (the rs step leaves the
 * rotor on phase c's), with the damping of cm_hold - and a voltage V_h of
 * alternating sign s_k = (-1)^k is added along the rotor's d axis (n_hf
 * periods), then along its q axis (n_hf periods), in the rotor frame of the
 * identified encoder offset. The current then zig-zags by dI = V_h Ts / L
 * per period around the bias. Demodulated over the window:
 *     L = Ts sum s_k (v_k - Rs (i_k + i_{k+1}) / 2) / sum s_k (i_{k+1} - i_k)
 * with v_k the applied voltage along the axis and i the axis current at the
 * two samples around the period it acted in.
 * Dead-time compensation: the bias keeps every phase current's sign fixed
 * (it lies on a phase axis: |i_x| >= i_hold / 2, and the zig-zag stays below
 * i_hold / 8), so the inverter's voltage error is the same constant in every
 * period and sum s_k e = 0 removes it, as it removes the regulator's slow
 * voltage; the resistive term uses the identified Rs (ignored before it
 * exists: a bias of Rs Ts / (2L), 0.3 % on the thesis SPMSM). The bias
 * regulator sees the mean of the last two samples, so it does not fight the
 * zig-zag.
 * Saliency: |Lq - Ld| above salient_min of their mean marks the machine
 * salient; otherwise both are set to the mean (a surface-magnet machine has
 * Ld = Lq, and controllers such as M2PTFC reject Ld > Lq).
 * Verdicts: L outside [l_min, l_max]: l_range.
 */
#include "cm_internal.h"

enum { P_ALIGN, P_D, P_Q };

/* Scratch: a[0] align start current, a[1] V_h, a[3] bias, k[0] settled
 * periods, s[0]/s[1] sums (v, di) of the running axis, a[2] = Ld. */

void cm_ldq_begin(cm_t *cm)
{
    cm->x.a[0] = cm->hold_valid ? cm->hold_i : 0;
    if (!cm->hold_valid) {
        cm->hold_angle = 0u;
        cm_pi_reset(&cm->pi_d, 0);
        cm_pi_reset(&cm->pi_q, 0);
    }
    /* The bias lies on the nearest phase axis (0, 120 or 240 deg): there every
     * phase current is at least half of it (the rs step ends on one). */
    const uint32_t third = 0x55555555u;
    const uint32_t k = (uint32_t)(((uint64_t)cm->hold_angle + third / 2u) / third) % 3u;
    cm->hold_angle = (fx_angle_t)(k * third + (k == 2u ? 1u : 0u));
    const q24_t l = cm_l_best(cm);
    cm_pi_tune_dq(cm, l, l, cm->par.v_lim);
    /* The bias within the voltage with its injection: Rs i + V_h, V_h =
     * (i / 8) L / Ts, within 80 % of v_lim (cm_i_within, through
     * Rs + L / (8 Ts)); at least 32 ADC counts (a zig-zag of 4 counts,
     * demodulated over n_hf periods), else supply. */
    q24_t l8 = 0;
    if (!cm_muldiv(l, FX_ONE, 8 * (int64_t)cm->par.ts, &l8)) {
        l8 = FX_MAX / 2;
    }
    const q24_t r = fx_add(cm_rs_best(cm), fx_min(l8, FX_MAX / 2));
    const q24_t bias = fx_min(cm->par.i_hold, cm_i_within(cm, cm->par.v_lim, 0, r));
    cm->x.a[3] = bias;
    /* V_h = dI L / Ts with dI = bias / 8, at most 3/4 of the voltage limit. */
    q24_t vh = 0;
    if (!cm_muldiv(bias / 8, l, cm->par.ts, &vh)) {
        vh = FX_MAX;
    }
    cm->x.a[1] = fx_min(vh, cm->par.v_lim - cm->par.v_lim / 4);
}

/* One demodulation sample along the rotor axis at angle ax. */
static void cm_ldq_sample(cm_t *cm, fx_angle_t ax, int32_t sign)
{
    cm_scratch_t *x = &cm->x;
    q24_t v, vo, i1, i0, o;
    if (!cm_acted(cm, ax, &v, &vo)) {
        return;
    }
    cm_to_frame(cm->io.i_al, cm->io.i_be, ax, &i1, &o);
    cm_to_frame(cm->io.i_al_prev, cm->io.i_be_prev, ax, &i0, &o);
    if ((cm->res.have & CM_HAVE_RS) != 0u) {
        v = fx_sub(v, fx_mul(cm->res.rs, (q24_t)(((int64_t)i0 + i1) / 2)));
    }
    x->s[0] += sign > 0 ? (int64_t)v : -(int64_t)v;
    x->s[1] += sign > 0 ? (int64_t)i1 - i0 : (int64_t)i0 - i1;
}

int cm_ldq_period(cm_t *cm, const cm_in_t *in, cm_out_t *out)
{
    (void)in;
    cm_scratch_t *x = &cm->x;
    const cm_par_t *p = &cm->par;
    const fx_angle_t h = cm->hold_angle;
    if (cm->phase == P_ALIGN) {
        cm->progress = 0u;
        if (x->a[3] < 32 * p->i_lsb) {
            /* the zig-zag (bias / 8) below 4 ADC counts */
            return cm_fail_supply(cm, cm_rs_best(cm), p->v_lim);
        }
        const q24_t i = fx_add(x->a[0], cm_ramp(fx_sub(x->a[3], x->a[0]), cm->t, p->n_ramp));
        cm_hold(cm, h, 0, i, 0, 0, out);
        x->k[0] = cm_slip(cm) < p->w_settle ? x->k[0] + 1 : 0;
        if (cm->t >= p->n_ramp && x->k[0] >= (int32_t)(p->n_settle / 2u)) {
            cm->hold_valid = 1u;
            cm->io.avg2 = 1u;
            cm_next(cm);
        } else if (cm->t >= p->n_hold_max) {
            return cm_fail(cm, CM_E_ENC_UNSTEADY, cm_slip(cm), p->w_settle, 0);
        }
        return CM_RUN;
    }
    cm->progress = (uint16_t)(((cm->phase - 1u) * p->n_hf + cm->t) * 500u / p->n_hf);
    /* Axis of this phase in the rotor frame; the injection in the hold frame. */
    const fx_angle_t ax = cm_rotor_angle(cm) + (cm->phase == P_Q ? 0x40000000u : 0u);
    /* The sign of the voltage commanded two periods ago (t counts from 0). */
    if (cm->t >= 2u) {
        cm_ldq_sample(cm, ax, ((cm->t - 2u) & 1u) == 0u ? 1 : -1);
    }
    const q24_t vh = (cm->t & 1u) == 0u ? x->a[1] : fx_neg(x->a[1]);
    q24_t s, c;
    fx_sincos(ax - h, &s, &c);
    q24_t ed = fx_mul(vh, c);
    q24_t eq = fx_mul(vh, s);
    const bool last = cm->t + 1u >= p->n_hf;
    if (last) {
        ed = eq = 0;
    }
    cm_hold(cm, h, 0, x->a[3], ed, eq, out);
    if (!last) {
        return CM_RUN;
    }
    q24_t l = 0;
    if (!cm_muldiv(x->s[0], p->ts, x->s[1], &l) || l <= 0) {
        return cm_fail(cm, CM_E_L_RANGE, 0, p->l_min, p->l_max);
    }
    if (l < p->l_min || l > p->l_max) {
        return cm_fail(cm, CM_E_L_RANGE, l, p->l_min, p->l_max);
    }
    x->s[0] = x->s[1] = 0;
    if (cm->phase == P_D) {
        cm->res.ld_raw = l;
        cm_next(cm);
        return CM_RUN;
    }
    cm->res.lq_raw = l;
    const q24_t ld = cm->res.ld_raw;
    const q24_t mean = (q24_t)(((int64_t)ld + l) / 2);
    cm->res.salient = fx_abs(fx_sub(l, ld)) > fx_mul(p->salient_min, mean) ? 1u : 0u;
    cm->res.ld = cm->res.salient ? ld : mean;
    cm->res.lq = cm->res.salient ? l : mean;
    cm->io.avg2 = 0u;
    return CM_DONE;
}
