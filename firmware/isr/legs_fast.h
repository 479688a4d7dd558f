/*
 * Plan -> centre-aligned leg duties for the PWM interrupt: ctrl_plan_to_legs
 * (control/plan.c) without its clamps, straight-line for the plans nearly
 * every controller produces, one vector (n_seg 1) or an active vector and a
 * zero vector (n_seg 2, ctrl_plan_active_zero), and in a short loop for three
 * or four segments. Same rule, same result for every input
 * (tests/loop/test_fw_fast.c compares them): the duty of leg x is the sum of
 * the on-times, each clamped to [0, FX_ONE], of the segments whose vector has
 * leg x high (Table 4.2), capped at FX_ONE; vector indices > 7 count as no leg
 * high. Plans with a bad n_seg or an on-time outside [0, FX_ONE] go to
 * ctrl_plan_to_legs.
 */
#ifndef FIRMWARE_LEGS_FAST_H
#define FIRMWARE_LEGS_FAST_H

#include <stdbool.h>
#include <stdint.h>

#include "ctrl_types.h"
#include "fx.h"
#include "plan.h"

/* Leg states of each vector index (Table 4.2: bit 0 = leg a, 1 = b, 2 = c;
 * V1 = 100 ... V6 = 101), 0 for the indices above 7: one byte load, no test. */
static const uint8_t fw_legs_mask_tab[256] = {0u, 1u, 3u, 2u, 6u, 4u, 5u, 7u};

/* Leg duties of a plan with one to four segments whose on-times lie in
 * [0, FX_ONE] (every plan the helpers build); returns false (legs not written)
 * for any other plan, whose duties ctrl_plan_to_legs computes. */
/* Three or four segments (SVM-like plans): the same sums in a loop. */
static inline bool fw_legs_fast34(const ctrl_plan_t *p, uint32_t n, ctrl_legs_t *legs)
{
    uint32_t a = 0u;
    uint32_t b = 0u;
    uint32_t c = 0u;
    uint32_t sum = 0u;
    for (uint32_t i = 0u; i < n; i++) {
        const uint32_t d = (uint32_t)p->dur[i];
        if (d > (uint32_t)FX_ONE) {
            return false;
        }
        const uint32_t m = fw_legs_mask_tab[p->vec[i]];
        a += d * (m & 1u);
        b += d * ((m >> 1) & 1u);
        c += d * (m >> 2);
        sum += d; /* <= 4 FX_ONE = 2^26 */
    }
    if (sum > (uint32_t)FX_ONE) {
        a = a < (uint32_t)FX_ONE ? a : (uint32_t)FX_ONE;
        b = b < (uint32_t)FX_ONE ? b : (uint32_t)FX_ONE;
        c = c < (uint32_t)FX_ONE ? c : (uint32_t)FX_ONE;
    }
    legs->duty[0] = (q24_t)a;
    legs->duty[1] = (q24_t)b;
    legs->duty[2] = (q24_t)c;
    return true;
}

static inline bool fw_legs_fast(const ctrl_plan_t *p, ctrl_legs_t *legs)
{
    const uint32_t n = p->n_seg;
    if (n - 1u > 1u) {
        /* 3 or 4 segments; 0 or out of range: ctrl_plan_to_legs. */
        return n - 3u <= 1u ? fw_legs_fast34(p, n, legs) : false;
    }
    /* One unsigned compare per on-time tests 0 <= dur <= FX_ONE (then the
     * clamp of ctrl_plan_to_legs changes nothing). */
    const uint32_t d0 = (uint32_t)p->dur[0];
    if (d0 > (uint32_t)FX_ONE) {
        return false;
    }
    const uint32_t m0 = fw_legs_mask_tab[p->vec[0]];
    if (n == 1u) {
        /* One segment: each duty is 0 or d0 <= FX_ONE. */
        legs->duty[0] = (q24_t)(d0 * (m0 & 1u));
        legs->duty[1] = (q24_t)(d0 * ((m0 >> 1) & 1u));
        legs->duty[2] = (q24_t)(d0 * (m0 >> 2));
        return true;
    }
    const uint32_t d1 = (uint32_t)p->dur[1];
    if (d1 > (uint32_t)FX_ONE) {
        return false;
    }
    const uint32_t m1 = fw_legs_mask_tab[p->vec[1]];
    /* On-time of each segment times its leg bit (0 or 1); sums <= 2^25. */
    uint32_t a = d0 * (m0 & 1u) + d1 * (m1 & 1u);
    uint32_t b = d0 * ((m0 >> 1) & 1u) + d1 * ((m1 >> 1) & 1u);
    uint32_t c = d0 * (m0 >> 2) + d1 * (m1 >> 2);
    if (d0 + d1 > (uint32_t)FX_ONE) {
        /* Only then can a sum exceed FX_ONE (the helpers' plans sum to it). */
        a = a < (uint32_t)FX_ONE ? a : (uint32_t)FX_ONE;
        b = b < (uint32_t)FX_ONE ? b : (uint32_t)FX_ONE;
        c = c < (uint32_t)FX_ONE ? c : (uint32_t)FX_ONE;
    }
    legs->duty[0] = (q24_t)a;
    legs->duty[1] = (q24_t)b;
    legs->duty[2] = (q24_t)c;
    return true;
}

/* Compare value of a leg duty d in [0, FX_ONE] for a period of n counts:
 * round(d n / 2^24) (ties up), in [0, n]; d n < 2^24 * 2^32 in 64 bits. */
static inline uint32_t fw_pwm_compare(uint32_t d, uint32_t n)
{
#if defined(__GNUC__)
    /* Emits nothing; keeps gcc from sign-extending d (from a q24_t) as if
     * it could be negative (an extra ASR and MLA per leg). */
    __asm__("" : "+r"(d));
#endif
    return (uint32_t)(((uint64_t)d * n + (1u << 23)) >> 24);
}

/* The same with n8 = n * 2^8 (n < 2^24): the high word of d n8 is
 * floor(d n / 2^24) and bit 31 of the low word is bit 23 of d n, the rounding
 * bit (one UMULL and one add). */
static inline uint32_t fw_pwm_compare8(uint32_t d, uint32_t n8)
{
#if defined(__GNUC__)
    __asm__("" : "+r"(d));
#endif
    const uint64_t p = (uint64_t)d * n8;
    return (uint32_t)(p >> 32) + ((uint32_t)p >> 31);
}

/* ctrl_plan_to_legs for every plan. */
static inline void fw_legs_from_plan(const ctrl_plan_t *p, ctrl_legs_t *legs)
{
    if (!fw_legs_fast(p, legs)) {
        ctrl_plan_to_legs(p, legs);
    }
}

#endif /* FIRMWARE_LEGS_FAST_H */
