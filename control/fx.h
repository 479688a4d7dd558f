/*
 * Fixed-point primitives of the control core.
 *
 * Scheme (see control/README.md for the full error budget):
 *   - Every physical signal is per-unit (bases in ctrl_params.h) and stored as
 *     q24_t: signed Q7.24 in an int32_t, value = raw / 2^24, range [-128, 128),
 *     resolution 6.0e-8 pu.
 *   - Angles are fx_angle_t: unsigned 32-bit, 2^32 = one full turn (2*pi).
 *     Unsigned wrap-around is well defined in C and is exactly angle modulo 2*pi.
 *   - Products go through int64_t and are brought back with a rounding shift
 *     that never shifts a negative value (C11 6.5.7: implementation-defined).
 *     Results saturate to the int32_t range instead of wrapping.
 *
 * Only integer operations here: this header is used by the per-sample path and
 * must compile for a Cortex-M0+ without floating-point helpers.
 */
#ifndef CONTROL_FX_H
#define CONTROL_FX_H

#include <stdint.h>

typedef int32_t q24_t;         /* signed Q7.24 per-unit value */
typedef uint32_t fx_angle_t;   /* 2^32 = 2*pi rad, wraps modulo one turn */

#define FX_QBITS 24
#define FX_ONE ((q24_t)1 << FX_QBITS) /* 1.0 pu in Q24 */
#define FX_MAX INT32_MAX
#define FX_MIN INT32_MIN

/* Angle constants (fx_angle_t). */
#define FX_ANGLE_PI ((fx_angle_t)0x80000000u)
#define FX_ANGLE_PI_3 ((fx_angle_t)0x2AAAAAABu) /* pi/3 rounded */
#define FX_ANGLE_PI_6 ((fx_angle_t)0x15555555u) /* pi/6 truncated */

/* Saturate a 64-bit intermediate to the int32_t range. */
static inline int32_t fx_sat32(int64_t x)
{
    if (x > (int64_t)INT32_MAX) {
        return INT32_MAX;
    }
    if (x < (int64_t)INT32_MIN) {
        return INT32_MIN;
    }
    return (int32_t)x;
}

/*
 * x / 2^n rounded to nearest (ties towards +inf), for 1 <= n <= 62, without
 * shifting a negative value: the two's-complement value is moved to offset
 * binary (x + 2^63, an unsigned number), shifted, and the offset removed.
 * Valid for |x| < 2^62, which every product of two int32_t satisfies.
 */
static inline int64_t fx_rshift64_round(int64_t x, unsigned n)
{
    const uint64_t offset = (uint64_t)1 << 63;
    uint64_t u = (uint64_t)x + offset + ((uint64_t)1 << (n - 1u));
    return (int64_t)(u >> n) - (int64_t)((uint64_t)1 << (63u - n));
}

/* x / 2^n rounded to nearest for int32_t, 1 <= n <= 31, same technique. */
static inline int32_t fx_rshift32_round(int32_t x, unsigned n)
{
    return (int32_t)fx_rshift64_round((int64_t)x, n);
}

/* x * 2^n saturated (a left shift of a negative value is undefined in C). */
static inline int32_t fx_lshift_sat(int32_t x, unsigned n)
{
    return fx_sat32((int64_t)x * ((int64_t)1 << n));
}

static inline q24_t fx_add(q24_t a, q24_t b)
{
    return fx_sat32((int64_t)a + b);
}

static inline q24_t fx_sub(q24_t a, q24_t b)
{
    return fx_sat32((int64_t)a - b);
}

static inline q24_t fx_neg(q24_t a)
{
    return fx_sat32(-(int64_t)a);
}

static inline q24_t fx_abs(q24_t a)
{
    return fx_sat32(a < 0 ? -(int64_t)a : (int64_t)a);
}

/* Q24 * Q24 -> Q24, rounded, saturated. */
static inline q24_t fx_mul(q24_t a, q24_t b)
{
    return fx_sat32(fx_rshift64_round((int64_t)a * b, FX_QBITS));
}

/* Q24 * Qn -> Q24 for a coefficient with n fractional bits (n >= 1). */
static inline q24_t fx_mul_qn(q24_t a, int32_t b, unsigned n)
{
    return fx_sat32(fx_rshift64_round((int64_t)a * b, n));
}

/* Cross product a x b = ax*by - ay*bx in Q24, one rounding. */
static inline q24_t fx_cross(q24_t ax, q24_t ay, q24_t bx, q24_t by)
{
    return fx_sat32(fx_rshift64_round((int64_t)ax * by - (int64_t)ay * bx, FX_QBITS));
}

/* Dot product a . b = ax*bx + ay*by in Q24, one rounding. */
static inline q24_t fx_dot(q24_t ax, q24_t ay, q24_t bx, q24_t by)
{
    return fx_sat32(fx_rshift64_round((int64_t)ax * bx + (int64_t)ay * by, FX_QBITS));
}

static inline q24_t fx_clamp(q24_t x, q24_t lo, q24_t hi)
{
    return x < lo ? lo : (x > hi ? hi : x);
}

static inline q24_t fx_min(q24_t a, q24_t b)
{
    return a < b ? a : b;
}

static inline q24_t fx_max(q24_t a, q24_t b)
{
    return a > b ? a : b;
}

/* Sign as -1, 0, +1. */
static inline int fx_sign(q24_t a)
{
    return (a > 0) - (a < 0);
}

/* ---- Implemented in fx.c (integer-only) ---- */

/* num / den in Q24, rounded, saturated; den == 0 saturates to the sign of num
 * (0 / 0 gives 0). Uses a 64-by-32 division: costly on Cortex-M, keep it out of
 * inner loops where a precomputed reciprocal serves. */
q24_t fx_div(q24_t num, q24_t den);

/* floor(sqrt(x)) for a 64-bit unsigned argument (result fits 32 bits). */
uint32_t fx_isqrt64(uint64_t x);

/* |(x, y)| in Q24, saturated. */
q24_t fx_mag(q24_t x, q24_t y);

/* sin and cos of an angle in Q24; maximum error stated in control/README.md. */
void fx_sincos(fx_angle_t angle, q24_t *sin_out, q24_t *cos_out);

#endif /* CONTROL_FX_H */
