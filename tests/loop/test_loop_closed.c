/*
 * Closed loop on the host (plant + HAL sim + firmware pipeline), thesis SPMSM.
 *
 * Steady-state bound: hysteresis DTC applies each vector for a whole period,
 * so the torque oscillates between the band edges plus one period's deviation,
 * and the unequal positive/negative deviations shift the mean (thesis §5.2,
 * Fig. 5.2): the thesis measures |T_sse| up to about 20 % of the rated torque
 * for the switching tables (Fig. 5.3). Bound used: |mean(T) - T_ref| <= 0.2 *
 * T_rated = 0.48 N*m. The flux amplitude is held on the MTPA reference (4.15),
 * psi_s = 0.09655 Wb at 1.8 N*m, inside the +-2 % psi_pm band (Table 4.7)
 * plus one period's flux step (sqrt(3) Vdc Ts / 3 = 6.4 mWb at 20 kHz, §5.3.5).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "loop_util.h"
#include "unity.h"

#define T_RATED 2.4
#define T_SSE_MAX (0.2 * T_RATED)
#define PSI_MTPA_1P8 0.09655
#define PSI_TOL (0.02 * 0.09427 + 0.0064)

void setUp(void)
{
}

static sim_run_t run;

void tearDown(void)
{
    sim_run_free(&run);
}

typedef struct {
    double t_mean, t_rip, psi_mean, psi_rip, f_av;
} loop_res_t;

static loop_res_t steady(const char *name, double rpm, double tref)
{
    sim_run_cfg_t c;
    loop_cfg(&c, name, rpm, tref, 0.06, 0.02);
    loop_start(&run, &c);
    char err[256];
    if (sim_run_all(&run, err, sizeof err) != 0) {
        TEST_FAIL_MESSAGE(err);
    }
    metrics_result_t mp, mc;
    TEST_ASSERT_EQUAL_INT(0, sim_run_metrics(&run, &mp, &mc));
    char msg[200];
    snprintf(msg, sizeof msg, "%s %+.0f r/min T_ref %+.1f: fault %s", name, rpm, tref,
             fw_fault_name(fw_fault(&run.fw)));
    TEST_ASSERT_EQUAL_INT_MESSAGE(FW_STATE_RUNNING, fw_state(&run.fw), msg);
    loop_res_t r = {mp.torque_mean_nm, mp.torque_ripple_nm, mp.flux_mean_wb, mp.flux_ripple_wb,
                    mp.f_av_hz};
    printf("  %-4s %+6.0f r/min  T_ref %+4.1f  T_mean %+.4f  T_rip %.4f  psi_mean %.5f  "
           "psi_rip %.5f  f_av %5.0f Hz  THD %.2f %%\n",
           name, rpm, tref, r.t_mean, r.t_rip, r.psi_mean, r.psi_rip, r.f_av, mp.thd_i_pct);
    sim_run_free(&run);
    snprintf(msg, sizeof msg, "%s %+.0f r/min: mean torque %.4f vs %.1f", name, rpm, r.t_mean,
             tref);
    TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(T_SSE_MAX, tref, r.t_mean, msg);
    snprintf(msg, sizeof msg, "%s %+.0f r/min: mean flux %.5f", name, rpm, r.psi_mean);
    TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(PSI_TOL, PSI_MTPA_1P8, r.psi_mean, msg);
    return r;
}

/* BST and FST hold 1.8 N*m at 750 and 2250 r/min, forward and backward
 * motoring (Fig. 3.9 quadrants I and III); FST ripple below BST's (thesis
 * §4.6.2.1: -46 % on average). */
static void test_bst_fst_hold_torque(void)
{
    const double speeds[2] = {750.0, 2250.0};
    for (int s = 0; s < 2; s++) {
        for (int dir = -1; dir <= 1; dir += 2) {
            const double rpm = dir * speeds[s];
            const double tref = dir * 1.8;
            const loop_res_t b = steady("bst", rpm, tref);
            const loop_res_t f = steady("fst", rpm, tref);
            char msg[160];
            snprintf(msg, sizeof msg, "%+.0f r/min: FST T_rip %.4f not below BST %.4f", rpm,
                     f.t_rip, b.t_rip);
            TEST_ASSERT_TRUE_MESSAGE(f.t_rip < b.t_rip, msg);
        }
    }
}

/* Thesis Fig. 4.14: free mechanics, load 1.6 N*m, T_ref 0 -> 2 N*m, then -2 N*m
 * once the speed reaches 1500 r/min. The load is passive (it opposes the
 * rotation, like the thesis' loading machine): it starts with the torque step
 * and changes sign at zero speed ("when speed<=0 load=-1.6"). Runs until
 * -1000 r/min (or 0.3 s). */
static loop_reversal_t reversal(const char *name)
{
    sim_run_cfg_t c;
    loop_cfg(&c, name, 0.0, 0.0, 0.3, 0.0);
    return loop_reversal(&run, &c,
                         "at 0 torque_ref=0 load=0\n"
                         "at 0.002 torque_ref=2 load=1.6\n"
                         "when speed>=1500 torque_ref=-2\n"
                         "when speed<=0 load=-1.6\n",
                         -1.8, 0.010, name);
}

/* Rise/fall bound: at standstill the fastest torque slope is
 * 1.5 p psi_pm (|V| / Lq) ~ 1.1e4 N*m/s (2 N*m in 0.18 ms); the thesis measures
 * 0.2 ms rise and 0.27 ms fall. Accepted: twice the thesis figure plus the
 * one-period computation delay. */
static void test_fst_speed_reversal(void)
{
    const loop_reversal_t r = reversal("fst");
    TEST_ASSERT_EQUAL_UINT32_MESSAGE(FW_FAULT_NONE, r.fault, fw_fault_name(r.fault));
    TEST_ASSERT_TRUE_MESSAGE(r.reached, "speed never reached 1500 r/min");
    TEST_ASSERT_TRUE_MESSAGE(r.min_rpm_after <= -1000.0, "speed did not reverse");
    TEST_ASSERT_TRUE(r.t_rise_ms <= 2.0 * 0.2 + 0.05);
    TEST_ASSERT_TRUE(r.t_fall_ms <= 2.0 * 0.27 + 0.05);
    /* Stable after the reversal: backward motoring holds -2 N*m (bound above). */
    TEST_ASSERT_DOUBLE_WITHIN(T_SSE_MAX, -2.0, r.tq_back_mean);
}

/* BST goes through the same reversal (thesis Fig. 4.14(a)). */
static void test_bst_speed_reversal(void)
{
    const loop_reversal_t r = reversal("bst");
    TEST_ASSERT_EQUAL_UINT32_MESSAGE(FW_FAULT_NONE, r.fault, fw_fault_name(r.fault));
    TEST_ASSERT_TRUE(r.reached);
    TEST_ASSERT_TRUE(r.min_rpm_after <= -1000.0);
    TEST_ASSERT_DOUBLE_WITHIN(T_SSE_MAX, -2.0, r.tq_back_mean);
}

/* ZST: the thesis reports instability when the speed crosses zero during the
 * reversal (Fig. 4.14(d)), because the zero vectors' torque deviation changes
 * sign there (§4.3) while ZST uses them to decrease the torque. Asserted: ZST
 * does NOT complete a stable reversal (reach -1000 r/min while holding -2 N*m
 * within the bound); observed (printed): the speed stalls near zero. */
static void test_zst_speed_reversal_unstable(void)
{
    const loop_reversal_t r = reversal("zst");
    TEST_ASSERT_TRUE(r.reached);
    const bool stable_reversal =
        r.min_rpm_after <= -1000.0 && fabs(r.tq_back_mean + 2.0) <= T_SSE_MAX;
    TEST_ASSERT_FALSE_MESSAGE(stable_reversal, "ZST reversed stably, unlike thesis Fig. 4.14(d)");
}

/* Outer speed loop (thesis gains, 1 kHz): free mechanics, load 1.8 N*m, speed
 * reference 750 r/min. Over the window the mean electromagnetic torque equals
 * the load: J (w_end - w_start) / T_win < 1.2e-4 * 2 rad/s / 0.1 s = 0.0024 N*m
 * when the speed stays within +-1 %; bound 0.02 N*m (sampling of the ripple). */
static void test_speed_loop(void)
{
    sim_run_cfg_t c;
    loop_cfg(&c, "fst", 0.0, 0.0, 0.25, 0.15);
    c.free_mech = true;
    c.load_nm = 1.8;
    c.speed_mode = true;
    c.speed_ref_rpm = 750.0;
    loop_start(&run, &c);
    char err[256];
    if (sim_run_all(&run, err, sizeof err) != 0) {
        TEST_FAIL_MESSAGE(err);
    }
    metrics_result_t mp, mc;
    TEST_ASSERT_EQUAL_INT(0, sim_run_metrics(&run, &mp, &mc));
    const double rpm = run.speed_sum_rpm / (double)run.speed_n;
    printf("  speed loop: mean speed %.2f r/min, mean torque %.4f N*m, T_rip %.4f N*m\n", rpm,
           mp.torque_mean_nm, mp.torque_ripple_nm);
    TEST_ASSERT_EQUAL_INT(FW_STATE_RUNNING, fw_state(&run.fw));
    TEST_ASSERT_DOUBLE_WITHIN(7.5, 750.0, rpm);
    TEST_ASSERT_DOUBLE_WITHIN(0.02, 1.8, mp.torque_mean_nm);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_bst_fst_hold_torque);
    RUN_TEST(test_speed_loop);
    RUN_TEST(test_fst_speed_reversal);
    RUN_TEST(test_bst_speed_reversal);
    RUN_TEST(test_zst_speed_reversal_unstable);
    return UNITY_END();
}
