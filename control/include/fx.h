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

typedef int32_t q24_t;       /* signed Q7.24 per-unit value */
typedef uint32_t fx_angle_t; /* 2^32 = 2*pi rad, wraps modulo one turn */

#define FX_QBITS 24
#define FX_ONE ((q24_t)1 << FX_QBITS) /* 1.0 pu in Q24 */
#define FX_MAX INT32_MAX
#define FX_MIN INT32_MIN

/* Irrational constants, round(x * 2^30) (Q30) and round(x * 2^24) (Q24): the
 * one home of each (transforms, vector tables, rotations). */
#define FX_Q30_ONE ((int32_t)1 << 30)
#define FX_Q30_HALF ((int32_t)1 << 29)
#define FX_Q30_SQRT3_2 929887697   /* sqrt(3)/2 */
#define FX_Q30_INV_SQRT3 619925131 /* 1/sqrt(3) */
#define FX_Q30_2_SQRT3 1239850262  /* 2/sqrt(3) */
#define FX_Q30_2_3 715827883       /* 2/3 */
#define FX_Q30_1_3 357913941       /* 1/3 */
#define FX_Q24_HALF ((int32_t)1 << 23)
#define FX_Q24_SQRT3_2 14529495 /* sqrt(3)/2 */

/* Angle constants (fx_angle_t). */
#define FX_ANGLE_PI ((fx_angle_t)0x80000000u)
#define FX_ANGLE_PI_3 ((fx_angle_t)0x2AAAAAABu) /* pi/3 rounded */
#define FX_ANGLE_PI_6 ((fx_angle_t)0x15555555u) /* pi/6 truncated */

/* uint32_t -> int32_t two's complement without the implementation-defined
 * conversion of values above INT32_MAX (gcc and clang compile it to nothing). */
static inline int32_t fx_u2i(uint32_t u)
{
    return u <= (uint32_t)INT32_MAX ? (int32_t)u : -(int32_t)(~u) - 1;
}

/* Optimisation barrier for gcc/clang (emits no instruction): the compiler may
 * otherwise merge a saturated 32-bit result with its saturation constants as
 * a 64-bit value, and a later (int64_t)r * b becomes a 64x64 multiply (three
 * multiplies and an add) instead of one SMULL on a Cortex-M4. */
static inline int32_t fx_keep32(int32_t r)
{
#if defined(__GNUC__)
    __asm__("" : "+r"(r));
#endif
    return r;
}

/* Saturate a 64-bit intermediate to the int32_t range. x is in range exactly
 * when x + 2^31 (mod 2^64) < 2^32; then its low 32 bits are the value (one
 * add-with-carry and a test of the high word on a 32-bit core). */
static inline int32_t fx_sat32(int64_t x)
{
    int32_t r = fx_u2i((uint32_t)(uint64_t)x);
    if ((uint64_t)x + 0x80000000u > 0xFFFFFFFFu) {
        r = x < 0 ? INT32_MIN : INT32_MAX;
    }
    return fx_keep32(r);
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

/* a + b saturated. Two's-complement sum of the unsigned images (well defined);
 * it overflowed exactly when a and b have the same sign and the sum another
 * gcc/clang: their overflow builtin, ADDS + a branch on V). */
static inline q24_t fx_add(q24_t a, q24_t b)
{
#if defined(__GNUC__)
    int32_t s;
    if (__builtin_add_overflow(a, b, &s)) {
        s = a < 0 ? INT32_MIN : INT32_MAX;
    }
    return fx_keep32(s);
#else
    const int32_t r = fx_u2i((uint32_t)a + (uint32_t)b);
    if ((a < 0) == (b < 0) && (r < 0) != (a < 0)) {
        return a < 0 ? INT32_MIN : INT32_MAX;
    }
    return r;
#endif
}

/* a - b saturated (overflow: a and b of different signs and the result not of a's sign). */
static inline q24_t fx_sub(q24_t a, q24_t b)
{
#if defined(__GNUC__)
    int32_t s;
    if (__builtin_sub_overflow(a, b, &s)) {
        s = a < 0 ? INT32_MIN : INT32_MAX;
    }
    return fx_keep32(s);
#else
    const int32_t r = fx_u2i((uint32_t)a - (uint32_t)b);
    if ((a < 0) != (b < 0) && (r < 0) != (a < 0)) {
        return a < 0 ? INT32_MIN : INT32_MAX;
    }
    return r;
#endif
}

static inline q24_t fx_neg(q24_t a)
{
    return a == INT32_MIN ? INT32_MAX : -a;
}

static inline q24_t fx_abs(q24_t a)
{
    return a < 0 ? fx_neg(a) : a;
}

/*
 * x / 2^n rounded to nearest (ties up) and saturated to int32_t, for every
 * int64_t x and 1 <= n <= 31 (= fx_sat32(fx_rshift64_round(x, n)) on that
 * function's domain |x| < 2^62), in the form a Cortex-M4 runs in ~7
 * instructions (SMLAL-friendly, one test of the high word) instead of ~14. u = x + 2^(n-1) +
 * 2^(n+31) (mod 2^64) lies in [0, 2^(n+32)) exactly when the rounded result r fits an int32_t; then
 * u >> n = r + 2^31 < 2^32 and flipping bit 31 gives r's two's-complement
 * bits. Otherwise the true sum is >= 2^(n+32) (x > 0) or negative (x < 0,
 * u wrapped to >= 2^63) and the result saturates with the sign of x.
 * Only unsigned shifts; n > 31 falls back to the generic form.
 */
static inline int32_t fx_round_sat(int64_t x, unsigned n)
{
    if (n > 31u) {
        return fx_sat32(fx_rshift64_round(x, n));
    }
    const uint64_t u = (uint64_t)x + ((uint64_t)1 << (n - 1u)) + ((uint64_t)1 << (n + 31u));
    int32_t r = fx_u2i((uint32_t)(u >> n) ^ 0x80000000u);
    if ((u >> (n + 32u)) != 0u) {
        r = x < 0 ? INT32_MIN : INT32_MAX;
    }
    return fx_keep32(r);
}

/*
 * x / 2^n rounded to nearest (ties up) WITHOUT saturation, for callers that
 * have shown |x / 2^n| < 2^31 (state the bound where it is used): the low 32
 * bits of the rounded unsigned shift are the two's-complement result
 * (~4 instructions on a Cortex-M4). Valid for 1 <= n <= 32.
 */
static inline int32_t fx_round_nosat(int64_t x, unsigned n)
{
    return fx_u2i((uint32_t)(((uint64_t)x + ((uint64_t)1 << (n - 1u))) >> n));
}

/* Q24 * Q24 -> Q24, rounded, saturated. */
static inline q24_t fx_mul(q24_t a, q24_t b)
{
    return fx_round_sat((int64_t)a * b, FX_QBITS);
}

/* Q24 * Qn -> Q24 for a coefficient with n fractional bits (n >= 1). */
static inline q24_t fx_mul_qn(q24_t a, int32_t b, unsigned n)
{
    return fx_round_sat((int64_t)a * b, n);
}

/*
 * (p1 + p2) / 2^n rounded and saturated, 1 <= n <= 31, where p1 and p2 are
 * products of int32_t values (or such a product negated): then
 * p1 + p2 lies in [-2^63 + 2^31, 2^63] and may not fit an int64_t
 * (fx_dot(FX_MIN, FX_MIN, FX_MIN, FX_MIN) sums to 2^63). The sum is formed
 * modulo 2^64 (well defined) with the bias B = 2^(n-1) + 2^(n+31) of
 * fx_round_sat: u < 2^(n+32) again means "fits". Otherwise a positive sum
 * gives u <= 2^63 + B and a negative one u >= 2^63 + 2^31 + B (it wrapped),
 * which tells the saturation side without keeping p1, p2 (so the compiler
 * still forms the sum with SMULL + SMLAL).
 */
static inline int32_t fx_round_sat_sum(int64_t p1, int64_t p2, unsigned n)
{
    const uint64_t bias = ((uint64_t)1 << (n - 1u)) + ((uint64_t)1 << (n + 31u));
    const uint64_t u = (uint64_t)p1 + (uint64_t)p2 + bias;
    int32_t r = fx_u2i((uint32_t)(u >> n) ^ 0x80000000u);
    if ((u >> (n + 32u)) != 0u) {
        r = u <= ((uint64_t)1 << 63) + bias ? INT32_MAX : INT32_MIN;
    }
    return fx_keep32(r);
}

/* Cross product a x b = ax*by - ay*bx in Q24, one rounding. */
static inline q24_t fx_cross(q24_t ax, q24_t ay, q24_t bx, q24_t by)
{
    return fx_round_sat_sum((int64_t)ax * by, -((int64_t)ay * bx), FX_QBITS);
}

/* Dot product a . b = ax*bx + ay*by in Q24, one rounding. */
static inline q24_t fx_dot(q24_t ax, q24_t ay, q24_t bx, q24_t by)
{
    return fx_round_sat_sum((int64_t)ax * bx, (int64_t)ay * by, FX_QBITS);
}

/* ---- non-saturating variants: same rounding, no saturation. Only where a
 * bound stated at the call keeps the result inside int32_t; outside it the
 * result wraps modulo 2^32 (no undefined behaviour). ---- */

/* a * b / 2^24 rounded; requires |a * b| < 2^55 - 2^23. */
static inline q24_t fx_mul_nosat(q24_t a, q24_t b)
{
    return fx_round_nosat((int64_t)a * b, FX_QBITS);
}

/* ax*bx + ay*by in Q24, one rounding; requires |sum| < 2^55 - 2^23. */
static inline q24_t fx_dot_nosat(q24_t ax, q24_t ay, q24_t bx, q24_t by)
{
    return fx_round_nosat((int64_t)ax * bx + (int64_t)ay * by, FX_QBITS);
}

/* ax*by - ay*bx in Q24, one rounding; requires |difference| < 2^55 - 2^23. */
static inline q24_t fx_cross_nosat(q24_t ax, q24_t ay, q24_t bx, q24_t by)
{
    return fx_round_nosat((int64_t)ax * by - (int64_t)ay * bx, FX_QBITS);
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

/* Angle of the vector (x, y) (any common scale), in [0, 2 pi) as fx_angle_t;
 * (0, 0) gives 0. Error <= 1.4e-6 rad (docs/error-budget.md); fx_atan.c. */
fx_angle_t fx_atan2(int32_t y, int32_t x);

#endif /* CONTROL_FX_H */
