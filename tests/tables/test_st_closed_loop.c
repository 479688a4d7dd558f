/*
 * Closed loop on the model of the control core: the plant is the core's
 * discrete machine model (fixture_predict: psi += Ts (v - Rs i), theta += omega Ts,
 * (5.15)/(6.10)-(6.12)) at constant speed, the estimate is exact and the
 * prediction to k+1 uses the vector applied during [k, k+1) (one-step delay,
 * docs/conventions.md). Each table must hold torque and flux in steady state in the
 * four quadrants of Fig. 3.9 (forward/backward motoring and braking), within
 * bounds from the physics, not from a run:
 *   |T - Tref| <= h_T + dT_max,  |psi - psi_ref| <= h_psi + dpsi_max,
 * where dT_max, dpsi_max bound the change one vector makes in one period,
 * from (4.10)/(4.13) in pu (L = psi_pm = 1):
 *   dpsi_max = Ts (|V| + Rs |i|),
 *   dT_max   = Ts (|V| + |omega| psi_s + Rs psi_s) * psi_pm ... taken with
 *              |V| = 2/3 Vdc, psi_s <= 1.3, plus 20 % for the rotor motion.
 * A table with a torque-sign or sector error runs away at once.
 * MBST only at low speed and ZST only forward (thesis §4.6: MBST unstable at
 * high speed, ZST at reverse rotation).
 */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "../core/est_fixture.h"
#include "controller.h"
#include "ctrl_params.h"
#include "mtpa.h"
#include "plan.h"
#include "unity.h"

void setUp(void)
{
}
void tearDown(void)
{
}

static const ctrl_machine_t SPMSM = {
    "thesis SPMSM", 4,   0.901,  6.552e-3, 6.552e-3, 0.09427, 220.0,
    1.2e-4,         2.4, 3000.0, 4.2,      8.4,      0.0,
};

static double pu(q24_t x)
{
    return (double)x / 16777216.0;
}

static q24_t q24(double v)
{
    return (q24_t)lround(v * 16777216.0);
}

typedef struct {
    double t_err_max, psi_err_max, t_err_mean;
    int n_zero, n_active;
} loop_result_t;

/* check = 0: only measure (a case the table is known not to hold). */
static loop_result_t run_loop_ex(const char *name, double tref, double omega, int check)
{
    static ctrl_params_t p;
    ctrl_bases_t b;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&p, &b, &SPMSM, 20000u));
    const ctrl_desc_t *d = ctrl_find(name);
    TEST_ASSERT_NOT_NULL(d);
    static _Alignas(8) unsigned char cfg[CTRL_CFG_MAX];
    static _Alignas(8) unsigned char st[CTRL_STATE_MAX];
    d->cfg_default(cfg, &SPMSM);
    const ctrl_setup_t su = {&SPMSM, &b, &p};
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_init(d, st, cfg, &su));
    d->reset(st);

    ctrl_mstate_t x;
    fixture_state_from_flux(&p, FX_ONE, 0, 0u, &x); /* rotor flux only, i = 0 */
    ctrl_legs_t applied = {{0, 0, 0}};
    ctrl_estimate_t est;
    memset(&est, 0, sizeof est);
    ctrl_refs_t ref = {q24(tref), 0}; /* flux reference: MTPA (4.15) */
    ctrl_ctx_t ctx = {&p, &est, &ref};
    const q24_t w = q24(omega);
    const q24_t psi_ref = ctrl_mtpa_psi(&p, ref.torque);

    loop_result_t r = {0.0, 0.0, 0.0, 0, 0};
    const int n_settle = 400, n_run = 3000;
    double sum = 0.0;
    for (int k = 0; k < n_settle + n_run; k++) {
        q24_t va;
        q24_t vb;
        /* estimator: state at k (exact) and prediction to k+1 with the applied plan */
        est.now = x;
        est.omega_e = w;
        est.vdc = p.vdc_nom;
        ctrl_legs_voltage(&applied, p.vdc_nom, &va, &vb);
        fixture_predict(&p, &x, va, vb, w, &est.next);
        ctrl_out_t o;
        fixture_rotation(&p, &est);
        d->step(st, &ctx, &o);
        const ctrl_plan_t out = o.plan;
        /* plant: [k, k+1) with the applied plan; then the new plan takes over */
        x = est.next;
        applied = o.legs;
        if (k >= n_settle) {
            const double te = pu(x.torque) - tref;
            const double pe = pu(x.psi_amp) - pu(psi_ref);
            r.t_err_max = fmax(r.t_err_max, fabs(te));
            r.psi_err_max = fmax(r.psi_err_max, fabs(pe));
            sum += te;
            if (out.vec[0] == 0u || out.vec[0] == 7u) {
                r.n_zero++;
            } else {
                r.n_active++;
            }
        }
    }
    r.t_err_mean = sum / n_run;
    /* bounds (pu) */
    const double ts = pu(p.ts);
    const double v = 2.0 / 3.0 * pu(p.vdc_nom);
    const double i_max = 1.5; /* |i| in pu at these operating points (|T| <= 0.25, i_base) */
    const double dpsi = ts * (v + pu(p.rs) * i_max);
    const double dt = 1.2 * ts * (v + fabs(omega) * 1.3 + pu(p.rs) * 1.3);
    const double h_t = name[0] == 'f' ? 0.0 : 0.02 * pu(p.torque_rated);
    const double h_psi = name[0] == 'f' ? 0.0 : 0.02;
    if (!check) {
        return r;
    }
    TEST_ASSERT_TRUE_MESSAGE(r.t_err_max <= h_t + dt, "torque outside h_T + dT_max");
    TEST_ASSERT_TRUE_MESSAGE(r.psi_err_max <= h_psi + dpsi, "flux outside h_psi + dpsi_max");
    TEST_ASSERT_TRUE_MESSAGE(fabs(r.t_err_mean) <= h_t + dt / 2.0, "mean torque error");
    return r;
}

static loop_result_t run_loop(const char *name, double tref, double omega)
{
    return run_loop_ex(name, tref, omega, 1);
}

static const double TQ = 0.2; /* pu, about 0.68 T_rated */
static const double W = 0.3;  /* pu electrical, about 1670 r/min */

static void four_quadrants(const char *name, int backward, double w)
{
    (void)run_loop(name, TQ, w);  /* forward motoring */
    (void)run_loop(name, -TQ, w); /* forward regenerative braking */
    if (backward) {
        (void)run_loop(name, -TQ, -w); /* backward motoring */
        (void)run_loop(name, TQ, -w);  /* backward braking */
    }
}

static void test_bst_loop(void)
{
    four_quadrants("bst", 1, W);
}

static void test_mbst_loop_low_speed(void)
{
    four_quadrants("mbst", 1, 0.05);
}

/*
 * MBST's voltage limit (explanation at ST_KIND_MBST in control/st_dtc.c). To
 * raise the torque MBST has only V_{x+1} and V_{x+3}, 120 deg apart (Table
 * 4.3, sectors (4.18)); holding |psi_s| within its band they average to a
 * point on the chord V_{x+1} V_{x+3}, whose tangential part at flux angle u
 * into the sector is |V| / (2 cos(30 deg - u)), |V| = 2/3 Vdc: between Vdc/3
 * (mid-sector) and |V|/sqrt(3) (edges), time average pi Vdc / 9 (BST: sqrt(3)
 * times more). The flux can then rotate at most at omega psi_ref = pi Vdc / 9
 * (less the R_s drop):
 *  - at 0.7 of that speed MBST must hold torque and flux like at low speed
 *    (a sector or table error would break it);
 *  - above |V| / (sqrt(3) psi_ref) no sector position can keep pace with the
 *    rotor (thesis SPMSM, 220 V: about 2100 r/min), so at 2250 r/min the
 *    mean torque must fall far below the reference (pole slipping):
 *    the over-current trip of the simulator.
 */
static void test_mbst_voltage_limit(void)
{
    static ctrl_params_t p;
    ctrl_bases_t b;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&p, &b, &SPMSM, 20000u));
    const double psi_ref = pu(ctrl_mtpa_psi(&p, q24(TQ)));
    const double vdc = pu(p.vdc_nom);
    const double w_avg = 3.14159265358979 * vdc / 9.0 / psi_ref;
    const double w_edge = 2.0 / 3.0 * vdc / sqrt(3.0) / psi_ref;
    (void)run_loop("mbst", TQ, 0.7 * w_avg);
    (void)run_loop("mbst", -TQ, -0.7 * w_avg); /* backward motoring */
    const double w_2250 = 2250.0 / 60.0 * 2.0 * 3.14159265358979 * SPMSM.pole_pairs / b.w_rad_s;
    TEST_ASSERT_TRUE(w_2250 > w_edge);
    const loop_result_t r = run_loop_ex("mbst", TQ, w_2250, 0);
    const double h_t = 0.02 * pu(p.torque_rated);
    TEST_ASSERT_TRUE_MESSAGE(r.t_err_mean < -(TQ / 2.0 + h_t), "MBST held torque beyond its limit");
}

static void test_ast_loop(void)
{
    four_quadrants("ast", 1, W);
}

static void test_zst_loop_forward(void)
{
    (void)run_loop("zst", TQ, W);
}

/* FST: steady state uses zero vectors in motoring (forward and backward);
 * braking keeps the dynamic state (T_ref * omega < 0, §4.5.3): active only. */
static void test_fst_loop(void)
{
    loop_result_t r = run_loop("fst", TQ, W);
    TEST_ASSERT_TRUE(r.n_zero > 0 && r.n_active > 0);
    r = run_loop("fst", -TQ, -W);
    TEST_ASSERT_TRUE(r.n_zero > 0 && r.n_active > 0);
    r = run_loop("fst", -TQ, W);
    TEST_ASSERT_EQUAL_INT(0, r.n_zero);
    r = run_loop("fst", TQ, -W);
    TEST_ASSERT_EQUAL_INT(0, r.n_zero);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_bst_loop);
    RUN_TEST(test_mbst_loop_low_speed);
    RUN_TEST(test_mbst_voltage_limit);
    RUN_TEST(test_ast_loop);
    RUN_TEST(test_zst_loop_forward);
    RUN_TEST(test_fst_loop);
    return UNITY_END();
}
