/*
 * Space-vector PWM (control/svpwm.h): leg duties against the textbook
 * min-max injection formula d_x = 1/2 + (v_x - (max + min)/2) / Vdc in every
 * sector and for random vectors, the equal split of the zero time between V0
 * and V7, the period-average voltage of the duties, and over-modulation
 * limiting (on the hexagon, angle kept). Bounds from the Q24 formats (see each test).
 */
#include <math.h>
#include <stdint.h>

#include "chapter_machines.h"
#include "ctrl_params.h"
#include "ctrl_units.h"
#include "plan.h"
#include "svpwm.h"
#include "unity.h"

void setUp(void)
{
}
void tearDown(void)
{
}

#define LSB (1.0 / 16777216.0)

static double q(q24_t x)
{
    return (double)x * LSB;
}

/* Textbook duties in double from the (exact) Q24 inputs. */
static void duties_ref(q24_t va, q24_t vb, q24_t vdc, double d[3])
{
    const double a = q(va);
    const double b = q(vb);
    const double ph[3] = {a, -0.5 * a + sqrt(3.0) / 2.0 * b, -0.5 * a - sqrt(3.0) / 2.0 * b};
    const double mx = fmax(ph[0], fmax(ph[1], ph[2]));
    const double mn = fmin(ph[0], fmin(ph[1], ph[2]));
    for (int x = 0; x < 3; x++) {
        d[x] = 0.5 + (ph[x] - 0.5 * (mx + mn)) / q(vdc);
    }
}

static void check_vector(q24_t va, q24_t vb, q24_t vdc)
{
    /* Error budget: inverse Clarke 1 LSB per phase, 1/Vdc in Q24 (relative
     * 2^-24 / (1/Vdc)), one rounding of the duty: < 8 LSB for Vdc >= 0.5 pu. */
    const double tol = 8.0 * LSB;
    ctrl_legs_t legs;
    ctrl_svpwm_duties(va, vb, vdc, &legs);
    double d[3];
    duties_ref(va, vb, vdc, d);
    for (int x = 0; x < 3; x++) {
        TEST_ASSERT_DOUBLE_WITHIN(tol, d[x], q(legs.duty[x]));
    }
    /* Equal zero-vector split (min-max injection): the time with every leg low
     * (1 - max) equals the time with every leg high (min) within the rounding. */
    const double dmax = fmax(q(legs.duty[0]), fmax(q(legs.duty[1]), q(legs.duty[2])));
    const double dmin = fmin(q(legs.duty[0]), fmin(q(legs.duty[1]), q(legs.duty[2])));
    TEST_ASSERT_DOUBLE_WITHIN(2.0 * tol, 1.0 - dmax, dmin);
    /* Period-average voltage equals the reference (legs_voltage: 2 roundings). */
    q24_t pa;
    q24_t pb;
    ctrl_legs_voltage(&legs, vdc, &pa, &pb);
    TEST_ASSERT_DOUBLE_WITHIN(4.0 * tol, q(va), q(pa));
    TEST_ASSERT_DOUBLE_WITHIN(4.0 * tol, q(vb), q(pb));
}

static void test_duties_all_sectors(void)
{
    /* Every sector, angles on a 1-degree grid including the vector directions,
     * amplitudes up to the hexagon edge in that direction (97 %). */
    const q24_t vdc = FX_ONE;
    for (int deg = 0; deg < 360; deg++) {
        const double a = deg * CTRL_PI / 180.0;
        /* hexagon radius in direction a: (Vdc/sqrt(3)) / cos(a mod 60 - 30) */
        const double off = fmod(a, CTRL_PI / 3.0) - CTRL_PI / 6.0;
        const double rmax = 1.0 / sqrt(3.0) / cos(off);
        for (int s = 1; s <= 4; s++) {
            const double r = 0.97 * rmax * s / 4.0;
            check_vector(ctrl_q24_from_double(r * cos(a)), ctrl_q24_from_double(r * sin(a)), vdc);
        }
    }
}

static void test_duties_random(void)
{
    uint64_t seed = 0x5eed1234u;
    for (int n = 0; n < 20000; n++) {
        const double vdc = 0.5 + 1.0 * chapter_rand(&seed);
        const double a = 2.0 * CTRL_PI * chapter_rand(&seed);
        const double off = fmod(a, CTRL_PI / 3.0) - CTRL_PI / 6.0;
        const double r = chapter_rand(&seed) * vdc / sqrt(3.0) / cos(off) * 0.999;
        q24_t va = ctrl_q24_from_double(r * cos(a));
        q24_t vb = ctrl_q24_from_double(r * sin(a));
        const q24_t vd = ctrl_q24_from_double(vdc);
        TEST_ASSERT_EQUAL_UINT8(0, ctrl_svpwm_limit(vd, &va, &vb)); /* inside: unchanged */
        check_vector(va, vb, vd);
    }
}

static void test_overmodulation_on_hexagon_same_angle(void)
{
    uint64_t seed = 42u;
    for (int n = 0; n < 20000; n++) {
        const double vdc = 0.5 + chapter_rand(&seed);
        const double a = 2.0 * CTRL_PI * chapter_rand(&seed);
        const double off = fmod(a, CTRL_PI / 3.0) - CTRL_PI / 6.0;
        const double rhex = vdc / sqrt(3.0) / cos(off);
        const double r = rhex * (1.001 + 3.0 * chapter_rand(&seed));
        const q24_t va0 = ctrl_q24_from_double(r * cos(a));
        const q24_t vb0 = ctrl_q24_from_double(r * sin(a));
        q24_t va = va0;
        q24_t vb = vb0;
        const q24_t vd = ctrl_q24_from_double(vdc);
        TEST_ASSERT_EQUAL_UINT8(1, ctrl_svpwm_limit(vd, &va, &vb));
        /* Angle kept: sin of the angle between before and after within the
         * rounding of two Q24 components (|v| >= 0.28 pu): 1e-6 rad. */
        const double cr = q(va0) * q(vb) - q(vb0) * q(va);
        const double sin_ang = cr / (hypot(q(va0), q(vb0)) * hypot(q(va), q(vb)));
        TEST_ASSERT_DOUBLE_WITHIN(1e-6, 0.0, sin_ang);
        TEST_ASSERT_TRUE(q(va0) * q(va) + q(vb0) * q(vb) > 0.0);
        /* On the hexagon: radius in its direction within 4 LSB (truncated k,
         * two roundings), never meaningfully outside. */
        const double ang = atan2(q(vb), q(va));
        const double o2 = fmod(ang + 4.0 * CTRL_PI, CTRL_PI / 3.0) - CTRL_PI / 6.0;
        const double rh = q(vd) / sqrt(3.0) / cos(o2);
        TEST_ASSERT_DOUBLE_WITHIN(4.0 * LSB, rh, hypot(q(va), q(vb)));
        /* Realisable: duties in [0, 1] and the plan gives back the vector. */
        check_vector(va, vb, vd);
    }
}

static void test_bad_vdc(void)
{
    q24_t va = FX_ONE / 4;
    q24_t vb = -FX_ONE / 8;
    ctrl_legs_t legs;
    TEST_ASSERT_EQUAL_UINT8(1, ctrl_svpwm(&va, &vb, 0, &legs));
    TEST_ASSERT_EQUAL_INT32(0, va);
    TEST_ASSERT_EQUAL_INT32(0, vb);
    TEST_ASSERT_EQUAL_INT32(legs.duty[0], legs.duty[1]); /* zero vector only */
    TEST_ASSERT_EQUAL_INT32(legs.duty[1], legs.duty[2]);
    ctrl_svpwm_duties(FX_ONE / 4, 0, -FX_ONE, &legs);
    TEST_ASSERT_EQUAL_INT32(0, legs.duty[0]);
    /* Saturated inputs do not overflow. */
    va = FX_MAX;
    vb = FX_MIN;
    TEST_ASSERT_EQUAL_UINT8(1, ctrl_svpwm(&va, &vb, FX_ONE, &legs));
    for (int x = 0; x < 3; x++) {
        TEST_ASSERT_TRUE(legs.duty[x] >= 0 && legs.duty[x] <= FX_ONE);
    }
}

/* 1/vdc without a 64-bit division is fx_div(FX_ONE, vdc) bit for bit: at
 * every power of two and its neighbours, densely at the low end of the fast
 * range (where the quotient nears 2^31), strided across it, and beyond. */
static void test_inv_vdc_equals_fx_div(void)
{
    for (int k = 0; k <= 30; k++) {
        for (int32_t e = -8; e <= 8; e++) {
            const int64_t v = ((int64_t)1 << k) + e;
            if (v > 0 && v <= INT32_MAX) {
                TEST_ASSERT_EQUAL_INT32(fx_div(FX_ONE, (q24_t)v), ctrl_svpwm_inv_vdc((q24_t)v));
            }
        }
    }
    for (q24_t v = (1 << 17) - 16; v < (1 << 17) + 65536; v++) {
        TEST_ASSERT_EQUAL_INT32(fx_div(FX_ONE, v), ctrl_svpwm_inv_vdc(v));
    }
    for (q24_t v = 1 << 17; v < (1 << 26) + 4096; v += 997) {
        TEST_ASSERT_EQUAL_INT32(fx_div(FX_ONE, v), ctrl_svpwm_inv_vdc(v));
    }
    TEST_ASSERT_EQUAL_INT32(fx_div(FX_ONE, FX_MAX), ctrl_svpwm_inv_vdc(FX_MAX));
}

/* ctrl_svpwm (phases formed once when not limited) equals ctrl_svpwm_limit
 * followed by ctrl_svpwm_duties bit for bit, inside the hexagon and beyond. */
static void test_svpwm_equals_limit_then_duties(void)
{
    uint64_t seed = 0x5eed5678u;
    for (int n = 0; n < 20000; n++) {
        const q24_t vdc = ctrl_q24_from_double(0.05 + 2.0 * chapter_rand(&seed));
        const double a = 2.0 * CTRL_PI * chapter_rand(&seed);
        const double r = 1.5 * chapter_rand(&seed) * q(vdc);
        q24_t va = ctrl_q24_from_double(r * cos(a));
        q24_t vb = ctrl_q24_from_double(r * sin(a));
        q24_t wa = va;
        q24_t wb = vb;
        ctrl_legs_t one;
        ctrl_legs_t two;
        const uint8_t lim = ctrl_svpwm(&va, &vb, vdc, &one);
        TEST_ASSERT_EQUAL_UINT8(ctrl_svpwm_limit(vdc, &wa, &wb), lim);
        ctrl_svpwm_duties(wa, wb, vdc, &two);
        TEST_ASSERT_EQUAL_INT32(wa, va);
        TEST_ASSERT_EQUAL_INT32(wb, vb);
        for (int x = 0; x < 3; x++) {
            TEST_ASSERT_EQUAL_INT32(two.duty[x], one.duty[x]);
        }
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_duties_all_sectors);
    RUN_TEST(test_duties_random);
    RUN_TEST(test_overmodulation_on_hexagon_same_angle);
    RUN_TEST(test_bad_vdc);
    RUN_TEST(test_inv_vdc_equals_fx_div);
    RUN_TEST(test_svpwm_equals_limit_then_duties);
    return UNITY_END();
}
