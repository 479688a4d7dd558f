/*
 * Plant speed: simulated seconds per wall-clock second for the thesis SPMSM at
 * 3000 r/min (imposed) with a 20 kHz centre-aligned sinusoidal PWM pattern
 * (modulation index 0.9 of the linear range, rotating with the rotor), with
 * and without an observer at 10 samples per PWM period.
 * Usage: plant_bench [simulated_seconds (default 2)]
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
static double run(double sim_s, int with_obs, int track_energy, double *torque_mean,
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
    *wall_ratio = sim_s / wall;
    return sim_s / cpu;
}

int main(int argc, char **argv)
{
    const double sim_s = (argc > 1) ? atof(argv[1]) : 2.0;
    double tq, wall;
    printf("SPMSM 3000 r/min, 20 kHz centre-aligned PWM, %.2f s simulated\n", sim_s);
    printf("simulated s per CPU s (per wall s)\n");
    double r = run(sim_s, 0, 0, &tq, &wall);
    printf("  plain:                      %8.1f (%.1f)\n", r, wall);
    r = run(sim_s, 1, 0, &tq, &wall);
    printf("  observer 10/period:         %8.1f (%.1f)\n", r, wall);
    r = run(sim_s, 1, 1, &tq, &wall);
    printf("  observer + energy tracking: %8.1f (%.1f)\n", r, wall);
    printf("  (mean torque %.4g N m)\n", tq);
    return 0;
}
