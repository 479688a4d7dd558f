/*
 * Step "probe": is a motor connected, is a phase shorted, and a first
 * (coarse) inductance for tuning the current regulator of the later steps.
 *
 * Method (in the spirit of VESC's inductance probe, which raises the pulse
 * until the current is measurable, and ODrive's alternating-voltage
 * inductance measurement): along alpha, a volt-second-balanced pulse pattern
 * +V for m periods, -V for 2m, +V for m, then rest; V starts at v_probe0 and
 * doubles - grows by half once the response is a quarter of the target - (then
 * m doubles once V reaches the standstill voltage limit) until the first
 * segment's current change reaches i_probe. The inductance comes
 * from the middle segment, where the current swings from +dI to -dI:
 *     L = Ts sum(v_alpha applied) / (i_end - i_start)
 * Its symmetric swing through zero makes the dead-time error change sign
 * half-way, so it cancels to first order; the resistive drop of a symmetric
 * swing cancels likewise. The result is within a few per cent, enough for
 * the regulator (its crossover moves by the same factor).
 * Verdicts: no measurable current (< i_open) at the largest pattern:
 * open_phase (motor not connected); L below l_min, or an over-current trip
 * during a pattern (cm_abort_fault): shorted_phase; L above l_max: l_range;
 * the three currents not summing to zero (third channel present): sense_sum.
 */
#include "cm_internal.h"

/* Scratch: a[0] = V, k[0] = m, k[1] = pattern period index p, s[0] = acted
 * volt-periods of segment 1, s[1] = of segment 2, a[1] = i at start,
 * a[2] = i after segment 1, k[2] = worst |sum of the three currents|. */
#define CM_PROBE_M_MAX 64

void cm_probe_begin(cm_t *cm)
{
    cm->x.a[0] = cm->par.v_probe0;
    cm->x.k[0] = 1;
    cm->x.k[1] = -1; /* first period starts a pattern */
}

static void cm_probe_cmd(cm_t *cm, q24_t v, cm_out_t *out)
{
    cm_modulate(cm, v, 0, out);
}

int cm_probe_period(cm_t *cm, const cm_in_t *in, cm_out_t *out)
{
    cm_scratch_t *x = &cm->x;
    const int32_t m = x->k[0];
    const q24_t v = x->a[0];
    int32_t p = ++x->k[1];
    if (p == 0) {
        x->a[1] = cm->io.i_al;
        x->s[0] = x->s[1] = 0;
    }
    /* Accumulate the acted voltage (commanded at p-2). */
    q24_t va = 0, vb = 0;
    const bool known = cm_acted(cm, 0u, &va, &vb);
    const int32_t j = p - 2; /* pattern index of the acted voltage */
    if (known && j >= 0 && j < m) {
        x->s[0] += va;
    } else if (known && j >= m && j < 3 * m) {
        x->s[1] += va;
    }
    if (cm->par.has_i_c) {
        const q24_t sum = fx_abs(fx_add(fx_add(in->i_a, in->i_b), in->i_c));
        x->k[2] = fx_max(x->k[2], sum);
    }
    const q24_t di = fx_sub(cm->io.i_al, x->a[1]);
    if (p == m + 1) {
        x->a[2] = cm->io.i_al;
        x->a[3] = fx_abs(di);
    }
    /* A current far beyond the target: stop driving (gates off), classify. */
    if (fx_abs(di) > 4 * cm->par.i_probe && p <= 3 * m + 1) {
        cm_out_off(cm, out);
        q24_t l = 0;
        (void)cm_muldiv(j < m ? x->s[0] : -x->s[1], cm->par.ts, fx_abs(di), &l);
        return cm_fail(cm, CM_E_SHORTED_PHASE, fx_abs(di), l, 0);
    }
    if (p < m) {
        cm_probe_cmd(cm, v, out);
    } else if (p < 3 * m) {
        cm_probe_cmd(cm, fx_neg(v), out);
    } else if (p < 4 * m) {
        cm_probe_cmd(cm, v, out);
    } else {
        cm_probe_cmd(cm, 0, out);
    }
    cm->progress = (uint16_t)fx_min(999, (q24_t)(cm->t_step / 8u));
    if (p < 3 * m + 1) {
        return CM_RUN;
    }
    if (p == 3 * m + 1) {
        /* Segment 2 acted fully: from +dI (p = m+1) to -dI (now). */
        x->a[4] = fx_sub(cm->io.i_al, x->a[2]);
        return CM_RUN;
    }
    /* Rest until the current has decayed (4m + 8 periods of zero volts). */
    if (p < 8 * m + 8) {
        return CM_RUN;
    }
    const q24_t d1 = x->a[3];
    if (cm->par.has_i_c && x->k[2] > fx_add(d1 / 5, 4 * cm->par.i_lsb) && d1 > cm->par.i_open) {
        return cm_fail(cm, CM_E_SENSE_SUM, x->k[2], d1, 0);
    }
    if (d1 < cm->par.i_probe) {
        /* Not enough current yet: raise V, then m; at the largest pattern,
         * no current is an open phase and a little current a large L. */
        bool more = true;
        if (d1 >= cm->par.i_probe / 4 && v <= (cm->par.v_lim / 3) * 2) {
            /* A measurable response: half as much again, not twice (with a
             * small L and the inverter's error eating the small pulses, the
             * response grows faster than V: doubling can overshoot the
             * target by more than the 4x that reads as a short). */
            x->a[0] = v + v / 2;
        } else if (v <= cm->par.v_lim / 2) {
            x->a[0] = 2 * v;
        } else if (v < cm->par.v_lim) {
            x->a[0] = cm->par.v_lim;
        } else if (m < CM_PROBE_M_MAX) {
            x->k[0] = 2 * m;
        } else if (d1 < cm->par.i_open) {
            return cm_fail(cm, CM_E_OPEN_PHASE, d1, cm->par.i_open, v);
        } else {
            more = false;
        }
        if (more) {
            x->k[1] = -1;
            x->k[2] = 0;
            return CM_RUN;
        }
    }
    /* L = Ts sum(v) / di over segment 2 (volt-periods and a negative swing). */
    q24_t l = 0;
    const q24_t swing = x->a[4];
    if (!cm_muldiv(x->s[1], cm->par.ts, swing, &l) || l <= 0) {
        return cm_fail(cm, CM_E_L_RANGE, 0, cm->par.l_min, cm->par.l_max);
    }
    if (l < cm->par.l_min) {
        return cm_fail(cm, CM_E_SHORTED_PHASE, d1, l, 0);
    }
    if (l > cm->par.l_max) {
        return cm_fail(cm, CM_E_L_RANGE, l, cm->par.l_min, cm->par.l_max);
    }
    cm->res.l_probe = l;
    cm_out_off(cm, out);
    return CM_DONE;
}
