/*
 * The rotor angle at standstill from the saliency (initial_angle.h) against
 * the exact linear machine: the pulses the module asks for applied one
 * period later (the pipeline's delay), the current changing by
 * Ts L^-1(theta) v in double, quantised to Q24 as the firmware measures it.
 *   - exact currents: the angle modulo pi within 0.01 deg for every theta
 *     on a 7-degree grid (the Q24 rounding of di ~ 0.1 pu is 1e-6 rad);
 *     the same with Ld > Lq (sal_sign -1);
 *   - currents with uniform noise of +-a: the angle error within 5 sigma,
 *     sigma from the sums' noise (each component of di has variance
 *     2 a^2 / 3; the sums' noise against their signal N Ts D |v|^2);
 *   - the configuration refused with bad arguments.
 * Runs on the host and in QEMU (integer core).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "../core/machines.h"
#include "ctrl_units.h"
#include "initial_angle.h"
#include "unity.h"

void setUp(void)
{
}
void tearDown(void)
{
}

#define TURN 4294967296.0

static ctrl_params_t P;
static ctrl_bases_t B;

static double d(q24_t x)
{
    return ctrl_q24_to_double(x);
}

/* error of est (fx angle, modulo pi) against theta (rad), in rad within +-pi/2 */
static double err_mod_pi(fx_angle_t est, double theta)
{
    double e = (double)est * 2.0 * CTRL_PI / TURN - theta;
    return e - CTRL_PI * floor((e + CTRL_PI / 2.0) / CTRL_PI);
}

static uint32_t rng = 12345u;
static double noise(double a)
{
    rng = rng * 1664525u + 1013904223u;
    return a * (2.0 * (double)(rng >> 8) / 16777216.0 - 1.0);
}

/* One measurement on the linear machine at theta (pu inverse inductances
 * inv_d, inv_q); currents with uniform noise +-a pu. */
static fx_angle_t measure(ctrl_ia_t *ia, double theta, double inv_d, double inv_q, double a)
{
    ctrl_ia_start(ia);
    const double ts = d(P.ts);
    const double s = 0.5 * (inv_d + inv_q);
    const double dd = 0.5 * (inv_d - inv_q);
    const double c2 = cos(2.0 * theta);
    const double s2 = sin(2.0 * theta);
    double ia_a = 0.0;
    double ia_b = 0.0;
    q24_t asked_a = 0; /* asked at k-1: acts in [k, k+1) */
    q24_t asked_b = 0;
    q24_t v_prev_a = 0; /* applied in [k-1, k) */
    q24_t v_prev_b = 0;
    uint8_t run = 1u;
    uint32_t guard = 0u;
    while (run != 0u && guard++ < 100000u) {
        /* the current at k after the voltage of [k-1, k) */
        const double va = d(v_prev_a);
        const double vb = d(v_prev_b);
        ia_a += ts * (s * va + dd * (c2 * va + s2 * vb));
        ia_b += ts * (s * vb + dd * (s2 * va - c2 * vb));
        const q24_t qa = ctrl_q24_from_double(ia_a + noise(a));
        const q24_t qb = ctrl_q24_from_double(ia_b + noise(a));
        q24_t oa;
        q24_t ob;
        run = ctrl_ia_step(ia, v_prev_a, v_prev_b, qa, qb, &oa, &ob);
        /* what was asked at k-1 acts in [k, k+1) */
        v_prev_a = asked_a;
        v_prev_b = asked_b;
        asked_a = oa;
        asked_b = ob;
    }
    TEST_ASSERT_EQUAL_UINT32(ctrl_ia_periods(ia), guard);
    return ctrl_ia_angle(ia);
}

static void setup(void)
{
    const ctrl_machine_t m = machine_thesis_ipmsm80();
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&P, &B, &m, 10000u));
}

static void test_exact(void)
{
    setup();
    ctrl_ia_t ia;
    const q24_t v = ctrl_q24_from_double(0.3);
    TEST_ASSERT_EQUAL_INT(0, ctrl_ia_init(&ia, v, 2u, 1));
    ctrl_ia_t ib;
    TEST_ASSERT_EQUAL_INT(0, ctrl_ia_init(&ib, v, 2u, -1));
    double worst = 0.0;
    for (int k = -60; k < 60; k++) {
        const double th = k * 7.0 * CTRL_PI / 180.0 + 0.01;
        const fx_angle_t e = measure(&ia, th, d(P.inv_ld), d(P.inv_lq), 0.0);
        TEST_ASSERT_TRUE(e < 0x80000000u); /* [0, pi) */
        worst = fmax(worst, fabs(err_mod_pi(e, th)));
        /* Ld > Lq: the same angle with the inductances swapped */
        const fx_angle_t f = measure(&ib, th, d(P.inv_lq), d(P.inv_ld), 0.0);
        worst = fmax(worst, fabs(err_mod_pi(f, th)));
    }
    printf("exact currents: worst angle error %.2e deg\n", worst * 180.0 / CTRL_PI);
    TEST_ASSERT_TRUE(worst <= 0.01 * CTRL_PI / 180.0);
}

static void test_noise(void)
{
    setup();
    ctrl_ia_t ia;
    const double v = 0.3;
    const uint32_t rounds = 2u;
    TEST_ASSERT_EQUAL_INT(0, ctrl_ia_init(&ia, ctrl_q24_from_double(v), rounds, 1));
    const double a = 0.005 * d(P.current_rated); /* +-0.5 % of the rated current */
    const double n = (double)(rounds * CTRL_IA_DIRS * CTRL_IA_PER_DIR);
    const double dd = 0.5 * (d(P.inv_ld) - d(P.inv_lq));
    const double sig_sum = sqrt(n * v * v * 2.0 * a * a / 3.0);
    const double signal = n * d(P.ts) * dd * v * v;
    const double sigma = 0.5 * sig_sum / signal; /* of theta = (2 theta) / 2 */
    double worst = 0.0;
    for (int k = 0; k < 72; k++) {
        const double th = k * 5.0 * CTRL_PI / 180.0 + 0.02;
        worst = fmax(worst, fabs(err_mod_pi(measure(&ia, th, d(P.inv_ld), d(P.inv_lq), a), th)));
    }
    printf("noise +-%.4f pu: worst angle error %.3f deg, sigma %.3f deg\n", a,
           worst * 180.0 / CTRL_PI, sigma * 180.0 / CTRL_PI);
    TEST_ASSERT_TRUE(worst <= 5.0 * sigma);
}

static void test_bad_config(void)
{
    ctrl_ia_t ia;
    TEST_ASSERT_EQUAL_INT(-1, ctrl_ia_init(&ia, 0, 2u, 1));
    TEST_ASSERT_EQUAL_INT(-1, ctrl_ia_init(&ia, FX_ONE, 0u, 1));
    TEST_ASSERT_EQUAL_INT(-1, ctrl_ia_init(&ia, FX_ONE, CTRL_IA_ROUNDS_MAX + 1u, 1));
    TEST_ASSERT_EQUAL_INT(-1, ctrl_ia_init(&ia, FX_ONE, 2u, 0));
    TEST_ASSERT_EQUAL_INT(-1, ctrl_ia_init(NULL, FX_ONE, 2u, 1));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_exact);
    RUN_TEST(test_noise);
    RUN_TEST(test_bad_config);
    return UNITY_END();
}
