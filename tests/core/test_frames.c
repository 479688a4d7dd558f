/*
 * Transforms (3.3)/(3.7), voltage vectors (Table 4.2), sectors (4.5)/(4.18)
 * on both sides of every boundary, index arithmetic (4.14), zero-vector rule,
 * and plan -> centre-aligned legs / volt-second average for every vector.
 * Tolerances are derived from the roundings of each function (README).
 */
#include <limits.h>
#include <math.h>

#include "ctrl_types.h"
#include "ctrl_units.h"
#include "fx.h"
#include "plan.h"
#include "transforms.h"
#include "unity.h"
#include "vectors.h"

void setUp(void)
{
}
void tearDown(void)
{
}

#define LSB (1.0 / 16777216.0)
#define SINCOS_ERR 3.18e-8

static q24_t q(double x)
{
    return (q24_t)lround(x * 16777216.0);
}

static double d(q24_t x)
{
    return (double)x * LSB;
}

static void test_clarke_balanced(void)
{
    /* Balanced set of amplitude 1.7 pu: alpha = cos, beta = sin (amplitude
     * invariant). Inputs rounded (0.5 LSB each): beta error <= 0.5 LSB
     * (rounding) + (0.5 + 2 * 0.5)/sqrt(3) LSB (inputs) < 1.4 LSB. */
    for (int k = 0; k < 720; k++) {
        const double th = 2.0 * CTRL_PI * k / 720.0;
        const double a = 1.7 * cos(th);
        const double b = 1.7 * cos(th - 2.0 * CTRL_PI / 3.0);
        q24_t al;
        q24_t be;
        ctrl_clarke(q(a), q(b), &al, &be);
        TEST_ASSERT_TRUE(fabs(d(al) - 1.7 * cos(th)) <= 0.5 * LSB);
        TEST_ASSERT_TRUE(fabs(d(be) - 1.7 * sin(th)) <= 1.4 * LSB);
        q24_t ra;
        q24_t rb;
        q24_t rc;
        ctrl_inv_clarke(al, be, &ra, &rb, &rc);
        /* inverse: 0.5 LSB rounding + sqrt(3)/2 * 1.4 LSB from beta */
        TEST_ASSERT_TRUE(fabs(d(ra) - a) <= 0.5 * LSB);
        TEST_ASSERT_TRUE(fabs(d(rb) - b) <= 2.0 * LSB);
        TEST_ASSERT_TRUE(fabs(d(rc) - 1.7 * cos(th + 2.0 * CTRL_PI / 3.0)) <= 2.5 * LSB);
    }
    q24_t al;
    q24_t be;
    ctrl_clarke(FX_MAX, FX_MAX, &al, &be); /* saturates, no overflow */
    TEST_ASSERT_EQUAL_INT32(FX_MAX, be);
    ctrl_clarke(FX_MIN, FX_MIN, &al, &be);
    TEST_ASSERT_EQUAL_INT32(FX_MIN, be);
}

static void test_park_roundtrip(void)
{
    /* Park of (cos phi, sin phi) * r at theta: (r cos(phi-theta), r sin(phi-theta)).
     * Error <= 0.5 LSB + SINCOS_ERR * (|al| + |be|) + input rounding. */
    for (int k = 0; k < 500; k++) {
        const double th = 2.0 * CTRL_PI * k / 500.0 + 0.1;
        const double phi = 0.37 * k;
        const double r = 2.5;
        const uint32_t ang =
            (uint32_t)llround(fmod(th, 2.0 * CTRL_PI) / (2.0 * CTRL_PI) * 4294967296.0);
        const double thq = (double)ang * 2.0 * CTRL_PI / 4294967296.0;
        q24_t s;
        q24_t c;
        fx_sincos(ang, &s, &c);
        q24_t dd;
        q24_t qq;
        ctrl_park(q(r * cos(phi)), q(r * sin(phi)), s, c, &dd, &qq);
        const double bound = 1.5 * LSB + SINCOS_ERR * 2.0 * r;
        TEST_ASSERT_TRUE(fabs(d(dd) - r * cos(phi - thq)) <= bound);
        TEST_ASSERT_TRUE(fabs(d(qq) - r * sin(phi - thq)) <= bound);
        q24_t al;
        q24_t be;
        ctrl_inv_park(dd, qq, s, c, &al, &be);
        TEST_ASSERT_TRUE(fabs(d(al) - r * cos(phi)) <= 2.0 * bound);
        TEST_ASSERT_TRUE(fabs(d(be) - r * sin(phi)) <= 2.0 * bound);
    }
}

/* Leg state of leg l (0..2) in vector v, from the core's table. */
static unsigned vleg(uint8_t v, unsigned l)
{
    return (ctrl_vec_legs[v] >> l) & 1u;
}

static void test_vectors_table_4_2(void)
{
    static const uint8_t legs[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                       {0, 1, 1}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}};
    const q24_t vdc = q(1.05);
    for (uint8_t i = 0; i < 8u; i++) {
        for (unsigned l = 0; l < 3u; l++) {
            TEST_ASSERT_EQUAL_UINT8(legs[i][l], vleg(i, l));
        }
        q24_t va;
        q24_t vb;
        ctrl_vector_ab(i, vdc, &va, &vb);
        /* (4.4) evaluated in double from the switching states */
        const double ea = 2.0 / 3.0 * 1.05 * (legs[i][0] - 0.5 * legs[i][1] - 0.5 * legs[i][2]);
        const double eb = 2.0 / 3.0 * 1.05 * (sqrt(3.0) / 2.0) * (legs[i][1] - legs[i][2]);
        TEST_ASSERT_TRUE(fabs(d(va) - ea) <= 0.6 * LSB);
        TEST_ASSERT_TRUE(fabs(d(vb) - eb) <= 0.6 * LSB);
    }
    q24_t va;
    q24_t vb;
    ctrl_vector_ab(9u, vdc, &va, &vb);
    TEST_ASSERT_EQUAL_INT32(0, va);
    TEST_ASSERT_EQUAL_INT32(0, vb);
    TEST_ASSERT_EQUAL_UINT8(0u, vleg(8u, 0u));
    for (unsigned v = 8u; v < 256u; v++) {
        TEST_ASSERT_EQUAL_UINT8(0u, ctrl_vec_legs[v]); /* any index is safe: no leg */
    }
    for (uint8_t i = 0; i < 8u; i++) {
        TEST_ASSERT_EQUAL_UINT8(i, ctrl_vec_of_legs[ctrl_vec_legs[i]]); /* inverse */
        /* unit directions: 3/2 of V_i / Vdc (Q30 -> Q24 within a rounding) */
        TEST_ASSERT_INT32_WITHIN(1, (q24_t)(1.5 * ctrl_vec_ab_q30[i][0] / 64.0),
                                 ctrl_vec_dir_q24[i][0]);
        TEST_ASSERT_INT32_WITHIN(1, (q24_t)(1.5 * ctrl_vec_ab_q30[i][1] / 64.0),
                                 ctrl_vec_dir_q24[i][1]);
    }
}

static void test_vec_wrap_and_zero(void)
{
    for (int x = -30; x <= 30; x++) {
        const int expect = ((x - 1) % 6 + 6) % 6 + 1;
        TEST_ASSERT_EQUAL_UINT8(expect, ctrl_vec_wrap(x));
    }
    TEST_ASSERT_EQUAL_UINT8(1u, ctrl_vec_wrap(7));
    TEST_ASSERT_EQUAL_UINT8(6u, ctrl_vec_wrap(0));
    TEST_ASSERT_EQUAL_UINT8(((INT_MAX - 1) % 6) + 1, ctrl_vec_wrap(INT_MAX));
    TEST_ASSERT_TRUE(ctrl_vec_wrap(INT_MIN) >= 1u && ctrl_vec_wrap(INT_MIN) <= 6u);
    static const uint8_t zero[8] = {0, 0, 7, 0, 7, 0, 7, 7};
    for (uint8_t v = 0; v < 8u; v++) {
        TEST_ASSERT_EQUAL_UINT8(zero[v], ctrl_zero_after(v));
        /* the zero vector differs from v in exactly one leg (active vectors) */
        if (v >= 1u && v <= 6u) {
            unsigned diff = 0;
            for (unsigned l = 0; l < 3u; l++) {
                diff += vleg(v, l) != vleg(zero[v], l);
            }
            TEST_ASSERT_EQUAL_UINT(1u, diff);
        }
    }
}

/* sector of an angle by the definitions, for angles away from boundaries */
static uint8_t sector_def(double th, int mbst)
{
    double t = fmod(th, 2.0 * CTRL_PI);
    if (t < 0) {
        t += 2.0 * CTRL_PI;
    }
    if (mbst) { /* (2x-2)pi/6 < t <= 2x pi/6 */
        int x = (int)ceil(t / (CTRL_PI / 3.0));
        return (uint8_t)(x < 1 ? 6 : x);
    }
    /* (2x-3)pi/6 < t <= (2x-1)pi/6: shift by pi/6 */
    double u = t + CTRL_PI / 6.0;
    int x = (int)ceil(u / (CTRL_PI / 3.0));
    if (x > 6) {
        x -= 6;
    }
    return (uint8_t)(x < 1 ? 1 : x);
}

static void test_sectors_boundaries(void)
{
    /* Both sides of every boundary, for radii from 1e-3 to 100 pu. */
    const double radii[] = {1e-3, 0.3, 1.0, 5.0, 100.0};
    for (unsigned ri = 0; ri < 5u; ri++) {
        const double r = radii[ri];
        for (int x = 1; x <= 6; x++) {
            const double b45 = (2 * x - 1) * CTRL_PI / 6.0; /* upper bound of sector x (4.5) */
            const double b418 = 2 * x * CTRL_PI / 6.0;      /* upper bound of sector x (4.18) */
            /* offset well above the angular resolution LSB / r at this radius */
            const double eps = fmax(1e-5, 10.0 * LSB / r);
            TEST_ASSERT_EQUAL_UINT8(x, ctrl_sector(q(r * cos(b45 - eps)), q(r * sin(b45 - eps))));
            TEST_ASSERT_EQUAL_UINT8(ctrl_vec_wrap(x + 1),
                                    ctrl_sector(q(r * cos(b45 + eps)), q(r * sin(b45 + eps))));
            TEST_ASSERT_EQUAL_UINT8(
                x, ctrl_sector_mbst(q(r * cos(b418 - eps)), q(r * sin(b418 - eps))));
            TEST_ASSERT_EQUAL_UINT8(ctrl_vec_wrap(x + 1), ctrl_sector_mbst(q(r * cos(b418 + eps)),
                                                                           q(r * sin(b418 + eps))));
        }
    }
    /* Exactly representable boundaries: upper bounds are inclusive. */
    TEST_ASSERT_EQUAL_UINT8(2u, ctrl_sector(0, FX_ONE));  /* pi/2 = (2*2-1)pi/6 */
    TEST_ASSERT_EQUAL_UINT8(5u, ctrl_sector(0, -FX_ONE)); /* 3pi/2 = (2*5-1)pi/6 */
    TEST_ASSERT_EQUAL_UINT8(1u, ctrl_sector(FX_ONE, 0));
    TEST_ASSERT_EQUAL_UINT8(4u, ctrl_sector(-FX_ONE, 0));
    TEST_ASSERT_EQUAL_UINT8(6u, ctrl_sector_mbst(FX_ONE, 0));  /* 0 = 2*6 pi/6 */
    TEST_ASSERT_EQUAL_UINT8(3u, ctrl_sector_mbst(-FX_ONE, 0)); /* pi = 2*3 pi/6 */
    TEST_ASSERT_EQUAL_UINT8(2u, ctrl_sector_mbst(0, FX_ONE));
    TEST_ASSERT_EQUAL_UINT8(5u, ctrl_sector_mbst(0, -FX_ONE));
    TEST_ASSERT_EQUAL_UINT8(1u, ctrl_sector(0, 0));
    TEST_ASSERT_EQUAL_UINT8(6u, ctrl_sector_mbst(0, 0));
    TEST_ASSERT_EQUAL_UINT8(1u, ctrl_sector(1, 0));
    TEST_ASSERT_EQUAL_UINT8(6u, ctrl_sector_mbst(1, 0));
    /* Extremes do not overflow. */
    TEST_ASSERT_EQUAL_UINT8(5u, ctrl_sector(FX_MIN, FX_MIN)); /* 225 deg */
    TEST_ASSERT_EQUAL_UINT8(4u, ctrl_sector_mbst(FX_MIN, FX_MIN));
    TEST_ASSERT_EQUAL_UINT8(2u, ctrl_sector(FX_MAX, FX_MAX)); /* 45 deg */
    /* Sweep away from boundaries. */
    for (int k = 0; k < 3600; k++) {
        const double th = 2.0 * CTRL_PI * (k + 0.5) / 3600.0;
        const q24_t x = q(0.8 * cos(th));
        const q24_t y = q(0.8 * sin(th));
        TEST_ASSERT_EQUAL_UINT8(sector_def(th, 0), ctrl_sector(x, y));
        TEST_ASSERT_EQUAL_UINT8(sector_def(th, 1), ctrl_sector_mbst(x, y));
    }
}

static void test_plan_legs_every_vector(void)
{
    const q24_t duties[] = {0, q(0.3), q(0.5), FX_ONE, -FX_ONE, 2 * FX_ONE};
    const q24_t vdc = q(0.97);
    for (uint8_t v = 0; v < 8u; v++) {
        for (unsigned k = 0; k < sizeof duties / sizeof duties[0]; k++) {
            ctrl_plan_t p;
            ctrl_plan_active_zero(&p, v, duties[k]);
            const q24_t dc = fx_clamp(duties[k], 0, FX_ONE);
            TEST_ASSERT_EQUAL_UINT8(v, p.vec[0]);
            TEST_ASSERT_EQUAL_INT32(dc, p.dur[0]);
            TEST_ASSERT_EQUAL_INT32(FX_ONE, p.dur[0] + p.dur[1]);
            ctrl_legs_t legs;
            ctrl_plan_legs(&p, &legs);
            const uint8_t z = ctrl_zero_after(v);
            unsigned switching = 0;
            for (unsigned l = 0; l < 3u; l++) {
                const q24_t expect = (q24_t)(vleg(v, l) * dc + vleg(z, l) * (FX_ONE - dc));
                TEST_ASSERT_EQUAL_INT32(expect, legs.duty[l]);
                switching += legs.duty[l] != 0 && legs.duty[l] != FX_ONE;
            }
            /* active + its zero vector: at most one leg switches in the period */
            TEST_ASSERT_TRUE(switching <= 1u);
            /* volt-second average = dc * V_v; two roundings + vdc * 0.5 LSB */
            q24_t va;
            q24_t vb;
            q24_t ea;
            q24_t eb;
            ctrl_legs_voltage(&legs, vdc, &va, &vb);
            ctrl_vector_ab(v, vdc, &ea, &eb);
            TEST_ASSERT_TRUE(fabs(d(va) - d(ea) * d(dc)) <= 2.0 * LSB);
            TEST_ASSERT_TRUE(fabs(d(vb) - d(eb) * d(dc)) <= 2.0 * LSB);
        }
    }
}

/* A three-segment plan: v1 for d1, v2 for d2, the zero vector after v1 the rest. */
static void plan_two(ctrl_plan_t *p, uint8_t v1, q24_t d1, uint8_t v2, q24_t d2)
{
    p->n_seg = 3u;
    p->vec[0] = v1;
    p->dur[0] = d1;
    p->vec[1] = v2;
    p->dur[1] = d2;
    p->vec[2] = ctrl_zero_after(v1);
    p->dur[2] = FX_ONE - d1 - d2;
}

static void test_plan_legs_three_and_single(void)
{
    ctrl_plan_t p;
    ctrl_legs_t l;
    plan_two(&p, 1u, q(0.4), 2u, FX_ONE - q(0.4));
    ctrl_plan_legs(&p, &l);
    TEST_ASSERT_EQUAL_INT32(FX_ONE, l.duty[0]);
    TEST_ASSERT_EQUAL_INT32(FX_ONE - q(0.4), l.duty[1]);
    TEST_ASSERT_EQUAL_INT32(0, l.duty[2]);
    /* V1 0.25 + V2 0.25 + V0 0.5: v = 0.25 (V1 + V2) */
    plan_two(&p, 1u, FX_ONE / 4, 2u, FX_ONE / 4);
    ctrl_plan_legs(&p, &l);
    q24_t va;
    q24_t vb;
    ctrl_legs_voltage(&l, FX_ONE, &va, &vb);
    TEST_ASSERT_TRUE(fabs(d(va) - 0.25 * (2.0 / 3.0 + 1.0 / 3.0)) <= 2.0 * LSB);
    TEST_ASSERT_TRUE(fabs(d(vb) - 0.25 * (1.0 / sqrt(3.0))) <= 2.0 * LSB);
    ctrl_plan_single(&p, 4u);
    ctrl_plan_legs(&p, &l);
    TEST_ASSERT_EQUAL_INT32(0, l.duty[0]);
    TEST_ASSERT_EQUAL_INT32(FX_ONE, l.duty[1]);
    TEST_ASSERT_EQUAL_INT32(FX_ONE, l.duty[2]);
    /* malformed plan: bad index and negative duration ignored, sum clamped */
    p.n_seg = 200u;
    p.vec[0] = 9u;
    p.dur[0] = FX_ONE;
    p.vec[1] = 1u;
    p.dur[1] = -5;
    p.vec[2] = 7u;
    p.dur[2] = FX_ONE;
    p.vec[3] = 7u;
    p.dur[3] = FX_ONE;
    ctrl_plan_legs(&p, &l);
    TEST_ASSERT_EQUAL_INT32(FX_ONE, l.duty[0]);
    TEST_ASSERT_EQUAL_INT32(FX_ONE, l.duty[2]);
    /* no segment: V0 */
    p.n_seg = 0u;
    ctrl_plan_legs(&p, &l);
    TEST_ASSERT_EQUAL_INT32(0, l.duty[0] | l.duty[1] | l.duty[2]);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_clarke_balanced);
    RUN_TEST(test_park_roundtrip);
    RUN_TEST(test_vectors_table_4_2);
    RUN_TEST(test_vec_wrap_and_zero);
    RUN_TEST(test_sectors_boundaries);
    RUN_TEST(test_plan_legs_every_vector);
    RUN_TEST(test_plan_legs_three_and_single);
    return UNITY_END();
}
