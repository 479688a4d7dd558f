/*
 * Commissioning helpers (firmware/commission/cm_core.c) on their own: the
 * duty grid and the applied-voltage record the identification relies on,
 * exact integer ratios and means, the regulator's limit, the step table and
 * its prerequisites, the results' reader (cm_si_field). Host and QEMU
 * (integer code, bit-exact on both).
 */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "../core/machines.h"
#include "cm_config.h"
#include "cm_internal.h"
#include "unity.h"

static cm_t cm;
static ctrl_params_t prm;
static ctrl_bases_t bas;

void setUp(void)
{
    memset(&cm, 0, sizeof cm);
    const ctrl_machine_t m = machine_thesis_spmsm();
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&prm, &bas, &m, 20000u));
    hal_info_t info;
    memset(&info, 0, sizeof info);
    info.pwm_freq_hz = 20000u;
    info.period_counts = 2500u; /* 100 MHz timer, centre-aligned, 20 kHz */
    info.adc_bits = 12u;
    info.adc_current_a_per_count = 2.0 * 12.6 / 4096.0;
    info.adc_vdc_v_per_count = 440.0 / 4096.0;
    info.encoder_counts_per_rev = 10000u;
    info.has_i_c = true;
    cm_config_t c;
    cm_config_default(&c);
    const char *what = NULL;
    TEST_ASSERT_EQUAL_INT(0, cm_configure(&cm, &c, &prm, &bas, &m, &info, 10000u, &what));
    cm.io.vdc = FX_ONE; /* nominal DC link */
}

void tearDown(void)
{
}

/* Duties land on the compare grid: the pipeline's rounding round(d N / 2^24)
 * gives back an integer c with d = c 2^24 / N to a few LSB. */
static void test_modulate_grid(void)
{
    const uint32_t n = cm.par.pwm_n;
    for (int k = 0; k < 64; k++) {
        const q24_t v_al = (q24_t)((k * 2654435761u) % 8000001u) - 4000000; /* +-0.24 pu */
        const q24_t v_be = (q24_t)((k * 40503u + 12345u) % 8000001u) - 4000000;
        cm_out_t out;
        cm_modulate(&cm, v_al, v_be, &out);
        TEST_ASSERT_EQUAL_UINT8(CM_OUT_LEGS, out.mode);
        for (int x = 0; x < 3; x++) {
            const uint64_t c = ((uint64_t)(uint32_t)out.legs[x] * n + (1u << 23)) >> 24;
            const int64_t back = (int64_t)((c << 24) / n);
            TEST_ASSERT_TRUE(out.legs[x] >= 0 && out.legs[x] <= FX_ONE);
            TEST_ASSERT_TRUE((int64_t)out.legs[x] - back <= 16 &&
                             back - (int64_t)out.legs[x] <= 16);
        }
        /* The recorded voltage is what the compare values make: within one
         * compare step (vdc / N = 4e-4 pu) of the request, per axis. */
        const q24_t step = (q24_t)((uint32_t)FX_ONE / n);
        TEST_ASSERT_TRUE(cm.io.va_valid[2]);
        TEST_ASSERT_INT32_WITHIN(step, v_al, cm.io.va_al[2]);
        TEST_ASSERT_INT32_WITHIN(2 * step, v_be, cm.io.va_be[2]);
    }
}

/* Min-max zero sequence: the legs are centred on half the period. */
static void test_modulate_centred(void)
{
    cm_out_t out;
    cm_modulate(&cm, 3000000, -2000000, &out);
    const q24_t hi = fx_max(out.legs[0], fx_max(out.legs[1], out.legs[2]));
    const q24_t lo = fx_min(out.legs[0], fx_min(out.legs[1], out.legs[2]));
    const q24_t step = (q24_t)((uint32_t)FX_ONE / cm.par.pwm_n);
    TEST_ASSERT_INT32_WITHIN(step, FX_ONE / 2, (q24_t)(((int64_t)hi + lo) / 2));
}

static void test_ratio_mean(void)
{
    q24_t r = 0;
    TEST_ASSERT_TRUE(cm_ratio(1, 3, &r));
    TEST_ASSERT_EQUAL_INT32(5592405, r); /* round(2^24 / 3) */
    TEST_ASSERT_TRUE(cm_ratio(-1, 3, &r));
    TEST_ASSERT_EQUAL_INT32(-5592405, r);
    TEST_ASSERT_TRUE(cm_ratio(7, -2, &r));
    TEST_ASSERT_EQUAL_INT32(-7 * (FX_ONE / 2), r);
    TEST_ASSERT_FALSE(cm_ratio(1, 0, &r));
    TEST_ASSERT_FALSE(cm_ratio((int64_t)1 << 40, 1, &r)); /* would overflow */
    TEST_ASSERT_FALSE(cm_ratio(200, 1, &r));              /* 200 pu: beyond Q24 */
    TEST_ASSERT_EQUAL_INT32(3, cm_mean(5, 2));            /* 2.5 rounds away from zero */
    TEST_ASSERT_EQUAL_INT32(-3, cm_mean(-5, 2));
    TEST_ASSERT_EQUAL_INT32(2, cm_mean(7, 3));
    TEST_ASSERT_EQUAL_INT32(0, cm_mean(5, 0));
}

/* The regulator never leaves its limit and does not wind up against it. */
static void test_pi_limit(void)
{
    cm_pi_t pi;
    memset(&pi, 0, sizeof pi);
    cm_pi_tune(&pi, FX_ONE, prm.ts, cm.par.loop_g, FX_ONE / 4);
    TEST_ASSERT_TRUE(pi.kp > 0 && pi.ki > 0);
    for (int k = 0; k < 1000; k++) {
        const q24_t u = cm_pi_step(&pi, FX_ONE);
        TEST_ASSERT_TRUE(u <= FX_ONE / 4);
    }
    TEST_ASSERT_TRUE(pi.sat);
    TEST_ASSERT_TRUE(pi.integ <= FX_ONE / 4);
    /* The error reverses: the output leaves the limit within a few periods. */
    int k = 0;
    while (cm_pi_step(&pi, -FX_ONE / 100) >= FX_ONE / 4 && k < 10) {
        k++;
    }
    TEST_ASSERT_TRUE(k < 10);
}

static void test_prepare_needs(void)
{
    uint8_t missing = 0;
    const uint8_t rs[] = {CM_STEP_RS};
    TEST_ASSERT_EQUAL_INT(CM_E_NEEDS, cm_prepare(&cm, rs, 1, &missing));
    TEST_ASSERT_EQUAL_UINT8(CM_STEP_ENCODER, missing);
    const uint8_t enc[] = {CM_STEP_ENCODER};
    TEST_ASSERT_EQUAL_INT(CM_E_NEEDS, cm_prepare(&cm, enc, 1, &missing));
    TEST_ASSERT_EQUAL_UINT8(CM_STEP_PROBE, missing);
    const uint8_t seq[] = {CM_STEP_VBUS, CM_STEP_PROBE, CM_STEP_ENCODER,
                           CM_STEP_RS,   CM_STEP_LDQ,   CM_STEP_FLUX};
    TEST_ASSERT_EQUAL_INT(CM_E_NONE, cm_prepare(&cm, seq, 6, &missing));
    const uint8_t flux[] = {CM_STEP_PROBE, CM_STEP_ENCODER, CM_STEP_FLUX};
    TEST_ASSERT_EQUAL_INT(CM_E_NEEDS, cm_prepare(&cm, flux, 3, &missing));
    TEST_ASSERT_EQUAL_UINT8(CM_STEP_LDQ, missing);
    const uint8_t bring[] = {CM_STEP_GATES, CM_STEP_SENSE, CM_STEP_RUN};
    TEST_ASSERT_EQUAL_INT(CM_E_NONE, cm_prepare(&cm, bring, 3, &missing));
}

/* Every step and error has a distinct name; names find their step. */
static void test_names(void)
{
    for (uint8_t s = 1; s < CM_STEP_COUNT; s++) {
        TEST_ASSERT_EQUAL_UINT8(s, cm_step_find(cm_step_name(s)));
    }
    TEST_ASSERT_EQUAL_UINT8(CM_STEP_NONE, cm_step_find("nope"));
    for (uint8_t a = 0; a < CM_E_COUNT; a++) {
        TEST_ASSERT_NOT_NULL(cm_err_name(a));
        TEST_ASSERT_TRUE(strcmp(cm_err_name(a), "?") != 0);
        for (uint8_t b = (uint8_t)(a + 1u); b < CM_E_COUNT; b++) {
            TEST_ASSERT_TRUE(strcmp(cm_err_name(a), cm_err_name(b)) != 0);
        }
    }
}

/* A stop or a protection ends the sequence and invalidates the running
 * step's results; the probe's over-current is a shorted phase. */
static void test_abort(void)
{
    cm.res.have = CM_HAVE_LPROBE | CM_HAVE_ENC;
    const uint8_t seq[] = {CM_STEP_ENCODER};
    TEST_ASSERT_EQUAL_INT(CM_E_NONE, cm_prepare(&cm, seq, 1, NULL));
    cm_begin(&cm);
    cm_abort_stop(&cm);
    TEST_ASSERT_EQUAL_UINT8(CM_E_STOPPED, cm.err);
    TEST_ASSERT_FALSE(cm.active);
    TEST_ASSERT_EQUAL_UINT32(CM_HAVE_LPROBE, cm.res.have);
    const uint8_t probe[] = {CM_STEP_PROBE};
    TEST_ASSERT_EQUAL_INT(CM_E_NONE, cm_prepare(&cm, probe, 1, NULL));
    cm_begin(&cm);
    cm_abort_fault(&cm, 1u);
    TEST_ASSERT_EQUAL_UINT8(CM_E_SHORTED_PHASE, cm.err);
    TEST_ASSERT_EQUAL_UINT32(0u, cm.res.have & CM_HAVE_LPROBE);
}

/* The results' reader: each kind from its field's own type, and which
 * results are listed (the mechanics only with a finite inertia > 0). */
static void test_si_field(void)
{
    cm_si_t r;
    memset(&r, 0, sizeof r);
    r.have = CM_HAVE_ENC | CM_HAVE_LDQ | CM_HAVE_MECH;
    r.enc_dir = -1;
    r.enc_cpr = 4000000001u; /* beyond INT32_MAX: read unsigned */
    r.salient = true;
    r.ld_h = 0.375e-3;
    r.lq_h = 1.5;
    TEST_ASSERT_EQUAL_DOUBLE(-1.0, cm_si_field(&r, offsetof(cm_si_t, enc_dir), CM_FIELD_INT));
    TEST_ASSERT_EQUAL_DOUBLE(4000000001.0,
                             cm_si_field(&r, offsetof(cm_si_t, enc_cpr), CM_FIELD_U32));
    TEST_ASSERT_EQUAL_DOUBLE(1.0, cm_si_field(&r, offsetof(cm_si_t, salient), CM_FIELD_BOOL));
    TEST_ASSERT_EQUAL_DOUBLE(0.375, cm_si_field(&r, offsetof(cm_si_t, ld_h), CM_FIELD_MILLI));
    TEST_ASSERT_EQUAL_DOUBLE(1.5, cm_si_field(&r, offsetof(cm_si_t, lq_h), CM_FIELD_SI));
    TEST_ASSERT_TRUE(cm_si_has(&r, CM_HAVE_ENC));
    TEST_ASSERT_FALSE(cm_si_has(&r, CM_HAVE_RS));
    const double inertia[4] = {NAN, INFINITY, 0.0, 2e-5};
    for (int k = 0; k < 4; k++) {
        r.inertia_kgm2 = inertia[k];
        TEST_ASSERT_EQUAL_INT(k == 3, cm_si_has(&r, CM_HAVE_MECH));
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_modulate_grid);
    RUN_TEST(test_modulate_centred);
    RUN_TEST(test_ratio_mean);
    RUN_TEST(test_pi_limit);
    RUN_TEST(test_prepare_needs);
    RUN_TEST(test_names);
    RUN_TEST(test_abort);
    RUN_TEST(test_si_field);
    return UNITY_END();
}
