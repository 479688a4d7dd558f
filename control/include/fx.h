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

/* Parameters changed while the drive runs (retune, control/CMakeLists.txt's
 * PMSM_LIVE_PARAMS): 0 leaves that code out of a flash-tight image. */
#ifndef PMSM_LIVE_PARAMS
#define PMSM_LIVE_PARAMS 1
#endif

/* Keeps a function out of line (gcc/clang): code that runs once per change,
 * not per period, in one copy (link-time optimisation would inline it). */
#if defined(__GNUC__)
#define FX_NOINLINE __attribute__((noinline))
#else
#define FX_NOINLINE
#endif

/* fx_rshift64_round out of line (fx.c): one copy of the variable 64-bit
 * shift for the code that runs once per change. */
FX_NOINLINE int64_t fx_rshift64_round_call(int64_t x, unsigned n);

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

/* Unsigned long division continued by `steps` digits of `bits` bits, each by
 * one 32-bit division (no 64-bit library division on the Cortex-M): with the
 * remainder *r <= d < 2^(32 - bits) on entry every shifted remainder fits 32
 * bits. Returns q 2^(bits steps) + floor(*r 2^(bits steps) / d) and leaves the
 * new remainder in *r. */
static inline uint32_t fx_udiv_digits(uint32_t q, uint32_t *r, uint32_t d, unsigned bits,
                                      unsigned steps)
{
    uint32_t rem = *r;
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC unroll 4 /* as written out by hand: the digits are few and per period */
#endif
    for (unsigned k = 0u; k < steps; k++) {
        rem <<= bits;
        const uint32_t digit = rem / d;
        rem -= digit * d;
        q = (q << bits) + digit;
    }
    *r = rem;
    return q;
}

/* A quotient q with remainder r < d rounded half up: q + 1 when r >= d / 2. */
static inline uint32_t fx_udiv_round(uint32_t q, uint32_t r, uint32_t d)
{
    return r >= d - r ? q + 1u : q;
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

/* x within [-2^(bits-1), 2^(bits-1) - 1] for a constant bits in 2..31: one
 * SSAT on a Cortex-M4 (the compiler's ACLE builtin; fx_clamp with these
 * bounds costs four compares and moves there), the same value elsewhere. */
#if defined(__ARM_FEATURE_SAT) && defined(__GNUC__)
#define FX_SAT(x, bits) ((q24_t)__builtin_arm_ssat((int)(x), (bits##u)))
#else
#define FX_SAT(x, bits) fx_clamp((x), -((q24_t)1 << ((bits)-1)), ((q24_t)1 << ((bits)-1)) - 1)
#endif

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
 * (0 / 0 gives 0). A 64-by-32 division (two 32-bit divisions, fx.c): costly
 * on Cortex-M, keep it out of inner loops where a precomputed reciprocal serves. */
q24_t fx_div(q24_t num, q24_t den);

/* floor(sqrt(x)) for a 64-bit unsigned argument (result fits 32 bits). */
uint32_t fx_isqrt64(uint64_t x);

/* |(x, y)| in Q24, saturated. */
q24_t fx_mag(q24_t x, q24_t y);

/* fx_mag(x, y) compared with t (any int64_t) through S = x^2 + y^2 (Q48,
 * exact in a uint64_t), without the square root: fx_mag <= t exactly when
 * S < fx_mag_le_lim(t), fx_mag >= t exactly when S >= fx_mag_ge_lim(t).
 * fx_mag = min(round(sqrt(S)), FX_MAX) and sqrt(S) of an integer S is never
 * a half-integer, so round(sqrt(S)) <= t <=> sqrt(S) < t + 1/2 <=>
 * S < t^2 + t + 1/4 <=> S < t^2 + t + 1, and round(sqrt(S)) >= t <=>
 * S >= t^2 - t + 1 for t >= 1; the cap: fx_mag <= t for every t >= FX_MAX,
 * fx_mag >= t for none above FX_MAX (S <= 2^63 < UINT64_MAX). */
static inline uint64_t fx_mag_le_lim(int64_t t)
{
    if (t < 0) {
        return 0u;
    }
    if (t >= FX_MAX) {
        return UINT64_MAX;
    }
    return (uint64_t)t * (uint64_t)t + (uint64_t)t + 1u;
}

static inline uint64_t fx_mag_ge_lim(int64_t t)
{
    if (t <= 0) {
        return 0u;
    }
    if (t > FX_MAX) {
        return UINT64_MAX;
    }
    return (uint64_t)t * (uint64_t)t - (uint64_t)t + 1u;
}

/* sin and cos of an angle in Q24: the nearest point of a Q30 quarter-wave
 * table turned by the remainder; maximum error 0.5 LSB + 2e-9 = 3.2e-8
 * (docs/fixed-point.md). Either output may be NULL. */
void fx_sincos(fx_angle_t angle, q24_t *sin_out, q24_t *cos_out);

/* Angle of the vector (x, y) (any common scale), in [0, 2 pi) as fx_angle_t;
 * (0, 0) gives 0. Error <= 1.4e-6 rad (docs/error-budget.md); fx_atan.c. */
fx_angle_t fx_atan2(int32_t y, int32_t x);

/* cos and sin of a signed angle step (fx_angle_t units, 2^32 = one turn) in
 * Q30, for turning a frame by the angle one period turns: error < 3e-9 up to
 * FX_ROT_TAB_MAX, fx_sincos's 3.2e-8 beyond (docs/fixed-point.md). */
#define FX_ROT_TAB_MAX 0x40000000u /* pi/2 */
void fx_rot_q30(int32_t step, int32_t *cos_q30, int32_t *sin_q30);

/* (x, y) rotated by the angle whose cosine and sine are c, s (Q30):
 * (x c - y s, x s + y c), Q24, one rounding each, saturated. */
static inline void fx_rotate(q24_t x, q24_t y, int32_t c, int32_t s, q24_t *xo, q24_t *yo)
{
    /* |x c| < 2^61: fx_round_sat_sum's domain. */
    *xo = fx_round_sat_sum((int64_t)x * c, -((int64_t)y * s), 30u);
    *yo = fx_round_sat_sum((int64_t)x * s, (int64_t)y * c, 30u);
}

/* ---- the bodies of fx_sincos and fx_rot_q30, inline for the estimator's
 * straight path (one copy each elsewhere, in fx.c) ---- */

/* round(sin(i pi/1024) 2^30), i = 0..512: a quarter wave (fx.c). */
extern const int32_t fx_sin_tab_q30[513];

#define FX_Q29_PI_2 843314857 /* pi/2 in Q29: fx_angle_t units -> Q30 rad */

/* (a b) / 2^30 rounded, for |a b| < 2^61. */
static inline int32_t fx_mul30(int32_t a, int32_t b)
{
    return fx_keep32(fx_round_nosat((int64_t)a * b, 30u));
}

/* sin and cos from the nearest table point a_i = i pi/1024 (|d| <= pi/2048)
 * turned by d: sin(a + d) = sin a cos d + cos a sin d, with cos d = 1 - d^2/2
 * (error d^4/24 < 3e-13) and sin d = d (error d^3/6 < 6.2e-10), the table in
 * Q30 (0.5 LSB = 4.7e-10 each), the sums rounded once to Q24: max error
 * 0.5 LSB + 2e-9 = 3.2e-8. */
static inline void fx_sincos_inline(fx_angle_t angle, q24_t *sin_out, q24_t *cos_out)
{
    const uint32_t quadrant = angle >> 30;
    const uint32_t pos = angle & 0x3FFFFFFFu;
    const uint32_t idx = (pos + (1u << 20)) >> 21; /* 0..512 */
    /* d in angle units, [-2^20, 2^20]; in Q30 rad |x| <= 1.7e6 */
    const int32_t frac = (int32_t)pos - (int32_t)(idx << 21);
    const int32_t x = fx_keep32(fx_round_nosat((int64_t)frac * FX_Q29_PI_2, 29u));
    const int32_t half_x2 = fx_keep32(fx_round_nosat((int64_t)x * x, 31u)); /* d^2/2, Q30 */
    const int32_t sa = fx_sin_tab_q30[idx];
    const int32_t ca = fx_sin_tab_q30[512u - idx];
    const int32_t cd = FX_Q30_ONE - half_x2;
    /* Q60 sums (|.| <= 2^60 (1 + 1.6e-3)): to Q24, rounded (|result| <= 2^24). */
    const q24_t a = (q24_t)fx_rshift64_round((int64_t)sa * cd + (int64_t)ca * x, 36u);
    const q24_t b = (q24_t)fx_rshift64_round((int64_t)ca * cd - (int64_t)sa * x, 36u);
    switch (quadrant) {
    case 0u:
        *sin_out = a;
        *cos_out = b;
        break;
    case 1u:
        *sin_out = b;
        *cos_out = -a;
        break;
    case 2u:
        *sin_out = -a;
        *cos_out = -b;
        break;
    default:
        *sin_out = -b;
        *cos_out = a;
        break;
    }
}

/* cos and sin of a signed step |step| <= pi/2 (2^30) in Q30: the nearest
 * table point turned by the remainder d as in fx_sincos_inline, kept in Q30
 * (error: d^3/6 < 6.2e-10, the table 2 x 4.7e-10, the roundings 2 x 4.7e-10:
 * < 3e-9); beyond pi/2, fx_sincos (3.2e-8). */
static inline void fx_rot_q30_inline(int32_t step, int32_t *cos_q30, int32_t *sin_q30)
{
    const uint32_t mag = step < 0 ? 0u - (uint32_t)step : (uint32_t)step;
    if (mag > FX_ROT_TAB_MAX) {
        q24_t s;
        q24_t c;
        fx_sincos_inline((fx_angle_t)step, &s, &c);
        *cos_q30 = c * 64; /* |c| <= 2^24 */
        *sin_q30 = s * 64;
        return;
    }
    const uint32_t idx = (mag + (1u << 20)) >> 21; /* 0..512 */
    const int32_t frac = (int32_t)mag - (int32_t)(idx << 21);
    const int32_t x = fx_keep32(fx_round_nosat((int64_t)frac * FX_Q29_PI_2, 29u));
    const int32_t cd = FX_Q30_ONE - fx_keep32(fx_round_nosat((int64_t)x * x, 31u));
    const int32_t sa = fx_sin_tab_q30[idx];
    const int32_t ca = fx_sin_tab_q30[512u - idx];
    /* Q60 sums < 2^61, to Q30 */
    const int32_t sn = fx_round_nosat((int64_t)sa * cd + (int64_t)ca * x, 30u);
    *cos_q30 = fx_round_nosat((int64_t)ca * cd - (int64_t)sa * x, 30u);
    *sin_q30 = step < 0 ? -sn : sn;
}

#endif /* CONTROL_FX_H */
