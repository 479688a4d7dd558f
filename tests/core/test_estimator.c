/*
 * Estimator (current model (3.9), speed from encoder differences, k+1
 * prediction (5.15)/(6.10)-(6.12)), predict.h consistency and the voltage-model
 * flux with its drift handling. Bounds from the roundings (README).
 */
#include <math.h>
#include <stddef.h>

#include "estimator.h"
#include "flux_vm.h"
#include "flux_vm_config.h"
#include "machines.h"
#include "plan.h"
#include "predict.h"
#include "transforms.h"
#include "unity.h"
#include "vectors.h"

void setUp(void)
{
}
void tearDown(void)
{
}

#define PI 3.14159265358979323846
#define LSB (1.0 / 16777216.0)
#define SC 1.24e-6 /* fx_sincos error bound */

static double d(q24_t x)
{
    return (double)x * LSB;
}

static q24_t q(double x)
{
    return ctrl_q24_from_double(x);
}

static ctrl_params_t P;
static ctrl_bases_t B;

/* Phase currents a, b of a dq current at electrical angle th. */
static void meas_from_dq(double id, double iq, fx_angle_t th, ctrl_meas_t *m)
{
    const double t = (double)th * 2.0 * PI / 4294967296.0;
    const double al = id * cos(t) - iq * sin(t);
    const double be = id * sin(t) + iq * cos(t);
    m->i_a = q(al);
    m->i_b = q(-0.5 * al + sqrt(3.0) / 2.0 * be);
    m->vdc = FX_ONE;
    m->theta_e = th;
}

static void run_speed(double omega)
{
    ctrl_estimator_t e;
    ctrl_estimate_t est;
    ctrl_meas_t m;
    ctrl_estimator_init(&e, &P);
    const q24_t w = q(omega);
    const fx_angle_t step = ctrl_angle_step(&P, w);
    fx_angle_t th = 0x12345678u;
    for (int k = 0; k < 300; k++) { /* > 2 turns: crosses the 2^32 wrap */
        meas_from_dq(-0.1, 0.5, th, &m);
        ctrl_estimator_update(&e, &P, &m, NULL, &est);
        th += step;
    }
    /* The increment is round(w K / 2^24): w recovered within 0.5 * 2^24 / K
     * LSB (< 0.1 LSB here), the Q28 coefficient m relative 0.5 / m, 0.5 LSB
     * rounding, the EMA settled ((1-k)^300 ~ 0): within 1 LSB + |w| 0.5 / m. */
    const double tol = 1.0 + fabs(omega) * 16777216.0 * 0.5 / (double)P.dangle_to_omega;
    TEST_ASSERT_INT32_WITHIN((int32_t)tol, w, est.omega_e);
    TEST_ASSERT_EQUAL_UINT32(est.now.theta_e + ctrl_angle_step(&P, est.omega_e), est.next.theta_e);
}

static void test_speed_both_directions(void)
{
    run_speed(0.3);
    run_speed(-0.3);
    run_speed(0.538); /* rated speed, about 0.2 rad per period at 10 kHz */
    run_speed(0.0);
}

static void test_speed_first_sample_and_reset(void)
{
    ctrl_estimator_t e;
    ctrl_estimate_t est;
    ctrl_meas_t m;
    ctrl_estimator_init(&e, &P);
    meas_from_dq(0.0, 0.2, 0x40000000u, &m);
    ctrl_estimator_update(&e, &P, &m, NULL, &est);
    TEST_ASSERT_EQUAL_INT32(0, est.omega_e); /* no difference yet */
    m.theta_e += 1000000u;
    ctrl_estimator_update(&e, &P, &m, NULL, &est);
    TEST_ASSERT_TRUE(est.omega_e > 0);
    ctrl_estimator_reset(&e);
    ctrl_estimator_update(&e, &P, &m, NULL, &est);
    TEST_ASSERT_EQUAL_INT32(0, est.omega_e);
    /* the EMA step after one sample is k * raw (first-order filter) */
    const fx_angle_t d_ang = 2000000u;
    m.theta_e += d_ang;
    ctrl_estimator_update(&e, &P, &m, NULL, &est);
    const double raw = (double)d_ang * 16777216.0 / (double)P.omega_to_dangle * LSB;
    TEST_ASSERT_TRUE(fabs(d(est.omega_e) - d(P.speed_lpf_k) * raw) <= 2.0 * LSB);
}

static void test_current_model_spmsm(void)
{
    ctrl_estimator_t e;
    ctrl_estimate_t est;
    ctrl_meas_t m;
    ctrl_estimator_init(&e, &P);
    for (int k = 0; k < 64; k++) {
        const fx_angle_t th = (fx_angle_t)k * 67108864u + 12345u;
        const double id = -0.2 + 0.01 * k;
        const double iq = (k % 2) ? 0.45 : -0.45; /* motoring and braking */
        meas_from_dq(id, iq, th, &m);
        ctrl_estimator_update(&e, &P, &m, NULL, &est);
        /* inputs rounded (<= 1.4 LSB after Clarke), Park 0.5 LSB + SC(|a|+|b|) */
        const double ei = 2.0 * LSB + SC * 2.0;
        TEST_ASSERT_TRUE(fabs(d(est.now.i_d) - id) <= ei);
        TEST_ASSERT_TRUE(fabs(d(est.now.i_q) - iq) <= ei);
        TEST_ASSERT_TRUE(fabs(d(est.now.psi_d) - (1.0 + id)) <= ei);
        TEST_ASSERT_TRUE(fabs(d(est.now.psi_q) - iq) <= ei + 0.5 * LSB);
        /* (3.10) with Ld = Lq: Te = psi_pm i_q */
        TEST_ASSERT_TRUE(fabs(d(est.now.torque) - iq) <= 0.5 * LSB + 3.0 * ei);
        const double amp = hypot(1.0 + id, iq);
        TEST_ASSERT_TRUE(fabs(d(est.now.psi_amp) - amp) <= 0.5 * LSB + 2.0 * ei);
        const double ths = atan2(d(est.now.psi_beta), d(est.now.psi_alpha));
        TEST_ASSERT_EQUAL_UINT8(ctrl_sector(q(cos(ths)), q(sin(ths))), est.now.sector);
    }
}

static void test_prediction_with_plan(void)
{
    ctrl_estimator_t e;
    ctrl_estimate_t est;
    ctrl_meas_t m;
    ctrl_plan_t plan;
    ctrl_legs_t legs;
    ctrl_estimator_init(&e, &P);
    meas_from_dq(-0.05, 0.3, 0x10000000u, &m);
    ctrl_plan_active_zero(&plan, 2u, FX_ONE / 2); /* V2 half the period, then V7 */
    ctrl_plan_legs(&plan, &legs);
    ctrl_estimator_update(&e, &P, &m, &legs, &est);
    q24_t va;
    q24_t vb;
    ctrl_legs_voltage(&legs, m.vdc, &va, &vb);
    /* (5.15) exactly as specified: one rounding of Ts v - Ts Rs i */
    const int64_t da = (int64_t)P.ts * va - (int64_t)P.ts_rs * est.now.i_alpha;
    const int64_t db = (int64_t)P.ts * vb - (int64_t)P.ts_rs * est.now.i_beta;
    TEST_ASSERT_EQUAL_INT32(est.now.psi_alpha + (q24_t)fx_rshift64_round(da, 24u),
                            est.next.psi_alpha);
    TEST_ASSERT_EQUAL_INT32(est.now.psi_beta + (q24_t)fx_rshift64_round(db, 24u),
                            est.next.psi_beta);
    /* V2 at half duty: v = 0.5 * (1/3, 1/sqrt(3)) Vdc */
    TEST_ASSERT_TRUE(fabs(d(va) - 0.5 / 3.0) <= 2.0 * LSB);
    TEST_ASSERT_TRUE(fabs(d(vb) - 0.5 / sqrt(3.0)) <= 2.0 * LSB);
    TEST_ASSERT_EQUAL_INT32(m.vdc, est.vdc);
    /* the predicted current obeys the current model at the predicted angle */
    const double t1 = (double)est.next.theta_e * 2.0 * PI / 4294967296.0;
    const double pd = d(est.next.psi_alpha) * cos(t1) + d(est.next.psi_beta) * sin(t1);
    const double pq = -d(est.next.psi_alpha) * sin(t1) + d(est.next.psi_beta) * cos(t1);
    const double eb = 1.0 * LSB + SC * 2.0 * 1.1;
    TEST_ASSERT_TRUE(fabs(d(est.next.i_d) - (pd - 1.0)) <= eb);
    TEST_ASSERT_TRUE(fabs(d(est.next.i_q) - pq) <= eb + 0.5 * LSB);
}

/* from_current -> psi -> from_flux returns the current: cascade of three
 * rotations, each 0.5 LSB + SC * sqrt(2) |x|, errors doubled by each rotation. */
static void test_flux_current_roundtrip(void)
{
    for (int k = 0; k < 200; k++) {
        const fx_angle_t th = (fx_angle_t)k * 21474836u * 7u;
        const double ia = 0.9 * cos(0.31 * k);
        const double ib = 0.9 * sin(0.47 * k);
        q24_t s;
        q24_t c;
        fx_sincos(th, &s, &c);
        ctrl_mstate_t a;
        ctrl_mstate_t b;
        ctrl_mstate_from_current(&P, q(ia), q(ib), th, s, c, &a);
        ctrl_mstate_from_flux(&P, a.psi_alpha, a.psi_beta, th, &b);
        const double psi = 2.0;
        const double e1 = 0.5 * LSB + SC * sqrt(2.0) * psi;
        const double e2 = 0.5 * LSB + SC * sqrt(2.0) * psi + 2.0 * e1;
        const double e3 = 0.5 * LSB + SC * sqrt(2.0) * 0.9 + 2.0 * e2;
        TEST_ASSERT_TRUE(fabs(d(b.i_alpha) - d(a.i_alpha)) <= e3);
        TEST_ASSERT_TRUE(fabs(d(b.i_beta) - d(a.i_beta)) <= e3);
        TEST_ASSERT_EQUAL_UINT32(th, b.theta_e);
    }
}

/* Optional outputs (CTRL_EST_*): a cleared bit leaves exactly that field at 0
 * and changes nothing else; every bit set gives the full state, whose |psi|
 * and sectors equal fx_mag / ctrl_sector of the returned fluxes (k: rotor
 * frame, k+1: alpha/beta), and ctrl_mstate_from_flux_noamp equals
 * ctrl_mstate_from_flux_sc but for psi_amp. */
static void test_optional_outputs(void)
{
    ctrl_estimator_t full;
    ctrl_estimator_t lean;
    ctrl_estimator_init(&full, &P);
    ctrl_estimator_init(&lean, &P);
    TEST_ASSERT_EQUAL_UINT8(CTRL_EST_ALL, full.outputs);
    lean.outputs = 0u;
    ctrl_plan_t plan;
    ctrl_legs_t legs;
    ctrl_plan_active_zero(&plan, 2u, FX_ONE / 3);
    ctrl_plan_legs(&plan, &legs);
    for (int k = 0; k < 200; k++) {
        ctrl_meas_t m;
        const fx_angle_t th = (fx_angle_t)(uint32_t)k * 0x01234567u;
        meas_from_dq(0.1 * sin(0.3 * k), 0.25 * cos(0.17 * k), th, &m);
        ctrl_estimate_t ef;
        ctrl_estimate_t el;
        ctrl_estimator_update(&full, &P, &m, &legs, &ef);
        ctrl_estimator_update(&lean, &P, &m, &legs, &el);
        TEST_ASSERT_EQUAL_INT32(fx_mag(ef.now.psi_d, ef.now.psi_q), ef.now.psi_amp);
        TEST_ASSERT_EQUAL_INT32(fx_mag(ef.next.psi_alpha, ef.next.psi_beta), ef.next.psi_amp);
        TEST_ASSERT_EQUAL_UINT8(ctrl_sector(ef.now.psi_alpha, ef.now.psi_beta), ef.now.sector);
        TEST_ASSERT_EQUAL_UINT8(ctrl_sector(ef.next.psi_alpha, ef.next.psi_beta), ef.next.sector);
        TEST_ASSERT_EQUAL_INT32(0, el.now.psi_amp);
        TEST_ASSERT_EQUAL_INT32(0, el.next.psi_amp);
        TEST_ASSERT_EQUAL_UINT8(0u, el.now.sector);
        el.now.psi_amp = ef.now.psi_amp;
        el.next.psi_amp = ef.next.psi_amp;
        el.now.sector = ef.now.sector;
        /* field by field (no padding compared) */
        const ctrl_mstate_t *a[2] = {&ef.now, &ef.next};
        const ctrl_mstate_t *b[2] = {&el.now, &el.next};
        for (int j = 0; j < 2; j++) {
            TEST_ASSERT_EQUAL_INT32(a[j]->i_alpha, b[j]->i_alpha);
            TEST_ASSERT_EQUAL_INT32(a[j]->i_beta, b[j]->i_beta);
            TEST_ASSERT_EQUAL_INT32(a[j]->i_d, b[j]->i_d);
            TEST_ASSERT_EQUAL_INT32(a[j]->i_q, b[j]->i_q);
            TEST_ASSERT_EQUAL_INT32(a[j]->psi_alpha, b[j]->psi_alpha);
            TEST_ASSERT_EQUAL_INT32(a[j]->psi_beta, b[j]->psi_beta);
            TEST_ASSERT_EQUAL_INT32(a[j]->psi_d, b[j]->psi_d);
            TEST_ASSERT_EQUAL_INT32(a[j]->psi_q, b[j]->psi_q);
            TEST_ASSERT_EQUAL_INT32(a[j]->psi_amp, b[j]->psi_amp);
            TEST_ASSERT_EQUAL_INT32(a[j]->torque, b[j]->torque);
            TEST_ASSERT_EQUAL_UINT32(a[j]->theta_e, b[j]->theta_e);
            TEST_ASSERT_EQUAL_INT32(a[j]->sin_theta, b[j]->sin_theta);
            TEST_ASSERT_EQUAL_INT32(a[j]->cos_theta, b[j]->cos_theta);
            TEST_ASSERT_EQUAL_UINT8(a[j]->sector, b[j]->sector);
        }
        TEST_ASSERT_EQUAL_INT32(ef.omega_e, el.omega_e);
        TEST_ASSERT_EQUAL_INT32(ef.vdc, el.vdc);
        /* outputs survive a reset */
        if (k == 100) {
            ctrl_estimator_reset(&full);
            ctrl_estimator_reset(&lean);
            TEST_ASSERT_EQUAL_UINT8(0u, lean.outputs);
        }
        ctrl_mstate_t x;
        ctrl_mstate_t y;
        ctrl_mstate_from_flux_sc(&P, ef.next.psi_alpha, ef.next.psi_beta, th, ef.now.sin_theta,
                                 ef.now.cos_theta, &x);
        ctrl_mstate_from_flux_noamp(&P, ef.next.psi_alpha, ef.next.psi_beta, th, ef.now.sin_theta,
                                    ef.now.cos_theta, &y);
        TEST_ASSERT_EQUAL_INT32(0, y.psi_amp);
        TEST_ASSERT_EQUAL_INT32(x.torque, y.torque);
        TEST_ASSERT_EQUAL_INT32(x.i_alpha, y.i_alpha);
        TEST_ASSERT_EQUAL_INT32(x.i_beta, y.i_beta);
        TEST_ASSERT_EQUAL_UINT8(x.sector, y.sector);
    }
}

static void test_flux_vm(void)
{
    ctrl_flux_vm_t vm;
    q24_t pa;
    q24_t pb;
    /* Not primed: the first update adopts the current-model flux. */
    ctrl_flux_vm_init(&vm, CTRL_VM_CORR_NONE, 0);
    ctrl_flux_vm_update(&vm, &P, 0, 0, 0, 0, FX_ONE, 0);
    ctrl_flux_vm_get(&vm, &pa, &pb);
    TEST_ASSERT_EQUAL_INT32(FX_ONE, pa);
    TEST_ASSERT_EQUAL_INT32(0, pb);
    /* Pure integrator, constant voltage, zero current: the increments Ts v
     * are exact in Q48, so after n steps psi = psi0 + n Ts v within the one
     * final rounding (0.5 LSB). */
    const q24_t v = q(0.0123);
    for (int n = 1; n <= 1000; n++) {
        ctrl_flux_vm_update(&vm, &P, v, -v, 0, 0, 0, 0);
    }
    ctrl_flux_vm_get(&vm, &pa, &pb);
    const double inc = 1000.0 * d(P.ts) * d(v);
    TEST_ASSERT_TRUE(fabs(d(pa) - (1.0 + inc)) <= 0.5 * LSB);
    TEST_ASSERT_TRUE(fabs(d(pb) + inc) <= 0.5 * LSB);
    /* Trapezoidal current S1(37)-(38): i from 0 to 2 di gives Rs Ts di. */
    ctrl_flux_vm_reset(&vm, 0, 0, 0, 0);
    const q24_t di = q(0.25);
    ctrl_flux_vm_update(&vm, &P, 0, 0, 2 * di, 0, 0, 0);
    ctrl_flux_vm_get(&vm, &pa, &pb);
    TEST_ASSERT_TRUE(fabs(d(pa) + d(P.ts_rs) * d(di)) <= 1.0 * LSB);

    /* Drift with a current offset: the pure integrator drifts linearly, the
     * correction towards the current model settles at ts_rs off / k. */
    const q24_t off = q(0.05);
    q24_t k_corr;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_flux_vm_gain(&P, 5.0, &k_corr));
    TEST_ASSERT_TRUE(fabs(d(k_corr) - 2 * PI * 5.0 / P.fs_hz) <= 0.5 * LSB);
    ctrl_flux_vm_t pure;
    ctrl_flux_vm_t cm;
    ctrl_flux_vm_t lp;
    ctrl_flux_vm_init(&pure, CTRL_VM_CORR_NONE, 0);
    ctrl_flux_vm_init(&cm, CTRL_VM_CORR_CM, k_corr);
    ctrl_flux_vm_init(&lp, CTRL_VM_CORR_LOWPASS, k_corr);
    ctrl_flux_vm_reset(&pure, FX_ONE, 0, off, 0);
    ctrl_flux_vm_reset(&cm, FX_ONE, 0, off, 0);
    ctrl_flux_vm_reset(&lp, 0, 0, off, 0);
    /* true state: standstill, psi = psi_pm, i = 0, but the sensor reads off */
    const int n = 20000;
    for (int i = 0; i < n; i++) {
        ctrl_flux_vm_update(&pure, &P, 0, 0, off, 0, FX_ONE, 0);
        ctrl_flux_vm_update(&cm, &P, 0, 0, off, 0, FX_ONE, 0);
        ctrl_flux_vm_update(&lp, &P, 0, 0, off, 0, 0, 0);
    }
    const double drift = d(P.ts_rs) * d(off);
    ctrl_flux_vm_get(&pure, &pa, &pb);
    TEST_ASSERT_TRUE(fabs((1.0 - d(pa)) - n * drift) <= 1.0 * LSB + n * 1e-9);
    ctrl_flux_vm_get(&cm, &pa, &pb);
    /* after 20000 steps (1 - k)^n = e^-63: settled at -drift / k */
    TEST_ASSERT_TRUE(fabs((d(pa) - 1.0) + drift / d(k_corr)) <= 2.0 * LSB);
    ctrl_flux_vm_get(&lp, &pa, &pb);
    TEST_ASSERT_TRUE(fabs(d(pa) + drift / d(k_corr)) <= 2.0 * LSB);
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_flux_vm_gain(&P, 0.0, &k_corr));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_flux_vm_gain(&P, 1e5, &k_corr));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_flux_vm_gain(NULL, 5.0, &k_corr));
}

/* The estimator with the voltage model on a consistent trajectory: the
 * current-model machine at standstill, zero vector applied: VM tracks CM. */
static void test_estimator_voltage_model_source(void)
{
    ctrl_estimator_t e;
    ctrl_estimate_t est;
    ctrl_meas_t m;
    const ctrl_legs_t zero = {{0, 0, 0}};
    ctrl_estimator_init(&e, &P);
    e.flux_source = CTRL_FLUX_VOLTAGE_MODEL;
    meas_from_dq(0.0, 0.0, 0x20000000u, &m);
    for (int k = 0; k < 10; k++) {
        ctrl_estimator_update(&e, &P, &m, &zero, &est);
    }
    /* zero current, zero voltage: flux stays at the initial current-model value */
    const double t = (double)m.theta_e * 2.0 * PI / 4294967296.0;
    TEST_ASSERT_TRUE(fabs(d(est.now.psi_alpha) - cos(t)) <= 1.0 * LSB + SC);
    TEST_ASSERT_TRUE(fabs(d(est.now.psi_beta) - sin(t)) <= 1.0 * LSB + SC);
    TEST_ASSERT_EQUAL_INT32(0, est.now.torque);
    ctrl_estimator_reset(&e);
    TEST_ASSERT_EQUAL_UINT8(CTRL_FLUX_VOLTAGE_MODEL, e.flux_source); /* kept */
}

int main(void)
{
    const ctrl_machine_t spm = machine_thesis_spmsm();
    if (ctrl_params_init(&P, &B, &spm, 10000u) != CTRL_OK) {
        return 1;
    }
    UNITY_BEGIN();
    RUN_TEST(test_speed_both_directions);
    RUN_TEST(test_speed_first_sample_and_reset);
    RUN_TEST(test_current_model_spmsm);
    RUN_TEST(test_prediction_with_plan);
    RUN_TEST(test_flux_current_roundtrip);
    RUN_TEST(test_optional_outputs);
    RUN_TEST(test_flux_vm);
    RUN_TEST(test_estimator_voltage_model_source);
    return UNITY_END();
}
