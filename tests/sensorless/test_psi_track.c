/*
 * PM-flux tracking with the encoder (psi_track.h): the estimator and the
 * tracker on an exact machine trajectory (host and QEMU). The bounds come
 * from the sampled complementary filter's steady state and the roundings;
 * nothing is copied from a printout.
 */
#include <math.h>
#include <stdio.h>

#include "../core/machines.h"
#include "ctrl_units.h"
#include "estimator.h"
#include "flux_observer_config.h"
#include "psi_track.h"
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
static ctrl_machine_t M;

static double d(q24_t x)
{
    return ctrl_q24_to_double(x);
}

static q24_t q(double x)
{
    return ctrl_q24_from_double(x);
}

static void track_config(ctrl_fobs_config_t *c)
{
    ctrl_fobs_config_default(c, &M);
    c->mode = CTRL_FOBS_ENCODER;
    c->psi_tau_s = 0.02;
    c->psi_speed_min = 0.1;
    c->pll_hz = fmin(c->pll_hz, 0.4 * (double)P.fs_hz / (4.0 * CTRL_PI)); /* as the firmware */
}

/* The tracker as the firmware sets it up: the observer, then the N periods. */
static int track_init(ctrl_psi_track_t *t, const ctrl_params_t *p, const ctrl_fobs_config_t *c,
                      ctrl_diag_t *why)
{
    const int rc = ctrl_fobs_init(&t->obs, p, &B, c, why);
    return rc != CTRL_OK ? rc : ctrl_psi_track_setup(t, p);
}

/* Leg duties around 1/2 that apply the stator voltage (ua, ub) per unit of
 * DC link: the inverse of (4.4) averaged. */
static void legs_for(double ua, double ub, ctrl_legs_t *l)
{
    const double h = 0.5 * sqrt(3.0) * ub;
    const double dut[3] = {0.5 + ua, 0.5 - 0.5 * ua + h, 0.5 - 0.5 * ua - h};
    for (int x = 0; x < 3; x++) {
        /* inside the linear range: the trajectory is one the inverter can apply */
        TEST_ASSERT_TRUE(dut[x] > 0.0 && dut[x] < 1.0);
        l->duty[x] = q(dut[x]);
    }
}

/*
 * Steady state on the thesis SPMSM at speed w (pu), i_q = 0.8 rated, with
 * the controller's psi_pm off by `scale`: the machine's exact flux and
 * currents at each sample, the voltage over [k, k+1) the one that moves the
 * exact flux with the trapezoidal resistive drop (the tracker's
 * discretisation), applied as leg duties through the estimator. Returns the
 * tracker's PM-flux estimate after n periods; *moves counts the periods in
 * which it moved.
 */
static double run_track(ctrl_psi_track_t *t, double w, double scale, long n, long *moves)
{
    ctrl_params_t po = P;
    po.psi_pm = q(scale * d(P.psi_pm));
    po.inv_psi_pm = q(1.0 / (scale * d(P.psi_pm)));
    ctrl_estimator_t e;
    ctrl_estimator_init(&e, &po);
    ctrl_estimator_set_outputs(&e, 0u);
    const double ld = d(P.ld);
    const double lq = d(P.lq);
    const double rs = d(P.rs);
    const double psi_pm = d(P.psi_pm);
    const double ts = d(P.ts);
    const double vdc = d(P.vdc_nom);
    const double id = 0.0;
    const double iq = 0.8 * d(P.current_rated);
    ctrl_legs_t legs = {{FX_ONE / 2, FX_ONE / 2, FX_ONE / 2}};
    ctrl_estimate_t est = {0};
    *moves = 0;
    for (long k = 0; k < n; k++) {
        /* sample k and k+1 of the exact trajectory */
        double ia[2];
        double ib[2];
        double pa[2];
        double pb[2];
        double th[2];
        for (int j = 0; j < 2; j++) {
            th[j] = w * ts * (double)(k + j);
            const double c = cos(th[j]);
            const double s = sin(th[j]);
            ia[j] = c * id - s * iq;
            ib[j] = s * id + c * iq;
            pa[j] = c * (ld * id + psi_pm) - s * lq * iq;
            pb[j] = s * (ld * id + psi_pm) + c * lq * iq;
        }
        ctrl_meas_t m;
        m.i_a = q(ia[0]);
        m.i_b = q(-0.5 * ia[0] + 0.5 * sqrt(3.0) * ib[0]);
        m.vdc = P.vdc_nom;
        m.theta_e = (fx_angle_t)(uint32_t)(uint64_t)llround(fmod(th[0], 2.0 * CTRL_PI) /
                                                            (2.0 * CTRL_PI) * TURN);
        ctrl_estimator_update(&e, &po, &m, &legs, &est);
        if (ctrl_psi_track_step(t, &po, &est, &legs, m.i_a, m.i_b)) {
            (*moves)++;
        }
        /* the duties of [k+1, k+2): the voltage that moves the flux from k+1
         * to k+2 */
        const double c2 = cos(w * ts * (double)(k + 2));
        const double s2 = sin(w * ts * (double)(k + 2));
        const double pa2 = c2 * (ld * id + psi_pm) - s2 * lq * iq;
        const double pb2 = s2 * (ld * id + psi_pm) + c2 * lq * iq;
        const double ia2 = c2 * id - s2 * iq;
        const double ib2 = s2 * id + c2 * iq;
        const double va = (pa2 - pa[1]) / ts + rs * 0.5 * (ia[1] + ia2);
        const double vb = (pb2 - pb[1]) / ts + rs * 0.5 * (ib[1] + ib2);
        legs_for(va / vdc, vb / vdc, &legs);
    }
    return d(ctrl_fobs_psi_pm(&t->obs));
}

/*
 * The sampled complementary filter: between two corrections (N periods) the
 * observer's error D (observer - machine) is fixed in the stator frame, so in
 * the rotor frame it turns by r = e^{-j N w Ts}; the correction takes
 * D+ = D- + k_N (E - D-), E = (dpsi, 0) the current model's error. The PM
 * flux is read before the correction: D- = r k_N E / (1 - r (1 - k_N)) in
 * steady state, and the estimate is psi_pm + Re(D-) (the EMA settles on its
 * input exactly). Checked within 1 % of that residual plus 1e-5 psi_pm (some
 * 170 LSB: the duties' and the Q24 views' roundings), at 0.3 and 0.8 x rated
 * speed (the inverter's linear range) for psi_pm x 0.8 and x 1.2; the
 * configured value would be off by the whole 20 %.
 */
static void test_steady_state_matches_sampled_filter(void)
{
    M = machine_thesis_spmsm();
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&P, &B, &M, 10000u));
    const double speeds[2] = {0.3, 0.8};
    const double scales[2] = {0.8, 1.2};
    for (int a = 0; a < 2; a++) {
        for (int b = 0; b < 2; b++) {
            ctrl_fobs_config_t c;
            track_config(&c);
            ctrl_psi_track_t t;
            ctrl_params_t po = P;
            po.psi_pm = q(scales[b] * d(P.psi_pm));
            TEST_ASSERT_EQUAL_INT(CTRL_OK, track_init(&t, &po, &c, NULL));
            const double w = speeds[a] * d(P.speed_rated_e);
            const double ts = d(P.ts);
            /* 0.25 s: the corrector (corner 5 % rated) and the EMA (20 ms) settle */
            long moves = 0;
            const double est = run_track(&t, w, scales[b], (long)(0.25 * 10000.0), &moves);
            const double psi_pm = d(P.psi_pm);
            const double dpsi = (scales[b] - 1.0) * psi_pm;
            const double kn = d(t.obs.kenc_ts);
            const double x = (double)t.div * w * ts;
            const double rr = cos(x);
            const double ri = -sin(x);
            /* D- = r kn E / (1 - r (1 - kn)) */
            const double nr = rr * kn * dpsi;
            const double ni = ri * kn * dpsi;
            const double dr = 1.0 - rr * (1.0 - kn);
            const double di = -ri * (1.0 - kn);
            const double dd = (nr * dr + ni * di) / (dr * dr + di * di);
            const double expect = psi_pm + dd;
            printf("w %.2f rated, psi_pm x %.1f: N %u, estimate %.6f pu, expected %.6f, "
                   "true %.6f, %ld moves\n",
                   speeds[a], scales[b], (unsigned)t.div, est, expect, psi_pm, moves);
            TEST_ASSERT_FLOAT_WITHIN(0.01 * fabs(dd) + 1e-5 * psi_pm, expect, est);
            /* far better than the configured value */
            TEST_ASSERT_TRUE(fabs(est - psi_pm) < 0.1 * fabs(dpsi));
            /* the estimate moves once per N periods (the speed gate is open
             * from the first periods on: the encoder's speed filter settles in
             * a few ms) */
            const long updates = (long)(0.25 * 10000.0) / (long)t.div;
            TEST_ASSERT_TRUE(moves <= updates + 1 && moves >= updates - 40);
        }
    }
}

/* Below the speed threshold the estimate does not move. */
static void test_speed_gate(void)
{
    M = machine_thesis_spmsm();
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&P, &B, &M, 10000u));
    ctrl_fobs_config_t c;
    track_config(&c);
    ctrl_psi_track_t t;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, track_init(&t, &P, &c, NULL));
    long moves = 0;
    const double est = run_track(&t, 0.05 * d(P.speed_rated_e), 1.2, 2000, &moves);
    TEST_ASSERT_EQUAL_INT(0, moves);
    TEST_ASSERT_EQUAL_DOUBLE(d(q(1.2 * d(P.psi_pm))), est);
}

/* The divider: at most a quarter turn between two corrections at twice the
 * rated speed, within [1, CTRL_PSI_TRACK_DIV_MAX]; the gains of N periods;
 * bad configurations refused. */
static void test_config(void)
{
    const uint32_t fss[3] = {2000u, 10000u, 40000u};
    for (int f = 0; f < 3; f++) {
        M = machine_thesis_spmsm();
        TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&P, &B, &M, fss[f]));
        ctrl_fobs_config_t c;
        track_config(&c);
        ctrl_psi_track_t t;
        TEST_ASSERT_EQUAL_INT(CTRL_OK, track_init(&t, &P, &c, NULL));
        const double ts = 1.0 / (double)fss[f];
        const double w2 = 2.0 * M.speed_rated_rpm * M.pole_pairs * 2.0 * CTRL_PI / 60.0;
        const double n = floor(0.5 * CTRL_PI / (w2 * ts));
        const unsigned expect = n < 1.0 ? 1u : (n > 8.0 ? 8u : (unsigned)n);
        printf("fs %u Hz: N %u (expected %u)\n", (unsigned)fss[f], (unsigned)t.div, expect);
        TEST_ASSERT_EQUAL_UINT(expect, t.div);
        /* k_N = 1 - (1 - w_c Ts)^N, 1 - exp(-N Ts / tau), within the roundings */
        TEST_ASSERT_FLOAT_WITHIN(1e-6, 1.0 - pow(1.0 - c.kenc_rad_s * ts, (double)t.div),
                                 d(t.obs.kenc_ts));
        TEST_ASSERT_FLOAT_WITHIN(1e-6, 1.0 - exp(-(double)t.div * ts / c.psi_tau_s), d(t.psi_k_n));
    }
    ctrl_fobs_config_t c;
    track_config(&c);
    ctrl_psi_track_t t;
    ctrl_diag_t why;
    ctrl_fobs_config_t bad = c;
    bad.psi_tau_s = 1e-6; /* the observer's own checks */
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, track_init(&t, &P, &bad, &why));
    TEST_ASSERT_EQUAL_STRING("psi_tau_s", why.quantity);
    bad = c;
    bad.mode = CTRL_FOBS_SENSORLESS;
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, track_init(&t, &P, &bad, &why));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_steady_state_matches_sampled_filter);
    RUN_TEST(test_speed_gate);
    RUN_TEST(test_config);
    return UNITY_END();
}
