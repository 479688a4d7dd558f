/*
 * Sensorless start-up (sensorless.h): the forced ramp, the handover, the
 * return to the forced angle and its configuration (host and QEMU).
 */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "../core/machines.h"
#include "angle_source.h"
#include "ctrl_units.h"
#include "fx.h"
#include "sensorless.h"
#include "sensorless_config.h"
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

static double wrap(double x)
{
    return x - 2.0 * CTRL_PI * floor((x + CTRL_PI) / (2.0 * CTRL_PI));
}

static void setup(ctrl_machine_t m, ctrl_sl_t *s)
{
    M = m;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&P, &B, &m, 10000u));
    ctrl_sl_config_t c;
    ctrl_sl_config_default(&c, &m);
    ctrl_diag_t why;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_sl_init(s, &P, &B, &c, &why));
}

/*
 * A rotor locked to the forced frame at gamma ahead of its d axis (what a
 * current along the forced q axis does to a rotor that needs t_start
 * cos(gamma)), then, after the handover, turning on at the speed reached:
 * the voltage and current of that motion, exact, fed to the sensorless angle.
 * Returns the number of periods to the handover (0: none within n), the
 * observer's angle error at the handover in *err_rad.
 */
static long run_locked(ctrl_sl_t *s, double gamma, double speed_ref, long n, double *err_rad,
                       ctrl_sl_out_t *last)
{
    const double ld = d(P.ld);
    const double lq = d(P.lq);
    const double rs = d(P.rs);
    const double psi = d(P.psi_pm);
    const double ts = d(P.ts);
    /* torque t_start cos(gamma) from a current of amplitude i_q = t_start /
     * psi_pm along the forced q axis (the SPMSM's MTPA current) */
    const double i_amp = d(s->t_start) / psi;
    double th_f = (double)s->theta0 * 2.0 * CTRL_PI / TURN;
    double w = 0.0;
    double th = th_f + gamma;
    double ia0 = -i_amp * sin(th_f);
    double ib0 = i_amp * cos(th_f);
    const double id0 = ia0 * cos(th) + ib0 * sin(th);
    double pa0 = lq * ia0 + (psi + (ld - lq) * id0) * cos(th);
    double pb0 = lq * ib0 + (psi + (ld - lq) * id0) * sin(th);
    q24_t va = 0;
    q24_t vb = 0;
    long handover = 0;
    for (long k = 0; k < n; k++) {
        ctrl_sl_out_t out;
        ctrl_sl_update(s, &P, va, vb, q(ia0), q(ib0), q(speed_ref), 0, &out);
        *last = out;
        if (out.handover) {
            handover = k;
            *err_rad = wrap((double)out.theta * 2.0 * CTRL_PI / TURN - th);
        }
        /* the motion over [k, k+1): forced frame at out.omega while forced */
        if (out.mode == CTRL_SL_FORCED) {
            w = d(out.omega);
            th_f = (double)out.theta * 2.0 * CTRL_PI / TURN + w * ts;
            th = th_f + gamma;
        } else {
            th += w * ts;
            th_f = th - gamma;
        }
        /* current stays on the forced q axis of the locked frame */
        const double ia = -i_amp * sin(th_f);
        const double ib = i_amp * cos(th_f);
        const double id = ia * cos(th) + ib * sin(th);
        const double pa = lq * ia + (psi + (ld - lq) * id) * cos(th);
        const double pb = lq * ib + (psi + (ld - lq) * id) * sin(th);
        va = q((pa - pa0) / ts + rs * 0.5 * (ia0 + ia));
        vb = q((pb - pb0) / ts + rs * 0.5 * (ib0 + ib));
        ia0 = ia;
        ib0 = ib;
        pa0 = pa;
        pb0 = pb;
    }
    return handover;
}

/*
 * The ramp: omega_f rises by ramp_dw per period to w_on, theta_f turns by
 * omega_f Ts, the torque reference is t_start; after settle_n periods at w_on
 * the handover, once. The observer, restarted at theta_f + 90 deg for a rotor
 * that sits at theta_f + 30 deg (a 60 deg error), has converged by then: with
 * kappa_start = 2 its error decays as e^{-w t} at w_on (critical damping) and
 * the settle time 6 / w_on leaves e^-6 of what the ramp left: below 1 deg.
 */
static void test_ramp_and_handover(void)
{
    ctrl_sl_t s;
    setup(machine_thesis_spmsm(), &s);
    const long ramp_n = (long)ceil(d(s.w_on) / d(s.ramp_dw));
    double err = 1.0;
    ctrl_sl_out_t last;
    const long h =
        run_locked(&s, CTRL_PI / 6.0, 2.0 * d(s.w_on), ramp_n + (long)s.settle_n + 50, &err, &last);
    TEST_ASSERT_TRUE_MESSAGE(h > 0, "no handover");
    /* the handover comes settle_n periods after w_on is first reached */
    TEST_ASSERT_INT_WITHIN(2, ramp_n + (long)s.settle_n - 1, h);
    printf("handover after %ld periods, observer error then %.4f deg\n", h, err * 180.0 / CTRL_PI);
    TEST_ASSERT_TRUE_MESSAGE(fabs(err) < CTRL_PI / 180.0, "observer not converged at the handover");
    TEST_ASSERT_EQUAL_UINT8(CTRL_SL_OBSERVER, last.mode);
    TEST_ASSERT_EQUAL_UINT8(0u, last.handover);
}

/* The forced outputs period by period: speed steps of ramp_dw, the angle
 * advancing by the previous speed, torque t_start; a reference under w_on
 * is held (no handover) and a negative one ramps down. Without the swing
 * damping (kd = 0: it shifts the angle by the observer's speed error, which
 * these zero inputs leave undefined; the closed loop sensorless_loop covers it). */
static void test_forced_sequence(void)
{
    ctrl_sl_t s;
    setup(machine_thesis_spmsm(), &s);
    s.kd = 0;
    const double half = 0.5 * d(s.w_on);
    fx_angle_t th_prev = s.theta0;
    q24_t w_prev = 0;
    for (int k = 0; k < (int)(3.0 * half / d(s.ramp_dw)) + (int)s.settle_n; k++) {
        ctrl_sl_out_t out;
        ctrl_sl_update(&s, &P, 0, 0, 0, 0, q(-half), 0, &out);
        TEST_ASSERT_EQUAL_UINT8(CTRL_SL_FORCED, out.mode);
        TEST_ASSERT_EQUAL_INT32(s.t_start, out.torque_ref);
        if (k > 0) {
            TEST_ASSERT_EQUAL_UINT32(th_prev + ctrl_angle_step(&P, w_prev), out.theta);
        }
        TEST_ASSERT_TRUE(out.omega <= 0 && out.omega >= q(-half) - 1);
        TEST_ASSERT_TRUE(w_prev - out.omega <= s.ramp_dw);
        th_prev = out.theta;
        w_prev = out.omega;
    }
    TEST_ASSERT_INT32_WITHIN(1, q(-half), w_prev); /* held at the reference */
}

/* Too slow for too long in the observer mode: the forced angle again, placed
 * gamma behind the observer's angle with t_start cos(gamma) = the torque
 * estimate (0 deg at +t_start, 90 deg at 0, 180 deg at -t_start). */
static void test_fallback_bumpless(void)
{
    const double ts[3] = {1.0, 0.0, -1.0};
    const double gam[3] = {0.0, 90.0, 180.0};
    for (int i = 0; i < 3; i++) {
        ctrl_sl_t s;
        setup(machine_thesis_spmsm(), &s);
        ctrl_fobs_reset(&s.obs, &P, 0x12345678u, 0, 0, 0);
        s.mode = CTRL_SL_OBSERVER;
        s.ramping = 1u;
        ctrl_sl_out_t out;
        long k = 0;
        do {
            ctrl_sl_update(&s, &P, 0, 0, 0, 0, 0, q(ts[i] * d(s.t_start)), &out);
            k++;
        } while (out.mode == CTRL_SL_OBSERVER && k < 100000);
        TEST_ASSERT_EQUAL_INT32((long)s.low_n, k); /* at rest: w_obs = 0 < w_off */
        const double g = wrap((double)(out.theta_obs - out.theta) * 2.0 * CTRL_PI / TURN);
        TEST_ASSERT_FLOAT_WITHIN(1e-4, wrap(gam[i] * CTRL_PI / 180.0), g);
    }
}

/*
 * The start of a salient machine (80 kW IPMSM) at standstill, exact: the
 * currents of the linear machine at rest, di = Ts L^-1(theta) (v - Rs i),
 * the voltage asked for in CTRL_SL_DETECT applied one period later (the
 * pipeline's delay); while the polarity pulse runs, the rotor turns by
 * +-10 deg the way the pulse's torque pushes it: forwards (the speed
 * reference's way) if the measured axis th1 is the magnet's north, backwards
 * if it is its south. Then the observer must take over at the rotor's angle
 * (within 0.1 deg: the measurement is exact up to Q24 rounding), for rotor
 * angles all round the turn and both directions. A rotor that does not turn
 * (a load as large as the pulse) must leave the polarity unknown: the blind
 * forced start.
 */
static int run_initial(ctrl_sl_t *s, double theta, double speed_ref, double turn_rad,
                       ctrl_sl_out_t *last)
{
    const double ts = d(P.ts);
    const double rs = d(P.rs);
    q24_t asked_a = 0; /* asked at k-1: acts in [k, k+1) */
    q24_t asked_b = 0;
    q24_t va = 0; /* applied in [k-1, k) */
    q24_t vb = 0;
    double ia = 0.0;
    double ib = 0.0;
    uint8_t turned = 0u;
    for (int k = 0; k < 2000; k++) {
        const double inv_d = d(P.inv_ld);
        const double inv_q = d(P.inv_lq);
        const double sm = 0.5 * (inv_d + inv_q);
        const double df = 0.5 * (inv_d - inv_q);
        const double c2 = cos(2.0 * theta);
        const double s2 = sin(2.0 * theta);
        const double ua = d(va) - rs * ia;
        const double ub = d(vb) - rs * ib;
        ia += ts * (sm * ua + df * (c2 * ua + s2 * ub));
        ib += ts * (sm * ub + df * (s2 * ua - c2 * ub));
        ctrl_sl_update(s, &P, va, vb, q(ia), q(ib), q(speed_ref), 0, last);
        if (s->phase == CTRL_SL_PH_D2 && turned == 0u) {
            /* the pulse is over: the rotor turned the way its torque pushed */
            const double th1 = (double)s->th1 * 2.0 * CTRL_PI / TURN;
            const int north = fabs(wrap(th1 - theta)) < 0.5 * CTRL_PI;
            const double dir = speed_ref < 0.0 ? -1.0 : 1.0;
            theta += (north ? dir : -dir) * turn_rad;
            turned = 1u;
        }
        if (last->mode == CTRL_SL_OBSERVER || (turned != 0u && s->phase == CTRL_SL_PH_NONE)) {
            return k;
        }
        va = asked_a;
        vb = asked_b;
        asked_a = last->mode == CTRL_SL_DETECT ? last->v_alpha : 0;
        asked_b = last->mode == CTRL_SL_DETECT ? last->v_beta : 0;
    }
    return -1;
}

static void test_initial_angle_start(void)
{
    double worst = 0.0;
    for (int j = 0; j < 24; j++) {
        const double theta = wrap(j * 15.0 * CTRL_PI / 180.0 + 0.05);
        for (int dir = -1; dir <= 1; dir += 2) {
            ctrl_sl_t s;
            setup(machine_thesis_ipmsm80(), &s);
            TEST_ASSERT_EQUAL_UINT8(1u, s.ia_on);
            ctrl_sl_out_t out;
            const double turn = 10.0 * CTRL_PI / 180.0;
            const int k = run_initial(
                &s, theta, dir * 300.0 / 60.0 * 2.0 * CTRL_PI * 4.0 / B.w_rad_s, turn, &out);
            TEST_ASSERT_TRUE(k > 0);
            TEST_ASSERT_EQUAL_UINT8(CTRL_SL_OBSERVER, out.mode);
            TEST_ASSERT_EQUAL_UINT8(1u, out.handover);
            /* where the rotor is now: theta turned by +-10 deg */
            const double th1 = (double)s.th1 * 2.0 * CTRL_PI / TURN;
            const int north = fabs(wrap(th1 - theta)) < 0.5 * CTRL_PI;
            const double now = theta + (north ? dir : -dir) * turn;
            const double e = wrap((double)out.theta * 2.0 * CTRL_PI / TURN - now);
            worst = fmax(worst, fabs(e));
        }
    }
    printf("initial angle and polarity, 48 starts: worst error %.4f deg\n",
           worst * 180.0 / CTRL_PI);
    TEST_ASSERT_TRUE(worst <= 0.1 * CTRL_PI / 180.0);
    /* a rotor that does not turn: polarity unknown, the blind forced start */
    ctrl_sl_t s;
    setup(machine_thesis_ipmsm80(), &s);
    ctrl_sl_out_t out;
    TEST_ASSERT_TRUE(run_initial(&s, 1.0, 0.01, 0.0, &out) > 0);
    TEST_ASSERT_EQUAL_UINT8(CTRL_SL_FORCED, s.mode);
    TEST_ASSERT_EQUAL_UINT8(CTRL_SL_PH_NONE, s.phase);
    TEST_ASSERT_EQUAL_UINT32(s.theta0, s.theta_f);
}

static void test_config(void)
{
    const ctrl_machine_t ms[3] = {machine_thesis_spmsm(), machine_thesis_ipmsm80(),
                                  machine_chapter_ipmsm()};
    for (int i = 0; i < 3; i++) {
        ctrl_sl_t s;
        setup(ms[i], &s);
        /* the IPMSMs measure their angle first (saliency >= 0.1) */
        const int salient = CTRL_SL_INITIAL_ANGLE != 0 &&
                            fabs(ms[i].lq_h - ms[i].ld_h) > 0.05 * (ms[i].lq_h + ms[i].ld_h);
        TEST_ASSERT_EQUAL_UINT8(salient, s.ia_on);
        TEST_ASSERT_EQUAL_UINT8(salient ? CTRL_SL_DETECT : CTRL_SL_FORCED, s.mode);
        TEST_ASSERT_TRUE(s.ramp_dw > 0 && s.w_on > s.w_off && s.settle_n > 0u);
    }
    ctrl_sl_config_t c0;
    ctrl_sl_config_default(&c0, &M);
    struct {
        const char *name;
        size_t off;
        double bad;
    } bad[] = {
        {"t_start_nm", offsetof(ctrl_sl_config_t, t_start_nm), 0.0},
        {"w_on_frac", offsetof(ctrl_sl_config_t, w_on_frac), 0.9},
        {"w_off_frac", offsetof(ctrl_sl_config_t, w_off_frac), 0.3},
        {"ramp_rad_s2", offsetof(ctrl_sl_config_t, ramp_rad_s2), 1e12},
        {"low_s", offsetof(ctrl_sl_config_t, low_s), 0.0},
        {"settle_s", offsetof(ctrl_sl_config_t, settle_s), -1.0},
        {"kappa_start", offsetof(ctrl_sl_config_t, kappa_start), 9.0},
        {"theta0_rad", offsetof(ctrl_sl_config_t, theta0_rad), NAN},
        {"damp_zeta", offsetof(ctrl_sl_config_t, damp_zeta), 3.0},
        {"inertia_kgm2", offsetof(ctrl_sl_config_t, inertia_kgm2), -1.0},
        {"ia_saliency_min", offsetof(ctrl_sl_config_t, ia_saliency_min), -0.1},
        {"ia_i_frac", offsetof(ctrl_sl_config_t, ia_i_frac), 0.9},
        {"ia_rounds", offsetof(ctrl_sl_config_t, ia_rounds), 0.0},
        {"pol_deg", offsetof(ctrl_sl_config_t, pol_deg), 180.0},
        {"pol_min_frac", offsetof(ctrl_sl_config_t, pol_min_frac), 2.0},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        ctrl_sl_config_t c = c0;
        memcpy((char *)&c + bad[i].off, &bad[i].bad, sizeof(double));
        ctrl_sl_t s;
        ctrl_diag_t why;
        memset(&why, 0, sizeof why);
        TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_sl_init(&s, &P, &B, &c, &why));
        TEST_ASSERT_EQUAL_STRING(bad[i].name, why.quantity);
    }
    ctrl_sl_config_t c = c0;
    c.obs.pll_hz = 1e6;
    ctrl_sl_t s;
    ctrl_diag_t why;
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_sl_init(&s, &P, &B, &c, &why));
    TEST_ASSERT_EQUAL_STRING("pll_hz", why.quantity);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_ramp_and_handover);
    RUN_TEST(test_forced_sequence);
    RUN_TEST(test_fallback_bumpless);
    RUN_TEST(test_initial_angle_start);
    RUN_TEST(test_config);
    return UNITY_END();
}
