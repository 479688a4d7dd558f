/*
 * Closed loop on the host (plant + HAL sim + firmware pipeline), the chapter's controllers:
 *
 * 1. foc on the thesis SPMSM, dynamometer 750 r/min, T_ref 1.8 N*m: mean
 *    torque within 2 %, current error zero-mean (mean i_q,ref - i_q and mean
 *    i_d within 2 % of i_q,ref = 1.8 / (1.5 p psi_pm) = 3.18 A), from the
 *    plant's true currents at the control instants.
 * 2. The chapter's case (S1 §5.3): chapter IPMSM (S1 Table 2), fs 10 kHz,
 *    free mechanics with 2 N*m load, speed loop closed at 70 rad/s
 *    (668.45 r/min), started at that speed: torque ripple, peak-to-peak and
 *    std of the plant's true torque on the Ts/10 grid (plant sampling) over
 *    150..300 ms (after the speed loop has recovered from the load applied
 *    at t = 0), of hdtc vs hpdtc (foc, svm_dtc, foc_hyst, hdtc_pred printed
 *    too). S1 reports 3.2 N*m p-p for HDTC and < 0.15 N*m for HP-DTC (a
 *    factor > 20). hdtc decides on the sampled errors as S1 does (measured
 *    1.19 N*m p-p); hdtc_pred, on the k+1 prediction, ripples about half as
 *    much. Asserted: hpdtc p-p and std <= 0.5 x hdtc's (at least halved: the
 *    measured ratios are 0.14 and 0.13), hpdtc p-p < 0.3 N*m (2x S1's
 *    < 0.15 N*m: measured 0.17, its excess over 0.15 the speed PI passing
 *    the 2500-line encoder's speed quantisation to the torque reference;
 *    HP-DTC's own ripple is inside 0.15, test report_analyses), both holding
 *    the speed (mean within 1 %) and the load (mean torque within 2 %).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "ctrl_units.h"
#include "loop_util.h"
#include "sim_run.h"
#include "unity.h"

static sim_run_t run;

void setUp(void)
{
}
void tearDown(void)
{
}

static void test_foc_spmsm_750(void)
{
    sim_run_cfg_t c;
    loop_cfg(&c, "foc", 750.0, 1.8, 0.1, 0.05);
    loop_start(&run, &c);
    const double iq_ref = 1.8 / (1.5 * 4.0 * 0.09427);
    double sum_eq = 0.0;
    double sum_d = 0.0;
    long n = 0;
    while (sim_run_time(&run) < c.duration_s) {
        TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run));
        if (sim_run_time(&run) >= c.win_start_s) {
            double id;
            double iq;
            plant_i_dq(&run.plant, &id, &iq);
            sum_eq += iq_ref - iq;
            sum_d += id;
            n++;
        }
    }
    metrics_result_t mp;
    metrics_result_t mc;
    TEST_ASSERT_EQUAL_INT(0, sim_run_metrics(&run, &mp, &mc));
    const int state = (int)fw_state(&run.fw);
    const uint32_t fault = fw_fault(&run.fw);
    sim_run_free(&run);
    TEST_ASSERT_EQUAL_INT_MESSAGE(FW_STATE_RUNNING, state, fw_fault_name(fault));
    TEST_ASSERT_TRUE(n > 100);
    printf("  foc SPMSM 750 r/min: T_mean %.4f N*m  T_rip %.4f N*m  mean(iq_ref - iq) %+.4f A  "
           "mean(id) %+.4f A  THD %.2f %%\n",
           mp.torque_mean_nm, mp.torque_ripple_nm, sum_eq / n, sum_d / n, mp.thd_i_pct);
    TEST_ASSERT_DOUBLE_WITHIN(0.02 * 1.8, 1.8, mp.torque_mean_nm);
    TEST_ASSERT_DOUBLE_WITHIN(0.02 * iq_ref, 0.0, sum_eq / n);
    TEST_ASSERT_DOUBLE_WITHIN(0.02 * iq_ref, 0.0, sum_d / n);
}

typedef struct {
    double pp, std, mean, speed;
} ripple_t;

#define W_RPM (70.0 * 60.0 / (2.0 * CTRL_PI))

static ripple_t chapter_case(const char *name)
{
    const sim_machine_t m = loop_machine_file("chapter_ipmsm.ini");
    sim_run_cfg_t c;
    /* the window after the speed loop's recovery from the load at t = 0 */
    loop_cfg_machine(&c, &m, name, 0u, W_RPM, 0.0, 0.3, 0.15);
    TEST_ASSERT_EQUAL_UINT32(10000u, c.fs_hz); /* S1: 100 us */
    c.free_mech = true;
    c.load_nm = 2.0;
    c.speed_mode = true;
    c.speed_ref_rpm = W_RPM;
    FILE *tr = tmpfile();
    TEST_ASSERT_NOT_NULL(tr);
    c.trace = tr;
    c.trace_decimation = 1u;
    c.trace_start_s = c.win_start_s;
    c.trace_end_s = c.win_end_s;
    char err[256];
    if (sim_run_init(&run, &c, err, sizeof err) != 0) {
        fclose(tr);
        TEST_FAIL_MESSAGE(err);
    }
    const int rc = sim_run_all(&run, err, sizeof err);
    const int state = (int)fw_state(&run.fw);
    const uint32_t fault = fw_fault(&run.fw);
    sim_run_free(&run);
    if (rc != 0) {
        fclose(tr);
        TEST_FAIL_MESSAGE(err);
    }
    TEST_ASSERT_EQUAL_INT_MESSAGE(FW_STATE_RUNNING, state, fw_fault_name(fault));
    /* Trace: t,i_a,i_b,i_c,i_d,i_q,psi_s,torque,speed_rpm,... (Ts/10 grid). */
    rewind(tr);
    char line[512];
    double tmin = 1e9;
    double tmax = -1e9;
    double s1 = 0.0;
    double s2 = 0.0;
    double sp = 0.0;
    long n = 0;
    while (fgets(line, sizeof line, tr) != NULL) {
        double v[9];
        if (sscanf(line, "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &v[0], &v[1], &v[2], &v[3], &v[4],
                   &v[5], &v[6], &v[7], &v[8]) != 9) {
            continue; /* header */
        }
        tmin = fmin(tmin, v[7]);
        tmax = fmax(tmax, v[7]);
        s1 += v[7];
        s2 += v[7] * v[7];
        sp += v[8];
        n++;
    }
    fclose(tr);
    TEST_ASSERT_TRUE(n > 5000);
    ripple_t r;
    r.pp = tmax - tmin;
    r.mean = s1 / n;
    r.std = sqrt(fmax(s2 / n - r.mean * r.mean, 0.0));
    r.speed = sp / n;
    printf("  %-8s chapter IPMSM 70 rad/s, 2 N*m: T p-p %.4f N*m  T std %.4f N*m  T_mean %.4f "
           "N*m  speed %.2f r/min\n",
           name, r.pp, r.std, r.mean, r.speed);
    TEST_ASSERT_DOUBLE_WITHIN(0.01 * W_RPM, W_RPM, r.speed);
    TEST_ASSERT_DOUBLE_WITHIN(0.02 * 2.0, 2.0, r.mean);
    return r;
}

static void test_chapter_hdtc_vs_hpdtc(void)
{
    const ripple_t h = chapter_case("hdtc");
    const ripple_t p = chapter_case("hpdtc");
    printf("  hpdtc / hdtc: p-p %.3f, std %.3f (S1: < 0.15 / 3.2 = 0.047)\n", p.pp / h.pp,
           p.std / h.std);
    TEST_ASSERT_TRUE(p.pp <= 0.5 * h.pp);
    TEST_ASSERT_TRUE(p.std <= 0.5 * h.std);
    TEST_ASSERT_TRUE(p.pp < 0.3);
}

static void test_chapter_others(void)
{
    /* The other chapter controllers in the same case: they hold speed and load. */
    chapter_case("foc");
    chapter_case("svm_dtc");
    chapter_case("foc_hyst");
    chapter_case("hdtc_pred");
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_foc_spmsm_750);
    RUN_TEST(test_chapter_hdtc_vs_hpdtc);
    RUN_TEST(test_chapter_others);
    return UNITY_END();
}
