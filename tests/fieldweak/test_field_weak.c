/*
 * Field-weakening limits (control/regulators/field_weak.h) against closed
 * forms: the flux the voltage allows, the torque limit below base speed (MTPA
 * at the current limit), on the current circle and voltage ellipse of the
 * SPMSM, at MTPV on the 80 kW IPMSM, above the SPMSM's maximum speed; the
 * resistive term; continuity through base speed (smooth entry and exit); the
 * DC-link filter; a fixed flux reference; the FOC current references on the
 * flux circle; the refusals of the configuration. Control core only: also
 * runs on the Cortex-M4 under QEMU.
 */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "ctrl_params.h"
#include "field_weak.h"
#include "field_weak_config.h"
#include "fx.h"
#include "mtpa.h"
#include "unity.h"

#include "../plant/ini_machines.h"
#include "ctrl_units.h"

#define LSB (1.0 / 16777216.0)

static ctrl_machine_t M;
static ctrl_params_t P;
static ctrl_bases_t B;
static ctrl_fieldweak_t S;
static ctrl_fieldweak_cfg_t C;
static char WHY[160];

void setUp(void)
{
}
void tearDown(void)
{
}

static q24_t q(double pu)
{
    return ctrl_q24_from_double(pu);
}
static double d(q24_t x)
{
    return ctrl_q24_to_double(x);
}

/* Machine m (Rs replaced by rs when rs >= 0) at 10 kHz with the default limits. */
static void setup(const ctrl_machine_t *m, double rs)
{
    M = *m;
    if (rs >= 0.0) {
        M.rs_ohm = rs;
    }
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&P, &B, &M, 10000u));
    ctrl_fieldweak_cfg_default(&C);
    TEST_ASSERT_EQUAL_INT_MESSAGE(CTRL_OK, ctrl_fieldweak_init(&S, &C, &M, &B, &P, WHY, sizeof WHY),
                                  WHY);
}

/* Nominal DC link in pu, electrical speed of rpm in pu. */
static q24_t vdc_pu(void)
{
    return q(M.vdc_v / B.v_v);
}
static q24_t omega_pu(double rpm)
{
    return q(rpm * 2.0 * CTRL_PI / 60.0 * M.pole_pairs / B.w_rad_s);
}

/* One step at nominal DC link (a fresh filter takes the sample as is). */
static ctrl_fieldweak_out_t step_at(double rpm, double t_req_nm, q24_t psi_cmd)
{
    ctrl_fieldweak_reset(&S);
    ctrl_fieldweak_out_t o;
    ctrl_fieldweak_step(&S, &P, vdc_pu(), omega_pu(rpm), q(t_req_nm / B.torque_nm), psi_cmd, &o);
    return o;
}

/* Usable phase voltage amplitude (V) and the machine's numbers, SI. */
static double v_max(void)
{
    return C.v_frac * M.vdc_v / sqrt(3.0);
}
static double we(double rpm)
{
    return rpm * 2.0 * CTRL_PI / 60.0 * M.pole_pairs;
}

static void test_config_refusals(void)
{
    setup(&ini_thesis_spmsm, -1.0);
    ctrl_fieldweak_cfg_t c = C;
    c.v_frac = 0.0;
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_fieldweak_init(&S, &c, &M, &B, &P, WHY, sizeof WHY));
    TEST_ASSERT_NOT_NULL(strstr(WHY, "v_frac"));
    c.v_frac = 1.2; /* beyond six-step */
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_fieldweak_init(&S, &c, &M, &B, &P, WHY, sizeof WHY));
    c = C;
    c.current_max_a = 1.01 * M.current_max_a; /* above the over-current trip */
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_fieldweak_init(&S, &c, &M, &B, &P, WHY, sizeof WHY));
    TEST_ASSERT_NOT_NULL(strstr(WHY, "current limit"));
    c = C;
    c.torque_margin = 1.5;
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_fieldweak_init(&S, &c, &M, &B, &P, WHY, sizeof WHY));
    c = C;
    c.vdc_lpf_hz = 5000.0; /* = fs/2 */
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_fieldweak_init(&S, &c, &M, &B, &P, WHY, sizeof WHY));
    ctrl_machine_t rev = ini_thesis_ipmsm80;
    rev.ld_h = 2e-3; /* Lq < Ld */
    ctrl_params_t pr;
    ctrl_bases_t br;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&pr, &br, &rev, 10000u));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL,
                          ctrl_fieldweak_init(&S, &C, &rev, &br, &pr, WHY, sizeof WHY));
    TEST_ASSERT_NOT_NULL(strstr(WHY, "reverse saliency"));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_fieldweak_init(NULL, &C, &M, &B, &P, WHY, sizeof WHY));
}

/* Rs = 0: psi_max = V / w exactly as the lossless voltage circle says. */
static void test_psi_max_lossless(void)
{
    setup(&ini_thesis_spmsm, 0.0);
    for (double rpm = 500.0; rpm <= 6000.0; rpm += 500.0) {
        const ctrl_fieldweak_out_t o = step_at(rpm, 1.0, 0);
        const double want = v_max() / we(rpm) / B.psi_wb;
        /* Error: V (0.5 LSB + v_frac in Q30), sqrt floor (1 LSB) over w (>= 0.2 pu
         * here), the division's rounding: < 8 LSB. */
        TEST_ASSERT_DOUBLE_WITHIN(8 * LSB, fmin(want, d(S.psi_ceil)), d(o.psi_max));
    }
    /* At standstill the ceiling psi_pm + Lq I_max. */
    const ctrl_fieldweak_out_t o = step_at(0.0, 1.0, 0);
    TEST_ASSERT_EQUAL_INT32(S.psi_ceil, o.psi_max);
}

/* The resistive terms: motoring leaves less flux than braking, and the flux
 * matches the steady-state |v|^2 = Rs^2 I^2 + w^2 psi^2 + 2 Rs w T with the
 * low-passed torque of the previous periods and its current I = |T| / psi_pm
 * (at most I_max). */
static void test_resistive_drop(void)
{
    setup(&ini_thesis_spmsm, -1.0);
    const double rpm = 3400.0;
    ctrl_fieldweak_out_t o;
    ctrl_fieldweak_reset(&S);
    const q24_t t = q(1.5 / B.torque_nm);
    for (int k = 0; k < 200; k++) { /* the low pass settles (1/8 per period) */
        ctrl_fieldweak_step(&S, &P, vdc_pu(), omega_pu(rpm), t, 0, &o);
    }
    const double T_pu = d(S.t_prev);
    TEST_ASSERT_DOUBLE_WITHIN(8 * LSB, d(o.torque), T_pu);
    ctrl_fieldweak_step(&S, &P, vdc_pu(), omega_pu(rpm), t, 0, &o);
    const double rs = M.rs_ohm / B.r_ohm;
    const double i = fmin(M.current_rated_a / B.i_a, T_pu / (M.psi_pm_wb / B.psi_wb));
    const double v = v_max() / B.v_v;
    const double w = we(rpm) / B.w_rad_s;
    const double want = sqrt(v * v - rs * rs * i * i - 2.0 * rs * w * T_pu) / w;
    TEST_ASSERT_DOUBLE_WITHIN(16 * LSB, want, d(o.psi_max));
    ctrl_fieldweak_out_t ob;
    for (int k = 0; k < 200; k++) { /* braking, backwards */
        ctrl_fieldweak_step(&S, &P, vdc_pu(), omega_pu(-rpm), t, 0, &ob);
    }
    TEST_ASSERT_TRUE(ob.psi_max > o.psi_max);
}

/* The torque of the Rs terms after a call. From a reset, the first call's
 * torque is taken whole: the second call's limit is that of the torque it
 * lets through (from 0 with 1/8 per call it was the flux of a much smaller
 * torque for tens of calls). Where the limit bites on a high-resistance
 * motor (GBM5208 at its rated speed, Rs I_max 35 % of the voltage) the
 * torque settles on the limit's fixed point instead of alternating between
 * full torque and none: after the second call (the Rs terms of the whole
 * request leave no torque) never 0, constant within 50 calls, and there the
 * torque the voltage allows at the flux of that torque. */
static void test_rs_torque(void)
{
    setup(&ini_thesis_spmsm, -1.0);
    ctrl_fieldweak_out_t o;
    ctrl_fieldweak_reset(&S);
    const q24_t t = q(1.5 / B.torque_nm);
    ctrl_fieldweak_step(&S, &P, vdc_pu(), omega_pu(3400.0), t, 0, &o);
    TEST_ASSERT_EQUAL_INT32(t, o.torque);
    TEST_ASSERT_EQUAL_INT32(o.torque, S.t_prev);

    setup(&ini_gbm5208_gimbal, -1.0);
    ctrl_fieldweak_reset(&S);
    const double rpm = M.speed_rated_rpm;
    q24_t settled = 0;
    for (int k = 0; k < 400; k++) {
        ctrl_fieldweak_step(&S, &P, vdc_pu(), omega_pu(rpm), S.t_mtpa, 0, &o);
        if (k >= 2) {
            TEST_ASSERT_TRUE(o.torque > 0);
        }
        if (k == 50) {
            settled = o.torque;
        } else if (k > 50) {
            TEST_ASSERT_EQUAL_INT32(settled, o.torque);
        }
    }
    TEST_ASSERT_EQUAL_UINT8(1u, o.clipped); /* the limit bites */
    /* the fixed point: this torque's Rs terms, within the 1/8 step's truncation */
    TEST_ASSERT_INT32_WITHIN(8, o.torque, S.t_prev);
    const double rs = M.rs_ohm / B.r_ohm;
    const double tp = d(S.t_prev);
    const double i = fmin(M.current_rated_a / B.i_a, tp / (M.psi_pm_wb / B.psi_wb));
    const double v = v_max() / B.v_v;
    const double w = we(rpm) / B.w_rad_s;
    const double psi = sqrt(v * v - rs * rs * i * i - 2.0 * rs * w * tp) / w;
    TEST_ASSERT_DOUBLE_WITHIN(16 * LSB, psi, d(o.psi_max));
}

/* Below base speed: the current limit, MTPA (4.15), nothing weakened. */
static void test_below_base(void)
{
    setup(&ini_thesis_spmsm, -1.0);
    const ctrl_fieldweak_out_t o = step_at(1000.0, 10.0, 0);
    const double t_i = 1.5 * M.pole_pairs * M.psi_pm_wb * M.current_rated_a; /* i_d = 0 */
    TEST_ASSERT_DOUBLE_WITHIN(4 * LSB, t_i / B.torque_nm, d(o.torque_max));
    TEST_ASSERT_EQUAL_INT32(o.torque_max, o.torque);
    TEST_ASSERT_EQUAL_UINT8(CTRL_FIELDWEAK_LIMIT_CURRENT, o.limit);
    TEST_ASSERT_EQUAL_UINT8(1u, o.clipped);
    TEST_ASSERT_EQUAL_UINT8(0u, o.weakening);
    TEST_ASSERT_EQUAL_INT32(ctrl_mtpa_psi(&P, o.torque), o.psi_ref);
    const ctrl_fieldweak_out_t o2 = step_at(1000.0, -1.0, 0);
    TEST_ASSERT_EQUAL_INT32(q(-1.0 / B.torque_nm), o2.torque);
    TEST_ASSERT_EQUAL_UINT8(0u, o2.clipped);
    /* IPMSM: MTPA torque at 400 A from the closed form of the MTPA split. */
    setup(&ini_thesis_ipmsm80, -1.0);
    double id;
    double iq;
    ctrl_mtpa_split(M.psi_pm_wb, M.ld_h, M.lq_h, M.current_rated_a, &id, &iq);
    const double t_m = 1.5 * M.pole_pairs * (M.psi_pm_wb * iq + (M.ld_h - M.lq_h) * id * iq);
    /* MTPA mode (the file's fixed 0.1837 Wb is tested below). */
    ctrl_params_t pm = P;
    pm.psi_ref = 0;
    ctrl_fieldweak_reset(&S);
    ctrl_fieldweak_out_t o4;
    ctrl_fieldweak_step(&S, &pm, vdc_pu(), omega_pu(500.0), q(1e4 / B.torque_nm), 0, &o4);
    TEST_ASSERT_DOUBLE_WITHIN(8 * LSB, t_m / B.torque_nm, d(o4.torque_max));
    TEST_ASSERT_EQUAL_UINT8(CTRL_FIELDWEAK_LIMIT_CURRENT, o4.limit);
}

/* SPMSM, Rs = 0, between base and maximum speed: the circle meets the circle at
 * i_d = ((V/w)^2 - psi^2 - L^2 I^2) / (2 L psi); above w_max = V/(psi - L I)
 * no torque is possible. */
static void test_spmsm_field_weakening(void)
{
    setup(&ini_thesis_spmsm, 0.0);
    const double L = M.ld_h;
    const double psi = M.psi_pm_wb;
    const double I = M.current_rated_a;
    const double V = v_max();
    const double wb = V / hypot(psi, L * I);
    const double wmax = V / (psi - L * I);
    for (double x = 0.1; x < 1.0; x += 0.2) {
        const double w = wb + x * (wmax - wb);
        const double rpm = w / M.pole_pairs * 60.0 / (2.0 * CTRL_PI);
        const ctrl_fieldweak_out_t o = step_at(rpm, 10.0, 0);
        const double id = ((V / w) * (V / w) - psi * psi - L * L * I * I) / (2.0 * L * psi);
        const double want = 1.5 * M.pole_pairs * psi * sqrt(I * I - id * id) / B.torque_nm;
        /* psi_max within 8 LSB (above) moves i_d by 8 LSB psi/L (pu: psi/Ld) and
         * T by that times i_d/i_q psi; 64 LSB covers it with the roundings. */
        TEST_ASSERT_DOUBLE_WITHIN(64 * LSB + 1e-6 * want, want, d(o.torque_max));
        TEST_ASSERT_EQUAL_UINT8(CTRL_FIELDWEAK_LIMIT_VOLTAGE, o.limit);
        TEST_ASSERT_EQUAL_UINT8(1u, o.weakening);
        TEST_ASSERT_EQUAL_INT32(o.psi_max, o.psi_ref);
    }
    const double rpm_hi = 1.02 * wmax / M.pole_pairs * 60.0 / (2.0 * CTRL_PI);
    const ctrl_fieldweak_out_t o = step_at(rpm_hi, 1.0, 0);
    TEST_ASSERT_EQUAL_INT32(0, o.torque_max);
    TEST_ASSERT_EQUAL_INT32(0, o.torque);
}

/* 80 kW IPMSM (psi_pm/Ld = 312.5 A < 400 A), Rs = 0, MTPA mode: at 4x base
 * speed the voltage alone bounds the torque (MTPV on the flux circle V/w),
 * with the load-angle margin. */
static void test_ipmsm_mtpv(void)
{
    setup(&ini_thesis_ipmsm80, 0.0);
    P.psi_ref = 0; /* MTPA (the file's fixed reference is tested below) */
    const double rpm = 4.0 * 1538.0;
    const ctrl_fieldweak_out_t o = step_at(rpm, 1e4, 0);
    TEST_ASSERT_EQUAL_UINT8(CTRL_FIELDWEAK_LIMIT_MTPV, o.limit);
    /* MTPV closed form (SI): psi_d = (c1 - sqrt(c1^2 + 8 c2^2 psi^2)) / (4 c2). */
    const double ps = d(o.psi_max) * B.psi_wb;
    const double c1 = M.psi_pm_wb / M.ld_h;
    const double c2 = 1.0 / M.ld_h - 1.0 / M.lq_h;
    const double pd = (c1 - sqrt(c1 * c1 + 8.0 * c2 * c2 * ps * ps)) / (4.0 * c2);
    const double pq = sqrt(ps * ps - pd * pd);
    const double id = (pd - M.psi_pm_wb) / M.ld_h;
    const double iq = pq / M.lq_h;
    TEST_ASSERT_TRUE(hypot(id, iq) < M.current_rated_a);
    const double t_v = 1.5 * M.pole_pairs * (M.psi_pm_wb * iq + (M.ld_h - M.lq_h) * id * iq);
    TEST_ASSERT_DOUBLE_WITHIN(64 * LSB, C.torque_margin * t_v / B.torque_nm, d(o.torque_max));
    /* MTPV is the largest torque on its flux circle: a scan never beats it. */
    double best = 0.0;
    for (int k = 0; k <= 4000; k++) {
        const double a = CTRL_PI * k / 4000.0;
        const double i_d = (ps * cos(a) - M.psi_pm_wb) / M.ld_h;
        const double i_q = ps * sin(a) / M.lq_h;
        best = fmax(best, 1.5 * M.pole_pairs * (M.psi_pm_wb * i_q + (M.ld_h - M.lq_h) * i_d * i_q));
    }
    TEST_ASSERT_DOUBLE_WITHIN(1e-5 * best, best, t_v);
    /* At 1.5x base the current circle and the voltage ellipse. */
    const ctrl_fieldweak_out_t o2 = step_at(1.5 * 1538.0, 1e4, 0);
    TEST_ASSERT_EQUAL_UINT8(CTRL_FIELDWEAK_LIMIT_VOLTAGE, o2.limit);
}

/* Smooth entry and exit: the limits are continuous in speed. From standstill
 * to 2.5x base speed in steps of 1 r/min no step of the torque limit exceeds
 * twice the envelope's steepest slope (|dT/dw| <= T_mtpa / w_base on these
 * machines by the closed forms up to 80 % of the SPMSM's maximum speed, where
 * T ~ sqrt(w_max - w) steepens without bound; there no step may stand out of
 * its neighbours), and psi_ref at a fixed torque never jumps (psi_max = V/w
 * falls by psi_max/w per unit speed). */
static void check_continuity(const ctrl_machine_t *m, double rpm_base, double t_nm)
{
    setup(m, -1.0);
    P.psi_ref = 0;
    const double t_m = d(S.t_mtpa);
    enum { N_MAX = 8000 };
    static double tl[N_MAX];
    static double pr[N_MAX];
    int n = 0;
    int n_zero = N_MAX;
    int entered = 0;
    for (double rpm = 0.0; rpm <= 2.5 * rpm_base && n < N_MAX; rpm += 1.0, n++) {
        const ctrl_fieldweak_out_t o = step_at(rpm, t_nm, 0);
        tl[n] = d(o.torque_max);
        pr[n] = d(o.psi_ref);
        entered |= o.weakening;
        if (o.torque_max == 0 && n_zero == N_MAX) {
            n_zero = n;
        }
    }
    TEST_ASSERT_TRUE(entered);
    const int n_end = n_zero < N_MAX ? (int)(0.8 * n_zero) : n;
    double worst_t = 0.0;
    double worst_p = 0.0;
    for (int k = 1; k < n; k++) {
        const double dk = fabs(tl[k] - tl[k - 1]);
        if (k < n_end) {
            worst_t = fmax(worst_t, dk);
        }
        worst_p = fmax(worst_p, fabs(pr[k] - pr[k - 1]));
        /* Everywhere (also on the steep part): no isolated step, i.e. none
         * larger than 1.5x both neighbouring steps (but the last one to
         * T = 0: sqrt(1) - sqrt(0) is 2.4x sqrt(2) - sqrt(1)). */
        if (k >= 2 && k + 1 < n && k + 1 < n_zero) {
            const double nb = fmax(fabs(tl[k - 1] - tl[k - 2]), fabs(tl[k + 1] - tl[k]));
            TEST_ASSERT_TRUE_MESSAGE(dk <= 1.5 * nb + 64 * LSB,
                                     "isolated step of the torque limit");
        }
    }
    TEST_ASSERT_TRUE_MESSAGE(worst_t <= 2.0 * t_m / rpm_base + 64 * LSB, "torque limit jumps");
    TEST_ASSERT_TRUE_MESSAGE(worst_p <= 2.0 * d(S.psi_mtpa) / rpm_base + 64 * LSB,
                             "flux reference jumps");
}

static void test_continuity(void)
{
    check_continuity(&ini_thesis_spmsm, 2752.0, 2.0);
    check_continuity(&ini_thesis_ipmsm80, 1538.0, 300.0);
    check_continuity(&ini_chapter_ipmsm, 1000.0, 3.0);
}

/* DC link: the first sample primes the filter; then an EMA with 1 - exp(-2 pi fc Ts). */
static void test_vdc_filter(void)
{
    setup(&ini_thesis_spmsm, -1.0);
    ctrl_fieldweak_out_t o;
    ctrl_fieldweak_reset(&S);
    const q24_t v0 = vdc_pu();
    ctrl_fieldweak_step(&S, &P, v0, 0, 0, 0, &o);
    TEST_ASSERT_EQUAL_INT32(v0, o.vdc);
    const q24_t v1 = q(0.8 * d(v0));
    const double k = 1.0 - exp(-2.0 * CTRL_PI * C.vdc_lpf_hz / 10000.0);
    for (int n = 1; n <= 20; n++) {
        ctrl_fieldweak_step(&S, &P, v1, 0, 0, 0, &o);
        const double want = d(v1) + (d(v0) - d(v1)) * pow(1.0 - k, n);
        TEST_ASSERT_DOUBLE_WITHIN(4 * LSB, want, d(o.vdc));
    }
    /* No DC link, no torque. */
    ctrl_fieldweak_reset(&S);
    ctrl_fieldweak_step(&S, &P, 0, omega_pu(1000.0), q(0.1), 0, &o);
    TEST_ASSERT_EQUAL_INT32(0, o.torque);
}

/* ctrl_fieldweak_step_lazy against ctrl_fieldweak_step on the same inputs
 * (speed swept from standstill to 2.5 x rated and back, DC link +-20 %,
 * torque requests up to 1.5 x rated held for a few periods, psi_pm moved as
 * the PM-flux tracking does): identical outputs, psi_max excepted where the
 * lazy form did not compute it - and there the exact one is at least the
 * MTPA flux at the current limit and the flux reference; with and without
 * the region of its first test (lz_*). */
static void check_lazy(const ctrl_machine_t *m, double psi_ref_wb)
{
    ctrl_machine_t mm = *m;
    mm.psi_ref_wb = psi_ref_wb;
    setup(&mm, -1.0);
    ctrl_fieldweak_t lazy = S;
    ctrl_params_t pl = P;
    uint32_t r = 12345u;
    unsigned n_lazy = 0u;
    unsigned n_exact = 0u;
    unsigned n_region = 0u; /* periods with a region of the first test (lz_*) */
    q24_t t_req = 0;
    const int n = 20000;
    for (int k = 0; k < n; k++) {
        r = r * 1664525u + 1013904223u;
        const double ramp = k < n / 2 ? (double)k / (n / 2) : (double)(n - k) / (n / 2);
        const double rpm = 2.5 * M.speed_rated_rpm * ramp * ((k / 5000) % 2 == 0 ? 1.0 : -1.0);
        const q24_t vdc = q(d(vdc_pu()) * (0.8 + 0.4 * (double)(r >> 16) / 65536.0));
        if ((r & 15u) == 0u) {
            t_req = q((double)(int32_t)(r - 2147483648u) / 2147483648.0 * 1.5 * M.torque_rated_nm /
                      B.torque_nm);
        }
        if ((r & 255u) == 1u) {
            P.psi_pm = pl.psi_pm = fx_add(P.psi_pm, (q24_t)((r >> 8) % 4001u) - 2000);
        }
        ctrl_fieldweak_out_t oe;
        ctrl_fieldweak_out_t ol;
        if (lazy.lz_w_max != 0) {
            n_region++;
        }
        ctrl_fieldweak_step(&S, &P, vdc, omega_pu(rpm), t_req, 0, &oe);
        ctrl_fieldweak_step_lazy(&lazy, &pl, vdc, omega_pu(rpm), t_req, &ol);
        TEST_ASSERT_EQUAL_INT32(oe.vdc, ol.vdc);
        TEST_ASSERT_EQUAL_INT32(oe.torque_max, ol.torque_max);
        TEST_ASSERT_EQUAL_INT32(oe.torque, ol.torque);
        TEST_ASSERT_EQUAL_INT32(oe.psi_ref, ol.psi_ref);
        TEST_ASSERT_EQUAL_UINT8(oe.limit, ol.limit);
        TEST_ASSERT_EQUAL_UINT8(oe.clipped, ol.clipped);
        TEST_ASSERT_EQUAL_UINT8(oe.weakening, ol.weakening);
        if (ol.psi_max == CTRL_FIELDWEAK_PSI_MAX_NOT_BINDING) {
            n_lazy++;
            TEST_ASSERT_TRUE(oe.psi_max >= S.psi_mtpa && oe.psi_max >= oe.psi_ref);
        } else {
            n_exact++;
            TEST_ASSERT_EQUAL_INT32(oe.psi_max, ol.psi_max);
        }
    }
    if (psi_ref_wb > 0.0) {
        TEST_ASSERT_EQUAL_UINT(0u, n_lazy); /* a fixed reference: always computed */
    } else {
        TEST_ASSERT_TRUE(n_lazy > 0u && n_exact > 0u && n_region > 0u);
    }
}

static void test_lazy(void)
{
    check_lazy(&ini_thesis_spmsm, 0.0);
    check_lazy(&ini_thesis_ipmsm80, 0.0);
    check_lazy(&ini_thesis_ipmsm80, 0.1837);
    check_lazy(&ini_chapter_ipmsm, 0.0);
}

/* The 80 kW IPMSM's fixed reference 0.1837 Wb (section 6.5.1) bounds the torque
 * below base speed: the flux circle at 0.1837 Wb meets the 400 A circle, or its
 * MTPV point with the margin. */
static void test_fixed_flux(void)
{
    setup(&ini_thesis_ipmsm80, -1.0);
    const ctrl_fieldweak_out_t o = step_at(1000.0, 1e4, 0);
    TEST_ASSERT_EQUAL_UINT8(CTRL_FIELDWEAK_LIMIT_FLUX, o.limit);
    TEST_ASSERT_EQUAL_INT32(P.psi_ref, o.psi_ref);
    /* Scan the flux circle 0.1837 Wb inside 400 A for the largest torque. */
    const double ps = M.psi_ref_wb;
    double best = 0.0;
    double best_v = 0.0;
    for (int k = 0; k <= 20000; k++) {
        const double a = CTRL_PI * k / 20000.0;
        const double i_d = (ps * cos(a) - M.psi_pm_wb) / M.ld_h;
        const double i_q = ps * sin(a) / M.lq_h;
        const double t = 1.5 * M.pole_pairs * (M.psi_pm_wb * i_q + (M.ld_h - M.lq_h) * i_d * i_q);
        best_v = fmax(best_v, t);
        if (hypot(i_d, i_q) <= M.current_rated_a) {
            best = fmax(best, t);
        }
    }
    const double want = fmin(best, C.torque_margin * best_v);
    TEST_ASSERT_DOUBLE_WITHIN(2e-4 * want, want / B.torque_nm, d(o.torque_max));
}

/* FOC: the currents for torque t on the flux circle psi_ref give t and psi_ref
 * (after the Newton steps have converged); MTPA below base speed. */
static void check_currents(const ctrl_machine_t *m, double rpm, double frac)
{
    setup(m, -1.0);
    P.psi_ref = 0;
    ctrl_fieldweak_out_t o = step_at(rpm, 1e5, 0);
    const q24_t t = q(frac * d(o.torque_max));
    ctrl_fieldweak_step(&S, &P, vdc_pu(), omega_pu(rpm), t, 0, &o);
    q24_t id = 0;
    q24_t iq = 0;
    for (int k = 0; k < 10; k++) {
        ctrl_fieldweak_currents(&S, &P, o.torque, o.psi_ref, &id, &iq);
    }
    const double ld = d(P.ld);
    const double lq = d(P.lq);
    const double pm = d(P.psi_pm);
    const double T = (pm + (ld - lq) * d(id)) * d(iq);
    const double psi = hypot(ld * d(id) + pm, lq * d(iq));
    /* Converged: residuals of a few LSB of the flux and torque, amplified by
     * the 1/Ld, 1/Lq of the current conversion (<= 4 pu here). */
    TEST_ASSERT_DOUBLE_WITHIN(256 * LSB, d(o.torque), T);
    if (o.weakening) {
        TEST_ASSERT_DOUBLE_WITHIN(256 * LSB, d(o.psi_ref), psi);
    } else {
        q24_t md;
        q24_t mq;
        ctrl_mtpa_current(&P, o.torque, &md, &mq);
        TEST_ASSERT_EQUAL_INT32(md, id);
        TEST_ASSERT_EQUAL_INT32(mq, iq);
    }
    TEST_ASSERT_TRUE(hypot(d(id), d(iq)) <= d(S.i_max) * 1.001);
    /* Negative torque: the mirror image. */
    q24_t id2 = 0;
    q24_t iq2 = 0;
    for (int k = 0; k < 10; k++) {
        ctrl_fieldweak_currents(&S, &P, fx_neg(o.torque), o.psi_ref, &id2, &iq2);
    }
    TEST_ASSERT_INT32_WITHIN(4, id, id2);
    TEST_ASSERT_INT32_WITHIN(4, -iq, iq2);
}

static void test_currents(void)
{
    check_currents(&ini_thesis_spmsm, 1000.0, 0.9);
    check_currents(&ini_thesis_spmsm, 3400.0, 0.9);
    check_currents(&ini_thesis_spmsm, 3750.0, 0.5);
    check_currents(&ini_thesis_ipmsm80, 3000.0, 0.9);
    check_currents(&ini_thesis_ipmsm80, 4500.0, 0.9);
    check_currents(&ini_thesis_ipmsm80, 6000.0, 0.9);
    check_currents(&ini_thesis_ipmsm80, 6000.0, 0.2);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_config_refusals);
    RUN_TEST(test_psi_max_lossless);
    RUN_TEST(test_resistive_drop);
    RUN_TEST(test_rs_torque);
    RUN_TEST(test_below_base);
    RUN_TEST(test_spmsm_field_weakening);
    RUN_TEST(test_ipmsm_mtpv);
    RUN_TEST(test_continuity);
    RUN_TEST(test_vdc_filter);
    RUN_TEST(test_fixed_flux);
    RUN_TEST(test_currents);
    RUN_TEST(test_lazy);
    return UNITY_END();
}
