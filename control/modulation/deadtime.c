/* Dead-time and device-drop compensation (deadtime.h). Integer-only. */
#include "deadtime.h"

#if CTRL_DEAD_COMP

/* sat(i / w) within [-1, 1], Q24: |i| < 2^31, inv_w < 2^31, the product
 * below 2^62. */
static inline q24_t dt_sign(const ctrl_deadtime_t *d, q24_t i)
{
    return fx_clamp(fx_round_sat((int64_t)i * d->inv_w, CTRL_DT_BAND_SHIFT), -FX_ONE, FX_ONE);
}

/* |ripple| of leg x's current at its edges (deadtime.h), Q24 pu: kr the
 * ripple per unit of the bracket at this period's DC link, dx the leg's duty,
 * dy and dz the others', each in [0, FX_ONE] (the bracket within [-1/2, 1/2]:
 * no saturation before kr's). */
static inline q24_t dt_ripple(q24_t kr, q24_t dx, q24_t dy, q24_t dz)
{
    const q24_t ey = dy - dx;
    const q24_t ez = dz - dx;
    const q24_t bracket = fx_max(ey, 0) + fx_max(ez, 0) - fx_mul(ey + ez, FX_ONE - dx);
    return fx_abs(fx_mul(kr, bracket));
}

/* The leg's sign at full compensation times 2: the sum of its two edges'
 * smoothed signs, the current at them i -+ r (deadtime.h), Q24 in [-2, 2]
 * (halved where it multiplies: one rounding). */
static inline q24_t dt_sign2_edges(const ctrl_deadtime_t *d, q24_t i, q24_t r)
{
    return dt_sign(d, fx_sub(i, r)) + dt_sign(d, fx_add(i, r));
}

/* x s2 / 2, Q24: x a correction below 1/2 (dd < 0.35, dt <= 0.25), |s2| <= 2:
 * the product below 2^50. */
static inline q24_t dt_half_mul(q24_t x, q24_t s2)
{
    return fx_round_sat((int64_t)x * s2, FX_QBITS + 1u);
}

/* Leg x's written duty for the intended duty (deadtime.h): s2 twice the sign
 * of its pulse's edges, s0 the sign of its current at the period's start
 * (the ripple's zero), high_prev whether it ended the last period high. */
static inline q24_t dt_leg(const ctrl_deadtime_t *d, q24_t duty, q24_t s2, q24_t s0,
                           uint32_t high_prev)
{
    if (duty <= 0) {
        return 0; /* no edge; a pulse of t_d with i > 0 would be lost anyway */
    }
    /* corrections below 1/2 in magnitude (dd < 0.35, dt <= 0.25) */
    q24_t corr = dt_half_mul(d->dd, s2);
    if (s0 < 0 && high_prev != 0u) {
        corr = fx_add(corr, fx_mul(d->dt, s0)); /* the late falling edge at the start */
    }
    return fx_clamp(fx_add(duty, corr), 0, FX_ONE);
}

void ctrl_deadtime_apply(ctrl_deadtime_t *d, const ctrl_estimate_t *est, ctrl_legs_t *legs)
{
    if (d->dd == 0) {
        return;
    }
    /* The predicted current of k+1 at the middle of [k+1, k+2). */
    const fx_angle_t theta = est->next.theta_e + (fx_angle_t)(est->dtheta / 2);
    q24_t sn;
    q24_t cs;
    fx_sincos_inline(theta, &sn, &cs);
    /* Inverse Park and Clarke (|i_dq| < 2^30, |sin|, |cos| <= 2^24: the sums
     * below 2^55; the phase currents below 2^31). */
    const int64_t id = est->next.i_d;
    const int64_t iq = est->next.i_q;
    const q24_t i_al = fx_round_sat(id * cs - iq * sn, 24u);
    const q24_t i_be = fx_round_sat(id * sn + iq * cs, 24u);
    const q24_t half = fx_rshift32_round(i_al, 1u);
    const q24_t root = fx_round_sat((int64_t)i_be * FX_Q30_SQRT3_2, 30u);
    q24_t i[3];
    i[0] = i_al;
    i[1] = fx_sub(root, half);
    i[2] = fx_neg(fx_add(root, half));
    /* The ripple at each leg's edges from the three duties at this period's
     * DC link (Q24 pu per unit of the bracket). */
    q24_t du[3];
    for (unsigned x = 0u; x < 3u; x++) {
        du[x] = fx_clamp(legs->duty[x], 0, FX_ONE);
    }
    const q24_t kr = fx_mul(d->k_rip, est->vdc);
    q24_t s2[3];
    s2[0] = dt_sign2_edges(d, i[0], dt_ripple(kr, du[0], du[1], du[2]));
    s2[1] = dt_sign2_edges(d, i[1], dt_ripple(kr, du[1], du[2], du[0]));
    s2[2] = dt_sign2_edges(d, i[2], dt_ripple(kr, du[2], du[0], du[1]));
    const uint32_t hp = d->high_prev;
    q24_t loss = 0;
    uint32_t pulses = 0u; /* bit x: leg x a pulse as intended */
    for (unsigned x = 0u; x < 3u; x++) {
        const uint32_t high = hp & (1u << x);
        if (du[x] >= FX_ONE) {
            if (high == 0u && s2[x] > 0) {
                /* high all period after a low end: the rising edge at the
                 * start is late and this leg cannot make up for it (a leg
                 * at 1 has no ripple term: s2 is twice its current's sign at
                 * the start) */
                loss = fx_max(loss, dt_half_mul(d->dt, s2[x]));
            }
        } else if (du[x] > 0) {
            pulses |= 1u << x;
        }
        /* the start's falling edge (after a high end) sees the current at
         * the ripple's zero */
        const q24_t s0 = high != 0u ? dt_sign(d, i[x]) : 0;
        legs->duty[x] = dt_leg(d, du[x], s2[x], s0, high);
    }
    if (loss > 0) {
        /* ... the others' pulses by as much less: the line voltages are kept */
        for (unsigned x = 0u; x < 3u; x++) {
            if ((pulses & (1u << x)) != 0u) {
                legs->duty[x] = fx_max(fx_sub(legs->duty[x], loss), 0);
            }
        }
    }
}

void ctrl_deadtime_written(ctrl_deadtime_t *d, const ctrl_legs_t *written)
{
    d->high_prev = (written->duty[0] >= FX_ONE ? 1u : 0u) | (written->duty[1] >= FX_ONE ? 2u : 0u) |
                   (written->duty[2] >= FX_ONE ? 4u : 0u);
}
#endif /* CTRL_DEAD_COMP */
