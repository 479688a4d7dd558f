/*
 * Space-vector PWM, min-max injection form (see svpwm.h). Integer-only.
 */
#include "svpwm.h"

#include "transforms.h"

/* Phase voltages of (v_alpha, v_beta) and their max and min (inverse Clarke). */
static void svpwm_phases(q24_t va, q24_t vb, q24_t ph[3], q24_t *mx, q24_t *mn)
{
    ctrl_inv_clarke(va, vb, &ph[0], &ph[1], &ph[2]);
    *mx = fx_max(ph[0], fx_max(ph[1], ph[2]));
    *mn = fx_min(ph[0], fx_min(ph[1], ph[2]));
}

/* (v_alpha, v_beta) scaled by vdc / span < 1 onto the hexagon (span > vdc > 0). */
static void svpwm_scale(q24_t vdc, int64_t span, q24_t *v_alpha, q24_t *v_beta)
{
    /* k = vdc / span < 1 in Q30 (span < 2^32, vdc < 2^31: the quotient fits),
     * truncated so the scaled vector does not land outside by rounding. */
    const int64_t k = ((int64_t)vdc * ((int64_t)1 << 30)) / span;
    *v_alpha = fx_sat32(fx_rshift64_round((int64_t)*v_alpha * k, 30u));
    *v_beta = fx_sat32(fx_rshift64_round((int64_t)*v_beta * k, 30u));
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

/* Leg duties from the phase voltages, their max and min and 0 < vdc < 2^30
 * (64 pu, svpwm_vdc). */
static void svpwm_legs(const q24_t ph[3], q24_t mx, q24_t mn, q24_t vdc, ctrl_legs_t *legs)
{
    const q24_t inv_vdc = ctrl_svpwm_inv_vdc(vdc); /* Q24, one division per period */
    for (unsigned x = 0u; x < 3u; x++) {
        /* d_x = 1/2 + (2 v_x - max - min) / (2 Vdc), the difference as
         * (v_x - max) + (v_x - min): terms of opposite signs, each saturated,
         * so the sum cannot overflow. Inside the hexagon (after the limit)
         * neither saturates: span = max - min <= 1.19 vdc + 4 < 2^31 (the
         * limit scales by vdc / span, rounding adds at most 4 LSB, 1.19
         * bounds what saturated phases under-report). Where |diff| > 2^30 the
         * duty is at 0 or 1 either way (inv_vdc >= 2^18 for vdc < 2^30), as
         * with the clamp of diff to 2^30 this replaced. */
        const int32_t diff = fx_sub(ph[x], mx) + fx_sub(ph[x], mn);
        /* |diff inv_vdc| < 2^62: rounded to Q24 and saturated, then the duty
         * taken in [0, 1]. */
        const q24_t half = FX_ONE / 2;
        const q24_t dv = fx_round_sat((int64_t)diff * inv_vdc, FX_QBITS + 1u);
        legs->duty[x] = fx_clamp(dv, -half, half) + half;
    }
}

/* The DC link taken below 64 pu (2^30, as the estimator takes it): keeps
 * the duties' 32-bit argument above. */
static q24_t svpwm_vdc(q24_t vdc)
{
    return vdc < ((q24_t)1 << 30) ? vdc : ((q24_t)1 << 30) - 1;
}

static void svpwm_legs_off(ctrl_legs_t *legs)
{
    legs->duty[0] = 0;
    legs->duty[1] = 0;
    legs->duty[2] = 0;
}

uint8_t ctrl_svpwm_limit(q24_t vdc, q24_t *v_alpha, q24_t *v_beta)
{
    if (vdc <= 0) {
        *v_alpha = 0;
        *v_beta = 0;
        return 1u;
    }
    vdc = svpwm_vdc(vdc);
    q24_t ph[3];
    q24_t mx;
    q24_t mn;
    svpwm_phases(*v_alpha, *v_beta, ph, &mx, &mn);
    const int64_t span = (int64_t)mx - mn; /* line-voltage span, >= 0, < 2^32 */
    if (span <= (int64_t)vdc) {
        return 0u;
    }
    svpwm_scale(vdc, span, v_alpha, v_beta);
    return 1u;
}

void ctrl_svpwm_duties(q24_t v_alpha, q24_t v_beta, q24_t vdc, ctrl_legs_t *legs)
{
    if (vdc <= 0) {
        svpwm_legs_off(legs);
        return;
    }
    q24_t ph[3];
    q24_t mx;
    q24_t mn;
    svpwm_phases(v_alpha, v_beta, ph, &mx, &mn);
    svpwm_legs(ph, mx, mn, svpwm_vdc(vdc), legs);
}

uint8_t ctrl_svpwm(q24_t *v_alpha, q24_t *v_beta, q24_t vdc, ctrl_legs_t *legs)
{
    /* ctrl_svpwm_limit then ctrl_svpwm_duties, bit for bit; the phase
     * voltages formed once when the vector is inside the hexagon. */
    if (vdc <= 0) {
        *v_alpha = 0;
        *v_beta = 0;
        svpwm_legs_off(legs);
        return 1u;
    }
    vdc = svpwm_vdc(vdc);
    q24_t ph[3];
    q24_t mx;
    q24_t mn;
    svpwm_phases(*v_alpha, *v_beta, ph, &mx, &mn);
    const int64_t span = (int64_t)mx - mn;
    uint8_t lim = 0u;
    if (span > (int64_t)vdc) {
        svpwm_scale(vdc, span, v_alpha, v_beta);
        svpwm_phases(*v_alpha, *v_beta, ph, &mx, &mn);
        lim = 1u;
    }
    svpwm_legs(ph, mx, mn, vdc, legs);
    return lim;
}
