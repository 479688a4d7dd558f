/*
 * Fixed-point primitives (control/fx.h, fx.c): saturation at the edges,
 * rounding of negative values, division by zero, exactness of the integer
 * square root, rounding of the magnitude, the sin/cos error bound derived in
 * docs/fixed-point.md (0.5 LSB + 2e-9: the nearest Q30 table point turned by
 * the remainder, rounded once to Q24) and that of the rotation over a period,
 * fx_rot_q30 (3e-9 up to pi/2, fx_sincos's beyond).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#include "ctrl_units.h"
#include "fx.h"
#include "unity.h"

void setUp(void)
{
}
void tearDown(void)
{
}

#define LSB (1.0 / 16777216.0)
/* the final rounding to Q24 (0.5 LSB) + the Q30 table (2 x 0.5 2^-30), d^3/6
 * <= 6.2e-10 for sin d = d, the Q30 roundings of d and d^2/2 */
#define SINCOS_BOUND (0.5 * LSB + 2.0e-9)
#define ROT_TAB_BOUND 3.0e-9 /* fx_rot_q30 up to pi/2 */

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static uint64_t rng(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return rng_state;
}

/* Uniform int32_t scaled down by 2^k (no shift of a negative value, no
 * implementation-defined conversion). */
static int32_t rnd_i32(unsigned k)
{
    const int64_t v = (int64_t)(rng() & 0xFFFFFFFFu) - ((int64_t)1 << 31);
    return (int32_t)(v / ((int64_t)1 << k));
}

static void test_inline_saturation_and_rounding(void)
{
    TEST_ASSERT_EQUAL_INT32(FX_MAX, fx_add(FX_MAX, 1));
    TEST_ASSERT_EQUAL_INT32(FX_MIN, fx_sub(FX_MIN, 1));
    TEST_ASSERT_EQUAL_INT32(FX_MAX, fx_neg(FX_MIN));
    TEST_ASSERT_EQUAL_INT32(FX_MAX, fx_abs(FX_MIN));
    TEST_ASSERT_EQUAL_INT32(FX_MAX, fx_mul(FX_MAX, FX_MAX));
    TEST_ASSERT_EQUAL_INT32(FX_MAX, fx_mul(FX_MIN, FX_MIN));
    TEST_ASSERT_EQUAL_INT32(FX_MIN, fx_mul(FX_MIN, FX_MAX));
    TEST_ASSERT_EQUAL_INT32(FX_MAX, fx_lshift_sat(FX_ONE, 10));
    TEST_ASSERT_EQUAL_INT32(FX_MIN, fx_lshift_sat(-FX_ONE, 10));
    /* Ties go towards +inf, also for negative values (no arithmetic shift). */
    TEST_ASSERT_EQUAL_INT32(-1, fx_rshift32_round(-3, 1)); /* -1.5 -> -1 */
    TEST_ASSERT_EQUAL_INT32(-2, fx_rshift32_round(-5, 1)); /* -2.5 -> -2 */
    TEST_ASSERT_EQUAL_INT32(-2, fx_rshift32_round(-7, 2)); /* -1.75 -> -2 */
    TEST_ASSERT_EQUAL_INT32(2, fx_rshift32_round(3, 1));
    TEST_ASSERT_EQUAL_INT32(0, fx_mul(-1, FX_ONE / 2));  /* -0.5 LSB -> 0 */
    TEST_ASSERT_EQUAL_INT32(-1, fx_mul(-3, FX_ONE / 2)); /* -1.5 LSB -> -1 */
    TEST_ASSERT_EQUAL_INT32(-FX_ONE / 4, fx_mul(-FX_ONE / 2, FX_ONE / 2));
}

/* |q * den - num * 2^24| <= |den| / 2 unless saturated; symmetric rounding. */
static void check_div(q24_t num, q24_t den)
{
    const q24_t q = fx_div(num, den);
    const int64_t target = (int64_t)num * FX_ONE;
    if (q == FX_MAX || q == FX_MIN) {
        /* saturation only when the exact quotient is out of range */
        const double exact = (double)num / (double)den * 16777216.0;
        TEST_ASSERT_TRUE_MESSAGE(exact >= 2147483646.5 || exact <= -2147483647.5,
                                 "fx_div saturated in range");
        return;
    }
    const int64_t r = (int64_t)q * den - target;
    const int64_t ad = den < 0 ? -(int64_t)den : den;
    const int64_t ar = r < 0 ? -r : r;
    TEST_ASSERT_TRUE_MESSAGE(2 * ar <= ad, "fx_div not rounded to nearest");
}

/* ---- independent references of the fast forms (fx_round_sat, fx_sat32,
 * fx_add/sub, fx_mul/dot/cross and the _nosat variants) ---- */

static int32_t ref_sat(int64_t x)
{
    if (x > INT32_MAX) {
        return INT32_MAX;
    }
    if (x < INT32_MIN) {
        return INT32_MIN;
    }
    return (int32_t)x;
}

/* floor((x + 2^(n-1)) / 2^n) for every int64_t x, 1 <= n <= 31, by C's
 * truncating division and a remainder correction (no overflow). */
static int64_t ref_round(int64_t x, unsigned n)
{
    const int64_t d = (int64_t)1 << n;
    int64_t q = x / d;
    int64_t r = x % d;
    if (r < 0) {
        q -= 1;
        r += d;
    }
    return q + (r + d / 2 >= d ? 1 : 0);
}

static int64_t rnd_i64(void)
{
    return (int64_t)(rng() >> 1) - (int64_t)(rng() >> 1); /* spans most of int64 */
}

static void check_round_sat(int64_t x, unsigned n)
{
    const int64_t r = ref_round(x, n);
    TEST_ASSERT_EQUAL_INT32(ref_sat(r), fx_round_sat(x, n));
    if (r >= INT32_MIN && r <= INT32_MAX && n <= 31u) {
        TEST_ASSERT_EQUAL_INT32((int32_t)r, fx_round_nosat(x, n));
    }
}

/* round-and-saturate of p1 + p2 when the sum may overflow int64_t */
static int32_t ref_sum(int64_t p1, int64_t p2, unsigned n)
{
    if (p1 > 0 && p2 > INT64_MAX - p1) {
        return INT32_MAX;
    }
    if (p1 < 0 && p2 < INT64_MIN - p1) {
        return INT32_MIN;
    }
    return ref_sat(ref_round(p1 + p2, n));
}

static void test_fast_forms_match_reference(void)
{
    /* dot/cross at the ends of the range: the sum of two products reaches
     * 2^63 (does not fit int64_t), e.g. fx_dot(FX_MIN, FX_MIN, FX_MIN, FX_MIN). */
    static const int32_t ex[] = {INT32_MIN, INT32_MIN + 1, -1, 0, 1, INT32_MAX};
    const unsigned nx = sizeof ex / sizeof ex[0];
    for (unsigned i = 0; i < nx * nx * nx * nx; i++) {
        const int32_t a = ex[i % nx];
        const int32_t b = ex[(i / nx) % nx];
        const int32_t c = ex[(i / nx / nx) % nx];
        const int32_t e = ex[i / nx / nx / nx];
        TEST_ASSERT_EQUAL_INT32(ref_sum((int64_t)a * c, (int64_t)b * e, 24u), fx_dot(a, b, c, e));
        TEST_ASSERT_EQUAL_INT32(ref_sum((int64_t)a * e, -((int64_t)b * c), 24u),
                                fx_cross(a, b, c, e));
    }
    TEST_ASSERT_EQUAL_INT32(FX_MAX, fx_dot(FX_MIN, FX_MIN, FX_MIN, FX_MIN));
    TEST_ASSERT_EQUAL_INT32(FX_MAX, fx_cross(FX_MIN, FX_MIN, FX_MAX, FX_MIN)); /* 2^63 - 2^31 */
    TEST_ASSERT_EQUAL_INT32(FX_MIN, fx_cross(FX_MIN, FX_MIN, FX_MIN, FX_MAX)); /* -2^63 + 2^31 */

    static const unsigned ns[] = {1u, 2u, 16u, 23u, 24u, 28u, 30u, 31u};
    for (unsigned i = 0; i < sizeof ns / sizeof ns[0]; i++) {
        const unsigned n = ns[i];
        const int64_t d = (int64_t)1 << n;
        /* Edges: around +-2^31 2^n (saturation thresholds with the rounding
         * half), zero, and the ends of int64_t. */
        const int64_t top = (((int64_t)1 << 31) * d) - d / 2;  /* rounds to 2^31 */
        const int64_t bot = -(((int64_t)1 << 31) * d) - d / 2; /* rounds to -2^31 */
        for (int64_t k = -3; k <= 3; k++) {
            check_round_sat(top + k, n);
            check_round_sat(bot + k, n);
            check_round_sat(k, n);
            check_round_sat(d / 2 + k, n);
            check_round_sat(-d / 2 + k, n);
        }
        check_round_sat(INT64_MAX, n);
        check_round_sat(INT64_MIN, n);
        check_round_sat(INT64_MIN + 1, n);
        for (int k = 0; k < 20000; k++) {
            const int64_t x = rnd_i64();
            check_round_sat(x, n);
            check_round_sat(x / ((int64_t)1 << (rng() % 40u)), n);
        }
    }
    const int64_t sat_edges[] = {0,
                                 1,
                                 -1,
                                 INT32_MAX,
                                 INT32_MIN,
                                 (int64_t)INT32_MAX + 1,
                                 (int64_t)INT32_MIN - 1,
                                 INT64_MAX,
                                 INT64_MIN};
    for (unsigned i = 0; i < sizeof sat_edges / sizeof sat_edges[0]; i++) {
        TEST_ASSERT_EQUAL_INT32(ref_sat(sat_edges[i]), fx_sat32(sat_edges[i]));
    }
    const int32_t e32[] = {
        0, 1, -1, 2, -2, FX_ONE, -FX_ONE, INT32_MAX, INT32_MIN, INT32_MAX - 1, INT32_MIN + 1};
    const unsigned ne = sizeof e32 / sizeof e32[0];
    for (int k = 0; k < 40000; k++) {
        const int32_t a = k < 121 ? e32[(unsigned)k % ne] : rnd_i32((unsigned)(rng() % 8u));
        const int32_t b = k < 121 ? e32[(unsigned)k / ne] : rnd_i32((unsigned)(rng() % 8u));
        const int32_t c = rnd_i32(0u);
        const int32_t dd = rnd_i32(7u);
        TEST_ASSERT_EQUAL_INT32(ref_sat(ref_sat((int64_t)a + b)), fx_add(a, b));
        TEST_ASSERT_EQUAL_INT32(ref_sat((int64_t)a - b), fx_sub(a, b));
        TEST_ASSERT_EQUAL_INT32(ref_sat(-(int64_t)a), fx_neg(a));
        TEST_ASSERT_EQUAL_INT32(ref_sat(a < 0 ? -(int64_t)a : a), fx_abs(a));
        TEST_ASSERT_EQUAL_INT32(ref_sat(ref_round((int64_t)a * b, 24u)), fx_mul(a, b));
        TEST_ASSERT_EQUAL_INT32(ref_sat(ref_round((int64_t)a * b, 30u)), fx_mul_qn(a, b, 30u));
        const int64_t dot = (int64_t)a * c + (int64_t)b * dd;
        const int64_t cross = (int64_t)a * dd - (int64_t)b * c;
        TEST_ASSERT_EQUAL_INT32(ref_sat(ref_round(dot, 24u)), fx_dot(a, b, c, dd));
        TEST_ASSERT_EQUAL_INT32(ref_sat(ref_round(cross, 24u)), fx_cross(a, b, c, dd));
        /* full-range operands (products up to 2^62) */
        const int32_t f1 = rnd_i32(0u);
        const int32_t f2 = rnd_i32(0u);
        TEST_ASSERT_EQUAL_INT32(ref_sum((int64_t)f1 * c, (int64_t)f2 * a, 24u),
                                fx_dot(f1, f2, c, a));
        TEST_ASSERT_EQUAL_INT32(ref_sum((int64_t)f1 * a, -((int64_t)f2 * c), 24u),
                                fx_cross(f1, f2, c, a));
        /* _nosat: equal wherever the documented bound holds (result fits) */
        const int64_t m = ref_round((int64_t)a * dd, 24u);
        if (m == ref_sat(m)) {
            TEST_ASSERT_EQUAL_INT32((int32_t)m, fx_mul_nosat(a, dd));
        }
        if (ref_round(dot, 24u) == ref_sat(ref_round(dot, 24u))) {
            TEST_ASSERT_EQUAL_INT32(fx_dot(a, b, c, dd), fx_dot_nosat(a, b, c, dd));
        }
        if (ref_round(cross, 24u) == ref_sat(ref_round(cross, 24u))) {
            TEST_ASSERT_EQUAL_INT32(fx_cross(a, b, c, dd), fx_cross_nosat(a, b, c, dd));
        }
    }
}

static void test_div(void)
{
    TEST_ASSERT_EQUAL_INT32(FX_ONE / 2, fx_div(FX_ONE, 2 * FX_ONE));
    TEST_ASSERT_EQUAL_INT32(-5592405, fx_div(-FX_ONE, 3 * FX_ONE)); /* -1/3 */
    TEST_ASSERT_EQUAL_INT32(fx_div(FX_ONE, 3 * FX_ONE), -fx_div(-FX_ONE, 3 * FX_ONE));
    TEST_ASSERT_EQUAL_INT32(1, fx_div(1, 2 * FX_ONE)); /* 0.5 LSB: away from zero */
    TEST_ASSERT_EQUAL_INT32(-1, fx_div(-1, 2 * FX_ONE));
    TEST_ASSERT_EQUAL_INT32(-1, fx_div(1, -2 * FX_ONE));
    TEST_ASSERT_EQUAL_INT32(FX_MAX, fx_div(1, 0));
    TEST_ASSERT_EQUAL_INT32(FX_MIN, fx_div(-1, 0));
    TEST_ASSERT_EQUAL_INT32(0, fx_div(0, 0));
    TEST_ASSERT_EQUAL_INT32(FX_MAX, fx_div(FX_MAX, 1));
    TEST_ASSERT_EQUAL_INT32(FX_MIN, fx_div(FX_MIN, 1));
    TEST_ASSERT_EQUAL_INT32(FX_MAX, fx_div(FX_MIN, -1));
    TEST_ASSERT_EQUAL_INT32(FX_MIN, fx_div(FX_MIN, FX_ONE / 64)); /* -128 * 64 */
    TEST_ASSERT_EQUAL_INT32(-FX_ONE, fx_div(FX_MIN, FX_MAX));     /* -1 - 5e-10 */
    const q24_t edge[] = {0, 1, -1, 2, -2, FX_ONE, -FX_ONE, FX_MAX, FX_MIN, FX_MAX - 1, FX_MIN + 1};
    for (unsigned a = 0; a < sizeof edge / sizeof edge[0]; a++) {
        for (unsigned b = 0; b < sizeof edge / sizeof edge[0]; b++) {
            if (edge[b] != 0) {
                check_div(edge[a], edge[b]);
            }
        }
    }
    for (int i = 0; i < 20000; i++) {
        const q24_t n = rnd_i32((unsigned)(rng() % 24u));
        q24_t d = rnd_i32((unsigned)(rng() % 31u));
        if (d == 0) {
            d = 1;
        }
        check_div(n, d);
    }
}

static void check_isqrt(uint64_t x)
{
    const uint64_t r = fx_isqrt64(x);
    TEST_ASSERT_TRUE_MESSAGE(r <= 0xFFFFFFFFull, "isqrt range");
    TEST_ASSERT_TRUE_MESSAGE(r * r <= x, "isqrt too large");
    if (r < 0xFFFFFFFFull) {
        TEST_ASSERT_TRUE_MESSAGE((r + 1u) * (r + 1u) > x, "isqrt too small");
    }
}

static void test_isqrt_exact(void)
{
    TEST_ASSERT_EQUAL_UINT32(0u, fx_isqrt64(0u));
    TEST_ASSERT_EQUAL_UINT32(1u, fx_isqrt64(1u));
    TEST_ASSERT_EQUAL_UINT32(1u, fx_isqrt64(3u));
    TEST_ASSERT_EQUAL_UINT32(2u, fx_isqrt64(4u));
    TEST_ASSERT_EQUAL_UINT32(0xFFFFFFFFu, fx_isqrt64(UINT64_MAX));
    TEST_ASSERT_EQUAL_UINT32(0xFFFFFFFFu, fx_isqrt64(0xFFFFFFFE00000001ull)); /* (2^32-1)^2 */
    TEST_ASSERT_EQUAL_UINT32(0xFFFFFFFEu, fx_isqrt64(0xFFFFFFFE00000000ull));
    for (unsigned k = 0; k < 64u; k++) {
        const uint64_t p = (uint64_t)1 << k;
        check_isqrt(p);
        check_isqrt(p - 1u);
        check_isqrt(p + 1u);
    }
    /* perfect squares and their neighbours over the whole range */
    for (uint64_t s = 1u; s <= 0xFFFFFFFFull; s += s / 7u + 1u) {
        const uint64_t sq = s * s;
        check_isqrt(sq);
        check_isqrt(sq - 1u);
        if (s < 0xFFFFFFFFull) {
            check_isqrt(sq + 2u * s); /* (s+1)^2 - 1 */
        }
    }
    for (int i = 0; i < 100000; i++) {
        check_isqrt(rng() >> (rng() % 64u));
    }
}

static void test_mag(void)
{
    TEST_ASSERT_EQUAL_INT32(5 * FX_ONE, fx_mag(3 * FX_ONE, -4 * FX_ONE));
    TEST_ASSERT_EQUAL_INT32(0, fx_mag(0, 0));
    TEST_ASSERT_EQUAL_INT32(1, fx_mag(-1, 0));
    TEST_ASSERT_EQUAL_INT32(FX_MAX, fx_mag(FX_MIN, FX_MIN));
    TEST_ASSERT_EQUAL_INT32(FX_MAX, fx_mag(FX_MAX, 1 << 20));
    TEST_ASSERT_EQUAL_INT32(FX_MAX, fx_mag(FX_MIN, 0)); /* 2^31 saturates */
    /* Rounded to nearest: |m - sqrt(x^2 + y^2)| <= 0.5 LSB (double sqrt of a
     * 63-bit integer: error < 1e-6 LSB). */
    for (int i = 0; i < 50000; i++) {
        const q24_t x = rnd_i32((unsigned)(rng() % 28u + 1u));
        const q24_t y = rnd_i32((unsigned)(rng() % 28u + 1u));
        const double exact = sqrt((double)x * (double)x + (double)y * (double)y);
        const q24_t m = fx_mag(x, y);
        TEST_ASSERT_TRUE_MESSAGE(fabs((double)m - exact) <= 0.5 + 1e-6, "fx_mag rounding");
    }
    /* Whole range (x^2 + y^2 up to 2^63: every normalisation shift, and the
     * saturation at sqrt >= 2^31 - 0.5), exact integer check of the rounding:
     * (m - 1/2)^2 <= S < (m + 1/2)^2  <=>  4m^2 - 4m + 1 <= 4S < 4m^2 + 4m + 1. */
    TEST_ASSERT_EQUAL_INT32(FX_MAX, fx_mag(FX_MAX, 0));
    TEST_ASSERT_EQUAL_INT32(FX_MAX, fx_mag(0, FX_MIN + 1));
    TEST_ASSERT_EQUAL_INT32(46341, fx_mag(32768, 32768)); /* sqrt(2) 2^15 = 46340.95 */
    for (int i = 0; i < 50000; i++) {
        const q24_t x = rnd_i32((unsigned)(rng() % 32u));
        const q24_t y = rnd_i32((unsigned)(rng() % 32u));
        const double exact = sqrt((double)x * (double)x + (double)y * (double)y);
        const q24_t m = fx_mag(x, y);
        if (exact >= 2147483647.5) {
            TEST_ASSERT_EQUAL_INT32(FX_MAX, m);
            continue;
        }
        const uint64_t ax = (uint64_t)(x < 0 ? -(int64_t)x : x);
        const uint64_t ay = (uint64_t)(y < 0 ? -(int64_t)y : y);
        const uint64_t s4 = 4u * (ax * ax + ay * ay); /* < 2^64 here: S < 2^62 */
        const uint64_t um = (uint64_t)m;
        TEST_ASSERT_TRUE_MESSAGE(4u * um * um - 4u * um + 1u <= s4 || m == 0, "fx_mag low");
        TEST_ASSERT_TRUE_MESSAGE(s4 < 4u * um * um + 4u * um + 1u, "fx_mag high");
    }
}

/* fx_mag_le_lim / fx_mag_ge_lim: S = x^2 + y^2 against them decides
 * fx_mag(x, y) <= t and >= t exactly as fx_mag itself, for t at and around
 * the amplitude (where the rounding decides), far from it, and at the ends
 * (negative, 0, FX_MAX, beyond). */
static void check_mag_lims(q24_t x, q24_t y)
{
    const q24_t m = fx_mag(x, y);
    const uint64_t s = (uint64_t)((int64_t)x * x) + (uint64_t)((int64_t)y * y);
    const int64_t ts[] = {(int64_t)m - 2,
                          (int64_t)m - 1,
                          m,
                          (int64_t)m + 1,
                          (int64_t)m + 2,
                          -1,
                          0,
                          1,
                          FX_MAX - 1,
                          FX_MAX,
                          (int64_t)FX_MAX + 1,
                          (int64_t)1 << 33,
                          -((int64_t)1 << 33),
                          (int64_t)m / 2,
                          (int64_t)m * 2};
    for (size_t i = 0; i < sizeof ts / sizeof ts[0]; i++) {
        const int64_t t = ts[i];
        TEST_ASSERT_EQUAL_INT_MESSAGE(m <= t, s < fx_mag_le_lim(t), "fx_mag <= t");
        TEST_ASSERT_EQUAL_INT_MESSAGE(m >= t, s >= fx_mag_ge_lim(t), "fx_mag >= t");
    }
}

static void test_mag_lims(void)
{
    static const q24_t e[] = {0,
                              1,
                              -1,
                              2,
                              3,
                              46340,
                              46341,
                              FX_ONE,
                              -FX_ONE,
                              (q24_t)1 << 30,
                              -((q24_t)1 << 30),
                              FX_MAX,
                              FX_MIN,
                              FX_MIN + 1,
                              1518500249,
                              1518500250};
    const size_t ne = sizeof e / sizeof e[0];
    for (size_t i = 0; i < ne * ne; i++) {
        check_mag_lims(e[i % ne], e[i / ne]);
    }
    for (int i = 0; i < 50000; i++) {
        check_mag_lims(rnd_i32((unsigned)(rng() % 32u)), rnd_i32((unsigned)(rng() % 32u)));
    }
}

static void test_sincos(void)
{
    q24_t s;
    q24_t c;
    fx_sincos(0u, &s, &c);
    TEST_ASSERT_EQUAL_INT32(0, s);
    TEST_ASSERT_EQUAL_INT32(FX_ONE, c);
    fx_sincos(0x40000000u, &s, &c);
    TEST_ASSERT_EQUAL_INT32(FX_ONE, s);
    TEST_ASSERT_EQUAL_INT32(0, c);
    fx_sincos(FX_ANGLE_PI, &s, &c);
    TEST_ASSERT_EQUAL_INT32(0, s);
    TEST_ASSERT_EQUAL_INT32(-FX_ONE, c);
    fx_sincos(0xC0000000u, &s, &c);
    TEST_ASSERT_EQUAL_INT32(-FX_ONE, s);
    TEST_ASSERT_EQUAL_INT32(0, c);
    fx_sincos(0u, NULL, &c); /* either output may be omitted */
    fx_sincos(0u, &s, NULL);

    /* Dense sweep: 2^16 angles with a varying offset (every table segment is
     * hit at many positions), plus random angles; both outputs. */
    double worst = 0.0;
    for (uint32_t k = 0; k < 65536u; k++) {
        const uint32_t a = (k << 16) + (uint32_t)((k * 2654435761u) & 0xFFFFu);
        fx_sincos(a, &s, &c);
        const double th = (double)a * (2.0 * CTRL_PI / 4294967296.0);
        const double es = fabs((double)s * LSB - sin(th));
        const double ec = fabs((double)c * LSB - cos(th));
        worst = fmax(worst, fmax(es, ec));
        TEST_ASSERT_TRUE(s <= FX_ONE && s >= -FX_ONE && c <= FX_ONE && c >= -FX_ONE);
    }
    for (int i = 0; i < 20000; i++) {
        const uint32_t a = (uint32_t)rng();
        fx_sincos(a, &s, &c);
        const double th = (double)a * (2.0 * CTRL_PI / 4294967296.0);
        worst = fmax(worst, fmax(fabs((double)s * LSB - sin(th)), fabs((double)c * LSB - cos(th))));
    }
    char msg[96];
    snprintf(msg, sizeof msg, "fx_sincos worst error %.3e (bound %.3e)", worst, SINCOS_BOUND);
    TEST_MESSAGE(msg);
    TEST_ASSERT_TRUE_MESSAGE(worst <= SINCOS_BOUND, "sin/cos error above the derived bound");
}

/* fx_rot_q30: cos and sin of a signed step, the nearest Q30 table point
 * turned up to pi/2, fx_sincos beyond; and the rotation fx_rotate with them. */
static void test_rot_q30(void)
{
    double worst_near = 0.0;
    double worst_tab = 0.0;
    for (int i = -200000; i <= 200000; i++) {
        /* up to +-1.7 rad, densely around 0 and the boundaries */
        const int32_t step = (int32_t)((double)i * 5840.3) + (int32_t)(rng() % 7u) - 3;
        int32_t c;
        int32_t s;
        fx_rot_q30(step, &c, &s);
        const double a = (double)step * (2.0 * CTRL_PI / 4294967296.0);
        const double e = fmax(fabs(c / 1073741824.0 - cos(a)), fabs(s / 1073741824.0 - sin(a)));
        const uint32_t mag = step < 0 ? 0u - (uint32_t)step : (uint32_t)step;
        if (mag <= FX_ROT_TAB_MAX) {
            worst_near = fmax(worst_near, e);
        } else {
            worst_tab = fmax(worst_tab, e);
        }
    }
    for (int i = 0; i < 20000; i++) { /* any step */
        const int32_t step = (int32_t)(uint32_t)rng();
        int32_t c;
        int32_t s;
        fx_rot_q30(step, &c, &s);
        const double a = (double)step * (2.0 * CTRL_PI / 4294967296.0);
        const double e = fmax(fabs(c / 1073741824.0 - cos(a)), fabs(s / 1073741824.0 - sin(a)));
        const uint32_t mag = step < 0 ? 0u - (uint32_t)step : (uint32_t)step;
        if (mag > FX_ROT_TAB_MAX) {
            worst_tab = fmax(worst_tab, e);
        }
    }
    char msg[96];
    snprintf(msg, sizeof msg, "fx_rot_q30 worst error %.3e (up to pi/2), %.3e (beyond)", worst_near,
             worst_tab);
    TEST_MESSAGE(msg);
    TEST_ASSERT_TRUE(worst_near <= ROT_TAB_BOUND);
    TEST_ASSERT_TRUE(worst_tab <= SINCOS_BOUND);
    int32_t c;
    int32_t s;
    fx_rot_q30(0, &c, &s);
    TEST_ASSERT_EQUAL_INT32(FX_Q30_ONE, c);
    TEST_ASSERT_EQUAL_INT32(0, s);
    /* fx_rotate: (x, y) turned, one rounding each, saturated at the edges */
    fx_rot_q30(0x10000000, &c, &s); /* pi/8 */
    q24_t xo;
    q24_t yo;
    fx_rotate(FX_ONE, 0, c, s, &xo, &yo);
    TEST_ASSERT_INT32_WITHIN(1, (int32_t)lround(cos(CTRL_PI / 8) * FX_ONE), xo);
    TEST_ASSERT_INT32_WITHIN(1, (int32_t)lround(sin(CTRL_PI / 8) * FX_ONE), yo);
    fx_rotate(FX_MAX, FX_MAX, FX_Q30_ONE, FX_Q30_ONE, &xo, &yo); /* 45 deg x sqrt2 */
    TEST_ASSERT_EQUAL_INT32(0, xo);
    TEST_ASSERT_EQUAL_INT32(FX_MAX, yo);
    fx_rotate(FX_MIN, FX_MIN, FX_Q30_ONE, FX_Q30_ONE, &xo, &yo);
    TEST_ASSERT_EQUAL_INT32(FX_MIN, yo);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_inline_saturation_and_rounding);
    RUN_TEST(test_fast_forms_match_reference);
    RUN_TEST(test_div);
    RUN_TEST(test_isqrt_exact);
    RUN_TEST(test_mag);
    RUN_TEST(test_mag_lims);
    RUN_TEST(test_sincos);
    RUN_TEST(test_rot_q30);
    return UNITY_END();
}
