/*
 * Closed loop on the host (plant + HAL sim + firmware pipeline),
 * thesis SPMSM, load point of thesis §5.6: 1.8 N*m at 750 and 2250 r/min,
 * dynamometer (imposed speed), torque mode. DRR methods at 10 kHz, BST at
 * 20 kHz (thesis §5.6: DRR methods at half the CDTC sampling frequency).
 * Indices (thesis Appendix B, (B.1)-(B.2)) from the plant's true torque on a Ts/10 grid
 * (plant sampling), window 30..70 ms after arming.
 *
 * What the thesis reports (§5.6.2, Fig. 5.17, thesis §5.6.2): torque ripple of
 * the proposed DRR -65 % vs CDTC, -15 % vs D1, -41 % vs D2; |T_sse| lower by
 * 92 % (CDTC), 95 % (D1), 76 % (D2). Asserted ratios (margin: each thesis
 * improvement about halved, the 15 % over D1 reduced to "not worse"):
 *   T_rip(drr) <= 0.65 T_rip(bst)      (thesis 0.35)
 *   T_rip(drr) <= 1.00 T_rip(drr_d1)   (thesis 0.85)
 *   T_rip(drr) <= 0.80 T_rip(drr_d2)   (thesis 0.59)
 *   |T_sse(drr)| <= 0.5 min(|T_sse| of bst, drr_d1, drr_d2)   (thesis <= 0.24)
 * Dynamic (thesis Fig. 5.12): T_ref 0 -> 2 N*m, -2 N*m once the speed reaches
 * 75 % of rated (2250 r/min), free mechanics with a passive 1.6 N*m load (the
 * reversal scenario of the closed-loop tests): the speed reverses without a fault and the
 * torque holds -2 N*m afterwards; fall time (step to 90 % of the 4 N*m step,
 * T <= -1.6 N*m) < 1 ms.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "loop_util.h"
#include "sim_run.h"
#include "unity.h"

#define T_RATED 2.4
#define T_LOAD 1.8

static sim_run_t run;

void setUp(void)
{
}

void tearDown(void)
{
}

typedef struct {
    double rip, sse, psi_rip, f_av, thd;
} res_t;

static res_t steady(const char *name, double rpm, double tref)
{
    sim_run_cfg_t c;
    /* 30 ms to settle (the EMA (5.4) time constant is 1/(lambda fs) = 3.3 ms),
     * then a 40 ms window: 2 and 6 electrical periods at 750 and 2250 r/min. */
    loop_cfg(&c, name, rpm, tref, 0.07, 0.03);
    loop_start(&run, &c);
    char err[256];
    if (sim_run_all(&run, err, sizeof err) != 0) {
        sim_run_free(&run);
        TEST_FAIL_MESSAGE(err);
    }
    metrics_result_t mp;
    metrics_result_t mc;
    TEST_ASSERT_EQUAL_INT(0, sim_run_metrics(&run, &mp, &mc));
    const int state = (int)fw_state(&run.fw);
    const uint32_t fault = fw_fault(&run.fw);
    sim_run_free(&run);
    TEST_ASSERT_EQUAL_INT_MESSAGE(FW_STATE_RUNNING, state, fw_fault_name(fault));
    res_t r = {mp.torque_ripple_nm, mp.torque_sse_nm, mp.flux_ripple_wb, mp.f_av_hz, mp.thd_i_pct};
    printf("  %-7s %5.0f kHz %+6.0f r/min: T_rip %.4f N*m  T_sse %+.4f N*m  psi_rip %.2f mWb  "
           "f_av %5.0f Hz  THD %.2f %%\n",
           name, c.fs_hz / 1000.0, rpm, r.rip, r.sse, r.psi_rip * 1e3, r.f_av, r.thd);
    return r;
}

static void compare_at(double rpm)
{
    const res_t b = steady("bst", rpm, T_LOAD);
    const res_t d1 = steady("drr_d1", rpm, T_LOAD);
    const res_t d2 = steady("drr_d2", rpm, T_LOAD);
    const res_t p = steady("drr", rpm, T_LOAD);
    printf("  ratios at %+.0f r/min: T_rip drr/bst %.3f, drr/d1 %.3f, drr/d2 %.3f; "
           "|T_sse| drr/bst %.3f, drr/d1 %.3f, drr/d2 %.3f\n",
           rpm, p.rip / b.rip, p.rip / d1.rip, p.rip / d2.rip, fabs(p.sse) / fabs(b.sse),
           fabs(p.sse) / fabs(d1.sse), fabs(p.sse) / fabs(d2.sse));
    char msg[160];
    snprintf(msg, sizeof msg, "%+.0f r/min: T_rip drr %.4f vs bst %.4f", rpm, p.rip, b.rip);
    TEST_ASSERT_TRUE_MESSAGE(p.rip <= 0.65 * b.rip, msg);
    snprintf(msg, sizeof msg, "%+.0f r/min: T_rip drr %.4f vs drr_d1 %.4f", rpm, p.rip, d1.rip);
    TEST_ASSERT_TRUE_MESSAGE(p.rip <= 1.00 * d1.rip, msg);
    snprintf(msg, sizeof msg, "%+.0f r/min: T_rip drr %.4f vs drr_d2 %.4f", rpm, p.rip, d2.rip);
    TEST_ASSERT_TRUE_MESSAGE(p.rip <= 0.80 * d2.rip, msg);
    const double others = fmin(fabs(b.sse), fmin(fabs(d1.sse), fabs(d2.sse)));
    snprintf(msg, sizeof msg, "%+.0f r/min: |T_sse| drr %.4f vs best other %.4f", rpm, fabs(p.sse),
             others);
    TEST_ASSERT_TRUE_MESSAGE(fabs(p.sse) <= 0.5 * others, msg);
}

static void test_steady_750(void)
{
    compare_at(750.0);
}

static void test_steady_2250(void)
{
    compare_at(2250.0);
}

/* Backward motoring (Fig. 3.9 quadrant III) and forward braking (II): the
 * virtual reference removes the offset in every quadrant (thesis Fig. 5.13:
 * negligible T_sse in both directions); bound 1 % of T_rated. */
static void test_other_quadrants(void)
{
    const res_t bw = steady("drr", -750.0, -T_LOAD);
    TEST_ASSERT_TRUE(fabs(bw.sse) <= 0.01 * T_RATED);
    const res_t br = steady("drr", 750.0, -T_LOAD);
    TEST_ASSERT_TRUE(fabs(br.sse) <= 0.01 * T_RATED);
    const res_t bb = steady("drr", -2250.0, T_LOAD);
    TEST_ASSERT_TRUE(fabs(bb.sse) <= 0.01 * T_RATED);
}

/* The other baselines run and hold the torque at 750 r/min within the bound
 * the thesis measures for switching-table DTC (|T_sse| <= 20 % T_rated,
 * Fig. 5.3). (At 2250 r/min D_PI with our default gains misses it; printed by
 * the report, not asserted.) */
static void test_baselines_run(void)
{
    const res_t pi = steady("drr_pi", 750.0, T_LOAD);
    TEST_ASSERT_TRUE(fabs(pi.sse) <= 0.2 * T_RATED);
    const res_t df = steady("drr_df", 750.0, T_LOAD);
    TEST_ASSERT_TRUE(fabs(df.sse) <= 0.2 * T_RATED);
}

/* Speed reversal of thesis Fig. 5.12. */
static void test_reversal(void)
{
    sim_run_cfg_t c;
    loop_cfg(&c, "drr", 0.0, 0.0, 0.3, 0.0);
    /* 20 ms of backward motoring: gamma is still settling after the 4 N*m step. */
    const loop_reversal_t r = loop_reversal(&run, &c,
                                            "at 0 torque_ref=0 load=1.6\n"
                                            "at 0.002 torque_ref=2\n"
                                            "when speed>=2250 torque_ref=-2\n"
                                            "when speed<=0 load=-1.6\n",
                                            -1.6, 0.020, "drr");
    TEST_ASSERT_EQUAL_UINT32_MESSAGE(FW_FAULT_NONE, r.fault, fw_fault_name(r.fault));
    TEST_ASSERT_TRUE_MESSAGE(r.reached, "speed never reached 2250 r/min");
    TEST_ASSERT_TRUE_MESSAGE(r.min_rpm_after <= -1000.0, "speed did not reverse");
    TEST_ASSERT_TRUE_MESSAGE(r.t_fall_ms < 1.0, "torque fall time >= 1 ms");
    /* Stable after the reversal: over the last 10 ms (speed below -1000 r/min)
     * the mean torque is within 2 % of T_rated of -2 N*m (gamma is still
     * settling: the EMA time constant is 3.3 ms and the reference stepped by
     * 4 N*m) and the ripple stays below 5 % of T_rated (the steady-state DRR
     * ripple scale: a sawtooth of +-gamma, gamma ~ B |w| / w_rn / |C|). */
    TEST_ASSERT_DOUBLE_WITHIN(0.02 * T_RATED, -2.0, r.tq_back_mean);
    TEST_ASSERT_TRUE(r.tq_back_rip < 0.05 * T_RATED);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_steady_750);
    RUN_TEST(test_steady_2250);
    RUN_TEST(test_other_quadrants);
    RUN_TEST(test_baselines_run);
    RUN_TEST(test_reversal);
    return UNITY_END();
}
