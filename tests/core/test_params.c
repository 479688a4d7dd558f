/*
 * ctrl_params_init (bases, Q24 fit, rejection of bad machines), the Q24
 * conversion helpers, MTPA ((4.15)-(4.16) for the thesis SPMSM and the IPMSM
 * table), the speed filter coefficient, the speed PI and the tunables API.
 */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "controller.h"
#include "ctrl_params.h"
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

#define PI 3.14159265358979323846
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
    const double wb = 220.0 / 0.09427;
    const double ib = 0.09427 / 6.552e-3;
    TEST_ASSERT_DOUBLE_WITHIN(1e-9 * wb, wb, b.w_rad_s);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 1.0 / wb, b.t_s);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12 * ib, ib, b.i_a);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 1.5 * 4 * 0.09427 * ib, b.torque_nm);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 220.0 / ib, b.r_ohm);
    TEST_ASSERT_EQUAL_INT32(FX_ONE, p.ld);
    TEST_ASSERT_EQUAL_INT32(FX_ONE, p.lq);
    TEST_ASSERT_EQUAL_INT32(FX_ONE, p.psi_pm);
    TEST_ASSERT_EQUAL_INT32(FX_ONE, p.vdc_nom);
    TEST_ASSERT_EQUAL_UINT8(0u, p.salient);
    /* each Q24 field is the rounded pu value: error <= 0.5 LSB */
    TEST_ASSERT_TRUE(fabs(d(p.ts) - wb * 1e-4) <= 0.5 * LSB);
    TEST_ASSERT_TRUE(fabs(d(p.rs) - 0.901 / (220.0 / ib)) <= 0.5 * LSB);
    TEST_ASSERT_TRUE(fabs(d(p.ts_rs) - wb * 1e-4 * 0.901 / (220.0 / ib)) <= 0.5 * LSB);
    TEST_ASSERT_TRUE(fabs(d(p.speed_rated_e) - 4 * 3000 * 2 * PI / 60 / wb) <= 0.5 * LSB);
    TEST_ASSERT_TRUE(fabs(d(p.current_max) - 8.4 / ib) <= 0.5 * LSB);
    /* Thesis SPMSM: omega_e psi_pm at 3000 r/min = 118.5 V (0.5386 pu of Vdc) */
    TEST_ASSERT_DOUBLE_WITHIN(0.05, 118.5, d(p.speed_rated_e) * b.v_v);
    /* angle increment per period: Ts_pu / (2 pi) turns, integer rounding */
    TEST_ASSERT_DOUBLE_WITHIN(0.5, wb * 1e-4 / (2 * PI) * 4294967296.0, (double)p.omega_to_dangle);
    /* inverse: dtheta * m / 2^28 = dtheta * 2^24 / k_ang, m rounded (0.5 / 2^28) */
    const double inv = ldexp((double)p.dangle_to_omega, -(int)CTRL_DANGLE_SHIFT);
    const double inv_exact = 16777216.0 / (wb * 1e-4 / (2 * PI) * 4294967296.0);
    TEST_ASSERT_DOUBLE_WITHIN(ldexp(0.5, -(int)CTRL_DANGLE_SHIFT) + inv_exact * 1e-15, inv_exact,
                              inv);
    /* speed filter: 1 - exp(-2 pi fc / fs) */
    TEST_ASSERT_TRUE(fabs(d(p.speed_lpf_k) -
                          (1.0 - exp(-2 * PI * CTRL_SPEED_LPF_HZ_DEFAULT / 1e4))) <= 0.5 * LSB);
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
    /* plausible SI, but the per-unit value does not fit Q24 (|x| <= 100 pu
     * with 2^-16 pu minimum): ERANGE */
    BAD(lq_h, 6.552, CTRL_ERANGE); /* Lq / Ld = 1000 */
    BAD(ld_h, 5.0, CTRL_ERANGE);   /* i_base = 19 mA: 8.4 A is 445 pu */
    BAD(current_max_a, 5000.0, CTRL_ERANGE);
    BAD(rs_ohm, 1e-7, CTRL_ERANGE); /* 6.5e-9 pu: no resolution */
#undef BAD
    /* 100 Hz sampling: 23 rad per period at 1 pu speed */
    expect_reject(&spm, 100u, CTRL_ERANGE);
    expect_reject(&spm, 100000000u, CTRL_EINVAL);
    /* an ideal lossless machine is accepted */
    m = spm;
    m.rs_ohm = 0.0;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&p, &b, &m, 10000u));
    TEST_ASSERT_EQUAL_INT32(0, p.rs);
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
    ctrl_mstate_from_current(&p, 0, t, 0u, 0, FX_ONE, &s); /* theta = 0: alpha = d */
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
    double c = PI / 2.0 + 0.7; /* beta from +q axis towards -d (and +d for lq<1) */
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

static void test_speed_lpf_setter(void)
{
    const ctrl_machine_t spm = machine_thesis_spmsm();
    ctrl_params_t p;
    ctrl_bases_t b;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&p, &b, &spm, 20000u));
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_set_speed_lpf(&p, 100.0));
    TEST_ASSERT_TRUE(fabs(d(p.speed_lpf_k) - (1.0 - exp(-2 * PI * 100.0 / 20000.0))) <= 0.5 * LSB);
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
    TEST_ASSERT_DOUBLE_WITHIN(kp_pu * 1e-8, kp_pu * 60.0 / (2 * PI),
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
    /* Saturation and anti-windup: a large error pins the output at the limit
     * and the integrator never exceeds it; when the error reverses, the output
     * leaves the limit at once (no wind-up to unwind). */
    const q24_t lim = pi.out_max;
    TEST_ASSERT_TRUE(fabs(d(lim) - 2.4 / b.torque_nm) <= 0.5 * LSB);
    for (int n = 0; n < 20000; n++) {
        u = ctrl_speed_pi_step(&pi, FX_ONE, 0);
    }
    TEST_ASSERT_EQUAL_INT32(lim, u);
    u = ctrl_speed_pi_step(&pi, -ctrl_q24_from_double(0.01), 0);
    TEST_ASSERT_TRUE(u < lim);
    ctrl_speed_pi_reset(&pi, 0);
    for (int n = 0; n < 20000; n++) {
        u = ctrl_speed_pi_step(&pi, -FX_ONE, 0);
    }
    TEST_ASSERT_EQUAL_INT32(-lim, u);
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
    RUN_TEST(test_q24_conversion);
    RUN_TEST(test_mtpa_oracle_spmsm);
    RUN_TEST(test_mtpa_ipmsm_table);
    RUN_TEST(test_speed_lpf_setter);
    RUN_TEST(test_speed_pi);
    RUN_TEST(test_tunables);
    return UNITY_END();
}
