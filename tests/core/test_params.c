/*
 * ctrl_params_init (bases, Q24 fit, rejection of bad machines), the Q24
 * conversion helpers, MTPA ((4.15)-(4.16) for the thesis SPMSM and the IPMSM
 * table), the speed filter coefficient, the speed PI and the tunables API.
 */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "controller.h"
#include "ctrl_params.h"
#include "ctrl_units.h"
#include "est_fixture.h"
#include "estimator.h"
#include "machines.h"
#include "mtpa.h"
#include "speed_pi.h"
#include "speed_pi_config.h"
#include "unity.h"

void setUp(void)
{
}
void tearDown(void)
{
}

#define LSB (1.0 / 16777216.0)

static double d(q24_t x)
{
    return (double)x * LSB;
}

static int all_zero(const void *p, size_t n)
{
    const unsigned char *c = p;
    for (size_t i = 0; i < n; i++) {
        if (c[i] != 0u) {
            return 0;
        }
    }
    return 1;
}

static void test_bases_spmsm(void)
{
    const ctrl_machine_t spm = machine_thesis_spmsm();
    ctrl_params_t p;
    ctrl_bases_t b;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&p, &b, &spm, 10000u));
    /* Bases (ctrl_params.h): psi_pm, the rated electrical speed, V = psi w, Ld. */
    const double wb = 4 * 3000 * 2 * CTRL_PI / 60;
    const double vb = 0.09427 * wb;
    const double ib = 0.09427 / 6.552e-3;
    TEST_ASSERT_DOUBLE_WITHIN(1e-12 * wb, wb, b.w_rad_s);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 1.0 / wb, b.t_s);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12 * vb, vb, b.v_v);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12 * ib, ib, b.i_a);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 1.5 * 4 * 0.09427 * ib, b.torque_nm);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, vb / ib, b.r_ohm);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, wb * 6.552e-3, b.r_ohm); /* w_base l_base */
    /* the per-unit values follow from the data, none is assumed */
    TEST_ASSERT_EQUAL_INT32(FX_ONE, p.ld);
    TEST_ASSERT_EQUAL_INT32(FX_ONE, p.lq);
    TEST_ASSERT_EQUAL_INT32(FX_ONE, p.psi_pm);
    TEST_ASSERT_EQUAL_INT32(FX_ONE, p.inv_psi_pm);
    TEST_ASSERT_EQUAL_INT32(FX_ONE, p.speed_rated_e);
    TEST_ASSERT_EQUAL_UINT8(0u, p.salient);
    /* each Q24 field is the rounded pu value: error <= 0.5 LSB */
    TEST_ASSERT_TRUE(fabs(d(p.vdc_nom) - 220.0 / vb) <= 0.5 * LSB); /* 1.857: DC link / EMF */
    TEST_ASSERT_TRUE(fabs(d(p.ts) - wb * 1e-4) <= 0.5 * LSB); /* rad per period at rated speed */
    TEST_ASSERT_TRUE(fabs(d(p.rs) - 0.901 / (vb / ib)) <= 0.5 * LSB);
    TEST_ASSERT_TRUE(fabs(d(p.ts_rs) - 1e-4 * 0.901 / 6.552e-3) <= 0.5 * LSB); /* Ts / tau */
    TEST_ASSERT_TRUE(fabs(d(p.current_max) - 8.4 / ib) <= 0.5 * LSB);
    /* Thesis SPMSM: omega_e psi_pm at 3000 r/min = 118.5 V: the voltage base */
    TEST_ASSERT_DOUBLE_WITHIN(0.05, 118.5, b.v_v);
    /* angle increment per period: Ts_pu / (2 pi) turns, integer rounding */
    TEST_ASSERT_DOUBLE_WITHIN(0.5, wb * 1e-4 / (2 * CTRL_PI) * 4294967296.0,
                              (double)p.omega_to_dangle);
    /* inverse: dtheta * m / 2^26 = dtheta * 2^24 / k_ang, m rounded (0.5 / 2^26) */
    const double inv = ldexp((double)p.dangle_to_omega, -(int)CTRL_DANGLE_SHIFT);
    const double inv_exact = 16777216.0 / (wb * 1e-4 / (2 * CTRL_PI) * 4294967296.0);
    TEST_ASSERT_DOUBLE_WITHIN(ldexp(0.5, -(int)CTRL_DANGLE_SHIFT) + inv_exact * 1e-15, inv_exact,
                              inv);
    /* speed filter: 1 - exp(-2 pi fc / fs) */
    TEST_ASSERT_TRUE(fabs(d(p.speed_lpf_k) - (1.0 - exp(-2 * CTRL_PI * CTRL_SPEED_LPF_HZ_DEFAULT /
                                                        1e4))) <= 0.5 * LSB);
}

static void test_bases_ipmsm(void)
{
    const ctrl_machine_t ipm = machine_thesis_ipmsm80();
    const ctrl_machine_t chap = machine_chapter_ipmsm();
    ctrl_params_t p;
    ctrl_bases_t b;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&p, &b, &ipm, 20000u));
    TEST_ASSERT_EQUAL_UINT8(1u, p.salient);
    TEST_ASSERT_TRUE(fabs(d(p.lq) - 1.33 / 0.6) <= 0.5 * LSB);
    TEST_ASSERT_TRUE(fabs(d(p.inv_lq) - 0.6 / 1.33) <= 0.5 * LSB);
    TEST_ASSERT_TRUE(fabs(d(p.psi_ref) - 0.1837 / 0.1875) <= 0.5 * LSB);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&p, &b, &chap, 10000u));
    TEST_ASSERT_EQUAL_UINT8(1u, p.salient);
}

static void expect_reject(const ctrl_machine_t *m, uint32_t fs, int code)
{
    ctrl_params_t p;
    ctrl_bases_t b;
    memset(&p, 0x5A, sizeof p);
    memset(&b, 0x5A, sizeof b);
    TEST_ASSERT_EQUAL_INT(code, ctrl_params_init(&p, &b, m, fs));
    TEST_ASSERT_TRUE_MESSAGE(all_zero(&p, sizeof p), "params not zeroed on error");
    TEST_ASSERT_TRUE_MESSAGE(all_zero(&b, sizeof b), "bases not zeroed on error");
}

static void test_reject_bad_machines(void)
{
    const ctrl_machine_t spm = machine_thesis_spmsm();
    ctrl_params_t p;
    ctrl_bases_t b;
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_params_init(NULL, &b, &spm, 10000u));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_params_init(&p, NULL, &spm, 10000u));
    expect_reject(NULL, 10000u, CTRL_EINVAL);
    expect_reject(&spm, 0u, CTRL_EINVAL);
    const double nan = NAN;
    const double inf = INFINITY;
    ctrl_machine_t m;
#define BAD(field, value, code)                                                                    \
    do {                                                                                           \
        m = spm;                                                                                   \
        m.field = (value);                                                                         \
        expect_reject(&m, 10000u, (code));                                                         \
    } while (0)
    BAD(rs_ohm, -0.901, CTRL_EINVAL);
    BAD(rs_ohm, nan, CTRL_EINVAL);
    BAD(rs_ohm, 1.0e4, CTRL_EINVAL); /* absurd: 1e4 ohm */
    BAD(ld_h, 0.0, CTRL_EINVAL);
    BAD(lq_h, 0.0, CTRL_EINVAL);
    BAD(ld_h, -1e-3, CTRL_EINVAL);
    BAD(lq_h, nan, CTRL_EINVAL);
    BAD(psi_pm_wb, 0.0, CTRL_EINVAL);
    BAD(psi_pm_wb, inf, CTRL_EINVAL);
    BAD(vdc_v, 0.0, CTRL_EINVAL);
    BAD(vdc_v, 1.0e7, CTRL_EINVAL); /* absurd: 10 MV */
    BAD(inertia_kgm2, 0.0, CTRL_EINVAL);
    BAD(torque_rated_nm, -2.4, CTRL_EINVAL);
    BAD(speed_rated_rpm, nan, CTRL_EINVAL);
    BAD(current_rated_a, 0.0, CTRL_EINVAL);
    BAD(current_max_a, 4.0, CTRL_EINVAL); /* below rated */
    BAD(psi_ref_wb, -0.1, CTRL_EINVAL);
    BAD(pole_pairs, 0, CTRL_EINVAL);
    BAD(pole_pairs, 1000, CTRL_EINVAL);
    /* plausible SI, but a per-unit value outside the core's formats: ERANGE */
    BAD(lq_h, 6.552, CTRL_ERANGE);              /* Lq / Ld = 1000 */
    BAD(ld_h, 5.0, CTRL_ERANGE);                /* Lq / Ld = 0.0013 */
    BAD(current_max_a, 5000.0, CTRL_ERANGE);    /* 348 x psi_pm / Ld */
    BAD(rs_ohm, 100.0, CTRL_ERANGE);            /* Ts Rs / Ld = 1.5: Euler of (5.15) */
    BAD(vdc_v, 5000.0, CTRL_ERANGE);            /* 42 x the rated back-EMF */
    BAD(speed_rated_rpm, 30000.0, CTRL_ERANGE); /* 1.26 rad per period at 10 kHz */
    BAD(speed_rated_rpm, 20.0, CTRL_ERANGE);    /* 8.4e-4 rad per period */
#undef BAD
    /* 100 Hz sampling: 12.6 rad per period at rated speed */
    expect_reject(&spm, 100u, CTRL_ERANGE);
    /* a tiny resistance is no problem (its drop is a correction term) */
    m = spm;
    m.rs_ohm = 1e-7;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&p, &b, &m, 10000u));
    expect_reject(&spm, 100000000u, CTRL_EINVAL);
    /* an ideal lossless machine is accepted */
    m = spm;
    m.rs_ohm = 0.0;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&p, &b, &m, 10000u));
    TEST_ASSERT_EQUAL_INT32(0, p.rs);
}

/* A refusal names the quantity, its value and the accepted range. */
static void expect_diag(const ctrl_machine_t *m, uint32_t fs, int code, const char *quantity,
                        double value)
{
    ctrl_params_t p;
    ctrl_bases_t b;
    ctrl_diag_t why;
    TEST_ASSERT_EQUAL_INT(code, ctrl_params_init_diag(&p, &b, m, fs, &why));
    TEST_ASSERT_EQUAL_INT(code, why.code);
    TEST_ASSERT_EQUAL_STRING(quantity, why.quantity);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9 * fabs(value) + 1e-12, value, why.value);
    TEST_ASSERT_TRUE(why.value < why.min || why.value > why.max);
    char msg[256];
    const size_t n = ctrl_diag_format(&why, msg, sizeof msg);
    TEST_ASSERT_TRUE(n > 0u && n < sizeof msg);
    TEST_ASSERT_NOT_NULL(strstr(msg, quantity));
    TEST_ASSERT_NOT_NULL(strstr(msg, "outside the range the core takes"));
    char num[32];
    snprintf(num, sizeof num, "[%.6g, %.6g]", why.min, why.max);
    TEST_ASSERT_NOT_NULL(strstr(msg, num));
    /* a buffer too short for the line: truncated, terminated */
    char shortbuf[16];
    TEST_ASSERT_EQUAL_UINT(sizeof shortbuf - 1u, ctrl_diag_format(&why, shortbuf, sizeof shortbuf));
    TEST_ASSERT_EQUAL_UINT(sizeof shortbuf - 1u, strlen(shortbuf));
}

static void test_refusals_explained(void)
{
    const ctrl_machine_t spm = machine_thesis_spmsm();
    ctrl_machine_t m = spm;
    m.psi_pm_wb = -1e-3;
    expect_diag(&m, 10000u, CTRL_EINVAL, "psi_pm_wb", -1e-3);
    m = spm;
    m.ld_h = NAN;
    ctrl_params_t p;
    ctrl_bases_t b;
    ctrl_diag_t why;
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_params_init_diag(&p, &b, &m, 10000u, &why));
    TEST_ASSERT_EQUAL_STRING("ld_h", why.quantity);
    m = spm;
    m.speed_rated_rpm = 30000.0; /* 12.57 rad/s x 10000 rpm / ... = 1.257 rad per period */
    expect_diag(&m, 10000u, CTRL_ERANGE, "rated electrical speed x Ts",
                30000.0 / 60.0 * 2.0 * CTRL_PI * 4.0 * 1e-4);
    expect_diag(&spm, 500u, CTRL_ERANGE, "rated electrical speed x Ts",
                3000.0 / 60.0 * 2.0 * CTRL_PI * 4.0 / 500.0);
    m = spm;
    m.vdc_v = 5000.0;
    expect_diag(&m, 10000u, CTRL_ERANGE, "vdc_v / rated back-EMF (psi_pm x rated electrical speed)",
                5000.0 / (0.09427 * 3000.0 / 60.0 * 2.0 * CTRL_PI * 4.0));
    m = spm;
    m.rs_ohm = 100.0;
    expect_diag(&m, 10000u, CTRL_ERANGE, "Ts Rs / Ld", 1e-4 * 100.0 / 6.552e-3);
    m = spm;
    m.pole_pairs = 0;
    expect_diag(&m, 10000u, CTRL_EINVAL, "pole_pairs", 0.0);
    /* the dependent data are named with a derived quantity */
    m = spm;
    m.speed_rated_rpm = 30000.0;
    TEST_ASSERT_EQUAL_INT(CTRL_ERANGE, ctrl_params_init_diag(&p, &b, &m, 10000u, &why));
    char msg[256];
    ctrl_diag_format(&why, msg, sizeof msg);
    TEST_ASSERT_NOT_NULL(strstr(msg, "speed_rated_rpm"));
    TEST_ASSERT_NOT_NULL(strstr(msg, "fs_hz"));
    /* accepted: "ok" */
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init_diag(&p, &b, &spm, 10000u, &why));
    ctrl_diag_format(&why, msg, sizeof msg);
    TEST_ASSERT_EQUAL_STRING("ok", msg);
}

/* The small motors (sim_host/machines/{mj5208_drone,
 * gbm5208_gimbal}.ini) are taken at 10, 20 and 40 kHz; their neighbours just
 * outside the core's range are refused with the quantity, its value and the
 * range (the same diagnosis the simulator and the serial link print). */
static void test_small_motor_neighbours(void)
{
    static const uint32_t fss[3] = {10000u, 20000u, 40000u};
    ctrl_params_t p;
    ctrl_bases_t b;
    ctrl_diag_t why;
    for (size_t f = 0; f < 3; f++) {
        TEST_ASSERT_EQUAL_INT(CTRL_OK,
                              ctrl_params_init_diag(&p, &b, &ini_mj5208_drone, fss[f], &why));
        TEST_ASSERT_EQUAL_INT(CTRL_OK,
                              ctrl_params_init_diag(&p, &b, &ini_gbm5208_gimbal, fss[f], &why));
    }
    /* a 40000 r/min rating on the drone motor: 7 x 40000 x 2 pi / 60 x 50 us */
    ctrl_machine_t m = ini_mj5208_drone;
    m.speed_rated_rpm = 40000.0;
    expect_diag(&m, 20000u, CTRL_ERANGE, "rated electrical speed x Ts",
                7.0 * 40000.0 / 60.0 * 2.0 * CTRL_PI / 20000.0);
    /* the gimbal motor rated at 15 r/min: 11 x 15 x 2 pi / 60 x 50 us < 0.001 */
    m = ini_gbm5208_gimbal;
    m.speed_rated_rpm = 15.0;
    expect_diag(&m, 20000u, CTRL_ERANGE, "rated electrical speed x Ts",
                11.0 * 15.0 / 60.0 * 2.0 * CTRL_PI / 20000.0);
    /* its winding with 0.3 mH: Ts Rs / Ld = 50 us x 7.545 / 0.3 mH */
    m = ini_gbm5208_gimbal;
    m.ld_h = 0.3e-3;
    m.lq_h = 0.3e-3;
    expect_diag(&m, 20000u, CTRL_ERANGE, "Ts Rs / Ld", 50e-6 * 7.545 / 0.3e-3);
    /* on 60 V and rated at 20 r/min: the DC link is 132 rated back-EMFs */
    m = ini_gbm5208_gimbal;
    m.vdc_v = 60.0;
    m.speed_rated_rpm = 20.0;
    expect_diag(&m, 20000u, CTRL_ERANGE, "vdc_v / rated back-EMF (psi_pm x rated electrical speed)",
                60.0 / (0.019655 * 20.0 / 60.0 * 2.0 * CTRL_PI * 11.0));
    /* the drone motor with a 2000 A trip: current_max / (psi_pm / Ld) = 20 > 16 */
    m = ini_mj5208_drone;
    m.current_max_a = 2000.0;
    TEST_ASSERT_EQUAL_INT(CTRL_ERANGE, ctrl_params_init_diag(&p, &b, &m, 20000u, &why));
    TEST_ASSERT_TRUE(why.value > why.max);
}

/* The range of the brief: psi_pm from 0.3 mWb, L from 10 uH, R from 20 mOhm,
 * Vdc 8-60 V and 540 V, fs 10-40 kHz. The machines (machines.h) at the
 * sampling frequencies their rated speed allows are accepted by the core and
 * by every registered controller (defaults); where one period would turn the
 * rotor by more than one radian at rated speed the refusal says so. */
static void test_range_corner_machines(void)
{
    const struct {
        ctrl_machine_t m;
        uint32_t fs_min; /* below: refused, "rated electrical speed x Ts" */
    } cases[] = {
        {machine_small_8v(), 20000u},       {machine_small_60v(), 20000u},
        {machine_small_10khz(), 10000u},    {machine_spmsm_1000v(), 10000u},
        {machine_thesis_ipmsm80(), 10000u}, {machine_thesis_spmsm(), 10000u},
        {machine_chapter_ipmsm(), 10000u},
    };
    static const uint32_t fss[3] = {10000u, 20000u, 40000u};
    static _Alignas(16) unsigned char cfg[CTRL_CFG_MAX];
    static _Alignas(16) unsigned char st[CTRL_STATE_MAX];
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        for (size_t f = 0; f < 3; f++) {
            ctrl_params_t p;
            ctrl_bases_t b;
            ctrl_diag_t why;
            const int rc = ctrl_params_init_diag(&p, &b, &cases[k].m, fss[f], &why);
            char msg[256];
            ctrl_diag_format(&why, msg, sizeof msg);
            if (fss[f] < cases[k].fs_min) {
                TEST_ASSERT_EQUAL_INT_MESSAGE(CTRL_ERANGE, rc, cases[k].m.name);
                TEST_ASSERT_EQUAL_STRING("rated electrical speed x Ts", why.quantity);
                continue;
            }
            TEST_ASSERT_EQUAL_INT_MESSAGE(CTRL_OK, rc, msg);
            const ctrl_setup_t su = {&cases[k].m, &b, &p, &why};
            for (size_t i = 0; i < ctrl_count(); i++) {
                const ctrl_desc_t *d = ctrl_at(i);
                TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_cfg_default(d, cfg, &cases[k].m));
                memset(&why, 0, sizeof why);
                const int ci = ctrl_init(d, st, cfg, &su);
                if (ci != CTRL_OK) {
                    /* A controller may have a narrower range than the core
                     * (its own arithmetic), but says which quantity is out;
                     * the proposed controllers take every corner case. */
                    char text[320];
                    ctrl_diag_format(&why, msg, sizeof msg);
                    snprintf(text, sizeof text, "%s on %s at %u Hz: %s", d->name, cases[k].m.name,
                             (unsigned)fss[f], msg);
                    TEST_ASSERT_NOT_NULL_MESSAGE(why.quantity, text);
                    TEST_ASSERT_TRUE_MESSAGE(why.value < why.min || why.value > why.max, text);
                    TEST_ASSERT_TRUE_MESSAGE(
                        strcmp(d->name, "m2ptfc") != 0 && strcmp(d->name, "fst") != 0, text);
                    TEST_MESSAGE(text);
                }
            }
        }
    }
}

static void test_q24_conversion(void)
{
    TEST_ASSERT_EQUAL_INT32(FX_ONE, ctrl_q24_from_double(1.0));
    TEST_ASSERT_EQUAL_INT32(-1, ctrl_q24_from_double(-0.5 * LSB)); /* half away from zero */
    TEST_ASSERT_EQUAL_INT32(1, ctrl_q24_from_double(0.5 * LSB));
    TEST_ASSERT_EQUAL_INT32(0, ctrl_q24_from_double(-0.49 * LSB));
    TEST_ASSERT_EQUAL_INT32(-2, ctrl_q24_from_double(-1.5 * LSB));
    TEST_ASSERT_EQUAL_INT32(FX_MAX, ctrl_q24_from_double(200.0));
    TEST_ASSERT_EQUAL_INT32(FX_MIN, ctrl_q24_from_double(-200.0));
    TEST_ASSERT_EQUAL_INT32(FX_MIN, ctrl_q24_from_double(-128.0));
    TEST_ASSERT_EQUAL_INT32(FX_MAX, ctrl_q24_from_double(INFINITY));
    TEST_ASSERT_EQUAL_INT32(FX_MIN, ctrl_q24_from_double(-INFINITY));
    TEST_ASSERT_EQUAL_INT32(0, ctrl_q24_from_double(NAN));
    TEST_ASSERT_DOUBLE_WITHIN(0.0, -128.0, ctrl_q24_to_double(FX_MIN));
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 0.25, ctrl_q24_to_double(FX_ONE / 4));
}

/* (4.15)-(4.16): MTPA at 1.8 N*m on the thesis SPMSM, psi_s = 0.09655 Wb and
 * delta = 0.2177 rad (4.15)-(4.16). The reference values are printed to 4
 * significant digits: tolerance half a unit of the last digit (5e-6 Wb,
 * 5e-5 rad) plus the fixed-point error (< 1e-6 pu, README). */
static void test_mtpa_oracle_spmsm(void)
{
    const ctrl_machine_t spm = machine_thesis_spmsm();
    ctrl_params_t p;
    ctrl_bases_t b;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&p, &b, &spm, 10000u));
    const q24_t t = ctrl_q24_from_double(1.8 / b.torque_nm);
    const q24_t psi = ctrl_mtpa_psi(&p, t);
    TEST_ASSERT_DOUBLE_WITHIN(5e-6 + 1e-6 * b.psi_wb, 0.09655, d(psi) * b.psi_wb);
    TEST_ASSERT_EQUAL_INT32(psi, ctrl_mtpa_psi(&p, -t)); /* braking: same amplitude */
    TEST_ASSERT_EQUAL_INT32(FX_ONE, ctrl_mtpa_psi(&p, 0));
    /* Load angle: the MTPA point of an SPMSM is i_d = 0, i_q = T (pu); the
     * current model gives the stator flux, delta = atan2(psi_q, psi_d). */
    ctrl_mstate_t s;
    fixture_state_from_current(&p, 0, t, 0u, &s); /* theta = 0: alpha = d */
    const double delta = atan2(d(s.psi_q), d(s.psi_d));
    TEST_ASSERT_DOUBLE_WITHIN(5e-5 + 1e-6, 0.2177, delta);
    TEST_ASSERT_INT32_WITHIN(1, psi, s.psi_amp); /* consistent amplitude (0.5 + 0.5 LSB) */
    TEST_ASSERT_INT32_WITHIN(2, t, s.torque);    /* (3.10) reproduces the demand */
}

/* Exact MTPA by direct search, independent of the config's closed form:
 * maximise T over the current angle for |i| = i, golden section. */
static void mtpa_search(double lq, double i, double *t_out, double *psi_out)
{
    double a = 0.0;
    double c = CTRL_PI / 2.0 + 0.7; /* beta from +q axis towards -d (and +d for lq<1) */
    const double g = (sqrt(5.0) - 1.0) / 2.0;
    for (int it = 0; it < 200; it++) {
        const double x1 = c - g * (c - a);
        const double x2 = a + g * (c - a);
        /* i_d = -i sin(beta - 0.7 shift), i_q = i cos(...) */
        const double b1 = x1 - 0.7;
        const double b2 = x2 - 0.7;
        const double t1 = i * cos(b1) * (1.0 + (1.0 - lq) * (-i * sin(b1)));
        const double t2 = i * cos(b2) * (1.0 + (1.0 - lq) * (-i * sin(b2)));
        if (t1 > t2) {
            c = x2;
        } else {
            a = x1;
        }
    }
    const double beta = 0.5 * (a + c) - 0.7;
    const double id = -i * sin(beta);
    const double iq = i * cos(beta);
    *t_out = iq * (1.0 + (1.0 - lq) * id);
    *psi_out = hypot(1.0 + id, lq * iq);
}

static void test_mtpa_ipmsm_table(void)
{
    const ctrl_machine_t ipm = machine_thesis_ipmsm80();
    ctrl_params_t p;
    ctrl_bases_t b;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&p, &b, &ipm, 20000u));
    const double lq = d(p.lq);
    TEST_ASSERT_EQUAL_INT32(FX_ONE, ctrl_mtpa_psi(&p, 0));
    q24_t prev = 0;
    double worst = 0.0;
    for (int k = 0; k <= 200; k++) {
        const double i = d(p.current_max) * k / 200.0;
        double t;
        double psi;
        mtpa_search(lq, i, &t, &psi);
        const q24_t got = ctrl_mtpa_psi(&p, ctrl_q24_from_double(t));
        TEST_ASSERT_EQUAL_INT32(got, ctrl_mtpa_psi(&p, ctrl_q24_from_double(-t)));
        TEST_ASSERT_TRUE(got >= prev); /* monotonic in |T| */
        prev = got;
        worst = fmax(worst, fabs(d(got) - psi));
    }
    /* Linear interpolation of psi(T) over 64 segments of width h: error
     * <= h^2/8 max|psi''|. Along the MTPA locus psi^2 = 1 + ((lq-1)^2 + 1) T^2
     * + O(T^4) and the curvature is largest at T = 0 (decreasing along the
     * locus for lq > 1), so max|psi''| = (lq-1)^2 + 1. Plus 0.5 LSB table
     * rounding, 0.5 LSB interpolation rounding, and the torque input rounding
     * times the slope (< 2): 1 LSB. */
    const double h = d(p.mtpa_t_max) / CTRL_MTPA_N;
    const double curv = (lq - 1.0) * (lq - 1.0) + 1.0;
    TEST_ASSERT_TRUE_MESSAGE(worst <= h * h / 8.0 * curv + 2.0 * LSB,
                             "IPMSM MTPA table interpolation error");
    /* beyond the table: still increasing, no overflow at the extremes */
    TEST_ASSERT_TRUE(ctrl_mtpa_psi(&p, 2 * p.mtpa_t_max) > ctrl_mtpa_psi(&p, p.mtpa_t_max));
    TEST_ASSERT_TRUE(ctrl_mtpa_psi(&p, FX_MAX) > 0);
    TEST_ASSERT_TRUE(ctrl_mtpa_psi(&p, FX_MIN) > 0);
}

/* The exact MTPA point of amplitude i in double precision (ctrl_mtpa_split:
 * ld = psi_pm = 1 pu by the bases): T (3.10) and |psi_s|. */
static void mtpa_exact(double lq, double i, double *id, double *iq, double *t, double *psi)
{
    ctrl_mtpa_split(1.0, 1.0, lq, i, id, iq);
    *t = *iq * (1.0 - (lq - 1.0) * *id);
    *psi = hypot(1.0 + *id, lq * *iq);
}

/* The integer MTPA table against the exact table in double precision (each
 * row's amplitude by 200 bisections on T(i), T increasing along the locus),
 * over the machines params_compute accepts: Lq / Ld from 0.125 to 8, the
 * current limit from 1/256 to 16 pu and up to Lq i_max = 31. Bound, in Q24
 * LSB: the table's amplitude lies within 3 LSB of the exact row's (half a
 * step of the bisection, one from the torque's rounding at i, 1.5 from the
 * rows' torques, which follow T(i_max) rounded to Q24), so an output x is
 * off by at most 1 (its own rounding and that of its inputs) + 3 |dx/di|,
 * with |di_d/di|, |di_q/di| <= 1 and |d|psi_s|/di| <= max(Ld, Lq) along the
 * locus; plus the rounding of |dL| to Q29 (2^-30 pu) times |di_d/d dL| <= i^2:
 * i^2 / 64 LSB. T_max: 1 LSB of rounding plus that of i_q and i_d times the torque's
 * sensitivity to them (psi - dL i_d <= 1 + 31). */
static void test_mtpa_table_integer(void)
{
    const double lqs[] = {0.125, 0.5, 0.97, 1.0 + 2e-6, 1.3, 2.0, 3.5, 8.0};
    const double imaxs[] = {1.0 / 256.0, 0.05, 0.4, 1.0, 2.5, 3.875, 9.0, 16.0};
    int n = 0;
    double worst[3] = {0.0, 0.0, 0.0};
    for (size_t a = 0; a < sizeof lqs / sizeof lqs[0]; a++) {
        for (size_t c = 0; c < sizeof imaxs / sizeof imaxs[0]; c++) {
            const double lq = lqs[a];
            const double i_max = imaxs[c];
            if (fmax(1.0, lq) * i_max > 31.0) {
                continue;
            }
            ctrl_machine_t m = machine_thesis_ipmsm80();
            m.lq_h = lq * m.ld_h;
            m.current_max_a = i_max * m.psi_pm_wb / m.ld_h;
            m.current_rated_a = m.current_max_a;
            m.torque_rated_nm = 1e-3 * m.torque_rated_nm;
            ctrl_params_t p;
            ctrl_bases_t b;
            ctrl_diag_t why;
            const int rc = ctrl_params_init_diag(&p, &b, &m, 20000u, &why);
            char msg[160];
            snprintf(msg, sizeof msg, "lq %g i_max %g: %s", lq, i_max, why.quantity);
            double id, iq, t_max, psi;
            mtpa_exact(lq, i_max, &id, &iq, &t_max, &psi);
            if (t_max > 100.0) {
                TEST_ASSERT_NOT_EQUAL_MESSAGE(CTRL_OK, rc, msg); /* does not fit Q24 */
                continue;
            }
            TEST_ASSERT_EQUAL_INT_MESSAGE(CTRL_OK, rc, msg);
            n++;
            const double dl = fabs(lq - 1.0);
            TEST_ASSERT_DOUBLE_WITHIN_MESSAGE((1.0 + 2.0 * (1.0 + dl * i_max)) * LSB, t_max,
                                              d(p.mtpa_t_max), msg);
            for (int k = 0; k <= CTRL_MTPA_N; k++) {
                const double t = t_max * k / CTRL_MTPA_N;
                double lo = 0.0;
                double hi = i_max;
                for (int it = 0; it < 200; it++) {
                    const double mid = 0.5 * (lo + hi);
                    double tm;
                    mtpa_exact(lq, mid, &id, &iq, &tm, &psi);
                    if (tm < t) {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                double tm;
                mtpa_exact(lq, 0.5 * (lo + hi), &id, &iq, &tm, &psi);
                const double e[3] = {fabs(d(p.mtpa_id[k]) - id) / LSB,
                                     fabs(d(p.mtpa_iq[k]) - iq) / LSB,
                                     fabs(d(p.mtpa_psi[k]) - psi) / LSB};
                const double in = i_max * i_max / 64.0; /* |dL|'s rounding */
                const double bound[3] = {4.0 + in, 4.0 + in, 1.0 + 3.0 * fmax(1.0, lq) + in};
                for (int j = 0; j < 3; j++) {
                    worst[j] = fmax(worst[j], e[j]);
                    snprintf(msg, sizeof msg, "lq %g i_max %g row %d output %d: %.2f LSB", lq,
                             i_max, k, j, e[j]);
                    TEST_ASSERT_TRUE_MESSAGE(e[j] <= bound[j], msg);
                }
            }
        }
    }
    TEST_ASSERT_TRUE(n >= 40);
    printf("MTPA table, integer vs double: %d machines, worst i_d %.2f, i_q %.2f, |psi_s| %.2f "
           "LSB\n",
           n, worst[0], worst[1], worst[2]);
}

static void test_speed_lpf_setter(void)
{
    const ctrl_machine_t spm = machine_thesis_spmsm();
    ctrl_params_t p;
    ctrl_bases_t b;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&p, &b, &spm, 20000u));
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_set_speed_lpf(&p, 100.0));
    TEST_ASSERT_TRUE(fabs(d(p.speed_lpf_k) - (1.0 - exp(-2 * CTRL_PI * 100.0 / 20000.0))) <=
                     0.5 * LSB);
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_params_set_speed_lpf(&p, 0.0));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_params_set_speed_lpf(&p, 10000.0));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_params_set_speed_lpf(&p, NAN));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_params_set_speed_lpf(NULL, 100.0));
}

static void test_speed_pi(void)
{
    const ctrl_machine_t spm = machine_thesis_spmsm();
    ctrl_params_t p;
    ctrl_bases_t b;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&p, &b, &spm, 10000u));
    ctrl_speed_pi_t pi;
    /* thesis gains, speed in mechanical rad/s, 2.4 N*m limit, loop at 10 kHz */
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_speed_pi_config(&pi, &b, 4, 0.006843, 0.78046,
                                                        CTRL_SPEED_UNIT_RAD_S_MECH, 2.4, 10000u));
    const double kp_pu = 0.006843 * b.w_rad_s / 4.0 / b.torque_nm;
    const double ki_pu = 0.78046 * b.w_rad_s / 4.0 / b.torque_nm / 10000.0;
    TEST_ASSERT_DOUBLE_WITHIN(kp_pu * 1e-9, kp_pu, ldexp((double)pi.kp, -(int)pi.kp_shift));
    TEST_ASSERT_DOUBLE_WITHIN(ki_pu * 1e-8, ki_pu, ldexp((double)pi.ki_ts, -(int)pi.ki_shift));
    /* the same gains per r/min are 60/(2 pi) times larger per rad/s */
    ctrl_speed_pi_t pr;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_speed_pi_config(&pr, &b, 4, 0.006843, 0.78046,
                                                        CTRL_SPEED_UNIT_RPM, 2.4, 10000u));
    TEST_ASSERT_DOUBLE_WITHIN(kp_pu * 1e-8, kp_pu * 60.0 / (2 * CTRL_PI),
                              ldexp((double)pr.kp, -(int)pr.kp_shift));

    /* Linear region: constant error e for n steps: u = kp e + n ki_ts e.
     * Per step: rounding of P (0.5 LSB) and of the integrator read-out (0.5 LSB). */
    ctrl_speed_pi_reset(&pi, 0);
    const q24_t e = ctrl_q24_from_double(0.001);
    q24_t u = 0;
    for (int n = 1; n <= 50; n++) {
        u = ctrl_speed_pi_step(&pi, e, 0);
        const double expect = (kp_pu + n * ki_pu) * d(e);
        TEST_ASSERT_TRUE(fabs(d(u) - expect) <= 1.0 * LSB + expect * 1e-8);
    }
    /* Saturation and anti-windup: a large error drives the output to the limit
     * (conditional integration stops within one integration step of it) and
     * the integrator never exceeds it; when the error reverses, the output
     * leaves the limit at once (no wind-up to unwind). */
    const q24_t lim = pi.out_max;
    TEST_ASSERT_TRUE(fabs(d(lim) - 2.4 / b.torque_nm) <= 0.5 * LSB);
    for (int n = 0; n < 20000; n++) {
        u = ctrl_speed_pi_step(&pi, FX_ONE, 0);
    }
    const double step_lsb = ki_pu * 16777216.0 + 1.0; /* one integration step of 1 pu */
    TEST_ASSERT_TRUE(u <= lim && (double)(lim - u) <= step_lsb);
    u = ctrl_speed_pi_step(&pi, -ctrl_q24_from_double(0.01), 0);
    TEST_ASSERT_TRUE(u < lim);
    ctrl_speed_pi_reset(&pi, 0);
    for (int n = 0; n < 20000; n++) {
        u = ctrl_speed_pi_step(&pi, -FX_ONE, 0);
    }
    TEST_ASSERT_TRUE(u >= -lim && (double)(u + lim) <= step_lsb);
    u = ctrl_speed_pi_step(&pi, FX_MAX, FX_MIN); /* extreme inputs: no overflow */
    TEST_ASSERT_EQUAL_INT32(lim, u);
    /* bumpless start */
    ctrl_speed_pi_reset(&pi, lim / 2);
    TEST_ASSERT_INT32_WITHIN(1, lim / 2, ctrl_speed_pi_step(&pi, 0, 0));
    /* a zeroed (unconfigured) controller outputs 0 and does not fault */
    ctrl_speed_pi_t z;
    memset(&z, 0, sizeof z);
    TEST_ASSERT_EQUAL_INT32(0, ctrl_speed_pi_step(&z, FX_ONE, 0));
    /* bad configuration */
    TEST_ASSERT_EQUAL_INT(
        CTRL_EINVAL, ctrl_speed_pi_config(&pi, &b, 4, -1.0, 0.7, CTRL_SPEED_UNIT_RPM, 2.4, 10000u));
    TEST_ASSERT_EQUAL_INT(
        CTRL_EINVAL, ctrl_speed_pi_config(&pi, &b, 4, 0.1, NAN, CTRL_SPEED_UNIT_RPM, 2.4, 10000u));
    TEST_ASSERT_EQUAL_INT(
        CTRL_EINVAL, ctrl_speed_pi_config(&pi, &b, 4, 0.1, 0.7, CTRL_SPEED_UNIT_RPM, 0.0, 10000u));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL,
                          ctrl_speed_pi_config(&pi, &b, 4, 0.1, 0.7, CTRL_SPEED_UNIT_RPM, 2.4, 0u));
    TEST_ASSERT_EQUAL_INT(
        CTRL_EINVAL, ctrl_speed_pi_config(NULL, &b, 4, 0.1, 0.7, CTRL_SPEED_UNIT_RPM, 2.4, 100u));
    TEST_ASSERT_EQUAL_INT(
        CTRL_ERANGE, ctrl_speed_pi_config(&pi, &b, 4, 0.1, 0.7, CTRL_SPEED_UNIT_RPM, 1e6, 100u));
}

/* New gains while running (ctrl_speed_pi_retune): the first step after the
 * change differs from the same step under the old gains only by
 * (Ki_new - Ki_old) Ts e' + (Kp_new - Kp_old)(e' - e), e the error the change
 * was made with, e' the step's (speed_pi.h), and 2 LSB of rounding (the
 * proportional parts and the integrator's read-out); the integrator's torque
 * survives a change of its format (ki_shift); a change that needs more than
 * the limit leaves the integrator at the limit. */
static void test_speed_pi_retune(void)
{
    const ctrl_machine_t spm = machine_thesis_spmsm();
    ctrl_params_t p;
    ctrl_bases_t b;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&p, &b, &spm, 10000u));
    /* old: the thesis gains (Ki Ts = 0.11 Kp at 1 kHz); new: Kp x 0.3 and Ki x 2
     * (ki_shift moves by 1), Kp x 3 and Ki / 8 (by 3), the same */
    const double kp = 0.006843, ki = 0.78046;
    const double scale[][2] = {{0.3, 2.0}, {3.0, 0.125}, {1.0, 1.0}};
    for (size_t c = 0; c < sizeof scale / sizeof scale[0]; c++) {
        ctrl_speed_pi_t pi, to;
        TEST_ASSERT_EQUAL_INT(
            CTRL_OK,
            ctrl_speed_pi_config(&pi, &b, 4, kp, ki, CTRL_SPEED_UNIT_RAD_S_MECH, 2.4, 1000u));
        TEST_ASSERT_EQUAL_INT(CTRL_OK,
                              ctrl_speed_pi_config(&to, &b, 4, kp * scale[c][0], ki * scale[c][1],
                                                   CTRL_SPEED_UNIT_RAD_S_MECH, 2.4, 1000u));
        if (scale[c][1] != 1.0) {
            TEST_ASSERT_NOT_EQUAL(pi.ki_shift, to.ki_shift);
        }
        /* an integrator away from zero and the limit */
        ctrl_speed_pi_reset(&pi, ctrl_q24_from_double(0.1)); /* the limit: 0.295 pu */
        const q24_t e = ctrl_q24_from_double(0.05);          /* the error of the change */
        const q24_t e1 = ctrl_q24_from_double(0.051);        /* the next step's */
        ctrl_speed_pi_t old = pi;
        const q24_t u_old = ctrl_speed_pi_step(&old, e1, 0);
        ctrl_speed_pi_retune(&pi, &to, e);
        const q24_t u_new = ctrl_speed_pi_step(&pi, e1, 0);
        const double kp_o = ldexp((double)old.kp, -(int)old.kp_shift);
        const double kp_n = ldexp((double)to.kp, -(int)to.kp_shift);
        const double ki_o = ldexp((double)old.ki_ts, -(int)old.ki_shift);
        const double ki_n = ldexp((double)to.ki_ts, -(int)to.ki_shift);
        const double bound =
            fabs((ki_n - ki_o) * d(e1)) + fabs((kp_n - kp_o) * (d(e1) - d(e))) + 2.0 * LSB;
        TEST_ASSERT_TRUE(u_old < pi.out_max && u_new < pi.out_max); /* not at the limit */
        TEST_ASSERT_TRUE_MESSAGE(fabs(d(u_new) - d(u_old)) <= bound, "bumpless within the bound");
        /* without the integrator's share it would have stepped by (Kp_new - Kp_old) e */
        if (scale[c][0] != 1.0) {
            TEST_ASSERT_TRUE(fabs((kp_n - kp_o) * d(e)) > 4.0 * bound);
        }
    }
    /* a change that needs more than the limit: the integrator stops there */
    ctrl_speed_pi_t pi, to;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_speed_pi_config(&pi, &b, 4, kp * 100.0, ki,
                                                        CTRL_SPEED_UNIT_RAD_S_MECH, 2.4, 1000u));
    TEST_ASSERT_EQUAL_INT(
        CTRL_OK, ctrl_speed_pi_config(&to, &b, 4, kp, ki, CTRL_SPEED_UNIT_RAD_S_MECH, 2.4, 1000u));
    ctrl_speed_pi_reset(&pi, pi.out_max / 2);
    ctrl_speed_pi_retune(&pi, &to, FX_ONE);
    TEST_ASSERT_TRUE(pi.integ == (int64_t)pi.out_max * ((int64_t)1 << pi.ki_shift));
    ctrl_speed_pi_retune(&pi, &to, FX_MIN); /* extreme error: no overflow (UBSan) */
}

typedef struct {
    double alpha;
    double beta;
} fake_cfg_t;

static const ctrl_tunable_t fake_tunables[] = {
    {"alpha", "1", "test", offsetof(fake_cfg_t, alpha), 0.0, 1.0},
    {"beta", "1", "test", offsetof(fake_cfg_t, beta), -5.0, 5.0},
    {"bad", "1", "offset outside cfg", sizeof(fake_cfg_t), 0.0, 1.0},
};

static void test_tunables(void)
{
    ctrl_desc_t desc;
    memset(&desc, 0, sizeof desc);
    desc.name = "fake";
    desc.cfg_size = sizeof(fake_cfg_t);
    desc.tunables = fake_tunables;
    desc.n_tunables = 3u;
    fake_cfg_t cfg = {0.5, 0.0};
    double v = 0.0;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_set(&desc, &cfg, "beta", -2.5));
    TEST_ASSERT_DOUBLE_WITHIN(0.0, -2.5, cfg.beta);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_get(&desc, &cfg, "alpha", &v));
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 0.5, v);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_set(&desc, &cfg, "alpha", 1.0)); /* inclusive */
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_tunable_set(&desc, &cfg, "alpha", 1.0000001));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_tunable_set(&desc, &cfg, "alpha", NAN));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_tunable_set(&desc, &cfg, "beta", INFINITY));
    TEST_ASSERT_EQUAL_INT(CTRL_ENOENT, ctrl_tunable_set(&desc, &cfg, "gamma", 0.1));
    TEST_ASSERT_EQUAL_INT(CTRL_ENOENT, ctrl_tunable_get(&desc, &cfg, "gamma", &v));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_tunable_set(&desc, &cfg, "bad", 0.1));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_tunable_get(&desc, &cfg, "bad", &v));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_tunable_set(NULL, &cfg, "alpha", 0.1));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_tunable_set(&desc, NULL, "alpha", 0.1));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_tunable_set(&desc, &cfg, NULL, 0.1));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_tunable_get(&desc, &cfg, "alpha", NULL));
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 1.0, cfg.alpha); /* rejected sets changed nothing */
    TEST_ASSERT_DOUBLE_WITHIN(0.0, -2.5, cfg.beta);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_bases_spmsm);
    RUN_TEST(test_bases_ipmsm);
    RUN_TEST(test_reject_bad_machines);
    RUN_TEST(test_refusals_explained);
    RUN_TEST(test_range_corner_machines);
    RUN_TEST(test_small_motor_neighbours);
    RUN_TEST(test_q24_conversion);
    RUN_TEST(test_mtpa_oracle_spmsm);
    RUN_TEST(test_mtpa_ipmsm_table);
    RUN_TEST(test_mtpa_table_integer);
    RUN_TEST(test_speed_lpf_setter);
    RUN_TEST(test_speed_pi);
    RUN_TEST(test_speed_pi_retune);
    RUN_TEST(test_tunables);
    return UNITY_END();
}
