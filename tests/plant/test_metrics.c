/*
 * Performance indices (thesis Appendix B) on synthetic signals whose
 * values are known in closed form.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "metrics.h"
#include "plant.h"
#include "unity.h"

void setUp(void)
{
}
void tearDown(void)
{
}

/* T = 2 + 0.3 sin(2 pi 500 t) + 0.1 cos(2 pi 3000 t), |psi| = 0.1 + 0.004 sin(..),
 * sampled uniformly over an integer number of periods of every component:
 * mean 2, std sqrt(0.3^2/2 + 0.1^2/2) exactly (discrete orthogonality). */
static void test_mean_std_sse(void)
{
    metrics_acc_t m;
    metrics_init(&m, METRICS_SAMPLING_PLANT, 0.0);
    const double h = 5e-6;
    const int n = 4000; /* 20 ms: 10 periods of 500 Hz, 60 of 3 kHz */
    for (int k = 0; k < n; ++k) {
        const double t = k * h;
        const double T =
            2.0 + 0.3 * sin(2 * PLANT_PI * 500 * t) + 0.1 * cos(2 * PLANT_PI * 3000 * t);
        const double psi = 0.1 + 0.004 * sin(2 * PLANT_PI * 1000 * t + 0.2);
        metrics_add(&m, t, T, 2.05, psi, 0.0);
    }
    metrics_result_t r;
    TEST_ASSERT_EQUAL_INT(0, metrics_finish(&m, &r));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 2.0, r.torque_mean_nm);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, sqrt(0.045 + 0.005), r.torque_ripple_nm);
    TEST_ASSERT_DOUBLE_WITHIN(1e-13, 0.1, r.flux_mean_wb);
    TEST_ASSERT_DOUBLE_WITHIN(1e-13, 0.004 / sqrt(2.0), r.flux_ripple_wb);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.05, r.torque_sse_nm); /* (B.2) mean(Tref - T) */
    TEST_ASSERT_TRUE(isnan(r.f_av_hz));
    TEST_ASSERT_TRUE(isnan(r.thd_i_pct));
    TEST_ASSERT_EQUAL_UINT32((uint32_t)n, (uint32_t)r.samples);
    metrics_free(&m);
}

/* i_a = 10 sin(w1 t) + 0.5 sin(5 w1 t + 0.3) + 0.2 cos(7 w1 t): THD =
 * sqrt(0.5^2 + 0.2^2) / 10 = 5.385 %. f1 = 50 Hz, sampled at 20 kHz over
 * 2.5 fundamental periods: THD uses the 2 whole periods. */
static void test_thd_known(void)
{
    metrics_acc_t m;
    metrics_init(&m, METRICS_SAMPLING_PLANT, 50.0);
    const double h = 50e-6, w1 = 2 * PLANT_PI * 50;
    for (int k = 0; k <= 1000; ++k) {   /* 50 ms */
        const double t = 0.013 + k * h; /* window not starting at 0 */
        const double ia = 10 * sin(w1 * t) + 0.5 * sin(5 * w1 * t + 0.3) + 0.2 * cos(7 * w1 * t);
        metrics_add(&m, t, 1.0, 1.0, 0.1, ia);
    }
    metrics_result_t r;
    TEST_ASSERT_EQUAL_INT(0, metrics_finish(&m, &r));
    const double thd = 100.0 * sqrt(0.25 + 0.04) / 10.0;
    char msg[96];
    snprintf(msg, sizeof msg, "THD %.12g %% (exact %.12g %%), N = %d", r.thd_i_pct, thd,
             r.thd_harmonics);
    TEST_MESSAGE(msg);
    /* trapezoid on whole periods of a band-limited periodic signal: exact to rounding */
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, thd, r.thd_i_pct);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 10.0, r.i1_amp_a);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.04, r.thd_window_s);
    TEST_ASSERT_EQUAL_INT(200, r.thd_harmonics); /* 10 kHz / 50 Hz (Nyquist 10 kHz) */
    metrics_free(&m);

    /* a window shorter than one fundamental period gives no THD */
    metrics_init(&m, METRICS_SAMPLING_PLANT, 50.0);
    for (int k = 0; k < 100; ++k) {
        metrics_add(&m, k * h, 1.0, 1.0, 0.1, sin(w1 * k * h));
    }
    TEST_ASSERT_EQUAL_INT(0, metrics_finish(&m, &r));
    TEST_ASSERT_TRUE(isnan(r.thd_i_pct));
    metrics_free(&m);
}

/* Harmonics above 10 kHz are excluded from (B.3). */
static void test_thd_band_limit(void)
{
    const double f1 = 100.0, w1 = 2 * PLANT_PI * f1, h = 1e-6; /* Nyquist 500 kHz */
    static double t[20001], x[20001];
    for (int k = 0; k <= 20000; ++k) { /* 2 periods */
        t[k] = k * h;
        x[k] = 4 * sin(w1 * t[k]) + 0.4 * sin(11 * w1 * t[k]) + 1.0 * sin(150 * w1 * t[k]);
    }
    int n;
    double win, a1;
    const double thd = metrics_thd_pct(t, x, 20001, f1, 10e3, &n, &win, &a1);
    TEST_ASSERT_EQUAL_INT(100, n);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 10.0, thd); /* the 15 kHz component is outside */
}

/* f_av = transitions / (2 * 3 * window) (thesis Appendix B, per switch and second). */
static void test_f_av(void)
{
    metrics_acc_t m;
    metrics_init(&m, METRICS_SAMPLING_CONTROL, 0.0);
    metrics_add(&m, 0.0, 1.0, 1.0, 0.1, 0.0);
    /* three legs each switching on and off once per 100 us for 0.1 s */
    metrics_set_transitions(&m, 3u * 2u * 1000u, 0.1);
    metrics_result_t r;
    TEST_ASSERT_EQUAL_INT(0, metrics_finish(&m, &r));
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 10e3, r.f_av_hz);
    TEST_ASSERT_EQUAL_INT(METRICS_SAMPLING_CONTROL, r.sampling);
    metrics_free(&m);
}

static void test_empty_and_json(void)
{
    metrics_acc_t m;
    metrics_init(&m, METRICS_SAMPLING_PLANT, 0.0);
    metrics_result_t r;
    TEST_ASSERT_EQUAL_INT(-1, metrics_finish(&m, &r));
    TEST_ASSERT_EQUAL_INT(-1, metrics_finish(NULL, &r));
    metrics_add(&m, 0.0, 1.5, 2.0, 0.1, 0.0);
    metrics_add(&m, 1e-5, 2.5, 2.0, 0.1, 0.0);
    TEST_ASSERT_EQUAL_INT(0, metrics_finish(&m, &r));
    FILE *f = tmpfile();
    TEST_ASSERT_NOT_NULL(f);
    metrics_write_json(f, &r);
    rewind(f);
    char buf[1024];
    const size_t n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = '\0';
    fclose(f);
    TEST_ASSERT_NOT_NULL(strstr(buf, "\"torque_mean_nm\": 2,"));
    TEST_ASSERT_NOT_NULL(strstr(buf, "\"torque_ripple_nm\": 0.5,"));
    TEST_ASSERT_NOT_NULL(strstr(buf, "\"f_av_hz\": null,"));
    TEST_ASSERT_NOT_NULL(strstr(buf, "\"sampling\": \"plant_grid\""));
    metrics_free(&m);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_mean_std_sse);
    RUN_TEST(test_thd_known);
    RUN_TEST(test_thd_band_limit);
    RUN_TEST(test_f_av);
    RUN_TEST(test_empty_and_json);
    return UNITY_END();
}
