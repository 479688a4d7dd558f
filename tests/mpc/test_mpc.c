/*
 * Unit tests of the chapter-6 predictive controllers (control/ctrl_m2ptfc*,
 * ctrl_m1*, ctrl_mptfc*, ctrl_m3*, ctrl_m2*). Needs only pmsm_control: also
 * runs on the Cortex-M4 in QEMU.
 *
 * The brute-force checks evaluate every candidate with the test fixture's
 * rotor-frame prediction fixture_predict_dq() (tests/core/est_fixture.h),
 * independently of the controllers' fast k+2 model, and assert the
 * controllers' choice against it.
 *
 * Tolerances (Q24 LSB = 2^-24 pu): both start from the same k+1 state in the
 * rotor frame and turn it by the same fx_rot_q30 rotation; the fixture turns
 * the voltage with the table at theta(k+1), the model with the table values
 * turned to theta(k+2) (a difference of 1.3e-7 of |Ts V| < 0.15 pu: < 1
 * LSB). The k+2 flux then differs by at most that and the roundings of
 * Ts V (3), of the rotation (2 per axis) and of the sums (2): < 16 LSB. The
 * torque multiplies that by |a + b psi_d| + |b psi_q| (< 3 pu for these
 * machines and currents) plus its own 4 roundings: < 64 LSB.
 * TOL_PSI = 16 LSB, TOL_T = 64 LSB.
 */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "../core/est_fixture.h"
#include "controller.h"
#include "ctrl_m1.h"
#include "ctrl_m2.h"
#include "ctrl_m2ptfc.h"
#include "ctrl_m2ptfc_config.h"
#include "ctrl_m3.h"
#include "ctrl_mptfc.h"
#include "mpc_machines.h"
#include "mtpa.h"
#include "plan.h"
#include "unity.h"
#include "vectors.h"

#define LSB (1.0 / 16777216.0)
#define TOL_PSI (16.0 * LSB)
#define TOL_T (64.0 * LSB)
#define N_RANDOM 400

void setUp(void)
{
}

void tearDown(void)
{
}

static uint64_t rng = 0x9E3779B97F4A7C15u;

static uint32_t rng_u32(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (uint32_t)(rng >> 32);
}

static double rng_uniform(double lo, double hi)
{
    return lo + (hi - lo) * ((double)rng_u32() / 4294967296.0);
}

static double d24(q24_t x)
{
    return (double)x / 16777216.0;
}

static q24_t q24(double x)
{
    return ctrl_q24_from_double(x);
}

/* The machine and bases of the last params_for (for init's setup). */
static const ctrl_machine_t *g_machine;
static ctrl_bases_t g_bases;

static void params_for(const ctrl_machine_t *m, uint32_t fs, ctrl_params_t *p)
{
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(p, &g_bases, m, fs));
    g_machine = m;
}

/* ctrl_init with the setup of the last params_for and these params. */
static int init_for(const ctrl_desc_t *d, void *state, const void *cfg, const ctrl_params_t *p)
{
    const ctrl_setup_t su = {g_machine, &g_bases, p};
    return ctrl_init(d, state, cfg, &su);
}

/* A random operating point: rotor angle anywhere (all sectors), current up to
 * 1.2 x rated in any direction (motoring and braking), speed +-1.1 x rated
 * (both directions), DC link +-10 %, torque reference around the estimate. */
static void random_point(const ctrl_params_t *p, ctrl_estimate_t *est, ctrl_refs_t *ref,
                         ctrl_plan_t *applied)
{
    const double imax = 1.2 * d24(p->current_rated);
    const double id = rng_uniform(-0.6 * imax, 0.3 * imax);
    const double iq = rng_uniform(-imax, imax);
    const fx_angle_t theta = rng_u32();
    memset(est, 0, sizeof *est);
    fixture_state_dq(p, q24(id), q24(iq), theta, &est->next); /* as the estimator hands it */
    est->now = est->next;
    est->omega_e = q24(rng_uniform(-1.1, 1.1) * d24(p->speed_rated_e));
    est->vdc = q24(d24(p->vdc_nom) * rng_uniform(0.9, 1.1));
    fixture_rotation(p, est);
    const double tr = d24(p->torque_rated);
    ref->torque = q24(d24(est->next.torque) + rng_uniform(-0.3, 0.3) * tr);
    ref->psi = (rng_u32() & 1u) ? 0 : q24(d24(est->next.psi_amp) * rng_uniform(0.95, 1.05));
    ctrl_plan_active_zero(applied, (uint8_t)(1u + rng_u32() % 6u), q24(rng_uniform(0.0, 1.0)));
}

/* k+2 state with vec on for duty (zero vector the rest), by fixture_predict(). */
static void predict2(const ctrl_params_t *p, const ctrl_estimate_t *est, uint8_t vec, q24_t duty,
                     ctrl_mstate_t *out)
{
    q24_t va;
    q24_t vb;
    ctrl_vector_ab(vec, est->vdc, &va, &vb);
    fixture_predict_dq(p, &est->next, fx_mul(duty, va), fx_mul(duty, vb), est->omega_e, out);
}

static double psi_ref_of(const ctrl_params_t *p, const ctrl_refs_t *ref)
{
    return d24(ctrl_flux_ref(p, ref->psi, ref->torque));
}

/* ---------------------------------------------------------------- (6.7) */

static void test_candidates_table(void)
{
    /* (6.7) transcribed: sector x -> {V_{x+1}, V_{x+2}} when T_ref + sigma_T >= Te,
     * {V_{x+4}, V_{x+5}} otherwise (indices wrapped in 1..6). */
    static const uint8_t up[7][2] = {{0, 0}, {2, 3}, {3, 4}, {4, 5}, {5, 6}, {6, 1}, {1, 2}};
    static const uint8_t down[7][2] = {{0, 0}, {5, 6}, {6, 1}, {1, 2}, {2, 3}, {3, 4}, {4, 5}};
    for (uint8_t x = 1u; x <= 6u; x++) {
        uint8_t c[2];
        ctrl_m2ptfc_candidates(x, FX_ONE / 10, FX_ONE / 20, c); /* upper > Te */
        TEST_ASSERT_EQUAL_UINT8_ARRAY(up[x], c, 2);
        ctrl_m2ptfc_candidates(x, FX_ONE / 20, FX_ONE / 20, c); /* equal: ">=" */
        TEST_ASSERT_EQUAL_UINT8_ARRAY(up[x], c, 2);
        ctrl_m2ptfc_candidates(x, -FX_ONE / 10, -FX_ONE / 20, c); /* negative torques */
        TEST_ASSERT_EQUAL_UINT8_ARRAY(down[x], c, 2);
        ctrl_m2ptfc_candidates(x, FX_ONE / 20, FX_ONE / 20 + 1, c); /* just below */
        TEST_ASSERT_EQUAL_UINT8_ARRAY(down[x], c, 2);
        ctrl_m2ptfc_candidates(x, -FX_ONE / 20, -FX_ONE / 10, c); /* braking, upper > Te */
        TEST_ASSERT_EQUAL_UINT8_ARRAY(up[x], c, 2);
    }
}

static void test_m3_set_and_m2_table(void)
{
    /* M3 (6.1): Set I {V_{x+1}, V_{x+2}} / Set II {V_{x+5}, V_{x+4}}; M2 Table 4.1
     * with two-level torque: (T up, psi up) V_{x+1}, (up, down) V_{x+2},
     * (down, up) V_{x+5}, (down, down) V_{x+4}. Sector 1 and 4 written out. */
    TEST_ASSERT_EQUAL_UINT8(2, ctrl_m2_table(1, 1, 1));
    TEST_ASSERT_EQUAL_UINT8(3, ctrl_m2_table(1, 1, 0));
    TEST_ASSERT_EQUAL_UINT8(6, ctrl_m2_table(1, 0, 1));
    TEST_ASSERT_EQUAL_UINT8(5, ctrl_m2_table(1, 0, 0));
    TEST_ASSERT_EQUAL_UINT8(5, ctrl_m2_table(4, 1, 1));
    TEST_ASSERT_EQUAL_UINT8(6, ctrl_m2_table(4, 1, 0));
    TEST_ASSERT_EQUAL_UINT8(3, ctrl_m2_table(4, 0, 1));
    TEST_ASSERT_EQUAL_UINT8(2, ctrl_m2_table(4, 0, 0));
    TEST_ASSERT_EQUAL_UINT8(1, ctrl_m2_table(6, 1, 1));
    TEST_ASSERT_EQUAL_UINT8(4, ctrl_m2_table(6, 0, 0));
}

/* ---------------------------------------------------------- (6.5)-(6.6) */

static void test_duty_clamp_edges(void)
{
    const q24_t den = FX_ONE / 7;
    TEST_ASSERT_EQUAL_INT32(FX_ONE, ctrl_m2ptfc_duty(den, den));     /* D = 1 kept */
    TEST_ASSERT_EQUAL_INT32(FX_ONE, ctrl_m2ptfc_duty(den + 1, den)); /* D > 1 -> 1 */
    TEST_ASSERT_EQUAL_INT32(0, ctrl_m2ptfc_duty(0, den));            /* D = 0 kept */
    TEST_ASSERT_EQUAL_INT32(FX_ONE, ctrl_m2ptfc_duty(-1, den));      /* D < 0 -> 1 (6.6) */
    TEST_ASSERT_EQUAL_INT32(FX_ONE, ctrl_m2ptfc_duty(1, -den));      /* D < 0 -> 1 */
    TEST_ASSERT_EQUAL_INT32(FX_ONE, ctrl_m2ptfc_duty(den, 0));       /* no finite D -> 1 */
    TEST_ASSERT_EQUAL_INT32(FX_ONE, ctrl_m2ptfc_duty(-den, 0));
    TEST_ASSERT_EQUAL_INT32(0, ctrl_m2ptfc_duty(0, 0));            /* documented choice */
    TEST_ASSERT_EQUAL_INT32(FX_ONE, ctrl_m2ptfc_duty(-den, -den)); /* both negative */
    TEST_ASSERT_EQUAL_INT32(FX_ONE, ctrl_m2ptfc_duty(-den - 1, -den));
    /* Just inside the edges: exact rounded quotient. */
    const q24_t below = ctrl_m2ptfc_duty(den - 1, den);
    TEST_ASSERT_TRUE(below < FX_ONE);
    TEST_ASSERT_INT32_WITHIN(1, FX_ONE - FX_ONE / den, below);
    TEST_ASSERT_INT32_WITHIN(1, FX_ONE / den, ctrl_m2ptfc_duty(1, den));
    TEST_ASSERT_INT32_WITHIN(1, FX_ONE / 2, ctrl_m2ptfc_duty(-FX_ONE / 16, -FX_ONE / 8));
    TEST_ASSERT_EQUAL_INT32(FX_ONE, ctrl_m2ptfc_duty(FX_MAX, FX_MIN + 1)); /* |D|=1, D<0 */
    /* D_f of M1/M3 saturates instead: */
    TEST_ASSERT_EQUAL_INT32(0, ctrl_mpc_duty_sat(-1, den));
    TEST_ASSERT_EQUAL_INT32(FX_ONE, ctrl_mpc_duty_sat(den + 1, den));
    TEST_ASSERT_EQUAL_INT32(FX_ONE, ctrl_mpc_duty_sat(1, 0));
    TEST_ASSERT_EQUAL_INT32(0, ctrl_mpc_duty_sat(-1, 0));
}

static void test_ratio_exact(void)
{
    /* ctrl_mpc_ratio == round(n 2^24 / d) for d < 2^24 (exact long division). */
    for (int i = 0; i < 2000; i++) {
        const uint32_t d = 1u + rng_u32() % ((1u << 24) - 1u);
        const uint32_t n = (uint32_t)(((uint64_t)rng_u32() * d) >> 32);
        const uint64_t want = (((uint64_t)n << 25) / d + 1u) >> 1;
        TEST_ASSERT_EQUAL_INT32((int32_t)want, ctrl_mpc_ratio(n, d));
    }
    /* d >= 2^24: prescaled, relative error < 2^-23. */
    const uint32_t d = 0x7FFFFFFFu;
    TEST_ASSERT_INT32_WITHIN(4, FX_ONE / 3, ctrl_mpc_ratio(d / 3u, d));
}

static void test_closer_matches_sqrt(void)
{
    /* ctrl_mpc_closer on squares agrees with |r - a| vs |r - b| on amplitudes. */
    for (int i = 0; i < 4000; i++) {
        const double r = rng_uniform(0.5, 1.5);
        const double a = r + rng_uniform(-0.2, 0.2);
        const double b = r + rng_uniform(-0.2, 0.2);
        const int32_t a2 = ctrl_mpc_amp2(q24(a), 0);
        const int32_t b2 = ctrl_mpc_amp2(q24(b), 0);
        const int32_t r2 = ctrl_mpc_amp2(q24(r), 0);
        const double diff = fabs(r - a) - fabs(r - b);
        if (fabs(diff) < 4.0 * LSB) {
            continue; /* below the resolution of the squares */
        }
        TEST_ASSERT_EQUAL_INT(diff < 0.0 ? -1 : 1, ctrl_mpc_closer(a2, b2, r2));
    }
    TEST_ASSERT_EQUAL_INT(0, ctrl_mpc_closer(FX_ONE, FX_ONE, FX_ONE));
}

/* sign((a - b)(a + b - 2r)) on squares in 64-bit arithmetic: the oracle of
 * ctrl_mpc_closer's 32-bit form (r2 taken at most 2^28, 16 pu^2). */
static int closer_oracle(int32_t a2, int32_t b2, int32_t r2)
{
    const int64_t r = r2 < ((int32_t)1 << 28) ? r2 : ((int32_t)1 << 28);
    const int sab = (a2 > b2) - (a2 < b2);
    const int64_t sum = 4 * r - (int64_t)a2 - (int64_t)b2;
    if (sab == 0 || sum < 0) {
        return sab;
    }
    const int64_t lhs = 4 * (int64_t)a2 * (int64_t)b2;
    const int64_t rhs = sum * sum;
    return sab * ((lhs > rhs) - (lhs < rhs));
}

static void test_closer_full_range(void)
{
    /* Every input range ctrl_mpc_amp2 can give, including its ceiling, and
     * near-ties (the products equal or one apart). */
    const int32_t top = CTRL_MPC_AMP2_MAX;
    for (int i = 0; i < 20000; i++) {
        int32_t a2 = (int32_t)(rng_u32() % ((uint32_t)top + 1u));
        int32_t b2 = (int32_t)(rng_u32() % ((uint32_t)top + 1u));
        const int32_t r2 = (int32_t)(rng_u32() % ((uint32_t)top + 1u));
        if (i % 4 == 1) { /* the scale of real fluxes: near r */
            a2 = r2 / 2 + (int32_t)(rng_u32() % 64u);
            b2 = r2 + r2 / 2 - a2 + (int32_t)(rng_u32() % 3u) - 1; /* a + b ~ 2r */
            b2 = b2 < 0 ? 0 : (b2 > top ? top : b2);
        }
        TEST_ASSERT_EQUAL_INT(closer_oracle(a2, b2, r2), ctrl_mpc_closer(a2, b2, r2));
    }
    /* a + b = 2r exactly: A = 1, B = 9, R = 4 (1 + 3 = 2 * 2). */
    TEST_ASSERT_EQUAL_INT(0, ctrl_mpc_closer(1, 9, 4));
    TEST_ASSERT_EQUAL_INT(closer_oracle(top, top - 1, top), ctrl_mpc_closer(top, top - 1, top));
    TEST_ASSERT_EQUAL_INT(closer_oracle(top, 0, 0), ctrl_mpc_closer(top, 0, 0));
}

/* ------------------------------------------------------- brute force */

/* centre: the tunable (1: Te_c = Te(k+1) + dT0/2 in (6.5), (6.7), (6.8), the
 * zero-vector change dT0 from fixture_predict(); 0: Te(k+1), the thesis literally). */
static void check_m2ptfc(const ctrl_machine_t *m, uint32_t fs, double centre)
{
    ctrl_params_t p;
    params_for(m, fs, &p);
    const ctrl_desc_t *d = &ctrl_desc_m2ptfc;
    uint8_t cfg[CTRL_CFG_MAX];
    ctrl_m2ptfc_t s;
    TEST_ASSERT_TRUE(d->cfg_size <= sizeof cfg);
    TEST_ASSERT_TRUE(d->state_size == sizeof s);
    d->cfg_default(cfg, m);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_set(d, cfg, "centre", centre));
    TEST_ASSERT_EQUAL_INT(CTRL_OK, init_for(d, &s, cfg, &p));
    int checked_duty = 0;
    int checked_set = 0;
    for (int i = 0; i < N_RANDOM; i++) {
        ctrl_estimate_t est;
        ctrl_refs_t ref;
        ctrl_plan_t applied;
        ctrl_out_t out_o;
        random_point(&p, &est, &ref, &applied);
        const double sigma_old = rng_uniform(-0.03, 0.03) * d24(p.torque_rated);
        s.sigma = q24(sigma_old);
        const ctrl_ctx_t ctx = {&p, &est, &ref};
        d->step(&s, &ctx, &out_o);
        const ctrl_plan_t out = out_o.plan;
        TEST_ASSERT_EQUAL_UINT8(2, s.trace.n);
        /* Te of (6.5)-(6.8): Te(k+1), with centre + half the zero-vector change. */
        ctrl_mstate_t zero;
        predict2(&p, &est, 1u, 0, &zero);
        const double t1 = d24(est.next.torque);
        const double te = centre != 0.0 ? t1 + 0.5 * (d24(zero.torque) - t1) : t1;
        /* (6.8), holding while the error exceeds one period's largest change:
         * A (5.9) plus the zero vector's */
        const double a_step =
            m->pole_pairs * m->vdc_v * m->psi_pm_wb / ((double)fs * m->ld_h) / g_bases.torque_nm +
            fabs(d24(zero.torque) - t1);
        const double chi = d24(ref.torque) - te;
        if (fabs(fabs(chi) - a_step) <= 4.0 * TOL_T) {
            continue; /* hold or not decided within the budget */
        }
        const double sigma = fabs(chi) > a_step ? sigma_old : sigma_old + 0.03 * (chi - sigma_old);
        TEST_ASSERT_DOUBLE_WITHIN(TOL_T, sigma, d24(s.sigma));
        /* Candidates (6.7), unless T_ref + sigma_T and Te are within the budget. */
        const double num = d24(ref.torque) + sigma - te;
        uint8_t c[2];
        ctrl_m2ptfc_candidates(est.next.sector, num >= 0.0 ? 0 : -1, 0, c);
        if (fabs(num) <= 2.0 * TOL_T) {
            continue;
        }
        TEST_ASSERT_EQUAL_UINT8_ARRAY(c, s.trace.vec, 2);
        checked_set++;
        const double psi_ref = psi_ref_of(&p, &ref);
        double cost[2];
        for (unsigned k = 0; k < 2u; k++) {
            ctrl_mstate_t full;
            ctrl_mstate_t dut;
            predict2(&p, &est, c[k], FX_ONE, &full);
            /* (6.5)-(6.6) from ctrl_predict's dTe. */
            const double den = d24(full.torque) - t1 + 2.0 * sigma;
            if (fabs(den) > 4.0 * TOL_T) {
                double dref = num / den;
                const double tol = 2.0 * TOL_T * (1.0 + fabs(dref)) / fabs(den) + 2.0 * LSB;
                if (dref < -tol || dref > 1.0 + tol) {
                    dref = 1.0; /* (6.6) */
                }
                if (dref >= tol || dref < -tol) { /* not at the D = 0 edge */
                    TEST_ASSERT_DOUBLE_WITHIN(tol, dref, d24(s.trace.duty[k]));
                    checked_duty++;
                }
            }
            predict2(&p, &est, c[k], s.trace.duty[k], &dut);
            cost[k] = fabs(psi_ref - d24(dut.psi_amp)); /* (6.9) */
        }
        TEST_ASSERT_EQUAL_UINT8(2, out.n_seg);
        const unsigned chosen = out.vec[0] == c[0] ? 0u : 1u;
        TEST_ASSERT_EQUAL_UINT8(c[chosen], out.vec[0]);
        TEST_ASSERT_EQUAL_INT32(s.trace.duty[chosen], out.dur[0]);
        TEST_ASSERT_EQUAL_UINT8(ctrl_zero_after(out.vec[0]), out.vec[1]);
        TEST_ASSERT_TRUE_MESSAGE(cost[chosen] <= cost[1u - chosen] + 2.0 * TOL_PSI,
                                 "m2ptfc: chosen candidate does not minimise (6.9)");
    }
    TEST_ASSERT_TRUE(checked_duty > N_RANDOM); /* most duties were checked */
    TEST_ASSERT_TRUE(checked_set > N_RANDOM * 9 / 10);
}

static void test_m2ptfc_minimises_cost_spmsm(void)
{
    check_m2ptfc(&ini_thesis_spmsm, 10000u, 1.0);
    check_m2ptfc(&ini_thesis_spmsm, 10000u, 0.0);
}

static void test_m2ptfc_minimises_cost_ipmsm(void)
{
    check_m2ptfc(&ini_thesis_ipmsm80, 20000u, 1.0);
    check_m2ptfc(&ini_chapter_ipmsm, 10000u, 1.0);
    check_m2ptfc(&ini_thesis_ipmsm80, 20000u, 0.0);
}

/* g of (6.13) for the k+2 state st. */
static double cost613(const ctrl_params_t *p, const ctrl_refs_t *ref, q24_t zeta,
                      const ctrl_mstate_t *st)
{
    return fabs(d24(ref->torque) - d24(st->torque)) +
           d24(zeta) * fabs(psi_ref_of(p, ref) - d24(st->psi_amp));
}

/* The applied vector and duty of a plan (duty 0 for a zero vector all period). */
static void plan_choice(const ctrl_plan_t *out, uint8_t *vec, q24_t *duty)
{
    if (out->n_seg == 1u && (out->vec[0] == 0u || out->vec[0] == 7u)) {
        *vec = 0u;
        *duty = 0;
    } else {
        *vec = out->vec[0];
        *duty = out->dur[0];
    }
}

/* Brute-force (6.13) check over the candidates of the trace, and (5.18) for
 * the duties when check_df. */
static void check_weighted(const ctrl_machine_t *m, uint32_t fs, const ctrl_desc_t *d, void *state,
                           const ctrl_mpc_trace_t *tr, const q24_t *zeta, int check_df)
{
    ctrl_params_t p;
    params_for(m, fs, &p);
    uint8_t cfg[CTRL_CFG_MAX];
    d->cfg_default(cfg, m);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, init_for(d, state, cfg, &p));
    for (int i = 0; i < N_RANDOM; i++) {
        ctrl_estimate_t est;
        ctrl_refs_t ref;
        ctrl_plan_t applied;
        ctrl_out_t out_o;
        random_point(&p, &est, &ref, &applied);
        const ctrl_ctx_t ctx = {&p, &est, &ref};
        d->step(state, &ctx, &out_o);
        const ctrl_plan_t out = out_o.plan;
        const q24_t z = *zeta; /* as initialised from the SI tunable */
        ctrl_mstate_t zero;
        predict2(&p, &est, 0u, 0, &zero);
        uint8_t cv;
        q24_t cd;
        plan_choice(&out, &cv, &cd);
        double best = 1e30;
        double chosen = -1.0;
        for (unsigned k = 0; k < tr->n; k++) {
            ctrl_mstate_t st;
            predict2(&p, &est, tr->vec[k], tr->duty[k], &st);
            const double g = cost613(&p, &ref, z, &st);
            best = g < best ? g : best;
            if (tr->vec[k] == cv && (cv == 0u || tr->duty[k] == cd)) {
                chosen = g;
            }
            if (check_df && tr->vec[k] != 0u) {
                ctrl_mstate_t full;
                predict2(&p, &est, tr->vec[k], FX_ONE, &full);
                const double num = d24(ref.torque) - d24(zero.torque);
                const double den = d24(full.torque) - d24(zero.torque);
                if (fabs(den) > 8.0 * TOL_T) {
                    double df = num / den; /* (5.18) */
                    df = df < 0.0 ? 0.0 : (df > 1.0 ? 1.0 : df);
                    const double tol = TOL_T * (1.0 + 2.0 * df) / fabs(den) + 2.0 * LSB;
                    TEST_ASSERT_DOUBLE_WITHIN(tol, df, d24(tr->duty[k]));
                }
            }
        }
        TEST_ASSERT_TRUE_MESSAGE(chosen >= 0.0, "applied vector is not a candidate");
        TEST_ASSERT_TRUE_MESSAGE(chosen <= best + 2.0 * (TOL_T + d24(z) * TOL_PSI),
                                 "chosen candidate does not minimise (6.13)");
    }
}

static void test_m1_argmin(void)
{
    ctrl_m1_t s;
    TEST_ASSERT_TRUE(ctrl_desc_m1.state_size == sizeof s);
    check_weighted(&ini_thesis_spmsm, 10000u, &ctrl_desc_m1, &s, &s.trace, &s.zeta, 1);
    TEST_ASSERT_EQUAL_UINT8(6, s.trace.n);
    check_weighted(&ini_thesis_ipmsm80, 20000u, &ctrl_desc_m1, &s, &s.trace, &s.zeta, 1);
}

static void test_mptfc_argmin(void)
{
    ctrl_mptfc_t s;
    TEST_ASSERT_TRUE(ctrl_desc_mptfc.state_size == sizeof s);
    check_weighted(&ini_thesis_spmsm, 10000u, &ctrl_desc_mptfc, &s, &s.trace, &s.zeta, 0);
    TEST_ASSERT_EQUAL_UINT8(7, s.trace.n);
    check_weighted(&ini_thesis_ipmsm80, 20000u, &ctrl_desc_mptfc, &s, &s.trace, &s.zeta, 0);
}

static void test_m3_argmin(void)
{
    ctrl_m3_t s;
    TEST_ASSERT_TRUE(ctrl_desc_m3.state_size == sizeof s);
    check_weighted(&ini_thesis_spmsm, 12000u, &ctrl_desc_m3, &s, &s.trace, &s.zeta, 1);
    TEST_ASSERT_EQUAL_UINT8(3, s.trace.n);
}

static void test_m2_band_and_argmin(void)
{
    ctrl_params_t p;
    params_for(&ini_thesis_spmsm, 10000u, &p);
    uint8_t cfg[CTRL_CFG_MAX];
    ctrl_m2_t s;
    ctrl_desc_m2.cfg_default(cfg, &ini_thesis_spmsm);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, init_for(&ctrl_desc_m2, &s, cfg, &p));
    TEST_ASSERT_EQUAL_UINT8(4, s.y);
    const double eps = d24(s.eps_psi);
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 6.60e-3 / ini_thesis_spmsm.psi_pm_wb, eps);
    for (int i = 0; i < N_RANDOM; i++) {
        ctrl_estimate_t est;
        ctrl_refs_t ref;
        ctrl_plan_t applied;
        ctrl_out_t out_o;
        random_point(&p, &est, &ref, &applied);
        const ctrl_ctx_t ctx = {&p, &est, &ref};
        ctrl_desc_m2.step(&s, &ctx, &out_o);
        const ctrl_plan_t out = out_o.plan;
        TEST_ASSERT_EQUAL_UINT8(5, s.trace.n);
        uint8_t cv;
        q24_t cd;
        plan_choice(&out, &cv, &cd);
        const double psi_ref = psi_ref_of(&p, &ref);
        double best_t = 1e30;
        int any = 0;
        double chosen_t = -1.0;
        int chosen_feasible = 0;
        int any_maybe = 0;
        double best_ef = 1e30;
        double chosen_ef = -1.0;
        for (unsigned nu = 0; nu <= 4u; nu++) {
            TEST_ASSERT_INT32_WITHIN(1, (q24_t)(FX_ONE / 4 * (int32_t)nu), s.trace.duty[nu]);
            ctrl_mstate_t st;
            predict2(&p, &est, s.trace.vec[nu], s.trace.duty[nu], &st);
            const double ef = fabs(psi_ref - d24(st.psi_amp));
            const double et = fabs(d24(ref.torque) - d24(st.torque));
            const int feasible = ef <= eps - 2.0 * TOL_PSI;
            const int maybe = ef <= eps + 2.0 * TOL_PSI;
            if (feasible) {
                any = 1;
                best_t = et < best_t ? et : best_t;
            }
            any_maybe |= maybe;
            best_ef = ef < best_ef ? ef : best_ef;
            const int is_chosen =
                (nu == 0u) ? (cv == 0u) : (cv == s.trace.vec[nu] && cd == s.trace.duty[nu]);
            if (is_chosen) {
                chosen_t = et;
                chosen_feasible = maybe;
                chosen_ef = ef;
            }
        }
        TEST_ASSERT_TRUE(chosen_t >= 0.0);
        if (!any_maybe) { /* none in the band: the smallest flux error */
            TEST_ASSERT_TRUE(chosen_ef <= best_ef + 2.0 * TOL_PSI);
        }
        if (any) { /* (6.16)-(6.17): a feasible minimum exists and was taken */
            TEST_ASSERT_TRUE(chosen_feasible);
            TEST_ASSERT_TRUE(chosen_t <= best_t + 2.0 * TOL_T);
        }
    }
}

/* -------------------------------------------------- registry, config */

static void test_registry_and_tunables(void)
{
    static const char *const names[] = {"m2ptfc", "m1", "mptfc", "m3", "m2"};
    static const uint32_t fs[] = {10000u, 10000u, 10000u, 12000u, 10000u};
    for (unsigned i = 0; i < 5u; i++) {
        const ctrl_desc_t *d = ctrl_find(names[i]);
        TEST_ASSERT_NOT_NULL(d);
        TEST_ASSERT_EQUAL_UINT32(fs[i], d->fs_default_hz);
        TEST_ASSERT_TRUE(d->state_size <= CTRL_STATE_MAX);
        TEST_ASSERT_TRUE(d->cfg_size <= CTRL_CFG_MAX);
        uint8_t cfg[CTRL_CFG_MAX];
        d->cfg_default(cfg, &ini_thesis_spmsm);
        double v;
        TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_get(d, cfg, "ld_model", &v));
        TEST_ASSERT_EQUAL_INT(0, (int)(v * 1e6)); /* 0 = machine */
        TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_tunable_set(d, cfg, "ld_model", -1.0));
        TEST_ASSERT_EQUAL_INT(CTRL_ENOENT, ctrl_tunable_set(d, cfg, "no_such", 1.0));
    }
    uint8_t cfg[CTRL_CFG_MAX];
    double v;
    ctrl_desc_m2ptfc.cfg_default(cfg, &ini_thesis_spmsm);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_get(&ctrl_desc_m2ptfc, cfg, "lambda", &v));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.03, v);
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_tunable_set(&ctrl_desc_m2ptfc, cfg, "lambda", 1.5));
    ctrl_desc_m1.cfg_default(cfg, &ini_thesis_spmsm);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_get(&ctrl_desc_m1, cfg, "zeta", &v));
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 0.0, v); /* equal importance, see ctrl_m1.h */
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_set(&ctrl_desc_m1, cfg, "zeta", 640.0));
    ctrl_desc_m3.cfg_default(cfg, &ini_thesis_spmsm);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_get(&ctrl_desc_m3, cfg, "zeta", &v));
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 0.0, v);
    ctrl_desc_m2.cfg_default(cfg, &ini_thesis_spmsm);
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_tunable_set(&ctrl_desc_m2, cfg, "y", 0.0));
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_set(&ctrl_desc_m2, cfg, "eps_psi", 9.42e-3));
}

static void test_zeta_in_pu(void)
{
    /* zeta [N*m/Wb] -> pu: zeta psi_base / T_base, T_base = 1.5 p psi_pm^2 / Ld. */
    ctrl_params_t p;
    params_for(&ini_thesis_spmsm, 10000u, &p);
    uint8_t cfg[CTRL_CFG_MAX];
    ctrl_m1_t s;
    ctrl_desc_m1.cfg_default(cfg, &ini_thesis_spmsm);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_set(&ctrl_desc_m1, cfg, "zeta", 250.0));
    TEST_ASSERT_EQUAL_INT(CTRL_OK, init_for(&ctrl_desc_m1, &s, cfg, &p));
    const double t_base = 1.5 * 4.0 * 0.09427 * 0.09427 / 6.552e-3;
    TEST_ASSERT_DOUBLE_WITHIN(1e-5, 250.0 * 0.09427 / t_base, d24(s.zeta));
    /* zeta = 0: T_rated / psi_pm (6.5): 2133 N*m/Wb for the 80 kW IPMSM. */
    params_for(&ini_thesis_ipmsm80, 20000u, &p);
    ctrl_desc_m1.cfg_default(cfg, &ini_thesis_ipmsm80);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_set(&ctrl_desc_m1, cfg, "zeta", 0.0));
    TEST_ASSERT_EQUAL_INT(CTRL_OK, init_for(&ctrl_desc_m1, &s, cfg, &p));
    const double t_base80 = 1.5 * 4.0 * 0.1875 * 0.1875 / 0.6e-3;
    TEST_ASSERT_DOUBLE_WITHIN(1e-5, 400.0 / 0.1875 * 0.1875 / t_base80, d24(s.zeta));
}

static void test_bad_input(void)
{
    ctrl_params_t p;
    params_for(&ini_thesis_spmsm, 10000u, &p);
    ctrl_m2ptfc_cfg_t c;
    ctrl_m2ptfc_t s;
    ctrl_desc_m2ptfc.cfg_default(&c, &ini_thesis_spmsm);
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, init_for(&ctrl_desc_m2ptfc, NULL, &c, &p));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, init_for(&ctrl_desc_m2ptfc, &s, NULL, &p));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, init_for(&ctrl_desc_m2ptfc, &s, &c, NULL));
    c.lambda = 0.0;
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, init_for(&ctrl_desc_m2ptfc, &s, &c, &p));
    c.lambda = NAN;
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, init_for(&ctrl_desc_m2ptfc, &s, &c, &p));
    c.lambda = 0.03;
    c.centre = 0.5; /* 0 or 1 only */
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, init_for(&ctrl_desc_m2ptfc, &s, &c, &p));
    c.centre = 1.0;
    c.model.ld_h = -1.0;
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, init_for(&ctrl_desc_m2ptfc, &s, &c, &p));
    c.model.ld_h = 0.0;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, init_for(&ctrl_desc_m2ptfc, &s, &c, &p));
}

/* The k+2 model's Rs override on a lossless machine (Rs = 0, which the core
 * accepts): nothing to scale the override from, so it is taken in pu of the
 * resistance base, Ts Rs_model exactly as (6.10) wants it (the link refused
 * it with no reason: found by the link's fuzzer); an override outside its
 * range is refused naming the tunable, its value and the range. */
static void test_model_rs_on_lossless_machine(void)
{
    ctrl_machine_t m = ini_thesis_spmsm;
    m.rs_ohm = 0.0;
    ctrl_params_t p;
    params_for(&m, 10000u, &p);
    ctrl_m2ptfc_cfg_t c;
    ctrl_m2ptfc_t s;
    ctrl_desc_m2ptfc.cfg_default(&c, &m);
    c.model.rs_ohm = 0.5;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, init_for(&ctrl_desc_m2ptfc, &s, &c, &p));
    const double ts_rs = g_bases.w_rad_s / 10000.0 * 0.5 / g_bases.r_ohm;
    TEST_ASSERT_DOUBLE_WITHIN(1.0 / 16777216.0, ts_rs, d24(s.model.ts_rs));
    c.model.rs_ohm = 0.0; /* the machine's: no resistive term */
    TEST_ASSERT_EQUAL_INT(CTRL_OK, init_for(&ctrl_desc_m2ptfc, &s, &c, &p));
    TEST_ASSERT_EQUAL_INT32(0, s.model.ts_rs);

    ctrl_diag_t why;
    memset(&why, 0, sizeof why);
    const ctrl_setup_t su = {g_machine, &g_bases, &p, &why};
    c.model.rs_ohm = CTRL_MPC_RS_MODEL_MAX * 2.0;
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_init(&ctrl_desc_m2ptfc, &s, &c, &su));
    TEST_ASSERT_EQUAL_STRING("rs_model", why.quantity);
    TEST_ASSERT_EQUAL_DOUBLE(CTRL_MPC_RS_MODEL_MAX * 2.0, why.value);
    TEST_ASSERT_EQUAL_DOUBLE(CTRL_MPC_RS_MODEL_MAX, why.max);
}

/* Every chapter-6 descriptor: NULL state / cfg / params refused, NaN and
 * out-of-range SI values refused at init (each tunable's own [min, max], also
 * when written into the cfg directly), NULL tolerated by cfg_default and
 * reset, and a step without a valid context answers with the zero vector. */
static void test_bad_input_all(void)
{
    const ctrl_desc_t *const descs[] = {&ctrl_desc_m2ptfc, &ctrl_desc_m1, &ctrl_desc_mptfc,
                                        &ctrl_desc_m3, &ctrl_desc_m2};
    ctrl_params_t p;
    params_for(&ini_thesis_spmsm, 10000u, &p);
    static _Alignas(16) uint8_t st[CTRL_STATE_MAX];
    static _Alignas(16) uint8_t cfg[CTRL_CFG_MAX];
    for (size_t i = 0; i < sizeof descs / sizeof descs[0]; i++) {
        const ctrl_desc_t *d = descs[i];
        TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_cfg_default(d, NULL, &ini_thesis_spmsm));
        TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_cfg_default(d, cfg, NULL));
        ctrl_reset(d, NULL);
        d->cfg_default(cfg, &ini_thesis_spmsm);
        TEST_ASSERT_EQUAL_INT_MESSAGE(CTRL_OK, init_for(d, st, cfg, &p), d->name);
        TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, init_for(d, NULL, cfg, &p));
        TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, init_for(d, st, NULL, &p));
        TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, init_for(d, st, cfg, NULL));
        for (size_t k = 0; k < d->n_tunables; k++) {
            const ctrl_tunable_t *t = &d->tunables[k];
            const double bad[3] = {NAN, t->max * 2.0 + 1.0, t->min - 1.0};
            for (int b = 0; b < 3; b++) {
                d->cfg_default(cfg, &ini_thesis_spmsm);
                memcpy(cfg + t->offset, &bad[b], sizeof bad[b]);
                const int rc = init_for(d, st, cfg, &p);
                TEST_ASSERT_TRUE_MESSAGE(rc == CTRL_EINVAL || rc == CTRL_ERANGE, t->name);
            }
        }
        d->cfg_default(cfg, &ini_thesis_spmsm);
        TEST_ASSERT_EQUAL_INT(CTRL_OK, init_for(d, st, cfg, &p));
        ctrl_out_t out;
        memset(&out, 0xA5, sizeof out);
        ctrl_step(d, st, NULL, &out);
        TEST_ASSERT_EQUAL_UINT8(1, out.plan.n_seg);
        TEST_ASSERT_EQUAL_UINT8(0, out.plan.vec[0]);
        ctrl_step(d, st, NULL, NULL);
        const ctrl_ctx_t no_est = {&p, NULL, NULL};
        ctrl_step(d, st, &no_est, &out);
        TEST_ASSERT_EQUAL_UINT8(0, out.plan.vec[0]);
    }
}

/* (**) of ctrl_m2ptfc.h: Te_c = t1 + (t0 - t1)/2 (rounded half), t1 when off;
 * saturating at the Q24 range ends instead of overflowing. */
static void test_t_eval(void)
{
    ctrl_m2ptfc_t s;
    memset(&s, 0, sizeof s);
    s.centre = 1u;
    TEST_ASSERT_EQUAL_INT32(FX_ONE, ctrl_m2ptfc_t_eval(&s, FX_ONE, FX_ONE));
    TEST_ASSERT_EQUAL_INT32(FX_ONE / 2, ctrl_m2ptfc_t_eval(&s, FX_ONE, 0));
    TEST_ASSERT_EQUAL_INT32(-FX_ONE / 4, ctrl_m2ptfc_t_eval(&s, 0, -FX_ONE / 2));
    for (int i = 0; i < 2000; i++) {
        const q24_t t1 = (q24_t)(int32_t)(rng_u32() >> 4) - (q24_t)(1 << 27);
        const q24_t t0 = (q24_t)(int32_t)(rng_u32() >> 4) - (q24_t)(1 << 27);
        const double want = (double)t1 + 0.5 * ((double)t0 - (double)t1);
        TEST_ASSERT_DOUBLE_WITHIN(0.5, want, (double)ctrl_m2ptfc_t_eval(&s, t1, t0));
    }
    const q24_t hi = ctrl_m2ptfc_t_eval(&s, FX_MAX, FX_MIN);
    const q24_t lo = ctrl_m2ptfc_t_eval(&s, FX_MIN, FX_MAX);
    TEST_ASSERT_TRUE(hi >= -1 && hi <= FX_MAX); /* no wrap-around */
    TEST_ASSERT_TRUE(lo <= 1 && lo >= FX_MIN);
    s.centre = 0u;
    TEST_ASSERT_EQUAL_INT32(12345, ctrl_m2ptfc_t_eval(&s, 12345, -FX_ONE));
}

/* ctrl_mpc_psi_ref2 == ctrl_flux_ref squared within the roundings: the
 * square of a rounded square root differs by up to 2 |psi| LSB (+1 rounding). */
static void test_psi_ref2(void)
{
    const ctrl_machine_t *ms[3] = {&ini_thesis_spmsm, &ini_thesis_ipmsm80, &ini_chapter_ipmsm};
    for (int k = 0; k < 3; k++) {
        ctrl_params_t p;
        params_for(ms[k], 10000u, &p);
        for (int i = 0; i < 500; i++) {
            ctrl_refs_t ref;
            ref.torque = q24(rng_uniform(-2.0, 2.0) * d24(p.torque_rated));
            ref.psi = (i % 3 == 0) ? q24(rng_uniform(0.5, 1.5)) : 0;
            const q24_t lin = ctrl_flux_ref(&p, ref.psi, ref.torque);
            const double want = d24(lin) * d24(lin) * 16777216.0;
            const double tol = 2.0 * d24(lin) + 2.0;
            TEST_ASSERT_DOUBLE_WITHIN(tol, want, (double)ctrl_mpc_psi_ref2(&p, &ref));
        }
    }
}

/* ctrl_mpc_basis3 (m2ptfc: V1..V3 only) gives the same basis as
 * ctrl_mpc_basis bit for bit, every V_i through ctrl_mpc_vec3_dq, also for
 * states far outside any machine's range (the clamps of the basis). */
static void test_basis3_equals_basis(void)
{
    const ctrl_machine_t *ms[3] = {&ini_thesis_spmsm, &ini_thesis_ipmsm80, &ini_chapter_ipmsm};
    for (int k = 0; k < 3; k++) {
        ctrl_params_t p;
        params_for(ms[k], 10000u, &p);
        ctrl_m2ptfc_cfg_t c;
        ctrl_m2ptfc_t s;
        ctrl_desc_m2ptfc.cfg_default(&c, ms[k]);
        TEST_ASSERT_EQUAL_INT(CTRL_OK, init_for(&ctrl_desc_m2ptfc, &s, &c, &p));
        for (int i = 0; i < N_RANDOM; i++) {
            ctrl_estimate_t est;
            ctrl_refs_t ref;
            ctrl_plan_t applied;
            random_point(&p, &est, &ref, &applied);
            if (i % 8 == 7) { /* any int32_t: beyond the clamps */
                est.next.i_d = fx_u2i(rng_u32());
                est.next.i_q = fx_u2i(rng_u32());
                est.next.psi_d = fx_u2i(rng_u32());
                est.next.psi_q = fx_u2i(rng_u32());
                est.vdc = fx_u2i(rng_u32());
            }
            ctrl_mpc_basis_t b6;
            ctrl_mpc_basis3_t b3;
            ctrl_mpc_basis(&s.model, &est, &b6);
            ctrl_mpc_basis3(&s.model, &est, &b3);
            TEST_ASSERT_EQUAL_INT32(b6.d0, b3.d0);
            TEST_ASSERT_EQUAL_INT32(b6.q0, b3.q0);
            TEST_ASSERT_EQUAL_INT32(b6.t0, b3.t0);
            for (uint8_t v = 1u; v <= 6u; v++) {
                q24_t d6;
                q24_t q6;
                q24_t d3;
                q24_t q3;
                ctrl_mpc_vec_dq(&b6, v, &d6, &q6);
                ctrl_mpc_vec3_dq(&b3, v, &d3, &q3);
                TEST_ASSERT_EQUAL_INT32(d6, d3);
                TEST_ASSERT_EQUAL_INT32(q6, q3);
            }
        }
    }
}

/* The cached psi_ref^2 of m2ptfc follows every change of ref->torque,
 * ref->psi and params: each step decides exactly as a step whose cache was
 * just invalidated (same sigma), and the cache holds ctrl_mpc_psi_ref2 of the
 * inputs of the last step. */
static void test_m2ptfc_psi2_cache(void)
{
    ctrl_params_t pa;
    ctrl_params_t pb;
    params_for(&ini_thesis_spmsm, 10000u, &pa);
    params_for(&ini_thesis_spmsm, 10000u, &pb);
    pb.psi_ref = q24(1.05 * d24(pa.psi_pm)); /* fixed reference instead of MTPA */
    ctrl_m2ptfc_cfg_t c;
    ctrl_m2ptfc_t s;
    ctrl_desc_m2ptfc.cfg_default(&c, &ini_thesis_spmsm);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, init_for(&ctrl_desc_m2ptfc, &s, &c, &pa));
    TEST_ASSERT_EQUAL_UINT8(0, s.psi2.valid);
    ctrl_estimate_t est;
    ctrl_refs_t ref;
    ctrl_plan_t applied;
    random_point(&pa, &est, &ref, &applied);
    int recomputed = 0;
    for (int i = 0; i < 300; i++) {
        /* references held for a few steps, then changed (torque, psi or params) */
        const ctrl_params_t *p = (i / 50) % 2 ? &pb : &pa;
        if (i % 7 == 0) {
            ref.torque = q24(rng_uniform(-1.2, 1.2) * d24(pa.torque_rated));
        }
        if (i % 11 == 0) {
            ref.psi = (rng_u32() & 1u) ? 0 : q24(rng_uniform(0.8, 1.2) * d24(pa.psi_pm));
        }
        if (i % 13 == 5) {
            /* the PM flux tracked in place (the pipeline's psi_adapt) */
            pa.psi_pm = q24(rng_uniform(0.9, 1.1) * d24(pb.psi_pm));
            pa.mtpa_k = fx_mul(pa.lq, fx_div(FX_ONE, pa.psi_pm));
        }
        est.next.theta_e += 0x01000000u; /* the machine moves on */
        ctrl_m2ptfc_t fresh = s;
        fresh.psi2.valid = 0u;
        const ctrl_flux_memo_t held = s.psi2;
        const ctrl_ctx_t ctx = {p, &est, &ref};
        ctrl_out_t o1;
        ctrl_out_t o2;
        ctrl_desc_m2ptfc.step(&s, &ctx, &o1);
        ctrl_desc_m2ptfc.step(&fresh, &ctx, &o2);
        TEST_ASSERT_EQUAL_UINT8(o2.plan.n_seg, o1.plan.n_seg);
        TEST_ASSERT_EQUAL_UINT8_ARRAY(o2.plan.vec, o1.plan.vec, o1.plan.n_seg);
        TEST_ASSERT_EQUAL_INT32_ARRAY(o2.plan.dur, o1.plan.dur, o1.plan.n_seg);
        TEST_ASSERT_EQUAL_INT32(fresh.sigma, s.sigma);
        TEST_ASSERT_EQUAL_INT32(ctrl_mpc_psi_ref2(p, &ref), s.psi2.value);
        TEST_ASSERT_TRUE(s.psi2.p == p);
        recomputed += held.p != p || held.torque != ref.torque || held.psi_cmd != ref.psi ||
                      held.psi_pm != p->psi_pm;
    }
    TEST_ASSERT_TRUE(recomputed > 20 && recomputed < 200); /* held and changed */
    ctrl_desc_m2ptfc.reset(&s);
    TEST_ASSERT_EQUAL_UINT8(0, s.psi2.valid);
}

static void test_sigma_ema(void)
{
    /* (6.8): a constant error e drives sigma to e with rate lambda:
     * sigma_n = e (1 - (1 - lambda)^n). */
    ctrl_params_t p;
    params_for(&ini_thesis_spmsm, 10000u, &p);
    ctrl_m2ptfc_cfg_t c;
    ctrl_m2ptfc_t s;
    ctrl_desc_m2ptfc.cfg_default(&c, &ini_thesis_spmsm);
    c.centre = 0.0; /* Te = Te(k+1): the error below is exactly T_ref - Te */
    TEST_ASSERT_EQUAL_INT(CTRL_OK, init_for(&ctrl_desc_m2ptfc, &s, &c, &p));
    ctrl_estimate_t est;
    ctrl_refs_t ref;
    ctrl_plan_t applied;
    ctrl_out_t out;
    random_point(&p, &est, &ref, &applied);
    ref.torque = fx_add(est.next.torque, FX_ONE / 100);
    const ctrl_ctx_t ctx = {&p, &est, &ref};
    for (int n = 1; n <= 50; n++) {
        ctrl_desc_m2ptfc.step(&s, &ctx, &out);
        const double want = 0.01 * (1.0 - pow(0.97, n));
        TEST_ASSERT_DOUBLE_WITHIN(n * LSB, want, d24(s.sigma));
    }
    ctrl_desc_m2ptfc.reset(&s);
    TEST_ASSERT_EQUAL_INT32(0, s.sigma);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_candidates_table);
    RUN_TEST(test_m3_set_and_m2_table);
    RUN_TEST(test_duty_clamp_edges);
    RUN_TEST(test_ratio_exact);
    RUN_TEST(test_closer_matches_sqrt);
    RUN_TEST(test_m2ptfc_minimises_cost_spmsm);
    RUN_TEST(test_m2ptfc_minimises_cost_ipmsm);
    RUN_TEST(test_m1_argmin);
    RUN_TEST(test_mptfc_argmin);
    RUN_TEST(test_m3_argmin);
    RUN_TEST(test_m2_band_and_argmin);
    RUN_TEST(test_registry_and_tunables);
    RUN_TEST(test_zeta_in_pu);
    RUN_TEST(test_bad_input);
    RUN_TEST(test_bad_input_all);
    RUN_TEST(test_model_rs_on_lossless_machine);
    RUN_TEST(test_sigma_ema);
    RUN_TEST(test_t_eval);
    RUN_TEST(test_psi_ref2);
    RUN_TEST(test_basis3_equals_basis);
    RUN_TEST(test_closer_full_range);
    RUN_TEST(test_m2ptfc_psi2_cache);
    return UNITY_END();
}
