/*
 * Fixed-point primitives (control/fx.h, fx.c): saturation at the edges,
 * rounding of negative values, division by zero, exactness of the integer
 * square root, rounding of the magnitude, and the sin/cos error bound derived
 * in control/README.md (1.24e-6: interpolation h^2/8 with h = pi/1024, plus
 * one LSB of table and interpolation rounding).
 */
#include <math.h>
#include <stdint.h>

#include "fx.h"
#include "unity.h"

void setUp(void)
{
}
void tearDown(void)
{
}

#define LSB (1.0 / 16777216.0)
#define SINCOS_BOUND                                                                               \
    (((3.14159265358979323846 / 1024.0) * (3.14159265358979323846 / 1024.0)) / 8.0 + LSB)

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
        const double th = (double)a * (2.0 * 3.14159265358979323846 / 4294967296.0);
        const double es = fabs((double)s * LSB - sin(th));
        const double ec = fabs((double)c * LSB - cos(th));
        worst = fmax(worst, fmax(es, ec));
        TEST_ASSERT_TRUE(s <= FX_ONE && s >= -FX_ONE && c <= FX_ONE && c >= -FX_ONE);
    }
    for (int i = 0; i < 20000; i++) {
        const uint32_t a = (uint32_t)rng();
        fx_sincos(a, &s, &c);
        const double th = (double)a * (2.0 * 3.14159265358979323846 / 4294967296.0);
        worst = fmax(worst, fmax(fabs((double)s * LSB - sin(th)), fabs((double)c * LSB - cos(th))));
    }
    TEST_ASSERT_TRUE_MESSAGE(worst <= SINCOS_BOUND, "sin/cos error above the derived bound");
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_inline_saturation_and_rounding);
    RUN_TEST(test_div);
    RUN_TEST(test_isqrt_exact);
    RUN_TEST(test_mag);
    RUN_TEST(test_sincos);
    return UNITY_END();
}
