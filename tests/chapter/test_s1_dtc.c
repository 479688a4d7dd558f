/*
 * hdtc, hdtc_pred and svm_dtc (control/ctrl_s1_dtc.h): registry entries and
 * defaults (S1 §3.3 bands +-0.01, S1 §4.1 Kp = 1, Ki = 0.03), the HDTC decisions
 * against S1 Table 3 as printed, on the sampled state (hdtc) or the k+1
 * prediction (hdtc_pred), the other instant holding opposite errors (every sector, phi, tau,
 * including its fixed V0/V7 entries reached after the preceding active vector), and the SVM-DTC
 * predictive controller's basic behaviour (hold, advance, PI integration).
 */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "chapter_machines.h"
#include "chapter_rig.h"
#include "controller.h"
#include "ctrl_params.h"
#include "ctrl_s1_dtc.h"
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

static double q(q24_t x)
{
    return (double)x / 16777216.0;
}

static chapter_rig_t rig;

static void rig_init(const char *name)
{
    chapter_rig_init(&rig, name, &ini_chapter_ipmsm);
    TEST_ASSERT_EQUAL_UINT32(10000u, rig.d->fs_default_hz);
}

/* The machine state m (rig.est.now or rig.est.next) with the flux at angle
 * lam, amplitude amp (pu) and torque t (pu); rotor at theta 0, so the rotor
 * and stator frames coincide. */
static void set_state(ctrl_mstate_t *m, double lam, double amp, double t)
{
    memset(m, 0, sizeof *m);
    m->psi_alpha = ctrl_q24_from_double(amp * cos(lam));
    m->psi_beta = ctrl_q24_from_double(amp * sin(lam));
    m->psi_d = m->psi_alpha;
    m->psi_q = m->psi_beta;
    m->psi_amp = ctrl_q24_from_double(amp);
    m->psi_amp_sq = (uint64_t)((int64_t)m->psi_amp * m->psi_amp); /* its root: psi_amp */
    m->torque = ctrl_q24_from_double(t);
    m->cos_theta = FX_ONE;
    m->sector = ctrl_sector(m->psi_alpha, m->psi_beta); /* (4.5), as the estimator */
}

static void set_next(double lam, double amp, double t)
{
    set_state(&rig.est.next, lam, amp, t);
}

/* S1 Table 3 as printed: [phi 1/0][tau 1/0/-1][sector 1..6]. */
static const uint8_t s1_table3[2][3][6] = {
    {{2, 3, 4, 5, 6, 1}, {7, 0, 7, 0, 7, 0}, {6, 1, 2, 3, 4, 5}},
    {{3, 4, 5, 6, 1, 2}, {0, 7, 0, 7, 0, 7}, {5, 6, 1, 2, 3, 4}},
};

/* hdtc decides on the sampled state (k), hdtc_pred on the prediction (k+1):
 * the other instant holds the opposite errors, so reading it would give
 * another vector of Table 3. */
static void hdtc_table3(const char *name, int sampled)
{
    rig_init(name);
    double v;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_get(rig.d, rig.cfg, "h_T", &v));
    TEST_ASSERT_EQUAL_DOUBLE(0.01, v);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_get(rig.d, rig.cfg, "h_psi", &v));
    TEST_ASSERT_EQUAL_DOUBLE(0.01, v);
    const double big = 0.05; /* pu, beyond both bands (0.01 Wb = 0.019 pu, 0.01 N*m) */
    for (int ph = 0; ph < 2; ph++) {
        for (int sec = 1; sec <= 6; sec++) {
            const double lam = (sec - 1) * CTRL_PI / 3.0 + 0.1; /* inside sector sec (4.5) */
            const double amp = ph == 0 ? 1.0 - big : 1.0 + big; /* psi_ref = psi_pm = 1 pu */
            /* tau = +1 */
            rig.d->reset(rig.state);
            const double amp_other = ph == 0 ? 1.0 + big : 1.0 - big;
            const double lam_other = lam + CTRL_PI; /* three sectors away */
            set_state(sampled ? &rig.est.now : &rig.est.next, lam, amp, 0.1);
            set_state(sampled ? &rig.est.next : &rig.est.now, lam_other, amp_other, 0.5);
            rig.ref.torque = ctrl_q24_from_double(0.1 + big);
            ctrl_out_t out;
            chapter_rig_step(&rig, &out);
            TEST_ASSERT_EQUAL_UINT8(1, out.plan.n_seg);
            TEST_ASSERT_EQUAL_UINT8(s1_table3[ph][0][sec - 1], out.plan.vec[0]);
            /* tau = 0: torque reached the reference after an increase; Table 3's
             * zero vector is the one after the active vector just applied. */
            rig.ref.torque = ctrl_q24_from_double(0.1);
            chapter_rig_step(&rig, &out);
            TEST_ASSERT_EQUAL_UINT8(s1_table3[ph][1][sec - 1], out.plan.vec[0]);
            /* tau = -1 */
            rig.ref.torque = ctrl_q24_from_double(0.1 - big);
            chapter_rig_step(&rig, &out);
            TEST_ASSERT_EQUAL_UINT8(s1_table3[ph][2][sec - 1], out.plan.vec[0]);
        }
    }
    ctrl_out_t out;
    ctrl_step(rig.d, rig.state, NULL, &out); /* no context: a zero vector, no crash */
    TEST_ASSERT_TRUE(out.plan.vec[0] == 0u || out.plan.vec[0] == 7u);
}

static void test_hdtc_table3(void)
{
    hdtc_table3("hdtc", 1);
}

static void test_hdtc_pred_table3(void)
{
    hdtc_table3("hdtc_pred", 0);
}

static void test_svm_dtc_basics(void)
{
    rig_init("svm_dtc");
    double v;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_get(rig.d, rig.cfg, "Kp", &v));
    TEST_ASSERT_EQUAL_DOUBLE(1.0, v);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_get(rig.d, rig.cfg, "Ki", &v));
    TEST_ASSERT_EQUAL_DOUBLE(0.03, v);
    const ctrl_svm_dtc_state_t *s = (const ctrl_svm_dtc_state_t *)rig.state;
    /* No error, no speed, flux at its reference, no current: no voltage. */
    set_next(0.3, 1.0, 0.2);
    rig.ref.torque = ctrl_q24_from_double(0.2);
    ctrl_out_t out;
    chapter_rig_step(&rig, &out);
    TEST_ASSERT_INT32_WITHIN(64, 0, s->v_alpha);
    TEST_ASSERT_INT32_WITHIN(64, 0, s->v_beta);
    /* Positive torque error: Delta delta = Kp e (first sample, empty
     * integrator) and the voltage advances the flux (positive tangential). */
    rig.d->reset(rig.state);
    rig.ref.torque = ctrl_q24_from_double(0.21);
    chapter_rig_step(&rig, &out);
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 0.01, q(s->dd));
    const double vt = -q(s->v_alpha) * sin(0.3) + q(s->v_beta) * cos(0.3);
    const double ts = q(rig.params.ts);
    TEST_ASSERT_DOUBLE_WITHIN(1e-4, sin(0.01) / ts, vt);
    /* Second sample: the integrator added Ki e = 0.0003 rad. */
    chapter_rig_step(&rig, &out);
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 0.01 + 0.03 * 0.01, q(s->dd));
    /* Speed feed-forward: omega Ts added. */
    rig.d->reset(rig.state);
    rig.ref.torque = ctrl_q24_from_double(0.2);
    rig.est.omega_e = ctrl_q24_from_double(0.3);
    chapter_rig_step(&rig, &out);
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 0.3 * ts, q(s->dd));
    /* A large error saturates: the voltage is limited, the plan still sums to 1. */
    rig.ref.torque = ctrl_q24_from_double(5.0);
    chapter_rig_step(&rig, &out);
    TEST_ASSERT_EQUAL_UINT8(1, s->limited);
    /* ... as leg duties inside [0, 1] of which one is 1 and one is 0 (on the hexagon). */
    TEST_ASSERT_EQUAL_UINT8(0, out.plan.n_seg);
    const q24_t dmax = fx_max(out.legs.duty[0], fx_max(out.legs.duty[1], out.legs.duty[2]));
    const q24_t dmin = fx_min(out.legs.duty[0], fx_min(out.legs.duty[1], out.legs.duty[2]));
    TEST_ASSERT_INT32_WITHIN(4, FX_ONE, dmax);
    TEST_ASSERT_INT32_WITHIN(4, 0, dmin);
    /* Integrator bounded (pi/6) whatever the error. */
    for (int k = 0; k < 1000; k++) {
        chapter_rig_step(&rig, &out);
    }
    TEST_ASSERT_TRUE(fabs(q(s->dd) - 0.3 * ts) <= CTRL_PI / 3.0 + 1e-6);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_hdtc_table3);
    RUN_TEST(test_hdtc_pred_table3);
    RUN_TEST(test_svm_dtc_basics);
    return UNITY_END();
}
