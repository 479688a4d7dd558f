/*
 * Plant model against closed forms: RL step at locked rotor (d and q time
 * constants), sinusoidal steady state (phasors), torque identities, energy
 * balance, the RK4 path against the exact path, free mechanics, dead time,
 * gates off, and argument checking.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "ini_machines.h"
#include "plant.h"
#include "unity.h"

void setUp(void)
{
}
void tearDown(void)
{
}

/* The electrical and mechanical data of a shipped machine file
 * (ini_machines.h), everything else of the plant zero (ideal inverter). */
static plant_config_t cfg_from_machine(const ctrl_machine_t *m)
{
    plant_config_t c;
    memset(&c, 0, sizeof c);
    c.pole_pairs = m->pole_pairs;
    c.rs_ohm = m->rs_ohm;
    c.ld_h = m->ld_h;
    c.lq_h = m->lq_h;
    c.psi_pm_wb = m->psi_pm_wb;
    c.vdc_v = m->vdc_v;
    c.inertia_kgm2 = m->inertia_kgm2;
    return c;
}

/* Thesis SPMSM, Table 3.2. */
static plant_config_t cfg_spmsm(void)
{
    return cfg_from_machine(&ini_thesis_spmsm);
}

/* Book-chapter IPMSM, S1 Table 2 (S1 prints the labels crossed; for an IPMSM Ld < Lq). */
static plant_config_t cfg_chapter(void)
{
    return cfg_from_machine(&ini_chapter_ipmsm);
}

static double rel_err(double a, double b, double scale)
{
    return fabs(a - b) / scale;
}

/* Locked rotor, V1 = 100 applied by the inverter: v_alpha = 2 Vdc / 3. With
 * theta = 0 the vector lies on d: id = V/R (1 - e^{-tR/Ld}), iq = 0. With
 * theta = pi/2 it lies on -q: iq = -V/R (1 - e^{-tR/Lq}), id = 0. */
static void check_locked_rotor(double theta0, int axis_q)
{
    plant_config_t c = cfg_chapter();
    c.theta0_e_rad = theta0;
    plant_t p;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
    const double V = 2.0 * c.vdc_v / 3.0, R = c.rs_ohm;
    const double L = axis_q ? c.lq_h : c.ld_h;
    const uint8_t v1[3] = {1, 0, 0};
    double t = 0.0, worst = 0.0;
    for (int k = 0; k < 200; ++k) {
        const double dt = 1e-4 * (1.0 + 0.37 * (double)(k % 5)); /* uneven steps */
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance(&p, dt, v1));
        t += dt;
        const double i_exp = V / R * (1.0 - exp(-t * R / L));
        double id, iq;
        plant_i_dq(&p, &id, &iq);
        const double on = axis_q ? -iq : id, off = axis_q ? id : iq;
        const double e = fmax(rel_err(on, i_exp, V / R), fabs(off) / (V / R));
        worst = fmax(worst, e);
    }
    char msg[96];
    snprintf(msg, sizeof msg, "locked rotor %s: max rel err %.3g", axis_q ? "q" : "d", worst);
    TEST_MESSAGE(msg);
    /* exact closed form in double: only rounding remains */
    TEST_ASSERT_TRUE_MESSAGE(worst < 1e-12, msg);
}

static void test_locked_rotor_d_axis(void)
{
    check_locked_rotor(0.0, 0);
}
static void test_locked_rotor_q_axis(void)
{
    check_locked_rotor(0.5 * PLANT_PI, 1);
}

/* SPMSM in alpha-beta: v = R i + L di/dt + j w psi_pm e^{j theta}. A stator
 * voltage V e^{j(wv t + phi)} at a frequency other than the rotor's gives the
 * steady state i = V e^{j(wv t+phi)} / (R + j wv L) - j w psi_pm e^{j theta}/(R + j w L). */
static void test_phasor_steady_state_spmsm(void)
{
    plant_config_t c = cfg_spmsm();
    c.speed0_rpm = 1500.0;
    c.theta0_e_rad = 0.3;
    plant_t p;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
    const double w = 1500.0 / 60.0 * 2.0 * PLANT_PI * 4.0;
    const double wv = 2.0 * PLANT_PI * 70.0, V = 100.0, phi = -0.4, R = c.rs_ohm, L = c.ld_h;
    /* 0.25 s = 34 time constants: transient below 1e-14 of the initial one */
    for (int k = 0; k < 250; ++k) {
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance_voltage_ab(&p, 1e-3, V, wv, phi));
    }
    double worst = 0.0;
    for (int k = 0; k < 100; ++k) {
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance_voltage_ab(&p, 1.3e-4, V, wv, phi));
        const double t = plant_time(&p);
        const double th = c.theta0_e_rad + w * t;
        /* V e^{j a} / (R + j wv L) */
        const double a = wv * t + phi, den1 = R * R + wv * wv * L * L;
        const double i1r = V * (cos(a) * R + sin(a) * wv * L) / den1;
        const double i1i = V * (sin(a) * R - cos(a) * wv * L) / den1;
        /* -j w psi e^{j th} / (R + j w L) */
        const double den2 = R * R + w * w * L * L;
        const double er = w * c.psi_pm_wb * sin(th), ei = -w * c.psi_pm_wb * cos(th);
        const double i2r = (er * R + ei * w * L) / den2, i2i = (ei * R - er * w * L) / den2;
        double ia, ib;
        plant_i_ab(&p, &ia, &ib);
        const double scale = hypot(i1r + i2r, i1i + i2i);
        worst = fmax(worst, hypot(ia - i1r - i2r, ib - i1i - i2i) / scale);
    }
    char msg[80];
    snprintf(msg, sizeof msg, "SPMSM phasor steady state: max rel err %.3g", worst);
    TEST_MESSAGE(msg);
    TEST_ASSERT_TRUE_MESSAGE(worst < 1e-9, msg);
}

/* IPMSM with a synchronously rotating voltage: constant v_dq, so the steady
 * state solves [Rs, -w Lq; w Ld, Rs] i = (vd, vq - w psi_pm). */
static void test_phasor_steady_state_ipmsm_sync(void)
{
    plant_config_t c = cfg_chapter();
    c.speed0_rpm = -700.0; /* backward rotation too */
    c.theta0_e_rad = 1.1;
    plant_t p;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
    const double w = -700.0 / 60.0 * 2.0 * PLANT_PI * 2.0;
    const double V = 90.0, phi = 2.0;
    for (int k = 0; k < 400; ++k) { /* 0.4 s: > 35 of the slowest time constant */
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance_voltage_ab(&p, 1e-3, V, w, phi));
    }
    /* v_dq = V e^{j(phi - theta0)} (constant) */
    const double vd = V * cos(phi - c.theta0_e_rad), vq = V * sin(phi - c.theta0_e_rad);
    const double R = c.rs_ohm, a11 = R, a12 = -w * c.lq_h, a21 = w * c.ld_h, a22 = R;
    const double b1 = vd, b2 = vq - w * c.psi_pm_wb, det = a11 * a22 - a12 * a21;
    const double id_e = (b1 * a22 - a12 * b2) / det, iq_e = (a11 * b2 - a21 * b1) / det;
    double id, iq;
    plant_i_dq(&p, &id, &iq);
    const double e = hypot(id - id_e, iq - iq_e) / hypot(id_e, iq_e);
    char msg[80];
    snprintf(msg, sizeof msg, "IPMSM synchronous steady state: rel err %.3g", e);
    TEST_MESSAGE(msg);
    TEST_ASSERT_TRUE_MESSAGE(e < 1e-9, msg);
}

/* (3.10) == (3.6) == 1.5 p (psi_pm iq + (Ld - Lq) id iq) on the plant's own state. */
static void test_torque_identities(void)
{
    plant_config_t c = cfg_chapter();
    unsigned seed = 12345u;
    for (int k = 0; k < 200; ++k) {
        seed = seed * 1103515245u + 12345u;
        c.id0_a = ((double)(seed >> 8 & 0xffff) / 65535.0 - 0.5) * 10.0;
        seed = seed * 1103515245u + 12345u;
        c.iq0_a = ((double)(seed >> 8 & 0xffff) / 65535.0 - 0.5) * 10.0;
        seed = seed * 1103515245u + 12345u;
        c.theta0_e_rad = ((double)(seed >> 8 & 0xffff) / 65535.0 - 0.5) * 20.0;
        plant_t p;
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
        double pa, pb, ia, ib;
        plant_psi_ab(&p, &pa, &pb);
        plant_i_ab(&p, &ia, &ib);
        const double t36 = 1.5 * c.pole_pairs * (pa * ib - pb * ia);
        const double tdq =
            1.5 * c.pole_pairs * (c.psi_pm_wb * c.iq0_a + (c.ld_h - c.lq_h) * c.id0_a * c.iq0_a);
        const double te = plant_torque(&p);
        TEST_ASSERT_DOUBLE_WITHIN(1e-12 * (1.0 + fabs(tdq)), tdq, te);
        TEST_ASSERT_DOUBLE_WITHIN(1e-12 * (1.0 + fabs(tdq)), tdq, t36);
        /* i_abc sums to zero and Clarke of it is i_ab */
        double iabc[3];
        plant_i_abc(&p, iabc);
        TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.0, iabc[0] + iabc[1] + iabc[2]);
        TEST_ASSERT_DOUBLE_WITHIN(1e-12, ia, iabc[0]);
        TEST_ASSERT_DOUBLE_WITHIN(1e-12, ib, (iabc[1] - iabc[2]) / sqrt(3.0));
        TEST_ASSERT_DOUBLE_WITHIN(1e-12, hypot(pa, pb), plant_psi_amp(&p));
    }
}

/* Deterministic pseudo-random duties. */
static double urand(unsigned *s)
{
    *s = *s * 1664525u + 1013904223u;
    return (double)(*s >> 8) / 16777216.0;
}

/* Energy balance of the machine: inverter output = copper + mechanical + dW.
 * Exact path: the state is exact and the energy integrals use 4-point
 * Gauss-Legendre per piece (<= 50 us, exact to degree 7): relative error
 * ~ (w h)^8 / 1e4 < 1e-12, so 1e-9 leaves a margin for rounding. */
static void check_energy(plant_config_t c, double rpm, double tol, const char *name)
{
    c.speed0_rpm = rpm;
    c.track_energy = 1;
    c.iq0_a = 1.0;
    plant_t p;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
    const double w0 = plant_magnetic_energy(&p);
    unsigned s = 7u;
    for (int k = 0; k < 400; ++k) {
        /* a rotating sinusoidal pattern plus noise: currents flow both ways */
        const double th = plant_theta_e(&p) + 1.7;
        double d[3];
        for (int x = 0; x < 3; ++x) {
            d[x] = 0.5 + 0.3 * cos(th - 2.0 * PLANT_PI / 3.0 * x) + 0.1 * (urand(&s) - 0.5);
        }
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance_period(&p, 50e-6, d));
    }
    double esrc, ein, ecu, emech;
    plant_energy(&p, &esrc, &ein, &ecu, &emech);
    const double dw = plant_magnetic_energy(&p) - w0;
    const double scale = fabs(ein) + fabs(ecu) + fabs(emech) + fabs(dw);
    const double e = fabs(ein - ecu - emech - dw) / scale;
    char msg[160];
    snprintf(msg, sizeof msg, "%s: E_in %.6g J = Cu %.6g + mech %.6g + dW %.6g; rel residual %.3g",
             name, ein, ecu, emech, dw, e);
    TEST_MESSAGE(msg);
    TEST_ASSERT_TRUE_MESSAGE(e < tol, msg);
    TEST_ASSERT_TRUE(ecu > 0.0);
}

static void test_energy_balance_spmsm(void)
{
    check_energy(cfg_spmsm(), 2000.0, 1e-9, "SPMSM");
}
static void test_energy_balance_ipmsm(void)
{
    check_energy(cfg_chapter(), -900.0, 1e-9, "chapter IPMSM");
}

/* RK4 path (forward drop, flux coordinates): balance to the RK4 error, and the
 * devices dissipate (source energy > machine input energy). */
static void test_energy_balance_forward_drop(void)
{
    plant_config_t c = cfg_spmsm();
    c.v_fwd_v = 1.5;
    c.speed0_rpm = 1200.0;
    c.track_energy = 1;
    c.iq0_a = 2.0;
    plant_t p;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
    const double w0 = plant_magnetic_energy(&p);
    for (int k = 0; k < 200; ++k) {
        const double th = plant_theta_e(&p) + 1.7;
        double d[3];
        for (int x = 0; x < 3; ++x) {
            d[x] = 0.5 + 0.3 * cos(th - 2.0 * PLANT_PI / 3.0 * x);
        }
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance_period(&p, 50e-6, d));
    }
    double esrc, ein, ecu, emech;
    plant_energy(&p, &esrc, &ein, &ecu, &emech);
    const double dw = plant_magnetic_energy(&p) - w0;
    const double scale = fabs(ein) + fabs(ecu) + fabs(emech) + fabs(dw);
    const double e = fabs(ein - ecu - emech - dw) / scale;
    char msg[120];
    snprintf(msg, sizeof msg, "forward drop: rel residual %.3g, device loss %.4g J", e, esrc - ein);
    TEST_MESSAGE(msg);
    /* RK4 (h = 0.5 us) of a state that is continuous but whose derivative
     * jumps when a phase current changes sign: first order at those steps */
    TEST_ASSERT_TRUE_MESSAGE(e < 1e-6, msg);
    TEST_ASSERT_TRUE(esrc - ein > 0.0);
}

/* A flux map that is exactly linear makes the RK4 flux-coordinate path
 * integrate the same model as the exact path: it measures the RK4 error. */
static void test_rk4_path_matches_exact(void)
{
    plant_config_t c = cfg_spmsm();
    c.ld_h = 5e-3;
    c.lq_h = 9e-3; /* salient */
    static double pd[5 * 5], pq[5 * 5];
    plant_fluxmap_t m = {5, 5, -40.0, 40.0, -40.0, 40.0, pd, pq};
    for (size_t a = 0; a < 5; ++a) {
        for (size_t b = 0; b < 5; ++b) {
            const double id = -40.0 + 20.0 * (double)a, iq = -40.0 + 20.0 * (double)b;
            pd[a * 5 + b] = c.ld_h * id + c.psi_pm_wb;
            pq[a * 5 + b] = c.lq_h * iq;
        }
    }
    c.speed0_rpm = 2500.0;
    c.id0_a = -1.0;
    c.iq0_a = 3.0;
    plant_t pe, pr;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&pe, &c));
    c.fluxmap = &m;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&pr, &c));
    unsigned s = 99u;
    double worst = 0.0, imax = 0.0;
    for (int k = 0; k < 200; ++k) {
        double d[3];
        for (int x = 0; x < 3; ++x) {
            d[x] = urand(&s);
        }
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance_period(&pe, 50e-6, d));
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance_period(&pr, 50e-6, d));
        double a1, b1, a2, b2;
        plant_i_dq(&pe, &a1, &b1);
        plant_i_dq(&pr, &a2, &b2);
        imax = fmax(imax, hypot(a1, b1));
        worst = fmax(worst, hypot(a1 - a2, b1 - b2));
    }
    char msg[96];
    snprintf(msg, sizeof msg, "RK4 (0.5 us) vs exact: max err %.3g A of %.3g A", worst, imax);
    TEST_MESSAGE(msg);
    TEST_ASSERT_TRUE_MESSAGE(worst < 1e-9 * imax, msg);
}

/* Free mechanics, B = 0, T_L = 0: the kinetic energy gained equals the
 * integral of Te w_m. The scheme holds w at the midpoint prediction and
 * updates it with the Simpson mean torque: per piece of length h the mismatch
 * is T (T_mean - T_0) h^2 / (2J) ~ |T| |dT/dt| h^3 / (4J). */
static void test_free_mechanics_energy(void)
{
    plant_config_t c = cfg_spmsm();
    c.mech = PLANT_MECH_FREE;
    c.track_energy = 1;
    c.speed0_rpm = 500.0;
    plant_t p;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
    const double ke0 = 0.5 * c.inertia_kgm2 * pow(plant_omega_m(&p), 2);
    for (int k = 0; k < 400; ++k) { /* accelerate with a vector leading the rotor by ~100 deg */
        const double th = plant_theta_e(&p) + 1.75;
        double d[3];
        for (int x = 0; x < 3; ++x) {
            d[x] = 0.5 + 0.15 * cos(th - 2.0 * PLANT_PI / 3.0 * x);
        }
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance_period(&p, 50e-6, d));
    }
    double esrc, ein, ecu, emech;
    plant_energy(&p, &esrc, &ein, &ecu, &emech);
    const double dke = 0.5 * c.inertia_kgm2 * pow(plant_omega_m(&p), 2) - ke0;
    /* bound: pieces <= 50 us, |T| <= 5 N m, |dT/dt| <= 1.5 p psi_pm (Vdc + w psi)/L */
    const double dtdt = 1.5 * 4 * c.psi_pm_wb * (c.vdc_v + 700.0 * 4 * c.psi_pm_wb) / c.ld_h;
    const double bound = 400.0 * 7.0 * 5.0 * dtdt * pow(50e-6, 3) / (4.0 * c.inertia_kgm2);
    char msg[128];
    snprintf(msg, sizeof msg, "free mech: dKE %.6g J, int Te w %.6g J, diff %.3g (bound %.3g)", dke,
             emech, fabs(dke - emech), bound);
    TEST_MESSAGE(msg);
    TEST_ASSERT_TRUE(dke > 0.0);
    TEST_ASSERT_TRUE_MESSAGE(fabs(dke - emech) < bound, msg);
}

/* Free mechanics with friction and load and no electromagnetic torque
 * (psi_pm = 0, no current): w(t) = w0 e^{-Bt/J} - T_L/B (1 - e^{-Bt/J}),
 * integrated exactly per interval; theta_m follows the midpoint speeds. */
static void test_free_mechanics_friction_load(void)
{
    plant_config_t c = cfg_spmsm();
    c.psi_pm_wb = 0.0;
    c.mech = PLANT_MECH_FREE;
    c.friction_nms = 2e-4;
    c.load_torque_nm = 0.05;
    c.speed0_rpm = 2000.0;
    plant_t p;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
    const uint8_t v0[3] = {0, 0, 0};
    const double w0 = 2000.0 / 60.0 * 2.0 * PLANT_PI, J = c.inertia_kgm2, B = c.friction_nms;
    const double tl = c.load_torque_nm;
    double theta_exp = 0.0;
    for (int k = 1; k <= 100; ++k) {
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance(&p, 1e-4, v0));
        const double t = k * 1e-4, a = exp(-B * t / J);
        const double w = w0 * a - tl / B * (1.0 - a);
        TEST_ASSERT_DOUBLE_WITHIN(1e-9 * w0, w, plant_omega_m(&p));
        /* angle: integral of w, midpoint rule error per step ~ w'' h^3 / 24 */
        theta_exp = (w0 + tl / B) * J / B * (1.0 - a) - tl / B * t;
        TEST_ASSERT_DOUBLE_WITHIN(1e-6, theta_exp, plant_theta_m(&p));
    }
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.0, plant_torque(&p));
    /* imposed speed change is honoured in free mode as a state reset */
    plant_set_speed_rpm(&p, 100.0);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 100.0 / 60.0 * 2.0 * PLANT_PI, plant_omega_m(&p));
}

/* Passive load T_p (no electromagnetic torque: psi_pm = 0, no current):
 * J dw/dt = -T_L - T_p sign(w). From w0 > 0 with T_L = 0 the rotor decelerates
 * at T_p/J, stops at t_s = J w0 / T_p and stays at rest (the load cannot drive
 * it backwards). An active load below T_p is then held; one above it turns
 * the rotor backwards at (T_L - T_p)/J. */
static void test_free_mechanics_passive_load(void)
{
    plant_config_t c = cfg_spmsm();
    c.psi_pm_wb = 0.0;
    c.mech = PLANT_MECH_FREE;
    c.load_passive_nm = 0.5;
    c.speed0_rpm = 500.0;
    plant_t p;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
    const uint8_t v0[3] = {0, 0, 0};
    const double w0 = 500.0 / 60.0 * 2.0 * PLANT_PI, J = c.inertia_kgm2, tp = c.load_passive_nm;
    const double t_stop = J * w0 / tp; /* 12.6 ms */
    const double h = 1e-4;
    for (int k = 1; k * h < 2.0 * t_stop; ++k) {
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance(&p, h, v0));
        const double t = k * h;
        const double w = t < t_stop ? w0 - tp / J * t : 0.0;
        /* exact per piece except the piece that contains the stop (one piece) */
        TEST_ASSERT_DOUBLE_WITHIN(tp / J * h + 1e-9, w, plant_omega_m(&p));
        TEST_ASSERT_TRUE(plant_omega_m(&p) >= 0.0);
    }
    TEST_ASSERT_EQUAL_DOUBLE(0.0, plant_omega_m(&p));
    TEST_ASSERT_EQUAL_DOUBLE(0.0, plant_load_torque(&p));
    plant_set_load_torque(&p, 0.3); /* below T_p: held */
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance(&p, 0.01, v0));
    TEST_ASSERT_EQUAL_DOUBLE(0.0, plant_omega_m(&p));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.0, plant_load_torque(&p)); /* T_L held by T_p */
    plant_set_load_torque(&p, 0.8); /* above T_p: backwards at (0.8 - 0.5)/J */
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance(&p, 0.01, v0));
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, -(0.8 - tp) / J * 0.01, plant_omega_m(&p));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.8 - tp, plant_load_torque(&p));
}

/* Dead time at locked rotor: leg a PWM at duty d, legs b, c low; i_a > 0, so
 * during each dead time after the turn-off command the lower diode conducts
 * (no change) and after the turn-on command the leg stays at 0 V: the leg
 * loses Td per period, i_a -> (2/3) Vdc (d - Td/T) / R. */
static void test_dead_time_volt_seconds(void)
{
    plant_config_t c = cfg_spmsm();
    c.vdc_v = 20.0;
    c.dead_time_s = 2e-6;
    plant_t p;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
    const double T = 50e-6, d = 0.5;
    const double duty[3] = {d, 0.0, 0.0};
    for (int k = 0; k < 2000; ++k) { /* 0.1 s = 14 time constants */
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance_period(&p, T, duty));
    }
    /* period average of i_a by sub-sampling */
    double sum = 0.0;
    for (int k = 0; k < 20; ++k) {
        for (int j = 0; j < 100; ++j) {
            const uint8_t s[3] = {(uint8_t)(j >= 25 && j < 75), 0, 0};
            TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance(&p, T / 100.0, s));
            double iabc[3];
            plant_i_abc(&p, iabc);
            sum += iabc[0];
        }
    }
    const double i_avg = sum / 2000.0;
    const double i_exp = 2.0 / 3.0 * c.vdc_v * (d - c.dead_time_s / T) / c.rs_ohm;
    char msg[96];
    snprintf(msg, sizeof msg, "dead time: mean i_a %.6g A, expected %.6g A", i_avg, i_exp);
    TEST_MESSAGE(msg);
    /* ripple-averaging and residual transient: well under 0.5 % */
    TEST_ASSERT_TRUE_MESSAGE(fabs(i_avg - i_exp) < 5e-3 * i_exp, msg);
    /* two transitions per period; the first period starts low (no edge) */
    TEST_ASSERT_EQUAL_UINT32(2u * 2020u, (uint32_t)plant_transitions(&p));
}

/* Gates off at a speed where the line back-EMF peak (sqrt 3 w psi_pm = 68 V)
 * stays below Vdc: the diodes block once the current has decayed, the
 * magnetic energy goes back to the link (E_src < 0). */
static void test_gates_off_current_decays(void)
{
    plant_config_t c = cfg_spmsm();
    c.speed0_rpm = 1000.0;
    c.id0_a = -3.0;
    c.iq0_a = 4.0;
    c.track_energy = 1;
    plant_t p;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
    const uint8_t off[3] = {PLANT_LEG_OFF, PLANT_LEG_OFF, PLANT_LEG_OFF};
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance(&p, 20e-3, off));
    double id, iq;
    plant_i_dq(&p, &id, &iq);
    char msg[96];
    snprintf(msg, sizeof msg, "gates off: |i| after 20 ms = %.3g A", hypot(id, iq));
    TEST_MESSAGE(msg);
    /* residual chatter ~ Vdc h / L = 17 mA with h = 0.5 us */
    TEST_ASSERT_TRUE_MESSAGE(hypot(id, iq) < 0.1, msg);
    double esrc, ein, ecu, emech;
    plant_energy(&p, &esrc, &ein, &ecu, &emech);
    TEST_ASSERT_TRUE(esrc < 0.0);
}

/* Observer: called on the global grid, with the state at that instant (same
 * as stopping there). */
typedef struct {
    int n;
    double t[64];
    double ia[64];
} obs_log_t;

static void obs_fn(void *ctx, const plant_t *p)
{
    obs_log_t *l = ctx;
    if (l->n < 64) {
        double iabc[3];
        plant_i_abc(p, iabc);
        l->t[l->n] = plant_time(p);
        l->ia[l->n] = iabc[0];
    }
    l->n++;
}

static void test_observer_grid(void)
{
    plant_config_t c = cfg_spmsm();
    c.speed0_rpm = 3000.0;
    plant_t p, q;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&q, &c));
    obs_log_t log;
    memset(&log, 0, sizeof log);
    plant_set_observer(&p, obs_fn, &log, 5e-6); /* 10 samples per 50 us period */
    const double d[3] = {0.8, 0.3, 0.45};
    for (int k = 0; k < 4; ++k) {
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance_period(&p, 50e-6, d));
    }
    TEST_ASSERT_EQUAL_INT(40, log.n);
    for (int k = 0; k < 40; ++k) {
        TEST_ASSERT_DOUBLE_WITHIN(1e-15, 5e-6 * (k + 1), log.t[k]);
    }
    /* reproduce each sample with a copy of a plain plant, stepped through the
     * same leg pattern up to the sample instant */
    const double T = 50e-6;
    double on[3], offt[3];
    for (int x = 0; x < 3; ++x) {
        on[x] = 0.5 * T * (1.0 - d[x]);
        offt[x] = 0.5 * T * (1.0 + d[x]);
    }
    double worst = 0.0;
    for (int per = 0; per < 4; ++per) {
        for (int k = 0; k < 10; ++k) {
            plant_t r = q; /* state at the period start */
            const double tau_end = (k + 1) * 5e-6;
            double tau = 0.0;
            while (tau < tau_end - 1e-15) {
                double nxt = tau_end;
                for (int x = 0; x < 3; ++x) {
                    if (on[x] > tau + 1e-15 && on[x] < nxt) {
                        nxt = on[x];
                    }
                    if (offt[x] > tau + 1e-15 && offt[x] < nxt) {
                        nxt = offt[x];
                    }
                }
                const double mid = 0.5 * (tau + nxt);
                uint8_t s[3];
                for (int x = 0; x < 3; ++x) {
                    s[x] = (uint8_t)(mid >= on[x] && mid < offt[x]);
                }
                TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance(&r, nxt - tau, s));
                tau = nxt;
            }
            double iabc[3];
            plant_i_abc(&r, iabc);
            worst = fmax(worst, fabs(iabc[0] - log.ia[per * 10 + k]));
        }
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance_period(&q, T, d));
    }
    char msg[80];
    snprintf(msg, sizeof msg, "observer samples vs direct stepping: max diff %.3g A", worst);
    TEST_MESSAGE(msg);
    TEST_ASSERT_TRUE_MESSAGE(worst < 1e-11, msg);
}

static void test_bad_arguments(void)
{
    plant_config_t c = cfg_spmsm();
    plant_t p;
    TEST_ASSERT_EQUAL_INT(PLANT_EINVAL, plant_init(NULL, &c));
    TEST_ASSERT_EQUAL_INT(PLANT_EINVAL, plant_init(&p, NULL));
    c.ld_h = -1e-3;
    TEST_ASSERT_EQUAL_INT(PLANT_EINVAL, plant_init(&p, &c));
    c = cfg_spmsm();
    c.rs_ohm = NAN;
    TEST_ASSERT_EQUAL_INT(PLANT_EINVAL, plant_init(&p, &c));
    c = cfg_spmsm();
    c.pole_pairs = 0;
    TEST_ASSERT_EQUAL_INT(PLANT_EINVAL, plant_init(&p, &c));
    c = cfg_spmsm();
    c.mech = PLANT_MECH_FREE;
    c.inertia_kgm2 = 0.0;
    TEST_ASSERT_EQUAL_INT(PLANT_EINVAL, plant_init(&p, &c));
    c = cfg_spmsm();
    c.dc_cap_f = 200e-6; /* without source resistance */
    TEST_ASSERT_EQUAL_INT(PLANT_EINVAL, plant_init(&p, &c));
    c = cfg_spmsm();
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
    const uint8_t bad[3] = {0, 3, 0};
    TEST_ASSERT_EQUAL_INT(PLANT_EINVAL, plant_advance(&p, 1e-6, bad));
    const uint8_t ok[3] = {0, 1, 0};
    TEST_ASSERT_EQUAL_INT(PLANT_EINVAL, plant_advance(&p, -1e-6, ok));
    TEST_ASSERT_EQUAL_INT(PLANT_EINVAL, plant_advance(&p, NAN, ok));
    TEST_ASSERT_EQUAL_INT(PLANT_EINVAL, plant_advance(NULL, 1e-6, ok));
    const double dn[3] = {0.5, NAN, 0.5};
    TEST_ASSERT_EQUAL_INT(PLANT_EINVAL, plant_advance_period(&p, 50e-6, dn));
    const double dd[3] = {0.5, 0.5, 0.5};
    TEST_ASSERT_EQUAL_INT(PLANT_EINVAL, plant_advance_period(&p, 0.0, dd));
}

/* DC link with capacitance: at standstill with no current the link charges to
 * the source; a load step makes it sag by about i_dc R_src. */
static void test_dc_link_rc(void)
{
    plant_config_t c = cfg_spmsm();
    c.dc_cap_f = 200e-6;
    c.dc_src_r_ohm = 0.5;
    c.track_energy = 1;
    plant_t p;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
    const uint8_t v1[3] = {1, 0, 0};
    /* V1 at locked rotor: i_a -> (2/3) vdc / Rs, i_dc = i_a; steady state
     * vdc = Vs - R i_dc with i_dc = (2/3) vdc / Rs: vdc = Vs / (1 + 2R/(3Rs)) */
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance(&p, 0.15, v1));
    const double v_exp = c.vdc_v / (1.0 + 2.0 * c.dc_src_r_ohm / (3.0 * c.rs_ohm));
    char msg[80];
    snprintf(msg, sizeof msg, "DC link RC: vdc %.6g V, expected %.6g V", plant_vdc(&p), v_exp);
    TEST_MESSAGE(msg);
    TEST_ASSERT_TRUE_MESSAGE(fabs(plant_vdc(&p) - v_exp) < 1e-6 * v_exp, msg);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_locked_rotor_d_axis);
    RUN_TEST(test_locked_rotor_q_axis);
    RUN_TEST(test_phasor_steady_state_spmsm);
    RUN_TEST(test_phasor_steady_state_ipmsm_sync);
    RUN_TEST(test_torque_identities);
    RUN_TEST(test_energy_balance_spmsm);
    RUN_TEST(test_energy_balance_ipmsm);
    RUN_TEST(test_energy_balance_forward_drop);
    RUN_TEST(test_rk4_path_matches_exact);
    RUN_TEST(test_free_mechanics_energy);
    RUN_TEST(test_free_mechanics_friction_load);
    RUN_TEST(test_free_mechanics_passive_load);
    RUN_TEST(test_dead_time_volt_seconds);
    RUN_TEST(test_gates_off_current_decays);
    RUN_TEST(test_observer_grid);
    RUN_TEST(test_bad_arguments);
    RUN_TEST(test_dc_link_rc);
    return UNITY_END();
}
