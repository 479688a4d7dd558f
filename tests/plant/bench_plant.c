/*
 * Plant speed: simulated seconds per wall-clock second for the thesis SPMSM at
 * 3000 r/min (imposed) with a 20 kHz centre-aligned sinusoidal PWM pattern
 * (modulation index 0.9 of the linear range, rotating with the rotor), with
 * and without an observer at 10 samples per PWM period; then free mechanics
 * from 3000 r/min with viscous friction and a constant load (the smooth
 * path), and with the stress case's non-ideal mechanics (Coulomb friction,
 * stiction, cogging at 24 and 48 per revolution, a passive load: the
 * event path, sim_host/README.md "Mechanics").
 * Usage: plant_bench [simulated_seconds (default 2) [case 1..5 (default all)]]
 * (one case: for an instruction count, valgrind --tool=callgrind).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "plant.h"

static double now_s(void)
{
    struct timespec ts;
    timespec_get(&ts, TIME_UTC);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void obs_sum(void *ctx, const plant_t *p)
{
    double *acc = ctx;
    *acc += plant_torque(p) + plant_psi_amp(p);
}

/* Returns simulated seconds per CPU second (process time: the machine is
 * shared, wall time would measure the other users); *wall_ratio per wall s. */
static double run(double sim_s, int with_obs, int track_energy, int mech, double *torque_mean,
                  double *wall_ratio)
{
    plant_config_t c = {0};
    c.pole_pairs = 4;
    c.rs_ohm = 0.901;
    c.ld_h = c.lq_h = 6.552e-3;
    c.psi_pm_wb = 0.09427;
    c.vdc_v = 220.0;
    c.speed0_rpm = 3000.0;
    c.track_energy = track_energy;
    if (mech > 0) {
        c.mech = PLANT_MECH_FREE;
        c.inertia_kgm2 = 1.2e-4;
        c.friction_nms = 3.82e-4;
        c.load_torque_nm = 1.0;
    }
    if (mech > 1) {
        c.load_torque_nm = 0.0;
        c.coulomb_nm = 0.24;
        c.stiction_nm = 0.36;
        c.load_passive_nm = 0.48;
        c.cog_per_rev = 24;
        c.cog_n = 2;
        c.cog_amp_nm[0] = 0.24;
        c.cog_amp_nm[1] = 0.07;
    }
    plant_t p;
    if (plant_init(&p, &c) != PLANT_OK) {
        return NAN;
    }
    double acc = 0.0;
    const double T = 50e-6;
    if (with_obs) {
        plant_set_observer(&p, obs_sum, &acc, T / 10.0);
    }
    const long n = (long)(sim_s / T);
    double tq = 0.0;
    const double t0 = now_s();
    const clock_t c0 = clock();
    for (long k = 0; k < n; ++k) {
        const double th = plant_theta_e(&p) + 0.5 * PLANT_PI + 0.2;
        double d[3];
        for (int x = 0; x < 3; ++x) {
            d[x] = 0.5 + 0.45 * cos(th - 2.0 * PLANT_PI / 3.0 * x);
        }
        if (plant_advance_period(&p, T, d) != PLANT_OK) {
            return NAN;
        }
        tq += plant_torque(&p);
    }
    const double cpu = (double)(clock() - c0) / CLOCKS_PER_SEC;
    const double wall = now_s() - t0;
    *torque_mean = tq / (double)n + 0.0 * acc;
    if (mech > 0) {
        printf("    (end speed %.0f r/min)\n", plant_omega_m(&p) * 60.0 / (2.0 * PLANT_PI));
    }
    *wall_ratio = sim_s / wall;
    return sim_s / cpu;
}

int main(int argc, char **argv)
{
    const double sim_s = (argc > 1) ? atof(argv[1]) : 2.0;
    const int only = (argc > 2) ? atoi(argv[2]) : 0;
    static const struct {
        const char *name;
        int obs, energy, mech;
    } cases[] = {{"plain:                     ", 0, 0, 0},
                 {"observer 10/period:        ", 1, 0, 0},
                 {"observer + energy tracking:", 1, 1, 0},
                 {"free, viscous + load:      ", 0, 0, 1},
                 {"free, non-ideal mechanics: ", 0, 0, 2}};
    double tq = 0.0, wall;
    printf("SPMSM 3000 r/min, 20 kHz centre-aligned PWM, %.2f s simulated\n", sim_s);
    printf("simulated s per CPU s (per wall s)\n");
    for (int i = 0; i < 5; ++i) {
        if (only == 0 || only == i + 1) {
            const double r = run(sim_s, cases[i].obs, cases[i].energy, cases[i].mech, &tq, &wall);
            printf("  %s %8.1f (%.1f)\n", cases[i].name, r, wall);
        }
    }
    printf("  (mean torque %.4g N m)\n", tq);
    return 0;
}
