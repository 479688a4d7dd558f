/*
 * The configuration's elementary functions (ctrl_cfg_math.h) against the C
 * library's: within a few ulp over the arguments configuration uses and
 * beyond (a Taylor kernel of the stated length on a reduced argument rounds
 * about one ulp per step of Horner's rule), the quadrants and signs exact,
 * and the documented edges (NaN out of range, 0 and +inf for exp). The
 * rounding and scaling helpers equal the C library's llround, ldexp and
 * frexp exactly (they replace them in the configuration code).
 */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#include "ctrl_cfg_math.h"
#include "unity.h"

void setUp(void)
{
}

void tearDown(void)
{
}

/* |got - want| <= n ulp of want, plus an absolute floor for results near 0
 * (sin near k pi: the reduction's absolute error, ~1e-16 |r| + n 1e-27). */
static void assert_close(double want, double got, double ulps, double floor_abs, double x)
{
    const double tol = ulps * DBL_EPSILON * fabs(want) + floor_abs;
    if (!(fabs(got - want) <= tol)) {
        char m[96];
        (void)snprintf(m, sizeof m, "x = %.17g: %.17g vs %.17g", x, got, want);
        TEST_FAIL_MESSAGE(m);
    }
}

static void test_sincos(void)
{
    for (int i = -20000; i <= 20000; i++) {
        const double x = (double)i * 0.00157079632679 * 3.7; /* about +-116 rad */
        double s, c;
        ctrl_cfg_sincos(x, &s, &c);
        assert_close(sin(x), s, 4.0, 1e-19, x);
        assert_close(cos(x), c, 4.0, 1e-19, x);
        TEST_ASSERT_EQUAL_DOUBLE(s, ctrl_cfg_sin(x));
        TEST_ASSERT_EQUAL_DOUBLE(c, ctrl_cfg_cos(x));
    }
    for (double x = 1e-300; x < 1.0; x *= 7.3) { /* tiny arguments: sin x = x */
        assert_close(sin(x), ctrl_cfg_sin(x), 2.0, 0.0, x);
        assert_close(cos(x), ctrl_cfg_cos(x), 2.0, 0.0, x);
    }
    assert_close(sin(CTRL_CFG_TRIG_MAX), ctrl_cfg_sin(CTRL_CFG_TRIG_MAX), 8.0, 1e-19, 1e6);
    TEST_ASSERT_TRUE(isnan(ctrl_cfg_sin(2.0 * CTRL_CFG_TRIG_MAX)));
    TEST_ASSERT_TRUE(isnan(ctrl_cfg_cos(-2.0 * CTRL_CFG_TRIG_MAX)));
    TEST_ASSERT_TRUE(isnan(ctrl_cfg_sin(NAN)));
    TEST_ASSERT_TRUE(isnan(ctrl_cfg_cos(INFINITY)));
}

static void test_exp(void)
{
    for (int i = -7080; i <= 7089; i++) { /* up to 708.91 */
        const double x = (double)i * 0.1 + 0.0123;
        assert_close(exp(x), ctrl_cfg_exp(x), 4.0, 0.0, x);
    }
    for (double x = 1e-300; x < 1.0; x *= 3.1) {
        assert_close(exp(x), ctrl_cfg_exp(x), 2.0, 0.0, x);
        assert_close(exp(-x), ctrl_cfg_exp(-x), 2.0, 0.0, -x);
    }
    TEST_ASSERT_EQUAL_DOUBLE(1.0, ctrl_cfg_exp(0.0));
    TEST_ASSERT_TRUE(isinf(ctrl_cfg_exp(710.0)) && ctrl_cfg_exp(710.0) > 0.0);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, ctrl_cfg_exp(-709.0));
    TEST_ASSERT_TRUE(isnan(ctrl_cfg_exp(NAN)));
}

static void test_hypot(void)
{
    for (int i = -50; i <= 50; i++) {
        for (int j = -50; j <= 50; j++) {
            const double x = (double)i * 0.731e-3;
            const double y = (double)j * 1.37e2;
            assert_close(hypot(x, y), ctrl_cfg_hypot(x, y), 2.0, 0.0, x);
        }
    }
    TEST_ASSERT_EQUAL_DOUBLE(5.0, ctrl_cfg_hypot(3.0, -4.0));
}

/* x and its neighbours one ulp away (halves, integers, 2^52 +- ...) against
 * llround; from 2^52 on every double is an integer, its own rounding (the
 * reference there: newlib's llround drops bits above 2^52, e.g.
 * 12530005615012148 -> 12530001320044852). */
static void assert_llround_around(double x)
{
    const double xs[3] = {nextafter(x, -INFINITY), x, nextafter(x, INFINITY)};
    for (int k = 0; k < 3; k++) {
        const int exact = fabs(xs[k]) >= 0x1p52;
        if (exact ? (double)ctrl_cfg_llround(xs[k]) != xs[k]
                  : llround(xs[k]) != ctrl_cfg_llround(xs[k])) {
            char m[128];
            (void)snprintf(m, sizeof m, "x = %.17g: %.17g vs llround %.17g", xs[k],
                           (double)ctrl_cfg_llround(xs[k]), (double)llround(xs[k]));
            TEST_FAIL_MESSAGE(m);
        }
    }
}

static void test_llround(void)
{
    for (int i = -4000; i <= 4000; i++) {
        assert_llround_around((double)i * 0.5);
        assert_llround_around((double)i * 0.1);
    }
    for (double x = 1e-300; x < 0x1p62; x *= 1.37) {
        assert_llround_around(x);
        assert_llround_around(-x);
    }
    for (int e = 50; e <= 62; e++) {
        const double p = ldexp(1.0, e);
        assert_llround_around(p + 1.0);
        assert_llround_around(-p - 1.0);
        assert_llround_around(p - 0.5);
        assert_llround_around(-p + 0.5);
    }
    TEST_ASSERT_TRUE(ctrl_cfg_llround(0.49999999999999994) == 0);
    TEST_ASSERT_TRUE(ctrl_cfg_llround(-2.5) == -3);
    TEST_ASSERT_TRUE(ctrl_cfg_llround(NAN) == 0);
    TEST_ASSERT_TRUE(ctrl_cfg_llround(0x1p63) == INT64_MAX);
    TEST_ASSERT_TRUE(ctrl_cfg_llround(-INFINITY) == INT64_MIN);
}

static void test_ldexp_exponent(void)
{
    for (double x = 1e-300; x < 1e300; x *= 3.3) {
        for (int n = -60; n <= 60; n++) {
            TEST_ASSERT_TRUE(ctrl_cfg_ldexp(x, n) == ldexp(x, n));
            TEST_ASSERT_TRUE(ctrl_cfg_ldexp(-x, n) == ldexp(-x, n));
        }
        int e;
        (void)frexp(x, &e);
        TEST_ASSERT_EQUAL_INT(e, ctrl_cfg_exponent(x));
        TEST_ASSERT_EQUAL_INT(e, ctrl_cfg_exponent(-x));
    }
    for (double x = DBL_TRUE_MIN; x < 4.0 * DBL_MIN; x *= 2.9) { /* subnormals */
        int e;
        (void)frexp(x, &e);
        TEST_ASSERT_EQUAL_INT(e, ctrl_cfg_exponent(x));
    }
    TEST_ASSERT_EQUAL_INT(1, ctrl_cfg_exponent(1.0)); /* 1 = 0.5 2^1 */
    TEST_ASSERT_EQUAL_INT(0, ctrl_cfg_exponent(0.0));
    TEST_ASSERT_EQUAL_INT(0, ctrl_cfg_exponent(INFINITY));
    TEST_ASSERT_EQUAL_INT(0, ctrl_cfg_exponent(NAN));
    TEST_ASSERT_TRUE(ctrl_cfg_ldexp(1.0, 1023) == 0x1p1023);
    TEST_ASSERT_TRUE(ctrl_cfg_ldexp(1.0, -1022) == 0x1p-1022);
    TEST_ASSERT_TRUE(isnan(ctrl_cfg_ldexp(1.0, 1024)));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_sincos);
    RUN_TEST(test_exp);
    RUN_TEST(test_hypot);
    RUN_TEST(test_llround);
    RUN_TEST(test_ldexp_exponent);
    return UNITY_END();
}
