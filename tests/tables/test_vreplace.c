/*
 * Voltage replacement (4.19)-(4.21), control/vreplace.h: for every sector and
 * every vector, at positions just inside and just outside both subsectors,
 * the returned vector is the one (4.20)/(4.21) prescribe. Expected
 * replacements are written out per sector (not computed from V_{x+n}).
 *
 * Margin: ctrl_vreplace's boundary direction u(a + sigma) is rounded once to
 * Q24 (error <= 2^-25 per component, so <= 2^-24.5 rad in angle), sin/cos of
 * sigma are Q24 (<= 2^-25 each) and the test point psi = (cos, sin) at
 * amplitude 1 pu is rounded to Q24 (<= 2^-24.5 rad). The sum is < 2^-22 rad;
 * the test points sit DELTA = 1e-5 rad (> 40 x that) from the boundary.
 */
#include <math.h>
#include <stddef.h>

#include "ctrl_params.h"
#include "ctrl_units.h"
#include "unity.h"
#include "vectors.h"
#include "vreplace.h"
#include "vreplace_config.h"

void setUp(void)
{
}
void tearDown(void)
{
}

#define DELTA 1e-5

/* Subsector I (4.20): [x-1][k] = {from, to} */
static const uint8_t REP_I[6][2][2] = {
    {{3, 2}, {6, 5}}, {{4, 3}, {1, 6}}, {{5, 4}, {2, 1}},
    {{6, 5}, {3, 2}}, {{1, 6}, {4, 3}}, {{2, 1}, {5, 4}},
};
/* Subsector II (4.21) */
static const uint8_t REP_II[6][2][2] = {
    {{2, 3}, {5, 6}}, {{3, 4}, {6, 1}}, {{4, 5}, {1, 2}},
    {{5, 6}, {2, 3}}, {{6, 1}, {3, 4}}, {{1, 2}, {4, 5}},
};

static q24_t q24(double v)
{
    return (q24_t)lround(v * 16777216.0);
}

/* expected output for vec in sector x when psi is in subsector sub (0 none, 1 I, 2 II) */
static uint8_t expected(uint8_t x, uint8_t vec, int sub)
{
    const uint8_t(*rep)[2][2] = sub == 1 ? REP_I : (sub == 2 ? REP_II : NULL);
    if (rep != NULL) {
        for (int k = 0; k < 2; k++) {
            if (rep[x - 1][k][0] == vec) {
                return rep[x - 1][k][1];
            }
        }
    }
    return vec;
}

static void check_at(const ctrl_vreplace_t *c, uint8_t x, double theta, double amp, int sub)
{
    const q24_t pa = q24(amp * cos(theta));
    const q24_t pb = q24(amp * sin(theta));
    TEST_ASSERT_EQUAL_UINT8_MESSAGE(x, ctrl_sector(pa, pb), "test point in the sector");
    for (uint8_t v = 0; v <= 7; v++) {
        TEST_ASSERT_EQUAL_UINT8(expected(x, v, sub), ctrl_vreplace(c, v, x, pa, pb));
    }
}

static void check_sigma(double sigma)
{
    ctrl_vreplace_t c;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_vreplace_config(&c, sigma));
    TEST_ASSERT_EQUAL_UINT8(1, c.enabled);
    static const double amps[3] = {0.05, 1.0, 3.0};
    for (uint8_t x = 1; x <= 6; x++) {
        const double a = (2.0 * x - 3.0) * CTRL_PI / 6.0; /* lower boundary (4.5) */
        const double b = (2.0 * x - 1.0) * CTRL_PI / 6.0; /* upper boundary */
        for (int k = 0; k < 3; k++) {
            const double m = amps[k];
            const double d = DELTA / fmin(1.0, m) * 2.0; /* keep >> Q24 step at small |psi| */
            check_at(&c, x, a + d, m, 1);                /* just after the sector start */
            check_at(&c, x, a + sigma - d, m, 1);        /* just inside I */
            check_at(&c, x, a + sigma + d, m, 0);        /* just outside I */
            check_at(&c, x, (a + b) / 2.0, m, 0);        /* sector centre */
            check_at(&c, x, b - sigma - d, m, 0);        /* just outside II */
            check_at(&c, x, b - sigma + d, m, 2);        /* just inside II */
            check_at(&c, x, b - d, m, 2);                /* just before the sector end */
        }
    }
}

static void test_subsector_boundaries_sigma_max(void)
{
    check_sigma(CTRL_PI / 12.0);
}

/* Beyond (4.19)'s pi/12 up to pi/6, where subsectors I and II meet at the
 * sector centre (the sigma study). */
static void test_subsector_boundaries_sigma_wide(void)
{
    check_sigma(CTRL_PI / 8.0);
    check_sigma(CTRL_PI / 6.0 - 1e-3);
}

static void test_subsector_boundaries_sigma_small(void)
{
    check_sigma(CTRL_PI / 48.0);
}

/* theta = pi/2 exactly (psi on the beta axis) is the end of sector 2 by (4.5):
 * subsector II of sector 2 for any sigma > 0; theta = 3pi/2 ends sector 5. */
static void test_exact_axis_points(void)
{
    ctrl_vreplace_t c;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_vreplace_config(&c, 1e-6));
    TEST_ASSERT_EQUAL_UINT8(2, ctrl_sector(0, FX_ONE));
    TEST_ASSERT_EQUAL_UINT8(4, ctrl_vreplace(&c, 3, 2, 0, FX_ONE)); /* V_{x+1} -> V_{x+2} */
    TEST_ASSERT_EQUAL_UINT8(1, ctrl_vreplace(&c, 6, 2, 0, FX_ONE)); /* V_{x+4} -> V_{x+5} */
    TEST_ASSERT_EQUAL_UINT8(5, ctrl_vreplace(&c, 5, 2, 0, FX_ONE)); /* V_{x+3}: unchanged */
    TEST_ASSERT_EQUAL_UINT8(5, ctrl_sector(0, -FX_ONE));
    TEST_ASSERT_EQUAL_UINT8(1, ctrl_vreplace(&c, 6, 5, 0, -FX_ONE)); /* II of sector 5 */
}

static void test_disabled_and_bad_input(void)
{
    ctrl_vreplace_t c;
    const q24_t pa = q24(cos(-CTRL_PI / 6.0 + 0.01)); /* deep in subsector I of sector 1 */
    const q24_t pb = q24(sin(-CTRL_PI / 6.0 + 0.01));
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_vreplace_config(&c, 0.0)); /* sigma = 0: off */
    TEST_ASSERT_EQUAL_UINT8(0, c.enabled);
    TEST_ASSERT_EQUAL_UINT8(3, ctrl_vreplace(&c, 3, 1, pa, pb));
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_vreplace_config(&c, CTRL_PI / 12.0));
    TEST_ASSERT_EQUAL_UINT8(2, ctrl_vreplace(&c, 3, 1, pa, pb));
    c.enabled = 0;
    TEST_ASSERT_EQUAL_UINT8(3, ctrl_vreplace(&c, 3, 1, pa, pb));
    c.enabled = 1;
    TEST_ASSERT_EQUAL_UINT8(3, ctrl_vreplace(NULL, 3, 1, pa, pb));
    TEST_ASSERT_EQUAL_UINT8(3, ctrl_vreplace(&c, 3, 0, pa, pb));
    TEST_ASSERT_EQUAL_UINT8(3, ctrl_vreplace(&c, 3, 7, pa, pb));
    TEST_ASSERT_EQUAL_UINT8(9, ctrl_vreplace(&c, 9, 1, pa, pb));
    TEST_ASSERT_EQUAL_UINT8(3, ctrl_vreplace(&c, 3, 1, 0, 0));           /* no flux */
    TEST_ASSERT_EQUAL_UINT8(3, ctrl_vreplace(&c, 3, 1, -pa, -pb));       /* opposite sector */
    TEST_ASSERT_EQUAL_UINT8(3, ctrl_vreplace(&c, 3, 1, FX_MIN, FX_MAX)); /* no overflow */
    /* configuration errors */
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_vreplace_config(NULL, 0.1));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_vreplace_config(&c, -1e-9));
    TEST_ASSERT_EQUAL_UINT8(0, c.enabled);
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_vreplace_config(&c, CTRL_PI / 6.0 + 1e-6));
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_vreplace_config(&c, 30.0 * CTRL_PI / 180.0));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_vreplace_config(&c, NAN));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_vreplace_config(&c, INFINITY));
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_vreplace_config(&c, 15.0 * CTRL_PI / 180.0));
    TEST_ASSERT_EQUAL_UINT8(1, c.enabled);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_subsector_boundaries_sigma_max);
    RUN_TEST(test_subsector_boundaries_sigma_small);
    RUN_TEST(test_subsector_boundaries_sigma_wide);
    RUN_TEST(test_exact_axis_points);
    RUN_TEST(test_disabled_and_bad_input);
    return UNITY_END();
}
