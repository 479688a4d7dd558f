/*
 * Non-ideal mechanics of the plant over one sub-interval (internal to
 * sim_host; plant.c calls it, tests/plant checks it through the plant):
 *
 *   J dw/dt = Te(t) + T_cog(theta) - T_La(t, w) - B w - (T_c + T_p) dir
 *   dtheta/dt = w
 *
 * with Te(t) the sub-interval's electromagnetic torque as a quadratic in t,
 * T_cog the cogging harmonics, T_La the active load (constant + profile in
 * time or speed), B viscous, T_c Coulomb friction and T_p the passive load
 * acting against the direction of motion dir = sign(w). At rest (dir = 0)
 * the rotor stays while |Te + T_cog - T_La(t, 0)| <= T_s + T_p.
 *
 * Method (sim_host/README.md, "Mechanics"): turning, classical RK4 on
 * (theta, w) and the energy integrals with the direction fixed (the right
 * side is then smooth), steps bounded by the cogging phase, the cogging
 * detent's natural frequency, J/B and the speed profile's slope; a speed
 * zero crossing is detected on each step (end value, or a dip of the cubic
 * Hermite interpolant) and located on the RK4 map by Illinois' method to
 * 1e-14 of the step; at rest, the break-away instant is a root of a
 * quadratic (Te quadratic, load linear between profile points), polished so
 * that the torque evaluated there exceeds the break-away torque.
 */
#ifndef SIM_HOST_PLANT_MECH_H
#define SIM_HOST_PLANT_MECH_H

#include "plant.h"

typedef struct {
    double j, b;                 /* J > 0, B >= 0 */
    double tc, tp;               /* bearing Coulomb friction, passive load (>= 0) */
    double tbrk;                 /* break-away: T_s + T_p */
    double tl;                   /* constant active load */
    const plant_profile_t *prof; /* NULL: no profile (or off) */
    double prof_x0;              /* time profile: x at the sub-interval's start */
    int cog_n;
    double cog_per_rev; /* N */
    const double *cog_amp;
    double cog_c[PLANT_COG_MAX], cog_s[PLANT_COG_MAX]; /* cos, sin of the phases */
    double cog_phase0;     /* N theta at the sub-interval's start, in [0, 2 pi) */
    double cog_s0, cog_c0; /* its sin and cos */
    double te[3];          /* Te(t) = te[0] + t (te[1] + t te[2]), t from the start */
    double acc_rest;       /* bound of |dw/dt| from all but Te and B w */
    double h_lin;          /* step bound of the linear parts (step_max) */
    int coarse;            /* 1: one RK4 step per event-free stretch (a mean speed to
                              hold, an event to split at), not the bounded steps */
} mech_in_t;

typedef struct {
    double t_event;       /* first stick or slip event (s from the start), +inf: none */
    double dtheta, omega; /* end: angle travelled, speed */
    int dir;              /* end direction (0: stuck) */
    plant_mech_stats_t d; /* increments over the sub-interval */
} mech_out_t;

/* Fill the constant part of in from the plant's configuration and state
 * (te[] and prof_x0 are the caller's). */
void mech_setup(const plant_t *p, mech_in_t *in);

/* Integrate h >= 0 seconds from speed w0, direction dir0 (0: at rest;
 * w0 must then be 0). Returns PLANT_OK, or PLANT_ERANGE if the events do not
 * end (more than 10^5 in one sub-interval) or the state is not finite. */
int mech_solve(const mech_in_t *in, double h, double w0, int dir0, mech_out_t *out);

/* The mean speed over h (for the electrical part's held speed): the midpoint
 * prediction when the speed cannot reach zero in h, else mech_solve's. */
int mech_mean_speed(const mech_in_t *in, double h, double w0, int dir, double *wh);

/* Cogging torque and potential at dth (mechanical angle travelled since
 * the sub-interval's start). */
double mech_cogging(const mech_in_t *in, double dth);
double mech_cogging_energy(const mech_in_t *in, double dth);

/* Active load T_La at sub-interval time t and speed w. */
double mech_load(const mech_in_t *in, double t, double w);

#endif /* SIM_HOST_PLANT_MECH_H */
