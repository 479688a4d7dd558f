/*
 * Estimator in the rotor frame (estimator.h): current model (3.9), the k+1
 * prediction (5.15)/(6.10)-(6.12) against the test fixture's separate
 * rotor-frame and stator-frame forms, the optional outputs, the angle
 * sources (encoder speed, forced angle, a source of the test's own, the
 * voltage a sensorless source reads), and the voltage-model flux with its
 * drift handling. Bounds from the roundings (docs/error-budget.md).
 */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "angle_source.h"
#include "ctrl_units.h"
#include "est_fixture.h"
#include "estimator.h"
#include "flux_vm.h"
#include "flux_vm_config.h"
#include "machines.h"
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
#define SC 3.18e-8  /* fx_sincos error bound: 0.5 LSB + 2e-9 */
#define EROT 3.0e-9 /* fx_rot_q30 error bound up to pi/2 */

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
    const double t = (double)th * 2.0 * CTRL_PI / 4294967296.0;
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
    TEST_ASSERT_EQUAL_INT32(fx_u2i(ctrl_angle_step(&P, est.omega_e)), est.dtheta);
}

static void test_speed_both_directions(void)
{
    run_speed(0.3);
    run_speed(-0.3);
    run_speed(1.0); /* rated speed */
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
    ctrl_estimator_reset(&e, &P);
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

/* The k+1 prediction against the fixture's rotor-frame form (the same
 * equations through the transforms: within a few roundings) and its
 * stator-frame form (5.15) exactly as written, psi(k+1) = psi + Ts (v - Rs i)
 * (within the table error of the frames), over every vector, any duty, both
 * directions of rotation and the corner machines. */
static void check_prediction(const ctrl_params_t *p, double imax, int n)
{
    ctrl_estimator_t e;
    ctrl_estimator_init(&e, p);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_estimator_set_angle_src(&e, p, &ctrl_angle_forced));
    uint32_t r = 12345u;
    for (int k = 0; k < n; k++) {
        r = r * 1664525u + 1013904223u;
        const fx_angle_t th = r;
        r = r * 1664525u + 1013904223u;
        const double w = 1.2 * ((double)(r >> 8) / 8388608.0 - 1.0);
        r = r * 1664525u + 1013904223u;
        const double id = imax * ((double)(r >> 8) / 16777216.0 - 0.7);
        r = r * 1664525u + 1013904223u;
        const double iq = imax * ((double)(r >> 8) / 8388608.0 - 1.0) * 0.7;
        ctrl_angle_forced_set(ctrl_estimator_angle_state(&e), p, th, q(w));
        ctrl_meas_t m;
        meas_from_dq(id, iq, th, &m);
        m.vdc = p->vdc_nom;
        ctrl_plan_t plan;
        ctrl_plan_active_zero(&plan, (uint8_t)(1u + (r >> 5) % 6u), (q24_t)(r >> 8));
        ctrl_legs_t legs;
        ctrl_plan_legs(&plan, &legs);
        ctrl_estimate_t est;
        ctrl_estimator_update(&e, p, &m, &legs, &est);
        TEST_ASSERT_EQUAL_UINT32(th, est.now.theta_e);
        TEST_ASSERT_EQUAL_INT32(q(w), est.omega_e);
        q24_t va;
        q24_t vb;
        ctrl_legs_voltage(&legs, m.vdc, &va, &vb);
        /* rotor-frame form: Ts Vdc u vs Ts v: one rounding of Ts Vdc times
         * |u| <= 2/3 and one of v times Ts, then the same path: 6 LSB + the
         * fixture's full-precision Ts Rs i vs the estimator's product (1 LSB). */
        ctrl_mstate_t fx;
        fixture_predict_dq(p, &est.now, va, vb, est.omega_e, &fx);
        const double ev = 6.0 * LSB + d(p->ts) * d(m.vdc) * LSB;
        TEST_ASSERT_TRUE(fabs(d(est.next.psi_d) - d(fx.psi_d)) <= ev);
        TEST_ASSERT_TRUE(fabs(d(est.next.psi_q) - d(fx.psi_q)) <= ev);
        TEST_ASSERT_TRUE(fabs(d(est.next.i_d) - d(fx.i_d)) <= ev * d(p->inv_ld) + LSB);
        TEST_ASSERT_TRUE(fabs(d(est.next.i_q) - d(fx.i_q)) <= ev * d(p->inv_lq) + LSB);
        TEST_ASSERT_EQUAL_UINT32(fx.theta_e, est.next.theta_e);
        /* the sine and cosine at k+1: the table values at k turned (SC + EROT
         * + 1 LSB) against the table at k+1 (SC) */
        TEST_ASSERT_TRUE(fabs(d(est.next.sin_theta) - d(fx.sin_theta)) <= 2.0 * SC + EROT + LSB);
        TEST_ASSERT_TRUE(fabs(d(est.next.cos_theta) - d(fx.cos_theta)) <= 2.0 * SC + EROT + LSB);
        /* stator-frame form (5.15) from the stator-frame values at k: the
         * increments went to the rotor frame and back with the table (its
         * scale |(s, c)|^2 = 1 +- 2 SC on Ts v and Ts Rs i); the amplitude
         * also sees the table's scale on psi at k (SC |psi|) */
        const double pa1 =
            d(est.now.psi_alpha) + d(p->ts) * d(va) - d(p->ts_rs) * d(est.now.i_alpha);
        const double pb1 = d(est.now.psi_beta) + d(p->ts) * d(vb) - d(p->ts_rs) * d(est.now.i_beta);
        const double amp = hypot(pa1, pb1);
        const double inc = d(p->ts) * hypot(d(va), d(vb)) +
                           d(p->ts_rs) * hypot(d(est.now.i_alpha), d(est.now.i_beta));
        const double es = ev + 2.0 * SC * 2.0 * inc + 3.0 * LSB;
        TEST_ASSERT_TRUE(fabs(d(est.next.psi_alpha) - pa1) <= es);
        TEST_ASSERT_TRUE(fabs(d(est.next.psi_beta) - pb1) <= es);
        TEST_ASSERT_TRUE(fabs(d(est.next.psi_amp) - amp) <= es + 2.0 * SC * amp);
        /* |psi(k+1)| from the flux before the frame turns: rotation-invariant */
        TEST_ASSERT_INT32_WITHIN(2, fx_mag(est.next.psi_d, est.next.psi_q), est.next.psi_amp);
        TEST_ASSERT_EQUAL_UINT8(ctrl_sector(est.next.psi_alpha, est.next.psi_beta),
                                est.next.sector);
    }
}

static void test_prediction(void)
{
    check_prediction(&P, 1.5, 3000);
    const ctrl_machine_t ms[3] = {machine_thesis_ipmsm80(), machine_small_8v(),
                                  machine_small_10khz()};
    const uint32_t fs[3] = {20000u, 40000u, 10000u};
    for (int i = 0; i < 3; i++) {
        ctrl_params_t p;
        ctrl_bases_t b;
        TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&p, &b, &ms[i], fs[i]));
        check_prediction(&p, d(p.current_max), 3000);
    }
}

/* Optional outputs (CTRL_EST_*): each bit alone writes exactly its fields
 * (equal to the full estimator's), the rest of the optional fields keep the
 * caller's values, the mandatory ones are always equal; the implications. */
static void test_optional_outputs(void)
{
    enum { NB = 9 };
    static const unsigned bits[NB] = {
        CTRL_EST_AMP_NOW,  CTRL_EST_SECTOR_NOW,  CTRL_EST_PSI_AB_NOW,
        CTRL_EST_AMP_NEXT, CTRL_EST_SECTOR_NEXT, CTRL_EST_PSI_AB_NEXT,
        CTRL_EST_SC_NEXT,  CTRL_EST_I_AB_NEXT,   CTRL_EST_AMP_SQ_NEXT};
    ctrl_estimator_t full;
    ctrl_estimator_init(&full, &P);
    TEST_ASSERT_EQUAL_UINT16(CTRL_EST_ALL, full.outputs);
    ctrl_estimator_t lean[NB + 1];
    for (int b = 0; b <= NB; b++) {
        ctrl_estimator_init(&lean[b], &P);
        ctrl_estimator_set_outputs(&lean[b], b < NB ? bits[b] : 0u);
    }
    TEST_ASSERT_EQUAL_UINT16(CTRL_EST_SECTOR_NOW | CTRL_EST_PSI_AB_NOW, lean[1].outputs);
    TEST_ASSERT_EQUAL_UINT16(CTRL_EST_SECTOR_NEXT | CTRL_EST_PSI_AB_NEXT, lean[4].outputs);
    TEST_ASSERT_EQUAL_UINT16(CTRL_EST_I_AB_NEXT | CTRL_EST_SC_NEXT, lean[7].outputs);
    TEST_ASSERT_EQUAL_UINT16(CTRL_EST_AMP_SQ_NEXT, lean[8].outputs);
    TEST_ASSERT_EQUAL_UINT16(0u, lean[NB].outputs);
    ctrl_plan_t plan;
    ctrl_legs_t legs;
    ctrl_plan_active_zero(&plan, 2u, FX_ONE / 3);
    ctrl_plan_legs(&plan, &legs);
    const q24_t mark = 0x5A5A5A5A;
    for (int k = 0; k < 200; k++) {
        ctrl_meas_t m;
        const fx_angle_t th = (fx_angle_t)(uint32_t)k * 0x01234567u;
        meas_from_dq(0.1 * sin(0.3 * k), 0.25 * cos(0.17 * k), th, &m);
        ctrl_estimate_t ef;
        ctrl_estimator_update(&full, &P, &m, &legs, &ef);
        for (int b = 0; b <= NB; b++) {
            ctrl_estimate_t el;
            ctrl_mstate_t *x[2] = {&el.now, &el.next};
            for (int j = 0; j < 2; j++) {
                x[j]->psi_amp = x[j]->psi_alpha = x[j]->psi_beta = mark;
                x[j]->i_alpha = x[j]->i_beta = x[j]->sin_theta = x[j]->cos_theta = mark;
                x[j]->sector = 0xA5u;
                x[j]->psi_amp_sq = 0x5A5A5A5A5A5Au;
            }
            ctrl_estimator_update(&lean[b], &P, &m, &legs, &el);
            const unsigned o = lean[b].outputs;
            const ctrl_mstate_t *a[2] = {&ef.now, &ef.next};
            const unsigned amp[2] = {CTRL_EST_AMP_NOW, CTRL_EST_AMP_NEXT};
            const unsigned sec[2] = {CTRL_EST_SECTOR_NOW, CTRL_EST_SECTOR_NEXT};
            const unsigned pab[2] = {CTRL_EST_PSI_AB_NOW, CTRL_EST_PSI_AB_NEXT};
            for (int j = 0; j < 2; j++) {
                TEST_ASSERT_EQUAL_INT32(a[j]->i_d, x[j]->i_d);
                TEST_ASSERT_EQUAL_INT32(a[j]->i_q, x[j]->i_q);
                TEST_ASSERT_EQUAL_INT32(a[j]->psi_d, x[j]->psi_d);
                TEST_ASSERT_EQUAL_INT32(a[j]->psi_q, x[j]->psi_q);
                TEST_ASSERT_EQUAL_INT32(a[j]->torque, x[j]->torque);
                TEST_ASSERT_EQUAL_UINT32(a[j]->theta_e, x[j]->theta_e);
                TEST_ASSERT_EQUAL_INT32(o & amp[j] ? a[j]->psi_amp : mark, x[j]->psi_amp);
                TEST_ASSERT_EQUAL_UINT8(o & sec[j] ? a[j]->sector : 0xA5u, x[j]->sector);
                TEST_ASSERT_EQUAL_INT32(o & pab[j] ? a[j]->psi_alpha : mark, x[j]->psi_alpha);
                TEST_ASSERT_EQUAL_INT32(o & pab[j] ? a[j]->psi_beta : mark, x[j]->psi_beta);
            }
            const int sq = (o & CTRL_EST_AMP_SQ_NEXT) != 0u;
            TEST_ASSERT_TRUE(el.next.psi_amp_sq == (sq ? ef.next.psi_amp_sq : 0x5A5A5A5A5A5Au));
            TEST_ASSERT_TRUE(el.now.psi_amp_sq == 0x5A5A5A5A5A5Au); /* no such output at k */
            TEST_ASSERT_EQUAL_INT32(ef.now.sin_theta, el.now.sin_theta);
            TEST_ASSERT_EQUAL_INT32(ef.now.i_alpha, el.now.i_alpha);
            const int sc = (o & CTRL_EST_SC_NEXT) != 0u;
            const int iab = (o & CTRL_EST_I_AB_NEXT) != 0u;
            TEST_ASSERT_EQUAL_INT32(sc ? ef.next.sin_theta : mark, el.next.sin_theta);
            TEST_ASSERT_EQUAL_INT32(sc ? ef.next.cos_theta : mark, el.next.cos_theta);
            TEST_ASSERT_EQUAL_INT32(iab ? ef.next.i_alpha : mark, el.next.i_alpha);
            TEST_ASSERT_EQUAL_INT32(iab ? ef.next.i_beta : mark, el.next.i_beta);
            TEST_ASSERT_EQUAL_INT32(ef.omega_e, el.omega_e);
            TEST_ASSERT_EQUAL_INT32(ef.rot_c, el.rot_c);
            TEST_ASSERT_EQUAL_INT32(ef.rot_s, el.rot_s);
        }
        /* full: the optional values are those of their definitions */
        TEST_ASSERT_EQUAL_INT32(fx_mag(ef.now.psi_d, ef.now.psi_q), ef.now.psi_amp);
        TEST_ASSERT_EQUAL_UINT8(ctrl_sector(ef.now.psi_alpha, ef.now.psi_beta), ef.now.sector);
        TEST_ASSERT_EQUAL_UINT8(ctrl_sector(ef.next.psi_alpha, ef.next.psi_beta), ef.next.sector);
        /* the square is the one of the amplitude: fx_mag(S) == psi_amp (fx.h) */
        TEST_ASSERT_TRUE(ef.next.psi_amp_sq < fx_mag_le_lim(ef.next.psi_amp));
        TEST_ASSERT_TRUE(ef.next.psi_amp_sq >= fx_mag_ge_lim(ef.next.psi_amp));
        /* outputs survive a reset */
        if (k == 100) {
            ctrl_estimator_reset(&full, &P);
            for (int b = 0; b <= NB; b++) {
                ctrl_estimator_reset(&lean[b], &P);
            }
            TEST_ASSERT_EQUAL_UINT16(0u, lean[NB].outputs);
        }
    }
}

/* A source of the test's own: the estimator takes theta and omega from it
 * (every rotor-frame value follows), hands it the Clarke currents, and, as it
 * asks (uses_voltage), the mean voltage of the previous period. */
typedef struct {
    fx_angle_t theta;
    q24_t omega;
    ctrl_angle_in_t seen;
    int resets;
} test_src_t;

static void test_src_reset(void *state, const ctrl_params_t *p)
{
    (void)p;
    ((test_src_t *)state)->resets++;
}

static void test_src_update(void *state, const ctrl_params_t *p, const ctrl_angle_in_t *in,
                            ctrl_angle_out_t *out)
{
    (void)p;
    test_src_t *s = state;
    s->seen = *in;
    out->theta = s->theta;
    out->omega = s->omega;
}

static void test_angle_sources(void)
{
    ctrl_estimator_t e;
    ctrl_estimator_init(&e, &P);
    const ctrl_angle_src_t own = {"test", sizeof(test_src_t), 1u, test_src_reset, test_src_update};
    const ctrl_angle_src_t big = {"big", CTRL_ANGLE_STATE_MAX + 1u, 0u, test_src_reset,
                                  test_src_update};
    const ctrl_angle_src_t none = {"none", 0u, 0u, test_src_reset, NULL};
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_estimator_set_angle_src(&e, &P, &big));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_estimator_set_angle_src(&e, &P, &none));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_estimator_set_angle_src(&e, &P, NULL));
    TEST_ASSERT_TRUE(e.src == &ctrl_angle_encoder); /* kept */
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_estimator_set_angle_src(&e, &P, &own));
    test_src_t *s = ctrl_estimator_angle_state(&e);
    TEST_ASSERT_EQUAL_INT(1, s->resets);
    s->theta = 0x2468ACE0u;
    s->omega = q(0.4);
    ctrl_meas_t m;
    meas_from_dq(0.1, 0.3, 0x11111111u, &m); /* the sensor's angle is not used */
    const ctrl_plan_t plan = {2u, {3u, 0u}, {FX_ONE / 4, FX_ONE - FX_ONE / 4}};
    ctrl_legs_t legs;
    ctrl_plan_legs(&plan, &legs);
    ctrl_estimate_t est;
    ctrl_estimator_update(&e, &P, &m, &legs, &est);
    TEST_ASSERT_EQUAL_UINT32(0x11111111u, s->seen.theta_meas);
    TEST_ASSERT_EQUAL_INT32(0, s->seen.v_alpha); /* nothing applied before */
    TEST_ASSERT_EQUAL_INT32(est.now.i_alpha, s->seen.i_alpha);
    TEST_ASSERT_EQUAL_INT32(est.now.i_beta, s->seen.i_beta);
    TEST_ASSERT_EQUAL_UINT32(0x2468ACE0u, est.now.theta_e);
    TEST_ASSERT_EQUAL_INT32(q(0.4), est.omega_e);
    ctrl_mstate_t want;
    fixture_state_from_current(&P, est.now.i_alpha, est.now.i_beta, 0x2468ACE0u, &want);
    TEST_ASSERT_EQUAL_INT32(want.i_d, est.now.i_d);
    TEST_ASSERT_EQUAL_INT32(want.psi_q, est.now.psi_q);
    /* next period: the source sees the mean voltage of the last one */
    ctrl_estimator_update(&e, &P, &m, NULL, &est);
    q24_t va;
    q24_t vb;
    ctrl_legs_voltage(&legs, m.vdc, &va, &vb);
    TEST_ASSERT_EQUAL_INT32(va, s->seen.v_alpha);
    TEST_ASSERT_EQUAL_INT32(vb, s->seen.v_beta);
    ctrl_estimator_reset(&e, &P);
    TEST_ASSERT_EQUAL_INT(2, s->resets);

    /* forced: theta advances by omega Ts from where it was set; omega reported */
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_estimator_set_angle_src(&e, &P, &ctrl_angle_forced));
    const q24_t w = q(-0.7);
    ctrl_angle_forced_set(ctrl_estimator_angle_state(&e), &P, 0x80000000u, w);
    ctrl_estimator_reset(&e, &P); /* keeps the command (arming resets the estimator) */
    fx_angle_t th = 0x80000000u;
    for (int k = 0; k < 50; k++) {
        ctrl_estimator_update(&e, &P, &m, NULL, &est);
        TEST_ASSERT_EQUAL_UINT32(th, est.now.theta_e);
        TEST_ASSERT_EQUAL_INT32(w, est.omega_e);
        TEST_ASSERT_EQUAL_UINT32(th + ctrl_angle_step(&P, w), est.next.theta_e);
        th += ctrl_angle_step(&P, w);
    }
    ctrl_angle_forced_set(NULL, &P, 0u, 0); /* ignored */
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
    TEST_ASSERT_TRUE(fabs(d(k_corr) - 2 * CTRL_PI * 5.0 / P.fs_hz) <= 0.5 * LSB);
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
    RUN_TEST(test_prediction);
    RUN_TEST(test_optional_outputs);
    RUN_TEST(test_angle_sources);
    RUN_TEST(test_flux_vm);
    return UNITY_END();
}
