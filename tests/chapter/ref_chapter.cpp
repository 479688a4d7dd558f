/*
 * Double-precision reference (C++/Eigen) of the chapter's equations against
 * the fixed-point code, on randomised inputs:
 *   - SVPWM: sector by atan2, dwell times by solving [V_k V_k+1] t = v with
 *     Eigen, over-modulation by scaling t1 + t2 to 1 (the hexagon edge, same
 *     angle), leg duties t0/2 + sum t_i S_x(V_i); vs ctrl_svpwm + plan->legs;
 *   - svm_dtc: the voltage reference S1(19)-(20) from psi(k+1), i(k+1),
 *     Delta delta = Kp e (+ omega Ts), vs the controller's pre-limit reference;
 *   - foc: one current-loop step (feed-forward + P part, fresh integrators),
 *     rotated by theta(k+1) + omega Ts/2, limited to the hexagon, vs the
 *     controller's v_d, v_q and the plan's period-average voltage.
 * The reference takes the Q24 inputs the controller sees (exact in double),
 * so the differences are the controller's arithmetic only. Bounds from the
 * Q24 formats, L = 2^-24, S = 3.18e-8 (fx_sincos, docs/fixed-point.md):
 *   - duties: inverse Clarke 1 L, Q24 reciprocal of Vdc (relative L/Vdc^-1),
 *     one rounding -> 8 L (16 L when the hexagon limit rescales first);
 *   - svm_dtc: unit vector (fx_div, 0.5 L each, relative to |psi| >= 0.5 ->
 *     2 L), Delta delta (1.5 L rad), sin/cos 2 S, four products 2 L: target
 *     error <= psi_ref (2 S + 6 L); times 1/Ts (Q24, relative L) plus 2 L:
 *     bound = (psi_ref (2 S + 6 L) + 2 L) / Ts + 4 L;
 *   - foc: v_dq 3 L; rotation 2 S |v| + 2 L; then the duties (16 L Vdc) and
 *     the plan voltage (2 L): bound 2 S |v| + 24 L.
 */
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

#include <Eigen/Dense>

extern "C" {
#include "angle_source.h"
#include "controller.h"
#include "ctrl_foc.h"
#include "ctrl_params.h"
#include "ctrl_s1_dtc.h"
#include "plan.h"
#include "svpwm.h"
#include "vectors.h"
}
#include "chapter_machines.h"
#include "unity.h"

void setUp(void)
{
}
void tearDown(void)
{
}

static const double PI = 3.14159265358979323846;
static const double L = 1.0 / 16777216.0;
static const double S = 3.18e-8;

static double q(q24_t x)
{
    return (double)x * L;
}

static Eigen::Vector2d vec_ab(int k, double vdc)
{
    const double a = (k - 1) * PI / 3.0;
    return Eigen::Vector2d(2.0 / 3.0 * vdc * std::cos(a), 2.0 / 3.0 * vdc * std::sin(a));
}

/* Leg states of V_k (Table 4.2). */
static int leg(int k, int x)
{
    static const int m[8] = {0, 1, 3, 2, 6, 4, 5, 7};
    return (m[k] >> x) & 1;
}

/* Reference SVPWM: duties of v (limited to the hexagon); returns the limited v. */
static Eigen::Vector2d svpwm_ref(Eigen::Vector2d v, double vdc, double d[3], bool *limited)
{
    double ang = std::atan2(v.y(), v.x());
    if (ang < 0.0) {
        ang += 2.0 * PI;
    }
    int k = (int)std::floor(ang / (PI / 3.0)) % 6 + 1;
    const int k1 = k % 6 + 1;
    Eigen::Matrix2d m;
    m.col(0) = vec_ab(k, vdc);
    m.col(1) = vec_ab(k1, vdc);
    Eigen::Vector2d t = m.inverse() * v; /* 2x2: closed-form inverse */
    *limited = t.sum() > 1.0;
    if (*limited) {
        t /= t.sum();
        v = m * t;
    }
    const double t0 = 1.0 - t.sum();
    for (int x = 0; x < 3; x++) {
        d[x] = 0.5 * t0 + t(0) * leg(k, x) + t(1) * leg(k1, x);
    }
    return v;
}

static void test_svpwm_reference(void)
{
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    double worst = 0.0;
    for (int n = 0; n < 30000; n++) {
        const double vdc = 0.5 + u(rng);
        const double r = 1.2 * vdc * u(rng); /* about 1/3 of the samples outside */
        const double a = 2.0 * PI * u(rng);
        q24_t va = ctrl_q24_from_double(r * std::cos(a));
        q24_t vb = ctrl_q24_from_double(r * std::sin(a));
        const q24_t vd = ctrl_q24_from_double(vdc);
        double d[3];
        bool lim;
        svpwm_ref(Eigen::Vector2d(q(va), q(vb)), q(vd), d, &lim);
        ctrl_legs_t legs;
        const uint8_t got_lim = ctrl_svpwm(&va, &vb, vd, &legs);
        const double tol = (got_lim ? 16.0 : 8.0) * L;
        for (int x = 0; x < 3; x++) {
            const double e = std::fabs(q(legs.duty[x]) - d[x]);
            worst = std::fmax(worst, e);
            TEST_ASSERT_TRUE(e <= tol);
        }
    }
    std::printf("svpwm duties: max |error| %.3g (%.2f LSB)\n", worst, worst / L);
}

typedef struct {
    ctrl_params_t params;
    ctrl_bases_t bases;
    ctrl_estimate_t est;
    ctrl_refs_t ref;
    ctrl_setup_t su;
    ctrl_ctx_t ctx;
    alignas(8) unsigned char state[CTRL_STATE_MAX];
    alignas(8) unsigned char cfg[CTRL_CFG_MAX];
    const ctrl_desc_t *d;
} rig_t;

static rig_t rig;

static void rig_init(const char *name, const ctrl_machine_t *m)
{
    std::memset(&rig, 0, sizeof rig);
    rig.d = ctrl_find(name);
    TEST_ASSERT_NOT_NULL(rig.d);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&rig.params, &rig.bases, m, 10000u));
    rig.d->cfg_default(rig.cfg, m);
    rig.su = ctrl_setup_t{m, &rig.bases, &rig.params};
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_init(rig.d, rig.state, rig.cfg, &rig.su));
    rig.ctx.params = &rig.params;
    rig.ctx.est = &rig.est;
    rig.ctx.ref = &rig.ref;
    rig.est.vdc = rig.params.vdc_nom;
}

static void test_svm_dtc_reference(void)
{
    for (int mi = 0; mi < 2; mi++) {
        rig_init("svm_dtc", mi == 0 ? &ini_chapter_ipmsm : &ini_thesis_spmsm);
        const ctrl_svm_dtc_state_t *s = (const ctrl_svm_dtc_state_t *)rig.state;
        const double ts = q(rig.params.ts);
        const double rs = q(rig.params.rs);
        std::mt19937_64 rng(11 + mi);
        std::uniform_real_distribution<double> u(-1.0, 1.0);
        double worst = 0.0;
        for (int n = 0; n < 20000; n++) {
            ctrl_mstate_t *nx = &rig.est.next;
            std::memset(nx, 0, sizeof *nx);
            const double amp = 1.0 + 0.5 * u(rng);
            const double lam = PI * u(rng);
            nx->psi_alpha = ctrl_q24_from_double(amp * std::cos(lam));
            nx->psi_beta = ctrl_q24_from_double(amp * std::sin(lam));
            nx->psi_amp = fx_mag(nx->psi_alpha, nx->psi_beta);
            nx->i_alpha = ctrl_q24_from_double(u(rng));
            nx->i_beta = ctrl_q24_from_double(u(rng));
            nx->torque = ctrl_q24_from_double(0.5 * u(rng));
            rig.ref.torque = ctrl_q24_from_double(q(nx->torque) + 0.3 * u(rng));
            rig.ref.psi = ctrl_q24_from_double(1.0 + 0.2 * u(rng));
            rig.est.omega_e = ctrl_q24_from_double(u(rng));
            rig.d->reset(rig.state);
            ctrl_out_t out;
            rig.d->step(rig.state, &rig.ctx, &out);
            /* Reference S1(19)-(20). */
            const double e = q(rig.ref.torque) - q(nx->torque);
            double dd = std::fmin(std::fmax(1.0 * e, -PI / 3.0), PI / 3.0);
            dd += q(rig.est.omega_e) * ts;
            const double pa = q(nx->psi_alpha);
            const double pb = q(nx->psi_beta);
            const double l = std::atan2(pb, pa);
            const double pr = q(rig.ref.psi);
            const double va = (pr * std::cos(l + dd) - pa) / ts + rs * q(nx->i_alpha);
            const double vb = (pr * std::sin(l + dd) - pb) / ts + rs * q(nx->i_beta);
            const double tol = (pr * (2.0 * S + 6.0 * L) + 2.0 * L) / ts + 4.0 * L;
            const double err =
                std::fmax(std::fabs(q(s->v_alpha) - va), std::fabs(q(s->v_beta) - vb));
            worst = std::fmax(worst, err / tol);
            TEST_ASSERT_TRUE(err <= tol);
        }
        std::printf("svm_dtc %s: max error / bound %.3f\n", mi == 0 ? "IPMSM" : "SPMSM", worst);
    }
}

static void test_foc_reference(void)
{
    rig_init("foc", &ini_thesis_spmsm);
    const ctrl_foc_state_t *s = (const ctrl_foc_state_t *)rig.state;
    const double ts = q(rig.params.ts);
    const double kp_d = s->pi_d.kp / 1048576.0; /* Q20 */
    const double kp_q = s->pi_q.kp / 1048576.0;
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    double worst = 0.0;
    for (int n = 0; n < 20000; n++) {
        ctrl_mstate_t *nx = &rig.est.next;
        std::memset(nx, 0, sizeof *nx);
        nx->i_d = ctrl_q24_from_double(0.2 * u(rng));
        nx->i_q = ctrl_q24_from_double(0.5 * u(rng));
        nx->psi_d = ctrl_q24_from_double(1.0 + q(nx->i_d));
        nx->psi_q = ctrl_q24_from_double(q(nx->i_q));
        nx->theta_e = (fx_angle_t)(rng() & 0xffffffffu);
        rig.est.omega_e = ctrl_q24_from_double(0.8 * u(rng));
        /* the estimator's angle at k and its rotation over the period (FOC
         * turns the sine and cosine at k by 3/2 of it) */
        rig.est.dtheta = fx_u2i(ctrl_angle_step(&rig.params, rig.est.omega_e));
        fx_rot_q30(rig.est.dtheta, &rig.est.rot_c, &rig.est.rot_s);
        rig.est.now.theta_e = nx->theta_e - (fx_angle_t)rig.est.dtheta;
        fx_sincos(rig.est.now.theta_e, &rig.est.now.sin_theta, &rig.est.now.cos_theta);
        rig.ref.torque = ctrl_q24_from_double(0.5 * u(rng));
        q24_t idr;
        q24_t iqr;
        ctrl_foc_iref(&rig.params, &s->iref, rig.ref.torque, &idr, &iqr);
        rig.d->reset(rig.state);
        ctrl_out_t out;
        rig.d->step(rig.state, &rig.ctx, &out);
        const double w = q(rig.est.omega_e);
        const double vd = -w * q(nx->psi_q) + kp_d * (q(idr) - q(nx->i_d));
        const double vq = w * q(nx->psi_d) + kp_q * (q(iqr) - q(nx->i_q));
        TEST_ASSERT_DOUBLE_WITHIN(3.0 * L, vd, q(s->v_d));
        TEST_ASSERT_DOUBLE_WITHIN(3.0 * L, vq, q(s->v_q));
        const double th = (double)nx->theta_e * (2.0 * PI / 4294967296.0) + 0.5 * w * ts;
        Eigen::Vector2d v(vd * std::cos(th) - vq * std::sin(th),
                          vd * std::sin(th) + vq * std::cos(th));
        double d[3];
        bool lim;
        v = svpwm_ref(v, q(rig.est.vdc), d, &lim);
        TEST_ASSERT_EQUAL_INT(lim ? 1 : 0, s->limited);
        q24_t pa;
        q24_t pb;
        ctrl_legs_voltage(&out.legs, rig.est.vdc, &pa, &pb);
        const double tol = 2.0 * S * std::hypot(vd, vq) + 24.0 * L;
        const double err = std::fmax(std::fabs(q(pa) - v.x()), std::fabs(q(pb) - v.y()));
        worst = std::fmax(worst, err / tol);
        TEST_ASSERT_TRUE(err <= tol);
    }
    std::printf("foc step: max error / bound %.3f\n", worst);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_svpwm_reference);
    RUN_TEST(test_svm_dtc_reference);
    RUN_TEST(test_foc_reference);
    return UNITY_END();
}
