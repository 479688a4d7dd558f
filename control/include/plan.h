/*
 * Switching plans, their realisation as centre-aligned leg duties, and the
 * period-average voltage of leg duties.
 *
 * A plan (ctrl_types.h) lists voltage vectors and their on-times as Q24
 * fractions of the period. The duty of leg x is the sum of the on-times of the
 * segments whose vector has leg x high (Table 4.2). With centre-aligned PWM
 * this gives the same period-average phase voltages as applying the segments
 * one after the other, and an active vector followed by ctrl_zero_after()
 * switches exactly one leg pair per period.
 */
#ifndef CONTROL_PLAN_H
#define CONTROL_PLAN_H

#include <stdint.h>

#include "ctrl_types.h"
#include "fx.h"
#include "vectors.h"

/* One vector for the whole period. */
static inline void ctrl_plan_single(ctrl_plan_t *p, uint8_t vec)
{
    p->n_seg = 1u;
    p->vec[0] = vec;
    p->dur[0] = FX_ONE;
}

/* Active vector vec for duty (clamped to [0, FX_ONE]), the rest of the period
 * the zero vector ctrl_zero_after(vec). Segment 0 is vec. */
static inline void ctrl_plan_active_zero(ctrl_plan_t *p, uint8_t vec, q24_t duty)
{
    const q24_t d = fx_clamp(duty, 0, FX_ONE);
    p->n_seg = 2u;
    p->vec[0] = vec;
    p->vec[1] = vec <= 7u ? ctrl_vec_zero_after[vec] : 0u;
    p->dur[0] = d;
    p->dur[1] = FX_ONE - d;
}

/* An on-time clamped to [0, FX_ONE], as an unsigned number (one unsigned
 * compare in the usual case). */
static inline uint32_t ctrl_plan_dur(q24_t d)
{
    const uint32_t u = (uint32_t)d;
    if (u > (uint32_t)FX_ONE) {
        return d < 0 ? 0u : (uint32_t)FX_ONE;
    }
    return u;
}

/* Each of a, b, c capped at FX_ONE (only needed when the on-times sum above it). */
static inline void ctrl_legs_put(ctrl_legs_t *legs, uint32_t a, uint32_t b, uint32_t c,
                                 uint32_t sum)
{
    if (sum > (uint32_t)FX_ONE) {
        a = a < (uint32_t)FX_ONE ? a : (uint32_t)FX_ONE;
        b = b < (uint32_t)FX_ONE ? b : (uint32_t)FX_ONE;
        c = c < (uint32_t)FX_ONE ? c : (uint32_t)FX_ONE;
    }
    legs->duty[0] = (q24_t)a;
    legs->duty[1] = (q24_t)b;
    legs->duty[2] = (q24_t)c;
}

/*
 * Centre-aligned leg duties realising the plan's volt-seconds, each in
 * [0, FX_ONE]: every on-time clamped to [0, FX_ONE], segments beyond
 * CTRL_PLAN_MAX_SEG ignored, vector indices > 7 count as no leg high
 * (ctrl_vec_legs), each sum capped at FX_ONE; n_seg 0 gives V0. Straight-line
 * for one segment and for an active vector with its zero vector (the plans of
 * nearly every controller), a short loop for three or four.
 */
static inline void ctrl_plan_legs(const ctrl_plan_t *p, ctrl_legs_t *legs)
{
    const uint32_t n = p->n_seg;
    if (n - 1u > 1u) {
        /* 0, 3, 4 or more segments. */
        const uint32_t nn = n < CTRL_PLAN_MAX_SEG ? n : CTRL_PLAN_MAX_SEG;
        uint32_t a = 0u;
        uint32_t b = 0u;
        uint32_t c = 0u;
        uint32_t sum = 0u;
        for (uint32_t i = 0u; i < nn; i++) {
            const uint32_t d = ctrl_plan_dur(p->dur[i]);
            const uint32_t m = ctrl_vec_legs[p->vec[i]];
            a += d * (m & 1u);
            b += d * ((m >> 1) & 1u);
            c += d * (m >> 2);
            sum += d; /* <= 4 FX_ONE = 2^26 */
        }
        ctrl_legs_put(legs, a, b, c, sum);
        return;
    }
    const uint32_t d0 = ctrl_plan_dur(p->dur[0]);
    const uint32_t m0 = ctrl_vec_legs[p->vec[0]];
    if (n == 1u) {
        /* Each duty is 0 or d0 <= FX_ONE. */
        legs->duty[0] = (q24_t)(d0 * (m0 & 1u));
        legs->duty[1] = (q24_t)(d0 * ((m0 >> 1) & 1u));
        legs->duty[2] = (q24_t)(d0 * (m0 >> 2));
        return;
    }
    const uint32_t d1 = ctrl_plan_dur(p->dur[1]);
    const uint32_t m1 = ctrl_vec_legs[p->vec[1]];
    /* On-time of each segment times its leg bit (0 or 1); sums <= 2^25. */
    ctrl_legs_put(legs, d0 * (m0 & 1u) + d1 * (m1 & 1u),
                  d0 * ((m0 >> 1) & 1u) + d1 * ((m1 >> 1) & 1u), d0 * (m0 >> 2) + d1 * (m1 >> 2),
                  d0 + d1);
}

/* A step's output from its plan: the leg duties that realise it. */
static inline void ctrl_out_plan(ctrl_out_t *o)
{
    ctrl_plan_legs(&o->plan, &o->legs);
}

/* One vector for the whole period, plan and leg duties. */
static inline void ctrl_out_single(ctrl_out_t *o, uint8_t vec)
{
    ctrl_plan_single(&o->plan, vec);
    const uint32_t m = ctrl_vec_legs[vec];
    o->legs.duty[0] = (q24_t)((m & 1u) << FX_QBITS);
    o->legs.duty[1] = (q24_t)(((m >> 1) & 1u) << FX_QBITS);
    o->legs.duty[2] = (q24_t)((m >> 2) << FX_QBITS);
}

/* Active vector vec (1..6) for duty (clamped to [0, FX_ONE]), its zero vector
 * ctrl_zero_after(vec) the rest: the plan of ctrl_plan_active_zero and its
 * leg duties (= ctrl_out_plan of it, without the general sum): a leg high in
 * vec is on for d, and for the rest too when the zero vector is V7. */
static inline void ctrl_out_active_zero(ctrl_out_t *o, uint8_t vec, q24_t duty)
{
    const uint32_t v = vec <= 7u ? vec : 0u;
    const uint32_t d = ctrl_plan_dur(duty);
    const uint32_t z = ctrl_vec_zero_after[v]; /* 0 or 7 */
    o->plan.n_seg = 2u;
    o->plan.vec[0] = (uint8_t)v;
    o->plan.vec[1] = (uint8_t)z;
    o->plan.dur[0] = (q24_t)d;
    o->plan.dur[1] = (q24_t)((uint32_t)FX_ONE - d);
    const uint32_t m = ctrl_vec_legs[v];
    const uint32_t rest = ((uint32_t)FX_ONE - d) & (0u - (z & 1u)); /* V7: all legs high */
    o->legs.duty[0] = (q24_t)(rest + (d & (0u - (m & 1u))));
    o->legs.duty[1] = (q24_t)(rest + (d & (0u - ((m >> 1) & 1u))));
    o->legs.duty[2] = (q24_t)(rest + (d & (0u - (m >> 2))));
}

/* Stator-frame voltage of leg duties per unit of DC link, Q24, (4.4)
 * averaged: (2 d_a - d_b - d_c) / 3 and (d_b - d_c) / sqrt(3). The
 * differences are exact in 64 bits (|.| < 2^33 for any int32_t duties), times
 * a Q30 constant < 2^30 (< 2^63), rounded once. */
static inline void ctrl_legs_uab(const ctrl_legs_t *legs, q24_t *u_alpha, q24_t *u_beta)
{
    const int64_t da = legs->duty[0];
    const int64_t db = legs->duty[1];
    const int64_t dc = legs->duty[2];
    *u_alpha = fx_round_sat((2 * da - db - dc) * FX_Q30_1_3, 30u);
    *u_beta = fx_round_sat((db - dc) * FX_Q30_INV_SQRT3, 30u);
}

/* Period-average alpha/beta voltage of leg duties (each in [0, FX_ONE], or
 * a dead-time-corrected duty slightly beyond; taken within [-2, 2)) at DC
 * link vdc: vdc times ctrl_legs_uab; for the duties of a plan whose on-times
 * sum to at most FX_ONE this equals the sum over its segments of dur_i V_i. */
void ctrl_legs_voltage(const ctrl_legs_t *legs, q24_t vdc, q24_t *v_alpha, q24_t *v_beta);

#endif /* CONTROL_PLAN_H */
