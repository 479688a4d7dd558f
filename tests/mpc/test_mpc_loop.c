/*
 * Closed loop (plant + HAL sim + firmware pipeline) of the
 * chapter-6 predictive controllers. Host only. One executable per group
 * (MPC_LOOP_GROUP): 1 = SPMSM steady state (thesis §6.6.2, Table 6.2),
 * 2 = dynamics (Fig. 6.17), 3 = IPMSMs (§6.5.1 case study).
 *
 * Torque series: the plant's true torque on the Ts/10 grid (plant sampling,
 * thesis Appendix B); ripple = standard deviation (B.1) over the window.
 *
 * Settings. Proposed m2ptfc: Table 6.2 (fs 10 kHz at 750, 11 kHz at 2250 r/min,
 * lambda 0.03), centre = 1 (default, ctrl_m2ptfc.h). M2: Table 6.2 (eps_psi
 * 6.60 / 9.42 mWb, fs 10 kHz). M3: fs 12 / 16 kHz (Table 6.2). M1 and M3
 * weighting: Table 6.2's zeta (M1 250 / 640, M3 440 N*m/Wb) exceed the limit
 * zeta_max = sqrt(3) (3p/2) psi_pm / Ls = 149.5 N*m/Wb derived in ctrl_m1.h
 * and lose torque control (the zero vector wins every period); these tests
 * use the default zeta = T_rated/psi_pm = 25.5 N*m/Wb (equal importance,
 * §6.5) for M1 and M3 at 750 r/min and Table 6.2's 110 N*m/Wb for M3 at
 * 2250 r/min (below the limit; works).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "loop_util.h"
#include "mpc_machines.h"
#include "sim_machine.h"
#include "unity.h"

#ifndef MPC_LOOP_GROUP
#define MPC_LOOP_GROUP 1
#endif

void setUp(void)
{
}
void tearDown(void)
{
}

static sim_run_t run;

typedef struct {
    double t_mean, t_rip, psi_mean, psi_rip, f_av;
    uint32_t fault;
    int running;
} mpc_res_t;

typedef struct {
    const char *name;
    uint32_t fs;         /* 0 = controller default */
    const char *tunable; /* NULL = none */
    double value;
} mpc_ctrl_t;

static const sim_machine_t *machine(const char *file)
{
    static sim_machine_t m[3];
    static const char *loaded[3];
    for (int i = 0; i < 3; i++) {
        if (loaded[i] != NULL && strcmp(loaded[i], file) == 0) {
            return &m[i];
        }
        if (loaded[i] == NULL) {
            m[i] = loop_machine_file(file);
            loaded[i] = file;
            return &m[i];
        }
    }
    TEST_FAIL_MESSAGE("too many machines");
    return NULL;
}

/* Controller configuration buffer: alive for the whole run. */
static unsigned char ctrl_cfg[CTRL_CFG_MAX];

/* Dynamometer run (torque mode, loop_cfg_machine()); the controller is
 * configured with psi_ref_wb (< 0: the machine file's) and k's tunable. */
static void mpc_cfg(sim_run_cfg_t *c, const sim_machine_t *m, const mpc_ctrl_t *k, double rpm,
                    double tref, double duration, double win_start, double psi_ref_wb)
{
    loop_cfg_machine(c, m, k->name, k->fs, rpm, tref, duration, win_start);
    if (psi_ref_wb >= 0.0) {
        c->ctrl_machine.psi_ref_wb = psi_ref_wb;
    }
    const ctrl_desc_t *d = ctrl_find(k->name);
    TEST_ASSERT_TRUE(d->cfg_size <= sizeof ctrl_cfg);
    d->cfg_default(ctrl_cfg, &c->ctrl_machine);
    if (k->tunable != NULL) {
        TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_set(d, ctrl_cfg, k->tunable, k->value));
    }
    c->ctrl_cfg = ctrl_cfg;
}

static mpc_res_t steady(const char *file, const mpc_ctrl_t *k, double rpm, double tref,
                        double psi_ref_wb)
{
    sim_run_cfg_t c;
    mpc_cfg(&c, machine(file), k, rpm, tref, 0.15, 0.05, psi_ref_wb);
    loop_start(&run, &c);
    char err[256];
    if (sim_run_all(&run, err, sizeof err) != 0) {
        TEST_FAIL_MESSAGE(err);
    }
    metrics_result_t mp;
    metrics_result_t mc;
    TEST_ASSERT_EQUAL_INT(0, sim_run_metrics(&run, &mp, &mc));
    mpc_res_t r = {mp.torque_mean_nm,
                   mp.torque_ripple_nm,
                   mp.flux_mean_wb,
                   mp.flux_ripple_wb,
                   mp.f_av_hz,
                   fw_fault(&run.fw),
                   fw_state(&run.fw) == FW_STATE_RUNNING};
    printf("  %-6s %-18s fs %5u %+6.0f r/min T_ref %+6.1f  T_mean %+8.3f  T_rip %.4f  "
           "psi_mean %.5f  psi_rip %.5f  f_av %5.0f Hz  fault %s\n",
           k->name, file, (unsigned)c.fs_hz, rpm, tref, r.t_mean, r.t_rip, r.psi_mean, r.psi_rip,
           r.f_av, fw_fault_name(r.fault));
    sim_run_free(&run);
    return r;
}

static void assert_running(const mpc_ctrl_t *k, const mpc_res_t *r)
{
    char msg[120];
    snprintf(msg, sizeof msg, "%s: fault %s", k->name, fw_fault_name(r->fault));
    TEST_ASSERT_TRUE_MESSAGE(r->running, msg);
}

#define SPMSM "thesis_spmsm.ini"
#define ZETA_EQUAL 0.0 /* tunable value 0 = T_rated / psi_pm (§6.5) */

#if MPC_LOOP_GROUP == 1

/* Zero-vector torque change per period dT0 of the SPMSM at torque t_nm (i_d = 0,
 * MTPA), speed rpm, period ts: psi' = e^{-j w Ts} (psi - Ts Rs i) in the rotor
 * frame ((6.10)-(6.12) with V = 0). sigma_0 = |dT0|/2 is the mean-torque
 * offset the literal (6.5)-(6.8) leave with centre-aligned PWM ((*) of
 * ctrl_m2ptfc.h). */
static double spmsm_sigma0(double t_nm, double rpm, double ts)
{
    const ctrl_machine_t *m = &ini_thesis_spmsm;
    const double k = 1.5 * m->pole_pairs;
    const double iq = t_nm / (k * m->psi_pm_wb);
    const double pd = m->psi_pm_wb;                       /* i_d = 0: no Rs drop on d */
    const double pq = m->ld_h * iq - ts * m->rs_ohm * iq; /* psi_q - Ts Rs i_q */
    const double a = rpm * 2.0 * 3.14159265358979 / 60.0 * m->pole_pairs * ts;
    const double pd2 = cos(a) * pd + sin(a) * pq;
    const double pq2 = cos(a) * pq - sin(a) * pd;
    const double t2 = k * (pd2 * (pq2 / m->ld_h) - pq2 * (pd2 - m->psi_pm_wb) / m->ld_h);
    return 0.5 * fabs(t2 - t_nm);
}

/* Thesis §6.6.2 at 1.8 N*m: m2ptfc torque ripple about equal to M1's (+5 % at
 * 2250 r/min) and 21 % / 28 % below M2 / M3; flux ripple 16 % below M1's.
 * Asserted with margins: T_rip(m2ptfc) <= 1.10 T_rip(m1);
 * T_rip(m2ptfc) <= 0.90 T_rip(m2), <= 0.90 T_rip(m3); psi_rip(m2ptfc) <=
 * 1.10 psi_rip(m1), the torque ripple's "about equal" margin: the 16 % is not
 * reproduced. At 750 r/min the two flux ripples are equal within the
 * decision-level numerics, a few per cent either way as the last bits of the
 * estimator or of the plant's integration change (m2ptfc / m1: 0.0011147 /
 * 0.0011225 Wb with the stage-2 stator-frame estimator, 0.0011251 / 0.0010973
 * Wb with the rotor-frame one and its 40x more accurate sine, 0.0011102 /
 * 0.0010529 Wb since the plant is integrated without breaks at the observed
 * instants); at 2250 r/min m2ptfc's is 3-5 % lower.
 * Mean torque of m2ptfc (centre = 1, default): |T_sse| <= 0.1 sigma_0, i.e. the
 * compensation (**) removes at least 90 % of the literal equations' offset
 * sigma_0 (0.14 N*m at 750 r/min; what is left comes from the per-period
 * variation of dT0, dTa over a sector and the estimator's errors). */
static void compare_at(double rpm, const mpc_ctrl_t ctl[4])
{
    mpc_res_t r[4];
    for (int i = 0; i < 4; i++) {
        r[i] = steady(SPMSM, &ctl[i], rpm, 1.8, -1.0);
        assert_running(&ctl[i], &r[i]);
    }
    printf("  %.0f r/min ratios m2ptfc/m1: T_rip %.3f psi_rip %.3f; m2ptfc/m2 T_rip %.3f; "
           "m2ptfc/m3 T_rip %.3f\n",
           rpm, r[0].t_rip / r[1].t_rip, r[0].psi_rip / r[1].psi_rip, r[0].t_rip / r[2].t_rip,
           r[0].t_rip / r[3].t_rip);
    char msg[160];
    snprintf(msg, sizeof msg, "%.0f r/min: T_rip m2ptfc %.4f vs m1 %.4f", rpm, r[0].t_rip,
             r[1].t_rip);
    TEST_ASSERT_TRUE_MESSAGE(r[0].t_rip <= 1.10 * r[1].t_rip, msg);
    snprintf(msg, sizeof msg, "%.0f r/min: T_rip m2ptfc %.4f vs m2 %.4f", rpm, r[0].t_rip,
             r[2].t_rip);
    TEST_ASSERT_TRUE_MESSAGE(r[0].t_rip <= 0.90 * r[2].t_rip, msg);
    snprintf(msg, sizeof msg, "%.0f r/min: T_rip m2ptfc %.4f vs m3 %.4f", rpm, r[0].t_rip,
             r[3].t_rip);
    TEST_ASSERT_TRUE_MESSAGE(r[0].t_rip <= 0.90 * r[3].t_rip, msg);
    snprintf(msg, sizeof msg, "%.0f r/min: psi_rip m2ptfc %.7f vs m1 %.7f", rpm, r[0].psi_rip,
             r[1].psi_rip);
    TEST_ASSERT_TRUE_MESSAGE(r[0].psi_rip <= 1.10 * r[1].psi_rip, msg);
    const double sigma0 = spmsm_sigma0(1.8, rpm, 1.0 / (double)ctl[0].fs);
    printf("  %.0f r/min m2ptfc T_sse %.4f N*m, bound 0.1 sigma_0 = %.4f N*m\n", rpm,
           1.8 - r[0].t_mean, 0.1 * sigma0);
    snprintf(msg, sizeof msg, "%.0f r/min: m2ptfc T_sse %.4f above 0.1 sigma_0 = %.4f", rpm,
             1.8 - r[0].t_mean, 0.1 * sigma0);
    TEST_ASSERT_TRUE_MESSAGE(fabs(1.8 - r[0].t_mean) <= 0.1 * sigma0, msg);
    /* Every controller holds the load: |T_sse| below 25 % of 1.8 N*m. */
    for (int i = 0; i < 4; i++) {
        snprintf(msg, sizeof msg, "%s: mean torque %.3f", ctl[i].name, r[i].t_mean);
        TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(0.25 * 1.8, 1.8, r[i].t_mean, msg);
    }
}

static void test_spmsm_750(void)
{
    const mpc_ctrl_t ctl[4] = {{"m2ptfc", 10000u, NULL, 0.0},
                               {"m1", 10000u, "zeta", ZETA_EQUAL},
                               {"m2", 10000u, "eps_psi", 6.60e-3},
                               {"m3", 12000u, "zeta", ZETA_EQUAL}};
    compare_at(750.0, ctl);
}

static void test_spmsm_2250(void)
{
    const mpc_ctrl_t ctl[4] = {{"m2ptfc", 11000u, NULL, 0.0},
                               {"m1", 10000u, "zeta", ZETA_EQUAL},
                               {"m2", 10000u, "eps_psi", 9.42e-3},
                               {"m3", 16000u, "zeta", 110.0}};
    compare_at(2250.0, ctl);
}

/* centre = 0 (the thesis' literal equations): the mean torque sits sigma_0 low,
 * as derived in ctrl_m2ptfc.h (*): T_sse within 0.7 .. 1.3 sigma_0 (the
 * derivation's linear per-period model). */
static void test_m2ptfc_literal_offset(void)
{
    const mpc_ctrl_t k = {"m2ptfc", 10000u, "centre", 0.0};
    const mpc_res_t r = steady(SPMSM, &k, 750.0, 1.8, -1.0);
    assert_running(&k, &r);
    const double sigma0 = spmsm_sigma0(1.8, 750.0, 1e-4);
    printf("  centre = 0: T_sse %.4f N*m, sigma_0 %.4f N*m\n", 1.8 - r.t_mean, sigma0);
    TEST_ASSERT_DOUBLE_WITHIN(0.3 * sigma0, sigma0, 1.8 - r.t_mean);
}

/* (**) of ctrl_m2ptfc.h holds for either sign of dT0: backward motoring and
 * both braking quadrants at 750 r/min, |T_sse| <= 0.1 sigma_0 of that point
 * (forward motoring: test_spmsm_750). */
static void test_m2ptfc_four_quadrants(void)
{
    static const double pts[3][2] = {{-750.0, -1.8}, {750.0, -1.8}, {-750.0, 1.8}};
    const mpc_ctrl_t k = {"m2ptfc", 10000u, NULL, 0.0};
    for (int i = 0; i < 3; i++) {
        const mpc_res_t r = steady(SPMSM, &k, pts[i][0], pts[i][1], -1.0);
        assert_running(&k, &r);
        const double sigma0 = spmsm_sigma0(pts[i][1], pts[i][0], 1e-4);
        char msg[160];
        snprintf(msg, sizeof msg, "%.0f r/min %.1f N*m: T_sse %.4f, bound %.4f", pts[i][0],
                 pts[i][1], pts[i][1] - r.t_mean, 0.1 * sigma0);
        printf("  %s\n", msg);
        TEST_ASSERT_TRUE_MESSAGE(fabs(pts[i][1] - r.t_mean) <= 0.1 * sigma0, msg);
    }
}

/* Documents (prints) the behaviour with Table 6.2's weight for M1 (250 N*m/Wb,
 * above zeta_max of ctrl_m1.h); asserts that M1 holds the load within 5 %
 * at 0.9 zeta_max (the limit is the point, not the equal-importance value)
 * and that the proposed method (no weight) holds it. */
static void test_table62_weights_report(void)
{
    const ctrl_machine_t *m = &ini_thesis_spmsm;
    const double zeta_max = sqrt(3.0) * 1.5 * m->pole_pairs * m->psi_pm_wb / m->ld_h;
    const mpc_ctrl_t m1_750 = {"m1", 10000u, "zeta", 250.0};
    const mpc_ctrl_t m1_lim = {"m1", 10000u, "zeta", 0.9 * zeta_max};
    const mpc_ctrl_t m2p = {"m2ptfc", 10000u, NULL, 0.0};
    const mpc_res_t a = steady(SPMSM, &m1_750, 750.0, 1.8, -1.0);
    const mpc_res_t c = steady(SPMSM, &m1_lim, 750.0, 1.8, -1.0);
    const mpc_res_t b = steady(SPMSM, &m2p, 750.0, 1.8, -1.0);
    printf("  Table 6.2 zeta = 250 N*m/Wb: m1 %s, mean torque %.3f N*m; zeta_max %.1f N*m/Wb\n",
           a.running ? "running" : "tripped", a.t_mean, zeta_max);
    assert_running(&m1_lim, &c);
    TEST_ASSERT_DOUBLE_WITHIN(0.05 * 1.8, 1.8, c.t_mean);
    assert_running(&m2p, &b);
}

#elif MPC_LOOP_GROUP == 2

/* Thesis Fig. 6.17: torque mode 2 N*m with a passive load, step to -2 N*m once
 * the speed reaches 0.5 pu (1500 r/min); continue to -1000 r/min. Load 1.6 N*m
 * as the closed-loop tests' Fig. 4.14 scenario and tools/compare.py (the thesis:
 * "around 1.8"). Fall time: from the step command until Te <= -1.6 N*m
 * (90 % of the 4 N*m swing). */
static loop_reversal_t reversal(const mpc_ctrl_t *k)
{
    sim_run_cfg_t c;
    mpc_cfg(&c, machine(SPMSM), k, 0.0, 0.0, 0.4, 0.0, -1.0);
    return loop_reversal(&run, &c,
                         "at 0 torque_ref=0 load=1.6\n"
                         "at 0.002 torque_ref=2\n"
                         "when speed>=1500 torque_ref=-2\n"
                         "when speed<=0 load=-1.6\n",
                         -1.6, 0.010, k->name);
}

/* Bounds: no fault; the speed reverses to -1000 r/min; fall time < 1 ms (thesis
 * < 0.4 ms; the fastest slope at 1500 r/min is about 1.1e4 N*m/s, 0.35 ms for
 * 4 N*m, plus the one-period delay); after the reversal the torque holds -2 N*m
 * within 25 % (no instability). */
static void check_reversal(const mpc_ctrl_t *k)
{
    const loop_reversal_t r = reversal(k);
    TEST_ASSERT_EQUAL_UINT32_MESSAGE(0u, r.fault, fw_fault_name(r.fault));
    TEST_ASSERT_TRUE_MESSAGE(r.reached, "speed never reached 1500 r/min");
    TEST_ASSERT_TRUE_MESSAGE(r.min_rpm_after <= -1000.0, "speed did not reverse");
    TEST_ASSERT_TRUE_MESSAGE(r.t_fall_ms < 1.0, "fall time not below 1 ms");
    TEST_ASSERT_DOUBLE_WITHIN(0.25 * 2.0, -2.0, r.tq_back_mean);
}

static void test_m2ptfc_reversal(void)
{
    const mpc_ctrl_t k = {"m2ptfc", 10000u, NULL, 0.0};
    check_reversal(&k);
}

static void test_m1_reversal(void)
{
    const mpc_ctrl_t k = {"m1", 10000u, "zeta", ZETA_EQUAL};
    check_reversal(&k);
}

#else

/* §6.5.1: m2ptfc holds rated torque at half and full base speed, mean within
 * 5 %. Flux reference: MTPA (the machine file's fixed 0.1837 Wb of §6.5.1
 * cannot carry 400 N*m with the linear Ld/Lq model: at most about 380 N*m).
 * Base speed: 80 kW IPMSM P/T = 80 kW / 400 N*m = 200 rad/s = 1910 r/min
 * (Table 3.1's 3000 r/min needs |psi_MTPA(400 N*m)| = 0.36 Wb times
 * 1257 rad/s = 456 V > Vdc/sqrt(3) = 312 V: not reachable at rated torque);
 * chapter IPMSM: the machine file's rated 1000 r/min. fs: 20 kHz (§6.5) and
 * 10 kHz (S1 Table 2). */
static void hold_rated(const char *file, uint32_t fs, double base_rpm, double t_rated)
{
    const mpc_ctrl_t k = {"m2ptfc", fs, NULL, 0.0};
    for (int h = 1; h <= 2; h++) {
        const double rpm = base_rpm * h / 2.0;
        const mpc_res_t r = steady(file, &k, rpm, t_rated, 0.0);
        assert_running(&k, &r);
        char msg[160];
        snprintf(msg, sizeof msg, "%s %.0f r/min: mean torque %.2f vs %.1f", file, rpm, r.t_mean,
                 t_rated);
        TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(0.05 * t_rated, t_rated, r.t_mean, msg);
    }
}

static void test_ipmsm80_rated(void)
{
    hold_rated("thesis_ipmsm_80kw.ini", 20000u, 80000.0 / 400.0 * 60.0 / (2.0 * 3.14159265358979),
               400.0);
}

static void test_chapter_ipmsm_rated(void)
{
    hold_rated("chapter_ipmsm.ini", 10000u, 1000.0, 4.0);
}

#endif

int main(void)
{
    UNITY_BEGIN();
#if MPC_LOOP_GROUP == 1
    RUN_TEST(test_spmsm_750);
    RUN_TEST(test_spmsm_2250);
    RUN_TEST(test_m2ptfc_literal_offset);
    RUN_TEST(test_m2ptfc_four_quadrants);
    RUN_TEST(test_table62_weights_report);
#elif MPC_LOOP_GROUP == 2
    RUN_TEST(test_m2ptfc_reversal);
    RUN_TEST(test_m1_reversal);
#else
    RUN_TEST(test_ipmsm80_rated);
    RUN_TEST(test_chapter_ipmsm_rated);
#endif
    return UNITY_END();
}
