/*
 * Non-ideal mechanics of the plant against closed forms: a stuck rotor stays
 * stuck below break-away and breaks away at the instant the locked-rotor
 * current's torque reaches it; the coast-down with Coulomb and viscous
 * friction; the cogging's period (lcm(slots, 2 p) per revolution) and its
 * speed ripple from energy conservation; the passive load; the energy
 * balance with every term; argument checking.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "ini_machines.h"
#include "plant.h"
#include "sim_machine.h"
#include "unity.h"

void setUp(void)
{
}
void tearDown(void)
{
}

/* Thesis SPMSM (Table 3.2), ideal inverter, free mechanics. */
static plant_config_t cfg_spmsm(void)
{
    const ctrl_machine_t *m = &ini_thesis_spmsm;
    plant_config_t c;
    memset(&c, 0, sizeof c);
    c.pole_pairs = m->pole_pairs;
    c.rs_ohm = m->rs_ohm;
    c.ld_h = m->ld_h;
    c.lq_h = m->lq_h;
    c.psi_pm_wb = m->psi_pm_wb;
    c.vdc_v = m->vdc_v;
    c.inertia_kgm2 = m->inertia_kgm2;
    c.mech = PLANT_MECH_FREE;
    return c;
}

static double rpm_to_rad(double rpm)
{
    return rpm * 2.0 * PLANT_PI / 60.0;
}

/* Locked-rotor torque build-up: the d axis at theta0, a constant voltage V on
 * the q axis (ideal source). While the rotor stays at rest, id = 0 and
 * iq = V/R (1 - e^{-t/tau}), tau = Lq/R, so Te = Te_ss (1 - e^{-t/tau}),
 * Te_ss = 1.5 p psi V/R. */
typedef struct {
    plant_t p;
    double v, theta0, te_ss, tau;
} locked_t;

static void locked_init(locked_t *k, plant_config_t c, double te_ss)
{
    k->theta0 = 0.4;
    c.theta0_e_rad = k->theta0;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&k->p, &c));
    k->te_ss = te_ss;
    k->v = te_ss / (1.5 * c.pole_pairs * c.psi_pm_wb) * c.rs_ohm;
    k->tau = c.lq_h / c.rs_ohm;
}

static int locked_advance(locked_t *k, double dt)
{
    /* v_ab on the q axis of the rotor at theta0: angle theta0 + pi/2 */
    return plant_advance_voltage_ab(&k->p, dt, k->v, 0.0, k->theta0 + 0.5 * PLANT_PI);
}

/* Below break-away the rotor does not move at all: speed exactly 0, angle
 * exactly theta0/p, every instant counted as stuck. */
static void test_stuck_below_breakaway(void)
{
    plant_config_t c = cfg_spmsm();
    c.coulomb_nm = 0.2;
    c.stiction_nm = 0.3;
    locked_t k;
    locked_init(&k, c, 0.98 * c.stiction_nm);
    const double th_m0 = plant_theta_m(&k.p);
    for (int i = 0; i < 500; ++i) { /* 50 ms = 6.9 tau: Te within 0.1 % of Te_ss */
        TEST_ASSERT_EQUAL_INT(PLANT_OK, locked_advance(&k, 1e-4));
        TEST_ASSERT_EQUAL_DOUBLE(0.0, plant_omega_m(&k.p));
        TEST_ASSERT_EQUAL_DOUBLE(th_m0, plant_theta_m(&k.p));
        TEST_ASSERT_TRUE(plant_stuck(&k.p));
    }
    TEST_ASSERT_TRUE(plant_torque(&k.p) > 0.97 * c.stiction_nm);
    plant_mech_stats_t st;
    plant_mech_stats(&k.p, &st);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.05, st.stuck_s);
    TEST_ASSERT_EQUAL_UINT64(0u, st.breakaways);
    /* the bearings hold all of it */
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, plant_torque(&k.p), plant_friction_torque(&k.p));
}

/* Above break-away the rotor leaves rest at t_b = -tau ln(1 - T_s/Te_ss),
 * located within the sub-interval: the error is that of the quadratic
 * through Te at 0, h/2, h, |Te - q| <= Te_ss h^3 / tau^3 * sqrt(3)/216,
 * divided by dTe/dt at t_b = (Te_ss - T_s)/tau. Stepping over it would be
 * off by up to one step (100 us). */
static void test_breakaway_instant(void)
{
    plant_config_t c = cfg_spmsm();
    c.coulomb_nm = 0.2;
    c.stiction_nm = 0.3;
    locked_t k;
    locked_init(&k, c, 2.0 * c.stiction_nm);
    const double h = 1e-4;
    const double tb = -k.tau * log(1.0 - c.stiction_nm / k.te_ss);
    const double bound =
        (k.te_ss * pow(h / k.tau, 3.0) * sqrt(3.0) / 216.0) / ((k.te_ss - c.stiction_nm) / k.tau);
    int moved = 0;
    for (int i = 1; i * h < tb + 2e-3; ++i) {
        TEST_ASSERT_EQUAL_INT(PLANT_OK, locked_advance(&k, h));
        if (i * h < tb - h) {
            TEST_ASSERT_EQUAL_DOUBLE(0.0, plant_omega_m(&k.p));
        }
        moved |= plant_omega_m(&k.p) > 0.0;
    }
    TEST_ASSERT_TRUE(moved);
    TEST_ASSERT_FALSE(plant_stuck(&k.p));
    plant_mech_stats_t st;
    plant_mech_stats(&k.p, &st);
    char msg[128];
    snprintf(msg, sizeof msg, "break-away at %.12f s, closed form %.12f s (bound %.2g s)",
             st.stuck_s, tb, bound);
    TEST_MESSAGE(msg);
    TEST_ASSERT_EQUAL_UINT64(1u, st.breakaways);
    TEST_ASSERT_TRUE_MESSAGE(fabs(st.stuck_s - tb) <= bound + 1e-13, msg);
}

/* Coast-down, no electromagnetic torque (psi_pm = 0, no current):
 * J dw/dt = -B w - T_c, w(t) = (w0 + T_c/B) e^{-Bt/J} - T_c/B until the stop at
 * t_s = J/B ln(1 + B w0/T_c); theta(t) = J/B (w0 + T_c/B)(1 - e^{-Bt/J}) - T_c t/B.
 * Then it stays at rest (nothing drives it). */
static void test_coast_down_coulomb_viscous(void)
{
    plant_config_t c = cfg_spmsm();
    c.psi_pm_wb = 0.0;
    c.friction_nms = 2e-4;
    c.coulomb_nm = 0.05;
    c.stiction_nm = 0.08;
    c.speed0_rpm = 1500.0;
    plant_t p;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
    const double J = c.inertia_kgm2, B = c.friction_nms, tc = c.coulomb_nm;
    const double w0 = rpm_to_rad(c.speed0_rpm), wc = tc / B;
    const double ts = J / B * log(1.0 + w0 / wc);
    const double th0 = plant_theta_m(&p);
    const uint8_t low[3] = {0, 0, 0};
    const double h = 1e-4 * (1.0 + 1.0 / 3.0); /* the stop falls inside a step */
    double worst_w = 0.0, worst_th = 0.0;
    for (int i = 1; i * h < 1.5 * ts; ++i) {
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance(&p, h, low));
        const double t = fmin(i * h, ts), a = exp(-B * t / J);
        const double w = i * h < ts ? (w0 + wc) * a - wc : 0.0;
        const double th = J / B * (w0 + wc) * (1.0 - a) - wc * t;
        worst_w = fmax(worst_w, fabs(plant_omega_m(&p) - w));
        worst_th = fmax(worst_th, fabs(plant_theta_m(&p) - th0 - th));
        TEST_ASSERT_TRUE(plant_omega_m(&p) >= 0.0);
    }
    plant_mech_stats_t st;
    plant_mech_stats(&p, &st);
    const double t_end = plant_time(&p);
    char msg[160];
    snprintf(msg, sizeof msg,
             "coast-down: stop at %.12f s (closed form %.12f s), speed err %.2g rad/s, angle err "
             "%.2g rad",
             t_end - st.stuck_s, ts, worst_w, worst_th);
    TEST_MESSAGE(msg);
    TEST_ASSERT_EQUAL_UINT64(1u, st.stops);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, plant_omega_m(&p));
    /* RK4 on steps of 133 us against J/B = 0.6 s: ~ (h B/J)^5/120 per step */
    TEST_ASSERT_TRUE_MESSAGE(fabs(t_end - st.stuck_s - ts) < 1e-12, msg);
    TEST_ASSERT_TRUE_MESSAGE(worst_w < 1e-10 * w0, msg);
    TEST_ASSERT_TRUE_MESSAGE(worst_th < 1e-10 * (J / B * w0), msg);
    /* the work of friction is the kinetic energy */
    TEST_ASSERT_DOUBLE_WITHIN(1e-9 * 0.5 * J * w0 * w0, 0.5 * J * w0 * w0, st.e_friction_j);
}

/* A frictionless rotor coasting with cogging only: 1/2 J w^2 + W(theta) is
 * constant, W = A/N cos(N theta + phi) (one harmonic, N = lcm(12, 14) = 84,
 * computed here, not by the plant); the speed's maxima are 2 pi/N apart in
 * angle. */
typedef struct {
    double t[4096], th[4096], w[4096];
    int n;
} trace_t;

static void trace_obs(void *ctx, const plant_t *p)
{
    trace_t *tr = ctx;
    if (tr->n < 4096) {
        tr->t[tr->n] = plant_time(p);
        tr->th[tr->n] = plant_theta_m(p);
        tr->w[tr->n] = plant_omega_m(p);
        tr->n++;
    }
}

static void test_cogging_period_and_energy(void)
{
    plant_config_t c = cfg_spmsm();
    c.pole_pairs = 7; /* 12 slots, 14 poles: N = 84 */
    c.psi_pm_wb = 0.0;
    const int N = 84;
    const double A = 0.02, phi = 0.7;
    c.cog_per_rev = N;
    c.cog_n = 1;
    c.cog_amp_nm[0] = A;
    c.cog_phase_rad[0] = phi;
    c.speed0_rpm = 60.0;
    c.theta0_e_rad = 0.3;
    plant_t p;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
    static trace_t tr;
    tr.n = 0;
    plant_set_observer(&p, trace_obs, &tr, 2e-5);
    const uint8_t low[3] = {0, 0, 0};
    for (int i = 0; i < 800; ++i) { /* 80 ms: ~ 6.7 cogging periods at 60 r/min */
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance(&p, 1e-4, low));
    }
    const double J = c.inertia_kgm2;
    double e_min = INFINITY, e_max = -INFINITY;
    for (int i = 0; i < tr.n; ++i) {
        const double e = 0.5 * J * tr.w[i] * tr.w[i] + A / N * cos(N * tr.th[i] + phi);
        e_min = fmin(e_min, e);
        e_max = fmax(e_max, e);
    }
    /* speed maxima: the parabola through each local maximum's neighbours */
    double pk[16];
    int npk = 0;
    for (int i = 1; i + 1 < tr.n && npk < 16; ++i) {
        if (tr.w[i] > tr.w[i - 1] && tr.w[i] >= tr.w[i + 1]) {
            const double d =
                0.5 * (tr.w[i - 1] - tr.w[i + 1]) / (tr.w[i - 1] - 2.0 * tr.w[i] + tr.w[i + 1]);
            pk[npk++] = tr.th[i] + d * (tr.th[i + 1] - tr.th[i - 1]) * 0.5;
        }
    }
    char msg[160];
    snprintf(msg, sizeof msg, "cogging: energy spread %.3g J of A/N = %.3g J; %d speed maxima",
             e_max - e_min, A / N, npk);
    TEST_MESSAGE(msg);
    /* RK4's local error on the cogging phase x = w N h per 100 us step is
     * ~ x^5/120 of the amplitude of W (top speed from 1/2 J w0^2 = 2.4 mJ
     * and the 2 A/N = 0.48 mJ of W: w <= 1.1 w0); over the 800 steps: */
    const double x = rpm_to_rad(60.0) * 1.15 * N * 1e-4; /* top speed <= 1.15 w0 */
    const double bound = 800.0 * pow(x, 5.0) / 120.0 * A / N;
    TEST_ASSERT_TRUE_MESSAGE(e_max - e_min < bound, msg);
    TEST_ASSERT_TRUE(npk >= 5);
    for (int i = 1; i < npk; ++i) {
        /* the parabola's vertex is within (grid angle)^2 of the maximum */
        TEST_ASSERT_DOUBLE_WITHIN(2e-3 * 2.0 * PLANT_PI / N, 2.0 * PLANT_PI / N, pk[i] - pk[i - 1]);
    }
    /* the maxima sit where W is lowest: N theta + phi = pi (mod 2 pi) */
    for (int i = 0; i < npk; ++i) {
        const double r = remainder(N * pk[i] + phi - PLANT_PI, 2.0 * PLANT_PI);
        TEST_ASSERT_DOUBLE_WITHIN(2e-3 * 2.0 * PLANT_PI, 0.0, r);
    }
    /* the getters agree with the formula */
    const double th = plant_theta_m(&p);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, A * sin(N * th + phi), plant_cogging_torque(&p));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12 * A, A / N * cos(N * th + phi), plant_cogging_energy(&p));
}

/* Cogging's period through the machine file: 12 slots and 7 pole pairs give
 * 84 periods per revolution (a 14-pole, 12-slot outrunner); the torque
 * repeats after 2 pi/84 and changes sign after half of it. */
static void test_cogging_period_from_file(void)
{
    const char *path = "/tmp/plant_mech_cog.ini";
    FILE *f = fopen(path, "w");
    TEST_ASSERT_NOT_NULL(f);
    fputs("[machine]\nname = t\npole_pairs = 7\nrs_ohm = 0.1\nld_mh = 0.03\nlq_mh = 0.03\n"
          "psi_pm_wb = 0.004\n[rated]\ntorque_nm = 0.5\nspeed_rpm = 3000\ncurrent_a = 20\n"
          "current_max_a = 40\n[inverter]\nvdc_v = 24\nfs_hz = 20000\n"
          "[mechanics]\ninertia_kgm2 = 1e-5\nslots = 12\ncogging_nm = 0.05\n"
          "cogging_phase_deg = 30\n",
          f);
    fclose(f);
    sim_machine_t m;
    char err[256];
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, sim_machine_load(path, &m, err, sizeof err), err);
    remove(path);
    TEST_ASSERT_EQUAL_INT(84, sim_machine_cog_per_rev(&m));
    plant_config_t c;
    sim_machine_to_plant(&m, &c);
    double t[3];
    const double th_m[3] = {0.123, 0.123 + 2.0 * PLANT_PI / 84.0, 0.123 + PLANT_PI / 84.0};
    for (int i = 0; i < 3; ++i) {
        c.theta0_e_rad = th_m[i] * 7.0;
        plant_t p;
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
        t[i] = plant_cogging_torque(&p);
    }
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.05 * sin(84.0 * 0.123 + PLANT_PI / 6.0), t[0]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, t[0], t[1]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, -t[0], t[2]);
}

/* Every term at once on a driven machine (PWM at 20 kHz, a rotating duty
 * pattern): the mechanical energy balance e_drive = dKE + e_friction +
 * e_load + dW_cog holds to the integration's accuracy, and the electrical
 * side's integral of Te times the held speed agrees with e_drive. */
static void test_energy_balance_all_terms(void)
{
    plant_config_t c = cfg_spmsm();
    c.friction_nms = 1e-4;
    c.coulomb_nm = 0.05;
    c.stiction_nm = 0.09;
    c.load_torque_nm = 0.1;
    c.load_passive_nm = 0.05;
    c.cog_per_rev = 12;
    c.cog_n = 2;
    c.cog_amp_nm[0] = 0.08;
    c.cog_amp_nm[1] = 0.03;
    c.cog_phase_rad[1] = 1.1;
    c.track_energy = 1;
    plant_t p;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
    const double J = c.inertia_kgm2, T = 5e-5;
    const double w0c = plant_cogging_energy(&p);
    for (int k = 0; k < 4000; ++k) { /* 0.2 s: accelerate from rest */
        const double ang = plant_theta_e(&p) + 1.75;
        const double m = 0.3;
        const double d[3] = {0.5 + m * cos(ang), 0.5 + m * cos(ang - 2.0 * PLANT_PI / 3.0),
                             0.5 + m * cos(ang + 2.0 * PLANT_PI / 3.0)};
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance_period(&p, T, d));
    }
    plant_mech_stats_t st;
    plant_mech_stats(&p, &st);
    const double ke = 0.5 * J * pow(plant_omega_m(&p), 2);
    const double dw = plant_cogging_energy(&p) - w0c;
    const double res = st.e_drive_j - (ke + st.e_friction_j + st.e_load_j + dw);
    double e_src, e_in, e_cu, e_mech;
    plant_energy(&p, &e_src, &e_in, &e_cu, &e_mech);
    char msg[200];
    snprintf(msg, sizeof msg,
             "balance: drive %.6g J = KE %.6g + friction %.6g + load %.6g + cogging %.3g; residual "
             "%.3g J; electrical side %.6g J; %.0f r/min",
             st.e_drive_j, ke, st.e_friction_j, st.e_load_j, dw, res, e_mech,
             plant_omega_m(&p) * 60.0 / (2.0 * PLANT_PI));
    TEST_MESSAGE(msg);
    TEST_ASSERT_TRUE(plant_omega_m(&p) > rpm_to_rad(500.0));
    TEST_ASSERT_TRUE(st.e_friction_j > 0.0 && st.e_load_j > 0.0);
    TEST_ASSERT_TRUE_MESSAGE(fabs(res) < 1e-9 * st.e_drive_j, msg);
    /* the two sides of the air gap: Te against the held speed and against the
     * true speed differ by the held speed's error, O(h^2 dw/dt) per piece */
    TEST_ASSERT_TRUE_MESSAGE(fabs(e_mech - st.e_drive_j) < 1e-5 * st.e_drive_j, msg);
}

/* A passive load alone keeps the smooth path (bit for bit the model before
 * the non-ideal terms); with friction present it joins the event path,
 * where the stop is located: from w0 with T_p only (plus a negligible
 * Coulomb friction) the rotor stops at J w0/(T_p + T_c) exactly. */
static void test_passive_load_stop_located(void)
{
    plant_config_t c = cfg_spmsm();
    c.psi_pm_wb = 0.0;
    c.load_passive_nm = 0.5;
    c.coulomb_nm = 1e-3;
    c.stiction_nm = 1e-3;
    c.speed0_rpm = 500.0;
    plant_t p;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
    const double w0 = rpm_to_rad(500.0), J = c.inertia_kgm2;
    const double ts = J * w0 / (c.load_passive_nm + c.coulomb_nm);
    const uint8_t low[3] = {0, 0, 0};
    for (int i = 0; i < 300; ++i) {
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance(&p, 1e-4, low));
    }
    plant_mech_stats_t st;
    plant_mech_stats(&p, &st);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, plant_omega_m(&p));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, ts, plant_time(&p) - st.stuck_s);
    /* an active load below T_s + T_p is held, the passive load takes what the
     * bearings do not */
    plant_set_load_torque(&p, 0.3);
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance(&p, 0.01, low));
    TEST_ASSERT_EQUAL_DOUBLE(0.0, plant_omega_m(&p));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.0, plant_load_torque(&p) + plant_friction_torque(&p));
    /* above it: backwards at (T_L - T_p - T_c)/J from the instant it acts */
    plant_set_load_torque(&p, 0.8);
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance(&p, 0.01, low));
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, -(0.8 - 0.5 - 1e-3) / J * 0.01, plant_omega_m(&p));
}

/* Time profile: an active load ramping 0 -> 0.5 N*m over 0.1 s from the
 * instant the profile is switched on (here 0.02 s after init), then held; no
 * electromagnetic torque (psi_pm = 0). The rotor at rest breaks away when the
 * load reaches T_s (0.2 N*m: at 0.04 s after the origin, a root of the
 * linear load), then turns backward:
 *   J w(t) = -(2.5 (t^2 - t_b^2) - T_c (t - t_b))   (t from the origin, up to 0.1 s)
 * and after 0.1 s at (0.5 - T_c)/J. A step boundary falls inside the ramp's
 * end (the profile's point splits the RK4 steps there). */
static void test_load_profile_time(void)
{
    plant_config_t c = cfg_spmsm();
    c.psi_pm_wb = 0.0;
    c.coulomb_nm = 0.1;
    c.stiction_nm = 0.2;
    c.load_profile.kind = PLANT_PROFILE_TIME;
    c.load_profile.n = 2;
    c.load_profile.x[0] = 0.0;
    c.load_profile.y[0] = 0.0;
    c.load_profile.x[1] = 0.1;
    c.load_profile.y[1] = 0.5;
    plant_t p;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
    plant_load_profile_enable(&p, 0);
    const uint8_t low[3] = {0, 0, 0};
    const double h = 0.7e-4, J = c.inertia_kgm2, tc = c.coulomb_nm;
    while (plant_time(&p) < 0.02 - 1e-12) {
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance(&p, fmin(h, 0.02 - plant_time(&p)), low));
    }
    plant_load_profile_enable(&p, 1); /* origin: 0.02 s */
    const double t0 = plant_time(&p), tb = 0.2 / 5.0;
    double worst = 0.0;
    for (int i = 1; i * h < 0.15; ++i) {
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance(&p, h, low));
        const double t = plant_time(&p) - t0;
        double w = 0.0;
        if (t > tb && t <= 0.1) {
            w = -(2.5 * (t * t - tb * tb) - tc * (t - tb)) / J;
        } else if (t > 0.1) {
            w = -(2.5 * (0.01 - tb * tb) - tc * (0.1 - tb) + (0.5 - tc) * (t - 0.1)) / J;
        }
        worst = fmax(worst, fabs(plant_omega_m(&p) - w));
    }
    plant_mech_stats_t st;
    plant_mech_stats(&p, &st);
    char msg[160];
    snprintf(msg, sizeof msg,
             "time profile: break-away %.12f s after the origin (%.12f), speed err %.3g rad/s",
             st.stuck_s - t0, tb, worst);
    TEST_MESSAGE(msg);
    TEST_ASSERT_EQUAL_UINT64(1u, st.breakaways);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, tb, st.stuck_s - t0);
    /* RK4 is exact for a load linear in time (w quadratic): rounding only */
    TEST_ASSERT_TRUE_MESSAGE(worst < 1e-9 * (0.5 / J) * 0.15, msg);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.5, plant_load_torque(&p)); /* the profile's end value */
}

/* Speed profile: T(w) = 0.001 N*m*s/rad x w between -200 and 200 rad/s, held at
 * +-0.2 N*m outside; from 300 rad/s (no electromagnetic torque, no friction)
 * the rotor decelerates at 0.2/J until 200 rad/s (t1 = 100 J/0.2), then
 * exponentially: w = 200 e^{-0.001 (t - t1)/J}. The table's corner at 200 rad/s
 * is not located: the step that holds it sees the slope's jump, an error of
 * about (slope/J) |a| h^2/2 = 8.3 x 1667 x (1.37e-4)^2/2 = 1.3e-4 rad/s at most. */
static void test_load_profile_speed(void)
{
    plant_config_t c = cfg_spmsm();
    c.psi_pm_wb = 0.0;
    c.load_profile.kind = PLANT_PROFILE_SPEED;
    c.load_profile.n = 2;
    c.load_profile.x[0] = -200.0;
    c.load_profile.y[0] = -0.2;
    c.load_profile.x[1] = 200.0;
    c.load_profile.y[1] = 0.2;
    c.speed0_rpm = 300.0 * 60.0 / (2.0 * PLANT_PI);
    plant_t p;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
    const uint8_t low[3] = {0, 0, 0};
    const double J = c.inertia_kgm2, t1 = 100.0 * J / 0.2, h = 1.37e-4; /* t1 inside a step */
    double worst = 0.0;
    for (int i = 1; i * h < 0.3; ++i) {
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance(&p, h, low));
        const double t = plant_time(&p);
        const double w = t < t1 ? 300.0 - 0.2 / J * t : 200.0 * exp(-0.001 * (t - t1) / J);
        worst = fmax(worst, fabs(plant_omega_m(&p) - w));
    }
    char msg[120];
    snprintf(msg, sizeof msg, "speed profile: speed err %.3g rad/s", worst);
    TEST_MESSAGE(msg);
    TEST_ASSERT_TRUE_MESSAGE(worst < 1.3e-4, msg);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.001 * plant_omega_m(&p), plant_load_torque(&p));
}

static void test_bad_config(void)
{
    plant_t p;
    plant_config_t c = cfg_spmsm();
    c.coulomb_nm = 0.2;
    c.stiction_nm = 0.1; /* below the running friction */
    TEST_ASSERT_EQUAL_INT(PLANT_EINVAL, plant_init(&p, &c));
    c = cfg_spmsm();
    c.coulomb_nm = -0.1;
    TEST_ASSERT_EQUAL_INT(PLANT_EINVAL, plant_init(&p, &c));
    c = cfg_spmsm();
    c.cog_n = 1;
    c.cog_amp_nm[0] = 0.1; /* no period */
    TEST_ASSERT_EQUAL_INT(PLANT_EINVAL, plant_init(&p, &c));
    c.cog_per_rev = 12;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
    c.cog_amp_nm[0] = NAN;
    TEST_ASSERT_EQUAL_INT(PLANT_EINVAL, plant_init(&p, &c));
    c = cfg_spmsm();
    c.cog_n = PLANT_COG_MAX + 1;
    TEST_ASSERT_EQUAL_INT(PLANT_EINVAL, plant_init(&p, &c));
    c = cfg_spmsm();
    c.load_profile.kind = PLANT_PROFILE_TIME;
    c.load_profile.n = 2;
    c.load_profile.x[0] = 1.0;
    c.load_profile.x[1] = 1.0; /* not increasing */
    TEST_ASSERT_EQUAL_INT(PLANT_EINVAL, plant_init(&p, &c));
    /* a filter holds the speed over a period: no stick-slip with it */
    sim_machine_t m;
    char err[256];
    TEST_ASSERT_EQUAL_INT_MESSAGE(0,
                                  sim_machine_load(PLANT_MACHINES_DIR
                                                   "/chapter_ipmsm_passive_filter.ini",
                                                   &m, err, sizeof err),
                                  err);
    sim_machine_to_plant(&m, &c);
    c.mech = PLANT_MECH_FREE;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
    c.coulomb_nm = c.stiction_nm = 0.1;
    TEST_ASSERT_EQUAL_INT(PLANT_EINVAL, plant_init(&p, &c));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_stuck_below_breakaway);
    RUN_TEST(test_breakaway_instant);
    RUN_TEST(test_coast_down_coulomb_viscous);
    RUN_TEST(test_cogging_period_and_energy);
    RUN_TEST(test_cogging_period_from_file);
    RUN_TEST(test_energy_balance_all_terms);
    RUN_TEST(test_passive_load_stop_located);
    RUN_TEST(test_load_profile_time);
    RUN_TEST(test_load_profile_speed);
    RUN_TEST(test_bad_config);
    return UNITY_END();
}
