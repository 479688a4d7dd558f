/* Dead-time and device-drop compensation (deadtime.h). Integer-only. */
#include "deadtime.h"

#if CTRL_DEAD_COMP

/* s(i) = i / band within [-1, 1], Q24: |i| < 2^31, inv_band < 2^31, the
 * product below 2^62. */
static inline q24_t dt_sign(const ctrl_deadtime_t *d, q24_t i)
{
    return fx_clamp(fx_round_sat((int64_t)i * d->inv_band, CTRL_DT_BAND_SHIFT), -FX_ONE, FX_ONE);
}

/* Leg x's written duty for the intended duty (deadtime.h): s the sign of
 * its current, high_prev whether it ended the last period high. */
static inline q24_t dt_leg(const ctrl_deadtime_t *d, q24_t duty, q24_t s, uint32_t high_prev)
{
    if (duty <= 0) {
        return 0; /* no edge; a pulse of t_d with i > 0 would be lost anyway */
    }
    /* corrections below 1/2 in magnitude (dd < 0.35, dt <= 0.25) */
    q24_t corr = fx_mul(d->dd, s);
    if (s < 0 && high_prev != 0u) {
        corr = fx_add(corr, fx_mul(d->dt, s)); /* the late falling edge at the start */
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
    q24_t s[3];
    s[0] = dt_sign(d, i_al);
    s[1] = dt_sign(d, fx_sub(root, half));
    s[2] = dt_sign(d, fx_neg(fx_add(root, half)));
    const uint32_t hp = d->high_prev;
    q24_t loss = 0;
    uint32_t pulses = 0u; /* bit x: leg x a pulse as intended */
    for (unsigned x = 0u; x < 3u; x++) {
        const q24_t du = legs->duty[x];
        const uint32_t high = hp & (1u << x);
        if (du >= FX_ONE) {
            if (high == 0u && s[x] > 0) {
                /* high all period after a low end: the rising edge at the
                 * start is late and this leg cannot make up for it */
                loss = fx_max(loss, fx_mul(d->dt, s[x]));
            }
        } else if (du > 0) {
            pulses |= 1u << x;
        }
        legs->duty[x] = dt_leg(d, du, s[x], high);
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
