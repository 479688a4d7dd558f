/*
 * Dead-time and device-drop compensation (control/modulation/deadtime.h)
 * against an edge model of the inverter written here from the physics (the
 * plant's: after each commanded edge both switches are off for t_d and the
 * current's diode sets the leg; centre-aligned pulses low at the period's
 * ends unless d = 1): with full-sign currents the duties the compensated legs
 * really apply equal the intended ones (line voltages, the common mode being
 * free), for pulses, clamped legs and edges at the period start.
 * The 24 V outrunner (sim_host/machines/outrunner_24v.ini) at 20 kHz,
 * 500 ns: t_d fs = 1 %.
 */
#include <math.h>
#include <stdbool.h>
#include <string.h>

#include "ctrl_params.h"
#include "deadtime.h"
#include "unity.h"

#include "../plant/ini_machines.h"

static ctrl_params_t p;
static ctrl_bases_t b;

void setUp(void)
{
}

void tearDown(void)
{
}

static const ctrl_machine_t *const outrunner = &ini_outrunner_24v;

static ctrl_deadtime_t setup(double td_s, double vf_v, double band_a)
{
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&p, &b, outrunner, 20000u));
    const ctrl_deadtime_config_t c = {td_s, vf_v, band_a};
    ctrl_deadtime_t d;
    ctrl_diag_t why;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_deadtime_init(&d, &c, &p, &b, &why));
    return d;
}

/* An estimate whose predicted current at the middle of [k+1, k+2) is
 * (i_a, i_b, -i_a - i_b) A: theta(k+1) = 0, no rotation, i_d = i_alpha,
 * i_q = i_beta. */
static ctrl_estimate_t est_currents(double i_a, double i_b)
{
    ctrl_estimate_t e;
    memset(&e, 0, sizeof e);
    e.next.i_d = ctrl_q24_from_double(i_a / b.i_a);
    e.next.i_q = ctrl_q24_from_double((i_a + 2.0 * i_b) / sqrt(3.0) / b.i_a);
    return e;
}

/* The leg's applied high time (fraction of the period) on a grid of N
 * slots: the commanded state (centre-aligned: high in [(1 - d)/2, (1 + d)/2],
 * all period for d >= 1, never for d <= 0), the state before the period
 * prev_high; after each commanded change both switches are off for t (t_d
 * fs) and the current's diode sets the leg (i > 0: low, i < 0: high). */
#define N_SLOTS 20000
static double applied(double d, bool prev_high, bool i_pos, double t)
{
    const int n_off = (int)lround(t * N_SLOTS);
    bool cmd_prev = prev_high;
    int off_left = 0;
    int high = 0;
    for (int k = 0; k < N_SLOTS; k++) {
        const double tc = (k + 0.5) / N_SLOTS;
        const bool cmd = d >= 1.0 || (d > 0.0 && tc >= 0.5 * (1.0 - d) && tc < 0.5 * (1.0 + d));
        if (cmd != cmd_prev) {
            off_left = n_off;
            cmd_prev = cmd;
        }
        bool out = cmd;
        if (off_left > 0) {
            out = !i_pos;
            off_left--;
        }
        high += out ? 1 : 0;
    }
    return (double)high / N_SLOTS;
}

static double q(q24_t x)
{
    return (double)x / 16777216.0;
}

/* The line voltages (per Vdc) of the applied duties equal the intended ones. */
static void check_lines(const double want[3], const ctrl_legs_t *w, uint32_t high_prev,
                        const bool i_pos[3], double t)
{
    double a[3];
    for (int x = 0; x < 3; x++) {
        a[x] = applied(q(w->duty[x]), (high_prev >> x) & 1u, i_pos[x], t);
    }
    TEST_ASSERT_DOUBLE_WITHIN(2e-4, want[0] - want[1], a[0] - a[1]);
    TEST_ASSERT_DOUBLE_WITHIN(2e-4, want[1] - want[2], a[1] - a[2]);
}

/* The duties want[] through the compensation after a period that ended as
 * high_prev says; the line voltages checked (currents' signs pos). */
static ctrl_legs_t apply_checked(ctrl_deadtime_t *d, const ctrl_estimate_t *e, const double want[3],
                                 uint32_t high_prev, const bool pos[3])
{
    ctrl_legs_t l;
    for (int x = 0; x < 3; x++) {
        l.duty[x] = ctrl_q24_from_double(want[x]);
    }
    d->high_prev = high_prev;
    ctrl_deadtime_apply(d, e, &l);
    check_lines(want, &l, high_prev, pos, 0.01);
    return l;
}

static void test_off(void)
{
    ctrl_deadtime_t d = setup(0.0, 0.0, 1.0);
    TEST_ASSERT_EQUAL_INT(0, d.dd);
    ctrl_estimate_t e = est_currents(3.0, -1.0);
    ctrl_legs_t l = {{FX_ONE / 3, FX_ONE / 2, FX_ONE / 5}};
    const ctrl_legs_t before = l;
    ctrl_deadtime_apply(&d, &e, &l);
    TEST_ASSERT_EQUAL_MEMORY(&before, &l, sizeof l);
}

/* Pulses on every leg: each moved by t_d fs towards its current's sign. */
static void test_pulses(void)
{
    ctrl_deadtime_t d = setup(500e-9, 0.0, 0.5);
    TEST_ASSERT_DOUBLE_WITHIN(1e-7, 0.01, q(d.dd));
    ctrl_estimate_t e = est_currents(4.0, -1.5); /* i_c = -2.5 A */
    const double want[3] = {0.6, 0.45, 0.3};
    const bool pos[3] = {true, false, false};
    const ctrl_legs_t l = apply_checked(&d, &e, want, 0u, pos);
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 0.61, q(l.duty[0]));
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 0.44, q(l.duty[1]));
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 0.29, q(l.duty[2]));
}

/* Within the band the correction is proportional: 0.25 A of 0.5 A: half. */
static void test_band(void)
{
    ctrl_deadtime_t d = setup(500e-9, 0.0, 0.5);
    ctrl_estimate_t e = est_currents(0.25, -3.0);
    ctrl_legs_t l = {{FX_ONE / 2, FX_ONE / 2, FX_ONE / 2}};
    ctrl_deadtime_apply(&d, &e, &l);
    TEST_ASSERT_DOUBLE_WITHIN(2e-6, 0.505, q(l.duty[0]));
    TEST_ASSERT_DOUBLE_WITHIN(2e-6, 0.49, q(l.duty[1]));
    TEST_ASSERT_DOUBLE_WITHIN(2e-6, 0.51, q(l.duty[2])); /* i_c = +2.75 A */
}

/* Clamped legs of a plan (the active vector with V7: legs high all period). */
static void test_clamped(void)
{
    ctrl_deadtime_t d = setup(500e-9, 0.0, 0.5);
    ctrl_estimate_t e = est_currents(-2.0, 3.0); /* i_c = -1 A */
    const bool pos[3] = {false, true, false};
    /* a: high all period after a period that ended high, i < 0: written
     * below 1, so that it ends low (no late falling edge next period) */
    const double want[3] = {1.0, 0.6, 0.4};
    ctrl_legs_t l = apply_checked(&d, &e, want, 1u, pos);
    TEST_ASSERT_TRUE(l.duty[0] < FX_ONE);
    /* b: high all period after a low end, i > 0: its late rising edge made
     * up by the other legs' pulses */
    const double want2[3] = {0.5, 1.0, 0.3};
    l = apply_checked(&d, &e, want2, 0u, pos);
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 1.0, q(l.duty[1]));
    /* a pulse after a period that ended high, i < 0: its late falling edge
     * at the start taken off too */
    const double want3[3] = {0.5, 0.2, 0.1};
    l = apply_checked(&d, &e, want3, 1u, pos);
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 0.48, q(l.duty[0]));
    /* a leg at 0 stays 0 */
    l.duty[0] = 0;
    l.duty[1] = FX_ONE / 2;
    l.duty[2] = FX_ONE / 2;
    ctrl_deadtime_apply(&d, &e, &l);
    TEST_ASSERT_EQUAL_INT(0, l.duty[0]);
}

/* The drop: v_f / Vdc_nom more on each leg (1.2 V of 24 V: 5 %). */
static void test_drop(void)
{
    ctrl_deadtime_t d = setup(0.0, 1.2, 0.5);
    TEST_ASSERT_DOUBLE_WITHIN(1e-7, 0.05, q(d.dd));
    ctrl_estimate_t e = est_currents(4.0, -1.5);
    ctrl_legs_t l = {{FX_ONE / 2, FX_ONE / 2, FX_ONE / 2}};
    ctrl_deadtime_apply(&d, &e, &l);
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 0.55, q(l.duty[0]));
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 0.45, q(l.duty[1]));
}

/* The sign is taken at theta(k+1) + omega Ts / 2: i_q only, the rotor at
 * -(a quarter turn) - half a step: the current vector on phase a's axis. */
static void test_angle(void)
{
    ctrl_deadtime_t d = setup(500e-9, 0.0, 0.5);
    ctrl_estimate_t e;
    memset(&e, 0, sizeof e);
    e.next.i_q = ctrl_q24_from_double(3.0 / b.i_a);
    e.dtheta = 1 << 26; /* 5.6 deg per period */
    e.next.theta_e = (fx_angle_t)(0xC0000000u - (1u << 25));
    ctrl_legs_t l = {{FX_ONE / 2, FX_ONE / 2, FX_ONE / 2}};
    ctrl_deadtime_apply(&d, &e, &l);
    /* i_a = +3 A, i_b = i_c = -1.5 A */
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 0.51, q(l.duty[0]));
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 0.49, q(l.duty[1]));
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 0.49, q(l.duty[2]));
}

static void test_refused(void)
{
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&p, &b, outrunner, 20000u));
    ctrl_deadtime_t d;
    ctrl_diag_t why;
    const ctrl_deadtime_config_t big = {20e-6, 0.0, 1.0}; /* beyond Ts / 4 = 12.5 us */
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_deadtime_init(&d, &big, &p, &b, &why));
    TEST_ASSERT_EQUAL_STRING("dead_time_s", why.quantity);
    const ctrl_deadtime_config_t nan_band = {500e-9, 0.0, NAN};
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_deadtime_init(&d, &nan_band, &p, &b, &why));
    TEST_ASSERT_EQUAL_STRING("band_a", why.quantity);
    /* the default band: half of Vdc / (6 L fs) = 1.5625 A */
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 1.5625, ctrl_deadtime_band_default(outrunner, 20000.0));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_off);
    RUN_TEST(test_pulses);
    RUN_TEST(test_band);
    RUN_TEST(test_clamped);
    RUN_TEST(test_drop);
    RUN_TEST(test_angle);
    RUN_TEST(test_refused);
    return UNITY_END();
}
