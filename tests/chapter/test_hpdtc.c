/*
 * HP-DTC (S1 §5, control/ctrl_s1_dtc.h): the vector selector S1 Table 4 for
 * every phi, tau and sector n (with the index wrap), the reflected position
 * sections of S1(40), the generated timing table (each (t_k1, t_k2) pair
 * synthesises the intended voltage within one point, 1/20 of the period, in
 * each component) and the controller step end to end (voltage direction,
 * level from |T_err|, V0/V7 split).
 */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "chapter_machines.h"
#include "chapter_rig.h"
#include "controller.h"
#include "ctrl_params.h"
#include "ctrl_s1_dtc.h"
#include "ctrl_s1_dtc_config.h"
#include "ctrl_units.h"
#include "plan.h"
#include "unity.h"
#include "vectors.h"

void setUp(void)
{
}
void tearDown(void)
{
}

#define DEG (CTRL_PI / 180.0)

static double q(q24_t x)
{
    return (double)x / 16777216.0;
}

/* S1 Table 4 as printed, with "if V_k > 6 then V_k - 6, if V_k < 1 then V_k + 6". */
static int wrap_s1(int v)
{
    if (v > 6) {
        v -= 6;
    }
    if (v < 1) {
        v += 6;
    }
    return v;
}

static void test_table4_all_entries(void)
{
    static const int rows[4][4] = {
        /* phi, tau, k1 offset, k2 offset */
        {1, 1, +1, +2},
        {1, 0, -1, -2},
        {0, 1, +2, +1},
        {0, 0, -2, -1},
    };
    for (int r = 0; r < 4; r++) {
        for (int n = 1; n <= 6; n++) {
            uint8_t k1 = 0;
            uint8_t k2 = 0;
            const int s = ctrl_hpdtc_vectors(rows[r][0], rows[r][1], n, &k1, &k2);
            TEST_ASSERT_EQUAL_INT(wrap_s1(n + rows[r][2]), k1);
            TEST_ASSERT_EQUAL_INT(wrap_s1(n + rows[r][3]), k2);
            TEST_ASSERT_EQUAL_INT(rows[r][0] == rows[r][1] ? 1 : -1, s);
        }
    }
    /* Any int sector wraps without overflow. */
    uint8_t k1;
    uint8_t k2;
    ctrl_hpdtc_vectors(1, 1, 7, &k1, &k2);
    TEST_ASSERT_EQUAL_INT(2, k1);
    ctrl_hpdtc_vectors(1, 1, 2147483647, &k1, &k2);
    TEST_ASSERT_TRUE(k1 >= 1 && k1 <= 6 && k2 >= 1 && k2 <= 6);
}

static void test_sections(void)
{
    /* rho = offset of the flux from its sector centre, [-30, 30) deg; 5 equal
     * sections of 12 deg. Grid of 0.25 deg, skipping 0.01 deg at the edges. */
    for (int k = 0; k < 360 * 4; k++) {
        const double lam = k * 0.25 + 0.1;
        const double r = 0.3 + 0.7 * (k % 7) / 6.0;
        const q24_t x = ctrl_q24_from_double(r * cos(lam * DEG));
        const q24_t y = ctrl_q24_from_double(r * sin(lam * DEG));
        const uint8_t n = ctrl_sector(x, y);
        double rho = fmod(lam + 30.0, 60.0) - 30.0; /* S1(40), sector-relative */
        TEST_ASSERT_DOUBLE_WITHIN(1e-9, 0.0, fmod(lam - (n - 1) * 60.0 - rho + 720.0, 360.0));
        const int expect = (int)floor((rho + 30.0) / 12.0) - 2;
        TEST_ASSERT_EQUAL_INT(expect, ctrl_hpdtc_section(x, y, n));
    }
}

/* Each pair synthesises the intended voltage within one point per component. */
static void check_table(double tilt)
{
    uint8_t pts[HPDTC_LEVELS][HPDTC_SECTIONS][2];
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_hpdtc_timing_table(tilt, pts));
    const double vk = 2.0 / 3.0; /* |V_k| at Vdc = 1 */
    for (int l = 0; l < HPDTC_LEVELS; l++) {
        const double m = (l + 1) / 5.0;
        for (int j = 0; j < HPDTC_SECTIONS; j++) {
            /* Intended: amplitude m Vdc/sqrt(3), direction = flux tangent at the
             * section centre rho = 12 (j - 2) deg, i.e. 30 + rho from V_k1,
             * tilted towards V_k1, within the 60-deg wedge. V_k1 on the x axis. */
            double a = (30.0 + 12.0 * (j - 2)) * DEG - tilt;
            a = fmin(fmax(a, 0.0), 60.0 * DEG);
            const double vx = m / sqrt(3.0) * cos(a);
            const double vy = m / sqrt(3.0) * sin(a);
            /* Dwell times by solving v = t1 V_k1 + t2 V_k2 (fractions of Ts). */
            const double t2 = vy / (vk * sin(60.0 * DEG));
            const double t1 = (vx - t2 * vk * cos(60.0 * DEG)) / vk;
            const int p1 = pts[l][j][0];
            const int p2 = pts[l][j][1];
            TEST_ASSERT_TRUE(p1 + p2 <= 20);
            TEST_ASSERT_DOUBLE_WITHIN(1.0, 20.0 * t1, p1);
            TEST_ASSERT_DOUBLE_WITHIN(1.0, 20.0 * t2, p2);
            /* Synthesised voltage, alpha and beta components, within one point
             * (|V_k| / 20) each. */
            const double sx = (p1 * vk + p2 * vk * cos(60.0 * DEG)) / 20.0;
            const double sy = (p2 * vk * sin(60.0 * DEG)) / 20.0;
            TEST_ASSERT_DOUBLE_WITHIN(vk / 20.0, vx, sx);
            TEST_ASSERT_DOUBLE_WITHIN(vk / 20.0, vy, sy);
        }
    }
}

static void test_timing_table_synthesis(void)
{
    check_table(CTRL_PI / 30.0); /* default tilt, 6 deg */
    check_table(0.0);
    check_table(12.0 * DEG);
    check_table(CTRL_PI / 6.0);
    uint8_t pts[HPDTC_LEVELS][HPDTC_SECTIONS][2];
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_hpdtc_timing_table(-0.1, pts));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_hpdtc_timing_table(NAN, pts));
}

static chapter_rig_t rig;

static void rig_init(void)
{
    chapter_rig_init(&rig, "hpdtc", &ini_chapter_ipmsm);
    TEST_ASSERT_EQUAL_UINT32(10000u, rig.d->fs_default_hz);
}

/* Flux at angle lam (rad), amplitude 1 pu, torque t (pu) in est->next. */
static void set_next(double lam, double t)
{
    ctrl_mstate_t *nx = &rig.est.next;
    nx->psi_alpha = ctrl_q24_from_double(cos(lam));
    nx->psi_beta = ctrl_q24_from_double(sin(lam));
    nx->psi_amp = FX_ONE;
    nx->psi_amp_sq = (uint64_t)FX_ONE * FX_ONE; /* its root: psi_amp */
    nx->torque = ctrl_q24_from_double(t);
    nx->sector = ctrl_sector(nx->psi_alpha, nx->psi_beta); /* (4.5), as the estimator */
}

static void test_step_geometry(void)
{
    rig_init();
    const ctrl_hpdtc_state_t *s = (const ctrl_hpdtc_state_t *)rig.state;
    const double thr1 = q(s->lvl_thr[0]); /* e_fs / 5 */
    for (int phi = 0; phi <= 1; phi++) {
        for (int tau = 0; tau <= 1; tau++) {
            for (int l = 0; l < 5; l++) {
                for (int k = 0; k < 60; k++) {
                    /* Section centres: sector centre + 12 deg * (-2..2). */
                    const double lam = ((k / 5) * 60.0 + 12.0 * (k % 5 - 2)) * DEG;
                    const double e = (l + 0.5) * thr1 * (tau ? 1.0 : -1.0);
                    set_next(lam, 0.1);
                    rig.ref.torque = ctrl_q24_from_double(0.1 + e);
                    rig.ref.psi = ctrl_q24_from_double(phi ? 1.2 : 0.8); /* beyond the band */
                    rig.d->reset(rig.state);
                    ctrl_out_t o;
                    chapter_rig_step(&rig, &o);
                    const ctrl_plan_t out = o.plan;
                    TEST_ASSERT_EQUAL_UINT8(l, s->last_level);
                    TEST_ASSERT_EQUAL_UINT8(4, out.n_seg);
                    int64_t sum = 0;
                    for (int i = 0; i < 4; i++) {
                        sum += out.dur[i];
                    }
                    TEST_ASSERT_EQUAL_INT64(FX_ONE, sum);
                    TEST_ASSERT_EQUAL_UINT8(0, out.vec[2]);
                    TEST_ASSERT_EQUAL_UINT8(7, out.vec[3]);
                    TEST_ASSERT_TRUE(out.dur[3] - out.dur[2] >= 0 && out.dur[3] - out.dur[2] <= 1);
                    q24_t va;
                    q24_t vb;
                    ctrl_legs_voltage(&o.legs, rig.est.vdc, &va, &vb);
                    const double m = (l + 1) / 5.0;
                    const double vmag = hypot(q(va), q(vb));
                    /* Amplitude m Vdc/sqrt(3) within one point of |V_k| (2/3 Vdc / 20). */
                    const double vdc = q(rig.est.vdc);
                    TEST_ASSERT_DOUBLE_WITHIN(2.0 / 3.0 * vdc / 20.0 + 1e-6, m * vdc / sqrt(3.0),
                                              vmag);
                    /* Direction: along the flux tangent (forward if tau), tilted
                     * towards the flux-increasing side if phi: radial and
                     * tangential components by sign, the angle from the tangent
                     * at most tilt (6 deg) + rounding (asin(1/40 / (m/sqrt 3))). */
                    const double ur = (q(va) * cos(lam) + q(vb) * sin(lam)) / vmag;
                    const double ut = (-q(va) * sin(lam) + q(vb) * cos(lam)) / vmag;
                    const double tsgn = tau ? 1.0 : -1.0;
                    const double tol = 6.0 * DEG + asin(fmin(1.0, (1.0 / 30.0) / (m / sqrt(3.0))));
                    TEST_ASSERT_TRUE(tsgn * ut >= cos(tol) - 1e-9);
                    if (l >= 1) { /* rounding below the tilt: radial sign is phi's */
                        TEST_ASSERT_TRUE((phi ? 1.0 : -1.0) * ur > 0.0);
                    }
                }
            }
        }
    }
}

static void test_defaults_and_bad_config(void)
{
    rig_init();
    double v;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_get(rig.d, rig.cfg, "h_T", &v));
    TEST_ASSERT_EQUAL_DOUBLE(0.01, v); /* S1 §3.3 */
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_get(rig.d, rig.cfg, "h_psi", &v));
    TEST_ASSERT_EQUAL_DOUBLE(0.01, v);
    /* Default e_fs: 5 x the torque step of one level in one period,
     * 5 * 0.2 Vdc/sqrt(3) Ts / psi_pm * 1.5 p psi_pm^2 / Lq. */
    const ctrl_hpdtc_state_t *s = (const ctrl_hpdtc_state_t *)rig.state;
    const double efs_nm = 1.0 * 264.0 / sqrt(3.0) * 1e-4 / 0.533 * 1.5 * 2 * 0.533 * 0.533 / 0.1027;
    TEST_ASSERT_DOUBLE_WITHIN(1e-4, efs_nm / 5.0, q(s->lvl_thr[0]) * rig.bases.torque_nm);
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_tunable_set(rig.d, rig.cfg, "tilt", 1.0));
    TEST_ASSERT_EQUAL_INT(CTRL_ENOENT, ctrl_tunable_set(rig.d, rig.cfg, "nope", 1.0));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_init(rig.d, rig.state, rig.cfg, NULL));
    ctrl_out_t out;
    ctrl_step(rig.d, rig.state, NULL, &out); /* no context: zero vector, no crash */
    TEST_ASSERT_EQUAL_UINT8(0, out.plan.vec[0]);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_table4_all_entries);
    RUN_TEST(test_sections);
    RUN_TEST(test_timing_table_synthesis);
    RUN_TEST(test_step_geometry);
    RUN_TEST(test_defaults_and_bad_config);
    return UNITY_END();
}
