/*
 * Space-vector PWM, min-max injection form (see svpwm.h), in units of the
 * DC link. Integer-only.
 */
#include "svpwm.h"

#include "transforms.h"

/* The reference in units of the DC link, normally Q28 (1 << SVPWM_QN = vdc;
 * the leg duties need no further product), Q16 for a reference of 4 vdc or
 * more (then only its limit is wanted). */
#define SVPWM_QN 28u
#define SVPWM_QC 16u

/* Phase voltages of v / vdc (inverse Clarke (3.3)), their max and min and
 * max - min, in Q(q). */
typedef struct {
    int32_t ph[3];
    int32_t mx, mn;
    uint32_t span; /* max - min, >= 0, < 2^32 */
    unsigned q;    /* SVPWM_QN or SVPWM_QC */
} svpwm_ph_t;

/* v / vdc with inv_vdc = 1 / vdc (Q24): products < 2^62 (both factors
 * int32_t). Q28 while |v| < 4 vdc (|p| < 2^50: the Q28 value within 2^30,
 * its phases within 1.37 2^30 and their span within 2.74 2^30, all
 * unsaturated), else Q16 (|p| < 2^62: the same bounds). */
static void svpwm_phases(q24_t va, q24_t vb, q24_t inv_vdc, svpwm_ph_t *o)
{
    const int64_t pa = (int64_t)va * inv_vdc;
    const int64_t pb = (int64_t)vb * inv_vdc;
    const int64_t big = (int64_t)1 << 50;
    int32_t ua;
    int32_t ub;
    if (pa < big && pa > -big && pb < big && pb > -big) {
        ua = fx_round_nosat(pa, 2u * FX_QBITS - SVPWM_QN);
        ub = fx_round_nosat(pb, 2u * FX_QBITS - SVPWM_QN);
        o->q = SVPWM_QN;
    } else {
        ua = fx_round_nosat(pa, 2u * FX_QBITS - SVPWM_QC);
        ub = fx_round_nosat(pb, 2u * FX_QBITS - SVPWM_QC);
        o->q = SVPWM_QC;
    }
    /* |ua|, |ub| <= 2^30: the inverse Clarke's sums within 1.37 2^30 */
    const int64_t half = (int64_t)ua * FX_Q30_HALF;
    const int64_t bq = (int64_t)ub * FX_Q30_SQRT3_2;
    const int32_t a = ua;
    const int32_t b = fx_round_nosat(bq - half, 30u);
    const int32_t c = fx_round_nosat(-bq - half, 30u);
    o->ph[0] = a;
    o->ph[1] = b;
    o->ph[2] = c;
    o->mx = fx_max(a, fx_max(b, c));
    o->mn = fx_min(a, fx_min(b, c));
    o->span = (uint32_t)o->mx - (uint32_t)o->mn;
}

/* Inside the hexagon: max - min <= vdc, and known to Q28. */
static int svpwm_inside(const svpwm_ph_t *p)
{
    return p->q == SVPWM_QN && p->span <= ((uint32_t)1 << SVPWM_QN);
}

/* (v_alpha, v_beta) scaled by vdc / span < 1 onto the hexagon (span >
 * vdc): k = floor(2^(q+30) / span) in Q30 (span > 2^q, so k < 2^30),
 * truncated so that the scaled vector does not land outside by rounding;
 * one 64-bit division, only when limiting. */
static void svpwm_scale(const svpwm_ph_t *p, q24_t *v_alpha, q24_t *v_beta)
{
    const int64_t k = (int64_t)(((uint64_t)1 << (p->q + 30u)) / p->span);
    *v_alpha = fx_round_nosat((int64_t)*v_alpha * k, 30u); /* |v k| < |v| 2^30 */
    *v_beta = fx_round_nosat((int64_t)*v_beta * k, 30u);
}

/* Limit onto the hexagon given the phases of v: a reference of 4 vdc or
 * more is first brought near it by its Q16 span, then, like any other
 * outside, onto it by its Q28 span. Leaves the phases of the result in *p
 * (inside, or on the hexagon within the rounding). Returns 1 if v was
 * scaled. */
static uint8_t svpwm_limit(q24_t inv_vdc, q24_t *v_alpha, q24_t *v_beta, svpwm_ph_t *p)
{
    uint8_t lim = 0u;
    for (unsigned pass = 0u; pass < 2u && !svpwm_inside(p); pass++) {
        const unsigned q = p->q;
        svpwm_scale(p, v_alpha, v_beta);
        svpwm_phases(*v_alpha, *v_beta, inv_vdc, p);
        lim = 1u;
        if (q == SVPWM_QN) {
            break; /* scaled by its Q28 span: on the hexagon */
        }
    }
    return lim;
}

/* Leg duties d_x = 1/2 + (2 v_x - max - min) / (2 vdc) (Q24, taken in
 * [0, 1] against residual rounding) from Q28 phases: |2 v_x - max - min|
 * <= max - min <= sqrt(3) |v| < 7 vdc < 2^31, exact in 32 bits (formed
 * modulo 2^32). */
static void svpwm_legs(const svpwm_ph_t *p, ctrl_legs_t *legs)
{
    const q24_t half = FX_ONE / 2;
    const uint32_t s = (uint32_t)p->mx + (uint32_t)p->mn;
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC unroll 3
#endif
    for (unsigned x = 0u; x < 3u; x++) {
        const int32_t diff = fx_u2i(2u * (uint32_t)p->ph[x] - s);
        const q24_t dv = fx_rshift32_round(diff, SVPWM_QN - FX_QBITS + 1u); /* Q28 * 2 -> Q24 */
        legs->duty[x] = fx_clamp(dv, -half, half) + half;
    }
}

static void svpwm_legs_off(ctrl_legs_t *legs)
{
    legs->duty[0] = 0;
    legs->duty[1] = 0;
    legs->duty[2] = 0;
}

/* For 2^17 < vdc < 2^26 by long division in 32-bit steps, four UDIV
 * instead of a 64-bit division: 2^32 = q vdc + r, then 6 + 6 + 4 more
 * quotient bits (the remainder stays below vdc < 2^26, so r 2^6 < 2^32);
 * q = floor(2^48 / vdc) < 2^31 there. Elsewhere fx_div itself. */
q24_t ctrl_svpwm_inv_vdc(q24_t vdc)
{
    const uint32_t d = (uint32_t)vdc;
    if (d <= ((uint32_t)1 << 17) || d >= ((uint32_t)1 << 26)) {
        return fx_div(FX_ONE, vdc);
    }
    uint32_t q = UINT32_MAX / d; /* 2^32 - 1 = q d + (r - 1) */
    uint32_t r = UINT32_MAX - q * d + 1u;
    if (r == d) {
        q++;
        r = 0u;
    }
    q = fx_udiv_digits(q, &r, d, 6u, 2u);
    q = fx_udiv_digits(q, &r, d, 4u, 1u);
    return (q24_t)fx_udiv_round(q, r, d); /* rounded as fx_div */
}

uint8_t ctrl_svpwm_limit(q24_t vdc, q24_t *v_alpha, q24_t *v_beta)
{
    if (vdc <= 0) {
        *v_alpha = 0;
        *v_beta = 0;
        return 1u;
    }
    const q24_t inv_vdc = ctrl_svpwm_inv_vdc(vdc);
    svpwm_ph_t p;
    svpwm_phases(*v_alpha, *v_beta, inv_vdc, &p);
    return svpwm_limit(inv_vdc, v_alpha, v_beta, &p);
}

void ctrl_svpwm_duties(q24_t v_alpha, q24_t v_beta, q24_t vdc, ctrl_legs_t *legs)
{
    if (vdc <= 0) {
        svpwm_legs_off(legs);
        return;
    }
    const q24_t inv_vdc = ctrl_svpwm_inv_vdc(vdc);
    svpwm_ph_t p;
    svpwm_phases(v_alpha, v_beta, inv_vdc, &p);
    if (p.q != SVPWM_QN) {
        /* 4 vdc or more (out of contract): the duties of its limit */
        svpwm_limit(inv_vdc, &v_alpha, &v_beta, &p);
    }
    svpwm_legs(&p, legs);
}

uint8_t ctrl_svpwm(q24_t *v_alpha, q24_t *v_beta, q24_t vdc, ctrl_legs_t *legs)
{
    /* ctrl_svpwm_limit then ctrl_svpwm_duties, bit for bit; the phases
     * formed once when the vector is inside the hexagon. */
    if (vdc <= 0) {
        *v_alpha = 0;
        *v_beta = 0;
        svpwm_legs_off(legs);
        return 1u;
    }
    const q24_t inv_vdc = ctrl_svpwm_inv_vdc(vdc);
    svpwm_ph_t p;
    svpwm_phases(*v_alpha, *v_beta, inv_vdc, &p);
    uint8_t lim = 0u;
    if (!svpwm_inside(&p)) {
        lim = svpwm_limit(inv_vdc, v_alpha, v_beta, &p);
    }
    svpwm_legs(&p, legs);
    return lim;
}
