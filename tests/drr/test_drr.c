/*
 * Unit tests of DRR-DTC (thesis ch. 5) and its baselines: control core only,
 * so they also run on the Cortex-M4 under QEMU.
 */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "../core/est_fixture.h"
#include "controller.h"
#include "ctrl_drr.h"
#include "ctrl_drr_config.h"
#include "ctrl_params.h"
#include "ctrl_units.h"
#include "drr_machines.h"
#include "plan.h"
#include "unity.h"
#include "vectors.h"

#define LSB (1.0 / 16777216.0) /* one Q24 step */

static ctrl_params_t P;
static ctrl_bases_t BASES;
static ctrl_setup_t SU;
static _Alignas(8) unsigned char STATE[CTRL_STATE_MAX];
static _Alignas(8) unsigned char CFG[CTRL_CFG_MAX];

void setUp(void)
{
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&P, &BASES, &ini_thesis_spmsm, CTRL_DRR_FS_HZ));
    SU = (ctrl_setup_t){&ini_thesis_spmsm, &BASES, &P};
}

void tearDown(void)
{
}

static q24_t q(double pu)
{
    return ctrl_q24_from_double(pu);
}

static double d(q24_t x)
{
    return ctrl_q24_to_double(x);
}

/* cfg_default + init of a registered controller on the thesis SPMSM at 10 kHz. */
static void *make(const char *name, void (*tweak)(void *cfg))
{
    const ctrl_desc_t *desc = ctrl_find(name);
    TEST_ASSERT_NOT_NULL(desc);
    TEST_ASSERT_TRUE(desc->state_size <= sizeof STATE);
    TEST_ASSERT_TRUE(desc->cfg_size <= sizeof CFG);
    desc->cfg_default(CFG, &ini_thesis_spmsm);
    if (tweak != NULL) {
        tweak(CFG);
    }
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_init(desc, STATE, CFG, &SU));
    return STATE;
}

/* ---- (5.9), (5.10): A = 1.266, B = 1.023 N*m (thesis Table 5.1: 1.27, 1.02) rounded to
 * 1e-3, so the exact values lie within +-0.5e-3 of them. ---- */
static void test_ab_thesis_spmsm(void)
{
    double a;
    double b;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_drr_ab_si(&ini_thesis_spmsm, 100e-6, &a, &b));
    TEST_ASSERT_DOUBLE_WITHIN(0.5e-3, 1.266, a);
    TEST_ASSERT_DOUBLE_WITHIN(0.5e-3, 1.023, b);

    /* The fixed-point values init derives: A in pu and B / w_rn in pu, back to
     * N*m. Q24 rounding adds at most 0.5 LSB of pu torque (and of the speed
     * scale, relative 0.5 LSB / kb). */
    ctrl_drr_state_t *s = make("drr", NULL);
    const double a_nm = d(s->a) * BASES.torque_nm;
    const double w_rn_pu = 2.0 * CTRL_PI * 3000.0 / 60.0 * 4.0 / BASES.w_rad_s;
    const double b_nm = d(s->kb) * w_rn_pu * BASES.torque_nm;
    TEST_ASSERT_DOUBLE_WITHIN(0.5e-3 + 0.5 * LSB * BASES.torque_nm, 1.266, a_nm);
    TEST_ASSERT_DOUBLE_WITHIN(0.5e-3 + 0.5 * LSB * BASES.torque_nm * w_rn_pu, 1.023, b_nm);
    /* (5.13) numerator 2 sqrt(3) A and the clamp |C| <= 64 */
    TEST_ASSERT_INT_WITHIN(2, q(2.0 * sqrt(3.0) * d(s->a)), s->c_num);
    TEST_ASSERT_TRUE(s->dc_max < 0);
    TEST_ASSERT_EQUAL_INT(0, s->dc_fixed);

    /* Bad machine data: clear error, no crash. */
    ctrl_machine_t bad = ini_thesis_spmsm;
    bad.ld_h = 0.0;
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_drr_ab_si(&bad, 100e-6, &a, &b));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_drr_ab_si(NULL, 100e-6, &a, &b));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_drr_ab_si(&ini_thesis_spmsm, 0.0, &a, &b));
}

/* ---- (5.5): lambda = 0.03 at 10 kHz -> 48.5 Hz (thesis §5.3.2, 3 digits). ---- */
static void test_ema_cutoff(void)
{
    const double fc = ctrl_drr_ema_cutoff_hz(0.03, 10000.0);
    TEST_ASSERT_DOUBLE_WITHIN(0.05, 48.5, fc);
    TEST_ASSERT_TRUE(isnan(ctrl_drr_ema_cutoff_hz(0.0, 10000.0)));
    TEST_ASSERT_TRUE(isnan(ctrl_drr_ema_cutoff_hz(1.0, 10000.0)));

    /* The integer EMA (5.4) itself has gain 1/sqrt(2) at that frequency
     * ((5.5) is its exact -3 dB point). Drive 0.1 pu at fc for 0.2 s (the
     * transient decays with 1/lambda = 33 samples) and take the peak of the last
     * 0.1 s: sampling the peak of a 206-sample period misses at most
     * 1 - cos(pi/206) = 1.2e-4; Q24 rounding is 1e-6 of the amplitude. */
    const ctrl_drr_state_t *s = make("drr", NULL);
    TEST_ASSERT_INT_WITHIN(1, q(0.03), s->lambda);
    q24_t g = 0;
    double peak = 0.0;
    for (int k = 0; k < 2000; k++) {
        const q24_t chi = q(0.1 * sin(2.0 * CTRL_PI * fc * k / 10000.0));
        g = ctrl_drr_ema(g, chi, s->lambda);
        if (k >= 1000 && fabs(d(g)) > peak) {
            peak = fabs(d(g));
        }
    }
    TEST_ASSERT_DOUBLE_WITHIN(0.1 * 2e-3, 0.1 / sqrt(2.0), peak);
    /* DC gain 1: a constant input is reached exactly (to 17 LSB: the update
     * lambda (chi - gamma) rounds to 0 below 0.5 LSB / lambda). */
    g = 0;
    for (int k = 0; k < 2000; k++) {
        g = ctrl_drr_ema(g, q(0.05), s->lambda);
    }
    TEST_ASSERT_INT_WITHIN(17, q(0.05), g);
}

/* ---- (5.1), transcribed: rows x = 1..6, columns
 * (T>=0, psi>=0) V_{x+1} | (T>=0, psi<0) V_{x+2} | (T<0, psi<0) V_{x+4} | (T<0, psi>=0) V_{x+5}
 * with V_{x+n} wrapped into 1..6 (footnote of (4.14)). ---- */
static void test_select_table_5_1(void)
{
    static const uint8_t table[6][4] = {
        {2, 3, 5, 6}, {3, 4, 6, 1}, {4, 5, 1, 2}, {5, 6, 2, 3}, {6, 1, 3, 4}, {1, 2, 4, 5},
    };
    const q24_t t_err[4] = {q(0.1), q(0.1), q(-0.1), q(-0.1)};
    const q24_t psi_err[4] = {q(0.01), q(-0.01), q(-0.01), q(0.01)};
    for (uint8_t x = 1; x <= 6; x++) {
        for (int c = 0; c < 4; c++) {
            TEST_ASSERT_EQUAL_UINT8(table[x - 1][c], ctrl_drr_select(x, t_err[c], psi_err[c]));
        }
        /* zero errors belong to the ">= 0" rows */
        TEST_ASSERT_EQUAL_UINT8(table[x - 1][0], ctrl_drr_select(x, 0, 0));
        TEST_ASSERT_EQUAL_UINT8(table[x - 1][3], ctrl_drr_select(x, -1, 0));
        TEST_ASSERT_EQUAL_UINT8(table[x - 1][1], ctrl_drr_select(x, 0, -1));
    }
}

/* ---- Duty (5.14): always in [0, 1] and non-decreasing in |T_err| on either
 * branch (dD/dT_err = 1 / (Delta T -+ C gamma), positive for T_err >= 0 and
 * negative for T_err < 0 by the sign check of the branch). ---- */
static void test_duty_limits_monotonic(void)
{
    const ctrl_drr_state_t *s = make("drr", NULL);
    const double speeds[] = {-0.53, -0.3, -0.05, 0.0, 0.05, 0.3, 0.4, 0.53, 0.6};
    const double gammas[] = {-0.03, 0.0, 0.01, 0.03};
    int checked = 0;
    for (int x = 1; x <= 6; x++) {
        for (int j = 1; j < 8; j++) {
            /* theta_s inside sector x, (4.5) */
            const double th = (2 * x - 3) * CTRL_PI / 6 + j * (CTRL_PI / 3) / 8;
            const q24_t pa = q(1.02 * cos(th));
            const q24_t pb = q(1.02 * sin(th));
            const q24_t amp = fx_mag(pa, pb);
            TEST_ASSERT_EQUAL_UINT8(x, ctrl_sector(pa, pb));
            for (size_t iw = 0; iw < sizeof speeds / sizeof speeds[0]; iw++) {
                for (size_t ig = 0; ig < sizeof gammas / sizeof gammas[0]; ig++) {
                    for (int ps = 0; ps < 2; ps++) {
                        const q24_t perr = ps ? q(0.01) : q(-0.01);
                        q24_t prev_pos = -1;
                        q24_t prev_neg = -1;
                        for (int k = 0; k <= 60; k++) {
                            const double e = 0.3 * k / 60.0;
                            const q24_t ep = q(e);
                            const q24_t en = q(-e - 1e-6);
                            const uint8_t vp = ctrl_drr_select((uint8_t)x, ep, perr);
                            const uint8_t vn = ctrl_drr_select((uint8_t)x, en, perr);
                            const q24_t dp =
                                ctrl_drr_duty(s, vp, pa, pb, amp, ep, q(gammas[ig]), q(speeds[iw]));
                            const q24_t dn =
                                ctrl_drr_duty(s, vn, pa, pb, amp, en, q(gammas[ig]), q(speeds[iw]));
                            TEST_ASSERT_TRUE(dp >= 0 && dp <= FX_ONE);
                            TEST_ASSERT_TRUE(dn >= 0 && dn <= FX_ONE);
                            TEST_ASSERT_TRUE(dp >= prev_pos);
                            TEST_ASSERT_TRUE(dn >= prev_neg);
                            prev_pos = dp;
                            prev_neg = dn;
                            checked++;
                        }
                    }
                }
            }
        }
    }
    TEST_ASSERT_TRUE(checked > 10000);
    /* A large error saturates at a full period (dynamic response, §5.3.1). */
    const q24_t pa = q(1.0);
    const q24_t pb = q(0.1);
    TEST_ASSERT_EQUAL_INT32(FX_ONE, ctrl_drr_duty(s, 2, pa, pb, fx_mag(pa, pb), q(0.5), 0, 0));
    TEST_ASSERT_EQUAL_INT32(FX_ONE, ctrl_drr_duty(s, 6, pa, pb, fx_mag(pa, pb), q(-0.5), 0, 0));
    /* Extreme and invalid inputs stay inside [0, 1] (no overflow: UBSan). */
    const q24_t ext[] = {FX_MIN, -FX_ONE, 0, FX_ONE, FX_MAX};
    for (size_t i = 0; i < 5; i++) {
        for (size_t k = 0; k < 5; k++) {
            for (size_t m = 0; m < 5; m++) {
                for (uint8_t v = 0; v <= 7; v++) {
                    const q24_t r =
                        ctrl_drr_duty(s, v, ext[i], ext[k], fx_abs(ext[m]), ext[k], ext[i], ext[m]);
                    TEST_ASSERT_TRUE(r >= 0 && r <= FX_ONE);
                }
            }
        }
    }
}

/* ---- §5.3.5: replacement only while |psi_err| < dpsi_max / 2,
 * dpsi_max = sqrt(3) Vdc Ts / 3 = 12.70 mWb at 220 V, 100 us. ---- */
static void sigma_off(void *cfg)
{
    ((ctrl_drr_cfg_t *)cfg)->sigma = 0.0;
}

static void fill_est(ctrl_estimate_t *est, double th_s, double amp, double delta, double w)
{
    memset(est, 0, sizeof *est);
    const double th_r = th_s - delta;
    const fx_angle_t a =
        (fx_angle_t)(int64_t)llround(fmod(th_r / (2 * CTRL_PI) + 2.0, 1.0) * 4294967296.0);
    fixture_state_from_flux(&P, q(amp * cos(th_s)), q(amp * sin(th_s)), a, &est->now);
    fixture_state_from_flux(&P, q(amp * cos(th_s)), q(amp * sin(th_s)), a, &est->next);
    est->omega_e = q(w);
    est->vdc = P.vdc_nom;
}

static void test_vreplace_condition(void)
{
    ctrl_drr_state_t *s = make("drr", NULL);
    const double half_pu = 0.5 * sqrt(3.0) * 220.0 * 100e-6 / 3.0 / BASES.psi_wb;
    TEST_ASSERT_INT_WITHIN(1, q(half_pu), s->half_dpsi);
    TEST_ASSERT_TRUE(ctrl_drr_vreplace_active(s, s->half_dpsi - 1));
    TEST_ASSERT_TRUE(ctrl_drr_vreplace_active(s, -(s->half_dpsi - 1)));
    TEST_ASSERT_TRUE(ctrl_drr_vreplace_active(s, 0));
    TEST_ASSERT_FALSE(ctrl_drr_vreplace_active(s, s->half_dpsi));
    TEST_ASSERT_FALSE(ctrl_drr_vreplace_active(s, -s->half_dpsi));

    /* In the loop: sector 1, theta_s = -25 deg (subsector I with sigma = 10 deg),
     * T_err > 0 and psi_err slightly < 0 -> (5.1) gives V3 = V_{x+2}, replaced by
     * V2 = V_{x+1} (4.20); with |psi_err| > dpsi_max / 2 V3 stays. */
    ctrl_estimate_t est;
    fill_est(&est, -25.0 * CTRL_PI / 180.0, 1.02, 0.1, 0.2);
    ctrl_refs_t ref = {q(0.25), 0};
    ctrl_ctx_t ctx = {&P, &est, &ref};
    ctrl_out_t o;
    TEST_ASSERT_EQUAL_UINT8(1, est.next.sector);

    ref.psi = est.next.psi_amp - s->half_dpsi / 2;
    ctrl_drr_reset(s);
    ctrl_drr_step(s, &ctx, &o);
    TEST_ASSERT_EQUAL_UINT8(3, s->last_vec_51);
    TEST_ASSERT_EQUAL_UINT8(2, o.plan.vec[0]);

    ref.psi = est.next.psi_amp - 2 * s->half_dpsi;
    ctrl_drr_reset(s);
    ctrl_drr_step(s, &ctx, &o);
    TEST_ASSERT_EQUAL_UINT8(3, s->last_vec_51);
    TEST_ASSERT_EQUAL_UINT8(3, o.plan.vec[0]);

    /* Subsector II (theta_s = +25 deg), psi_err >= 0: V2 = V_{x+1} -> V3 (4.21). */
    fill_est(&est, 25.0 * CTRL_PI / 180.0, 1.02, 0.1, 0.2);
    ref.psi = est.next.psi_amp + s->half_dpsi / 2;
    ctrl_drr_reset(s);
    ctrl_drr_step(s, &ctx, &o);
    TEST_ASSERT_EQUAL_UINT8(2, s->last_vec_51);
    TEST_ASSERT_EQUAL_UINT8(3, o.plan.vec[0]);

    /* sigma = 0 disables the replacement. */
    s = make("drr", sigma_off);
    TEST_ASSERT_FALSE(ctrl_drr_vreplace_active(s, 0));
    ctrl_drr_step(s, &ctx, &o);
    TEST_ASSERT_EQUAL_UINT8(2, o.plan.vec[0]);
}

/* ---- Plan shape: active vector for D, then V0 after V1/V3/V5, V7 after
 * V2/V4/V6 (§5.4); durations sum to one period. ---- */
static void test_plan_zero_vector(void)
{
    ctrl_drr_state_t *s = make("drr", sigma_off);
    ctrl_estimate_t est;
    ctrl_refs_t ref = {0, 0};
    ctrl_ctx_t ctx = {&P, &est, &ref};
    ctrl_out_t o;
    for (int x = 1; x <= 6; x++) {
        for (int sgn = -1; sgn <= 1; sgn += 2) {
            fill_est(&est, (x - 1) * CTRL_PI / 3 + 0.05, 1.0, 0.05 * sgn, 0.1);
            ref.torque = fx_add(est.next.torque, q(0.02 * sgn));
            ctrl_drr_reset(s);
            ctrl_drr_step(s, &ctx, &o);
            const uint8_t v = o.plan.vec[0];
            TEST_ASSERT_TRUE(v >= 1 && v <= 6);
            TEST_ASSERT_TRUE(o.plan.n_seg >= 1 && o.plan.n_seg <= CTRL_PLAN_MAX_SEG);
            int64_t sum = 0;
            for (unsigned i = 0; i < o.plan.n_seg; i++) {
                sum += o.plan.dur[i];
                if (i > 0 && o.plan.dur[i] > 0) {
                    TEST_ASSERT_EQUAL_UINT8((v % 2u) == 1u ? 0u : 7u, o.plan.vec[i]);
                }
            }
            TEST_ASSERT_EQUAL_INT64(FX_ONE, sum);
            TEST_ASSERT_EQUAL_INT32(s->last_duty, o.plan.dur[0]);
        }
    }
}

/* ---- Torque at the active-vector start of a centre-aligned period:
 * T(k+1) + (1 - D)/2 C gamma ((5.12)); no shift for D = 1; forward motoring
 * (gamma > 0, C < 0) lies below T(k+1) by half the zero-vector deviation. ---- */
static void test_t_start_centre(void)
{
    ctrl_drr_state_t *s = make("drr", NULL);
    const q24_t w = q(0.2);
    q24_t cn;
    q24_t dc;
    ctrl_drr_c_parts(s, w, &cn, &dc);
    const double c = d(cn) / d(dc);
    /* (5.13) with the SI-derived A, B: C = 2 sqrt3 A / (2 B w / w_rn - sqrt3 A) */
    const double a = d(s->a);
    const double kb = d(s->kb);
    TEST_ASSERT_DOUBLE_WITHIN(1e-5 * fabs(c), 2 * sqrt(3.0) * a / (2 * kb * 0.2 - sqrt(3.0) * a),
                              c);
    TEST_ASSERT_TRUE(c < -2.0);
    s->gamma = q(0.01);
    s->last_duty = FX_ONE;
    TEST_ASSERT_INT_WITHIN(1, q(0.2), ctrl_drr_t_start(s, q(0.2), w));
    s->last_duty = 0;
    TEST_ASSERT_INT_WITHIN(4, q(0.2 + 0.5 * c * 0.01), ctrl_drr_t_start(s, q(0.2), w));
    s->last_duty = q(0.4);
    TEST_ASSERT_INT_WITHIN(4, q(0.2 + 0.3 * c * 0.01), ctrl_drr_t_start(s, q(0.2), w));
    TEST_ASSERT_TRUE(ctrl_drr_t_start(s, q(0.2), w) < q(0.2));
}

/* ---- (5.16): T(k+1) = T(k) + D Delta T - (1 - D) B w / w_rn with the plan
 * applied during [k, k+1) (pred_516 = 1, centre shift off to observe it). ---- */
static void pred_516_on(void *cfg)
{
    ((ctrl_drr_cfg_t *)cfg)->pred_516 = 1.0;
    ((ctrl_drr_cfg_t *)cfg)->centre = 0.0;
}

static void test_pred_516(void)
{
    ctrl_drr_state_t *s = make("drr", pred_516_on);
    ctrl_estimate_t est;
    fill_est(&est, 0.3, 1.02, 0.2, 0.25);
    ctrl_refs_t ref = {q(0.22), 0};
    ctrl_ctx_t ctx = {&P, &est, &ref};
    ctrl_out_t o;
    /* V3 for 0.35 of [k, k+1): the vector and duty this controller chose at k-1. */
    s->vec_sel = 3;
    s->last_duty = q(0.35);
    s->dt_sel = q(0.1);
    ctrl_drr_step(s, &ctx, &o);
    const double pred = d(est.now.torque) + 0.35 * 0.1 - 0.65 * d(s->kb) * 0.25;
    TEST_ASSERT_INT_WITHIN(4, q(pred), fx_sub(s->last_tvref, s->last_terr));
    /* The stored Delta T of the new vector is (5.6)/(5.7) at the predicted flux. */
    const ctrl_mstate_t *nx = &est.next;
    const q24_t ux = ctrl_vec_dir_q24[o.plan.vec[0]][0];
    const q24_t uy = ctrl_vec_dir_q24[o.plan.vec[0]][1];
    const double cr = (d(nx->psi_alpha) * d(uy) - d(nx->psi_beta) * d(ux)) / d(nx->psi_amp);
    TEST_ASSERT_DOUBLE_WITHIN(8 * LSB, d(s->a) * cr - d(s->kb) * 0.25, d(s->dt_sel));
    /* No active vector chosen at k-1 (after reset): a zero vector, T(k) - B w / w_rn. */
    s->vec_sel = 0;
    ctrl_drr_step(s, &ctx, &o);
    TEST_ASSERT_INT_WITHIN(4, q(d(est.now.torque) - d(s->kb) * 0.25),
                           fx_sub(s->last_tvref, s->last_terr));
}

/* ---- Baselines with the thesis parameters (Table 5.1). ---- */
static void test_baselines_thesis_values(void)
{
    const double tb = BASES.torque_nm;
    /* D1 (5.19), C_T = 1.2 N*m, C_psi = 0.09427 Wb: 0.6 N*m -> 0.5; + 9.427 mWb -> 0.6 */
    ctrl_drr_base_state_t *s = make("drr_d1", NULL);
    TEST_ASSERT_INT_WITHIN(64, q(0.5), ctrl_drr_duty_d1(s, q(0.6 / tb), 0));
    TEST_ASSERT_INT_WITHIN(64, q(0.5), ctrl_drr_duty_d1(s, q(-0.6 / tb), 0));
    TEST_ASSERT_INT_WITHIN(64, q(0.6), ctrl_drr_duty_d1(s, q(0.6 / tb), q(-0.1)));
    TEST_ASSERT_EQUAL_INT32(FX_ONE, ctrl_drr_duty_d1(s, q(1.3 / tb), 0));

    /* D2 (5.21), K_a = 2 N*m, K_b = 6e-4 N*m/(r/min): at standstill
     * 2 T_err / K_a; at 1000 r/min and T_err = 0: 0.6 / (2 - 0.6) = 0.4286. */
    s = make("drr_d2", NULL);
    TEST_ASSERT_INT_WITHIN(64, q(0.5), ctrl_drr_duty_d2(s, q(0.5 / tb), 0));
    TEST_ASSERT_INT_WITHIN(64, q(0.5), ctrl_drr_duty_d2(s, q(-0.5 / tb), 0));
    const double w1000 = 2 * CTRL_PI * 1000.0 / 60.0 * 4.0 / BASES.w_rad_s;
    TEST_ASSERT_INT_WITHIN(256, q(0.6 / 1.4), ctrl_drr_duty_d2(s, 0, q(w1000)));
    /* T_err < 0 at forward speed: numerator > 0, denominator < 0 -> D = 0 (ZVV). */
    TEST_ASSERT_EQUAL_INT32(0, ctrl_drr_duty_d2(s, q(-0.1 / tb), q(w1000)));

    /* D_PI (5.20): 3 w psi_pm / (2 Vdc) = back-EMF over |V_active|: at 3000 r/min
     * 118.5 V / 146.7 V = 0.808 (thesis SPMSM), no error, no integral. */
    s = make("drr_pi", NULL);
    const double w3000 = 2 * CTRL_PI * 3000.0 / 60.0 * 4.0 / BASES.w_rad_s;
    const double ff = 3.0 * (w3000 * BASES.w_rad_s) * 0.09427 / (2.0 * 220.0);
    TEST_ASSERT_DOUBLE_WITHIN(1e-3, 0.808, ff);
    TEST_ASSERT_INT_WITHIN(64, q(ff), ctrl_drr_duty_pi(s, 0, 0, q(w3000)));
    TEST_ASSERT_INT_WITHIN(64, q(ff), ctrl_drr_duty_pi(s, 0, 0, q(-w3000)));
}

/* ---- Registry, defaults, bad configuration, NULL safety. ---- */
static void bad_lambda(void *cfg)
{
    ((ctrl_drr_cfg_t *)cfg)->lambda = 1.5;
}

static void test_descriptors(void)
{
    const char *names[] = {"drr", "drr_d1", "drr_d2", "drr_pi", "drr_df"};
    for (size_t i = 0; i < 5; i++) {
        const ctrl_desc_t *desc = ctrl_find(names[i]);
        TEST_ASSERT_NOT_NULL(desc);
        TEST_ASSERT_EQUAL_UINT32(10000u, desc->fs_default_hz);
        TEST_ASSERT_TRUE(desc->n_tunables > 0);
        for (size_t k = 0; k < desc->n_tunables; k++) {
            TEST_ASSERT_TRUE(desc->tunables[k].min <= desc->tunables[k].max);
            TEST_ASSERT_TRUE(desc->tunables[k].offset + sizeof(double) <= desc->cfg_size);
        }
        make(names[i], NULL);
        TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_init(desc, NULL, CFG, &SU));
        TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_init(desc, STATE, NULL, &SU));
        TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_init(desc, STATE, CFG, NULL));
        /* NULL context: a zero-vector plan, no crash */
        make(names[i], NULL);
        ctrl_out_t o;
        ctrl_step(desc, STATE, NULL, &o);
        TEST_ASSERT_EQUAL_UINT8(1, o.plan.n_seg);
        TEST_ASSERT_EQUAL_UINT8(0, o.plan.vec[0]);
        ctrl_step(desc, STATE, NULL, NULL);
        ctrl_reset(desc, NULL);
    }
    const ctrl_desc_t *desc = ctrl_find("drr");
    desc->cfg_default(CFG, &ini_thesis_spmsm);
    bad_lambda(CFG);
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_init(desc, STATE, CFG, &SU));
    desc->cfg_default(CFG, &ini_thesis_spmsm);
    ((ctrl_drr_cfg_t *)CFG)->c = 1.0; /* C must be < 0 */
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_init(desc, STATE, CFG, &SU));
    desc->cfg_default(CFG, &ini_thesis_spmsm);
    ((ctrl_drr_cfg_t *)CFG)->sigma = NAN;
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_init(desc, STATE, CFG, &SU));
    desc = ctrl_find("drr_d1");
    desc->cfg_default(CFG, &ini_thesis_spmsm);
    ((ctrl_drr_base_cfg_t *)CFG)->c_t_nm = 0.0;
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_init(desc, STATE, CFG, &SU));
}

/* ---- Tunables by name (SI): the thesis' Table 5.1 values A = 1.27, B = 1.02 N*m
 * override the computed ones; out-of-range and unknown names are refused. ---- */
static void test_tunables_by_name(void)
{
    const ctrl_desc_t *desc = ctrl_find("drr");
    desc->cfg_default(CFG, &ini_thesis_spmsm);
    double v = 0.0;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_get(desc, CFG, "lambda", &v));
    TEST_ASSERT_EQUAL_DOUBLE(0.03, v);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_set(desc, CFG, "A", 1.27));
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_set(desc, CFG, "B", 1.02));
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_set(desc, CFG, "C", -3.0));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_tunable_set(desc, CFG, "lambda", 1.5));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_tunable_set(desc, CFG, "sigma", 1.0));
    TEST_ASSERT_EQUAL_INT(CTRL_ENOENT, ctrl_tunable_set(desc, CFG, "no_such", 1.0));
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_init(desc, STATE, CFG, &SU));
    const ctrl_drr_state_t *s = (const ctrl_drr_state_t *)STATE;
    TEST_ASSERT_INT_WITHIN(1, q(1.27 / BASES.torque_nm), s->a);
    const double w_rn_pu = 2.0 * CTRL_PI * 3000.0 / 60.0 * 4.0 / BASES.w_rad_s;
    TEST_ASSERT_INT_WITHIN(1, q(1.02 / BASES.torque_nm / w_rn_pu), s->kb);
    /* fixed C: C = -c_num / 1 at every speed */
    q24_t cn;
    q24_t dc;
    ctrl_drr_c_parts(s, q(0.4), &cn, &dc);
    TEST_ASSERT_EQUAL_INT32(-FX_ONE, dc);
    TEST_ASSERT_INT_WITHIN(1, q(3.0), cn);

    const char *base_names[] = {"drr_d1", "drr_d2", "drr_pi", "drr_df"};
    const char *first[] = {"C_T", "K_a", "K_P", "rms"};
    for (size_t i = 0; i < 4; i++) {
        desc = ctrl_find(base_names[i]);
        desc->cfg_default(CFG, &ini_thesis_spmsm);
        TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_get(desc, CFG, first[i], &v));
        TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_set(desc, CFG, first[i], v));
        TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_init(desc, STATE, CFG, &SU));
    }
    /* Table 5.1 defaults for the thesis SPMSM */
    desc = ctrl_find("drr_d1");
    desc->cfg_default(CFG, &ini_thesis_spmsm);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_get(desc, CFG, "C_T", &v));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 1.2, v);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_get(desc, CFG, "C_psi", &v));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.09427, v);
    desc = ctrl_find("drr_d2");
    desc->cfg_default(CFG, &ini_thesis_spmsm);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_get(desc, CFG, "K_a", &v));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 2.0, v);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_get(desc, CFG, "K_b", &v));
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 6e-4, v);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_ab_thesis_spmsm);
    RUN_TEST(test_ema_cutoff);
    RUN_TEST(test_select_table_5_1);
    RUN_TEST(test_duty_limits_monotonic);
    RUN_TEST(test_vreplace_condition);
    RUN_TEST(test_plan_zero_vector);
    RUN_TEST(test_t_start_centre);
    RUN_TEST(test_pred_516);
    RUN_TEST(test_baselines_thesis_values);
    RUN_TEST(test_descriptors);
    RUN_TEST(test_tunables_by_name);
    return UNITY_END();
}
