/*
 * Plant model: two-level VSI (3.1) + PMSM in the rotor frame (3.8)-(3.10),
 * optional flux-map saturation (3.11)-(3.14), mechanics (3.15). Double
 * precision, host only; knows nothing of the controllers.
 *
 * Conventions (docs/conventions.md): amplitude-invariant Clarke (3.3), alpha
 * on phase a; Park (3.7) f_dq = f_ab e^{-j theta_e}; theta_e is the electrical
 * angle of the d axis (magnet); positive torque accelerates positive speed.
 *
 * Integration (see plant.c for the derivation):
 *  - linear model (no flux map, stiff DC link, no dead time, no forward drop):
 *    EXACT between switching instants for constant speed in the sub-interval.
 *    Over a sub-interval the alpha-beta voltage is constant, so in the rotor
 *    frame it rotates at -omega_e; the current obeys x' = A x + B u(t) + c with
 *    u a rotating phasor: closed form  x(t) = e^{At}(x0 - xp(0) - xc) + xp(t) + xc
 *    (2x2 exponential in closed form, phasor particular solution xp, constant
 *    particular solution xc). Checked against Eigen's matrix exponential.
 *  - any non-ideality (flux map, DC link with capacitance, dead time, forward
 *    drop, gates off): fixed-sub-step RK4 in flux coordinates (psi_d, psi_q,
 *    vdc), sub-step cfg.rk4_step_s (default 0.5 us), still split at every
 *    switching instant.
 *  - free mechanics, smooth (viscous friction, constant and passive load
 *    only): omega is held in each sub-interval at the midpoint prediction
 *    omega_k + dt/2 * (Te_k - T_L - B omega_k)/J, then updated exactly for
 *    the interval's mean torque (Simpson on Te at 0, dt/2, dt).
 *  - free mechanics with Coulomb friction, stiction, cogging or a load
 *    profile (plant_mech.c): the electrical part holds omega at the
 *    sub-interval's predicted mean speed; the mechanics are integrated
 *    against the sub-interval's torque Te(t) (the quadratic through Te at 0,
 *    dt/2, dt) by RK4 with steps bounded by the cogging phase, the stick and
 *    slip instants (speed zero crossings, break-away) located inside the
 *    sub-interval, not stepped over (sim_host/README.md, "Mechanics").
 *
 * The observer (plant_set_observer) sees the state at every instant of its
 * grid n * obs_dt (global time), so metrics see the true continuous signals,
 * not period-start samples; it does not split the integration: a copy of the
 * plant is advanced from the piece's start to each instant, the plant itself
 * takes the same pieces with and without an observer (bit-identical results).
 */
#ifndef SIM_HOST_PLANT_H
#define SIM_HOST_PLANT_H

#include <stddef.h>
#include <stdint.h>

#include "plant_filter.h"

/* pi of the host simulator (plant, filters, metrics): its own home, apart from
 * the control core's CTRL_PI, so that the plant shares no code with what it
 * checks. */
#define PLANT_PI 3.14159265358979323846

#ifdef __cplusplus
extern "C" {
#endif

/* Error codes. */
#define PLANT_OK 0
#define PLANT_EINVAL (-1) /* NULL pointer, non-finite or out-of-range value */
#define PLANT_ERANGE (-2) /* state left the valid domain (flux map, vdc < 0) */

/* Leg states accepted by plant_advance: 0 = lower switch on, 1 = upper on,
 * PLANT_LEG_OFF = both off (the leg voltage follows the current sign through
 * the free-wheeling diodes: 0 V for i > 0, Vdc for i < 0). */
#define PLANT_LEG_LOW 0u
#define PLANT_LEG_HIGH 1u
#define PLANT_LEG_OFF 2u

/* Saturation flux map on a regular grid (thesis 3.2.3, theta-independent):
 * psi_d(id, iq), psi_q(id, iq), row-major: psi[k_d * n_q + k_q] at
 * id = id_min + k_d * did, iq = iq_min + k_q * diq. Bilinear interpolation;
 * the inverse i(psi) by Newton on the interpolant. Loaded by plant_fluxmap_load. */
typedef struct {
    size_t n_d, n_q;
    double id_min, id_max, iq_min, iq_max; /* A */
    double *psi_d, *psi_q;                 /* Wb, n_d * n_q each (heap) */
} plant_fluxmap_t;

typedef enum {
    PLANT_MECH_IMPOSED = 0, /* dynamometer: omega follows plant_set_speed */
    PLANT_MECH_FREE = 1     /* (3.15): J dw_m/dt + B w_m = Te - T_L, with the
                               friction, cogging and load terms below */
} plant_mech_mode_t;

/* Cogging harmonics (fundamental included) and load-profile points. */
#define PLANT_COG_MAX 8
#define PLANT_PROFILE_MAX 32

typedef enum {
    PLANT_PROFILE_NONE = 0,
    PLANT_PROFILE_TIME = 1, /* x: time since the profile's origin, s */
    PLANT_PROFILE_SPEED = 2 /* x: signed mechanical speed, rad/s */
} plant_profile_kind_t;

/* Active load profile T(x), piecewise linear through the points, held at the
 * first and last value outside them; x strictly increasing; positive values
 * oppose positive rotation (like load_torque_nm, to which it adds). */
typedef struct {
    plant_profile_kind_t kind;
    int n; /* points, 2..PLANT_PROFILE_MAX (kind != NONE) */
    double x[PLANT_PROFILE_MAX];
    double y[PLANT_PROFILE_MAX]; /* N*m */
} plant_profile_t;

typedef struct {
    /* Machine, (3.8)-(3.10). */
    int pole_pairs;   /* p >= 1 */
    double rs_ohm;    /* > 0 */
    double ld_h;      /* > 0 */
    double lq_h;      /* > 0 */
    double psi_pm_wb; /* >= 0 */
    /* Optional saturation (NULL: linear model (3.9)). Not copied: must outlive
     * the plant. psi_pm_wb, ld_h, lq_h are then only used for reporting. */
    const plant_fluxmap_t *fluxmap;

    /* Inverter (3.1). */
    double vdc_v;        /* DC source voltage (> 0) */
    double dc_cap_f;     /* 0: stiff DC link; > 0: link capacitor, then  */
    double dc_src_r_ohm; /*    source resistance (> 0) between source and C */
    double dead_time_s;  /* >= 0, default 0: both switches off after each
                            leg transition, leg voltage follows current sign */
    double v_fwd_v;      /* >= 0, default 0: device forward drop, leg voltage
                            S*vdc - v_fwd*sign(i) */

    /* Mechanics (3.15), mechanical units. */
    plant_mech_mode_t mech;
    double inertia_kgm2;    /* J > 0 (needed when mech == PLANT_MECH_FREE) */
    double friction_nms;    /* B >= 0, N*m*s/rad (mechanical) */
    double load_torque_nm;  /* initial T_L (active: acts whatever the motion) */
    double load_passive_nm; /* >= 0: passive load T_p sign(w_m) (Coulomb friction of a
                               load): opposes the rotation, holds the rotor at rest
                               while |Te - T_L| <= T_p, never drives it */
    /* Non-ideal mechanics (all 0: the smooth model above, integrated as
     * before, bit for bit). Free mechanics:
     *   J dw/dt = Te + T_cog(theta_m) - T_L - T_prof - B w - (T_c + T_p) sign(w)
     * and at rest (w = 0) the rotor stays stuck while
     *   |Te + T_cog - T_L - T_prof| <= T_s + T_p. */
    double coulomb_nm;  /* T_c >= 0: running (Coulomb) friction of the bearings */
    double stiction_nm; /* T_s >= T_c: break-away friction (T_s = T_c: none extra) */
    /* Cogging, the torque of the magnets on the stator teeth acting on the
     * rotor: T_cog = sum_k cog_amp_nm[k] sin((k+1) N theta_m + cog_phase_rad[k]),
     * N = cog_per_rev periods per revolution (lcm(slots, 2 p)). */
    int cog_per_rev;                     /* N >= 1 when cog_n > 0 */
    int cog_n;                           /* harmonics given, 0..PLANT_COG_MAX */
    double cog_amp_nm[PLANT_COG_MAX];    /* >= 0 */
    double cog_phase_rad[PLANT_COG_MAX]; /* finite */
    plant_profile_t load_profile;        /* active, on from init (plant_load_profile_enable) */

    /* Initial state. */
    double theta0_e_rad; /* electrical rotor angle */
    double id0_a, iq0_a; /* currents (with a flux map: psi from the map) */
    double speed0_rpm;   /* mechanical speed (imposed or initial) */

    /* Numerics. 0 = default. */
    double rk4_step_s; /* sub-step of the RK4 path; default 0.5e-6 s */
    int track_energy;  /* 1: integrate the energy terms (plant_energy), costs
                          ~2x on the exact path (4-point Gauss-Legendre) */

    /* Optional output filter between the inverter and the machine
     * (plant_filter.h; type 0 = none). Needs the linear model: no flux map,
     * stiff DC link, no dead time, no forward drop. With a filter the
     * electrical speed is held over each plant step (one plant_advance_period
     * or plant_advance call) at the midpoint prediction, and the speed is
     * updated at the step's end with the step's mean torque. */
    plant_filter_cfg_t filter;
} plant_config_t;

typedef struct plant plant_t;

/* Mechanical accounting since init (free mechanics with non-ideal
 * mechanics; zero otherwise). Energy balance, exact up to the integration:
 *   e_drive = dKE + e_friction + e_load + dW_cog   (plant_cogging_energy). */
typedef struct {
    double stuck_s;       /* time at rest held by friction (stiction + passive load) */
    uint64_t breakaways;  /* stuck -> turning */
    uint64_t stops;       /* turning -> stuck */
    uint64_t reversals;   /* speed through zero without sticking */
    double e_drive_j;     /* integral Te w_m dt (Te: the sub-interval's quadratic) */
    double e_friction_j;  /* integral (B w + T_c sign w) w dt, >= 0: the bearings */
    double e_load_j;      /* integral (T_L + T_prof + T_p sign w) w dt: into the load */
    double moving_s;      /* time turning */
    double abs_angle_rad; /* integral |w_m| dt */
} plant_mech_stats_t;

/* Observer: called at every grid instant n * obs_dt (n integer, global time)
 * reached during an advance, with the true state at that instant. */
typedef void (*plant_observer_fn)(void *ctx, const plant_t *p);

/* Plant state. Fields are private: use the functions below. */
struct plant {
    plant_config_t cfg;
    /* electrical state, rotor frame */
    double id, iq;          /* A */
    double psi_d, psi_q;    /* Wb */
    double theta_e;         /* electrical angle, wrapped to [-pi, pi) */
    double theta_m;         /* mechanical angle, unwrapped (rad) */
    double omega_m;         /* mechanical speed, rad/s */
    double vdc;             /* V */
    double t;               /* simulated time, s */
    double load_torque_nm;  /* T_L */
    double load_passive_nm; /* T_p */
    uint8_t s[3];           /* last applied leg states (for transitions) */
    uint8_t s_valid;
    uint64_t transitions[3]; /* leg transitions since init (on and off) */
    double dead_end[3];      /* leg x is off (dead time) until this time */
    /* observer */
    plant_observer_fn obs;
    void *obs_ctx;
    double obs_dt;
    int64_t obs_next; /* index of the next grid instant */
    /* linear-model constants */
    int linear_exact;
    /* cos, sin of theta_e == trig_key, carried by rotation on the exact path */
    double trig_c, trig_s, trig_key;
    int trig_n; /* rotations since the last direct evaluation; 0 = invalid */
    /* energy accounting (cfg.track_energy): integrated over every advance */
    double e_in_j;   /* inverter output energy into the machine, J (sum v_leg i) */
    double e_cu_j;   /* copper loss, J: integral 1.5 Rs |i|^2 */
    double e_mech_j; /* electromagnetic -> mechanical, J: integral Te w_m */
    double e_src_j;  /* energy delivered by the DC source, J (= e_in_j when stiff) */
    /* integral of the motor-terminal alpha-beta voltage since the last
     * observer instant (plant_v_motor_mean_abc) */
    double v_int[2];
    double v_int_t0;
    /* non-ideal mechanics (plant_mech.c): on when the configuration has
     * Coulomb friction, stiction, cogging or a load profile */
    int mech_events;
    int mech_dir; /* -1, +1: turning that way (w may be 0 at a break-away
                     or a reversal); 0: stuck, held by friction */
    double cog_c[PLANT_COG_MAX], cog_s[PLANT_COG_MAX]; /* cos, sin of the cogging phases */
    int profile_on;                                    /* the load profile acts */
    double profile_t0;                                 /* its time origin (PLANT_PROFILE_TIME) */
    double cog_phase0;                                 /* N theta_m mod 2 pi, kept with theta_m */
    plant_mech_stats_t ms;                             /* since init */
    /* output filter (cfg.filter.type != PLANT_FILTER_NONE) and its step */
    plant_filter_t flt;
    int step_on;
    double step_t0, step_len, step_wm0, step_wm, step_te_int;
};

/* Validate cfg and set the initial state. Returns PLANT_OK or PLANT_EINVAL
 * (p is then zeroed). */
int plant_init(plant_t *p, const plant_config_t *cfg);

/* Hold leg states s[0..2] (PLANT_LEG_*) for dt >= 0 seconds. Exact for the
 * linear model. Returns PLANT_OK, PLANT_EINVAL (bad argument) or PLANT_ERANGE. */
int plant_advance(plant_t *p, double dt, const uint8_t s[3]);

/* Test / ideal-source input (linear model only, else PLANT_EINVAL): hold the
 * stator voltage v_ab(t) = v_amp e^{j (omega_v t + phase)} (t = plant time)
 * for dt, integrated exactly. omega_v = 0: a constant alpha-beta vector. Leg
 * states and transition counts are not touched. */
int plant_advance_voltage_ab(plant_t *p, double dt, double v_amp, double omega_v, double phase);

/* One centre-aligned PWM period of length T: leg x is high during
 * [T(1-d_x)/2, T(1+d_x)/2], duty d_x clamped to [0, 1]; the legs switch at
 * their exact instants (sorted; integrated exactly between them). */
int plant_advance_period(plant_t *p, double T, const double duty[3]);

/* Observer on the grid n * obs_dt; fn == NULL or obs_dt <= 0 removes it. The
 * first call is at the first grid instant strictly after the current time. */
void plant_set_observer(plant_t *p, plant_observer_fn fn, void *ctx, double obs_dt);

/* Time-varying inputs: call between advances (piecewise-constant profiles). */
void plant_set_load_torque(plant_t *p, double t_load_nm);
void plant_set_load_passive(plant_t *p, double t_passive_nm); /* magnitude >= 0 */
/* Load torque on the shaft now (free mechanics): T_L + the passive load's
 * present value (T_p sign(w_m); at rest the part of Te - T_L it holds). */
double plant_load_torque(const plant_t *p);
void plant_set_speed_rpm(plant_t *p, double rpm); /* imposed speed (and free: sets the state) */
/* The active load profile on (its time origin: now) or off. */
void plant_load_profile_enable(plant_t *p, int on);
/* Cogging torque on the rotor now, T_cog(theta_m), N*m; and its potential
 * W_cog(theta_m) = sum A_k/(k N) cos(k N theta_m + phi_k), J (T_cog = -dW/dtheta). */
double plant_cogging_torque(const plant_t *p);
double plant_cogging_energy(const plant_t *p);
/* Bearing friction torque now (opposing the motion, signed like the speed;
 * at rest the part of the net torque it holds), N*m. */
double plant_friction_torque(const plant_t *p);
/* 1: the rotor is at rest held by friction (non-ideal mechanics). */
int plant_stuck(const plant_t *p);
void plant_mech_stats(const plant_t *p, plant_mech_stats_t *st);

/* True state getters. */
double plant_time(const plant_t *p);
void plant_i_abc(const plant_t *p, double i_abc[3]);
void plant_i_dq(const plant_t *p, double *id, double *iq);
void plant_i_ab(const plant_t *p, double *i_alpha, double *i_beta);
void plant_psi_ab(const plant_t *p, double *psi_alpha, double *psi_beta);
double plant_psi_amp(const plant_t *p); /* |psi_s| (4.3) */
double plant_torque(const plant_t *p);  /* (3.10): 1.5 p (psi_d iq - psi_q id) */
double plant_theta_e(const plant_t *p); /* [-pi, pi) */
double plant_omega_e(const plant_t *p); /* rad/s electrical */
double plant_theta_m(const plant_t *p); /* rad mechanical, unwrapped */
double plant_omega_m(const plant_t *p); /* rad/s mechanical */
double plant_vdc(const plant_t *p);
uint64_t plant_transitions(const plant_t *p); /* total of the three legs */
/* Stored magnetic energy of the linear model, 1.5 (Ld id^2 + Lq iq^2)/2 J
 * (with a flux map: NaN, not provided). Capacitor energy: C vdc^2 / 2. */
double plant_magnetic_energy(const plant_t *p);
/* Energy integrals since init (cfg.track_energy must be 1, else all 0):
 * e_src = source output, e_in = inverter output to the machine, e_cu = copper
 * loss, e_mech = integral Te * w_m. Balance: e_in = e_cu + e_mech + dW_mag. */
void plant_energy(const plant_t *p, double *e_src_j, double *e_in_j, double *e_cu_j,
                  double *e_mech_j);

/* Voltage at the motor terminals, phase to motor neutral: without a filter
 * the inverter's phase voltages of the present leg states (ideal switches);
 * with one the filter's output. */
void plant_v_motor_abc(const plant_t *p, double v_abc[3]);
/* Inside an observer callback: the mean motor-terminal phase voltages over
 * the interval since the previous observer instant (exact for the
 * piecewise-constant inverter voltage; open Newton-Cotes per piece with a
 * filter). */
void plant_v_motor_mean_abc(const plant_t *p, double v_abc[3]);
/* Inverter output currents (= plant_i_abc without a filter). */
void plant_i_inverter_abc(const plant_t *p, double i_abc[3]);

/* Name of branch b (PLANT_FB_*) of a filter type, NULL if none. */
const char *plant_filter_branch_name(int type, int branch);
/* Output filter (plant_filter.h). Each returns PLANT_EINVAL without one. */
int plant_filter_stats(const plant_t *p, plant_filter_stats_t *st);
int plant_filter_reset_peaks(plant_t *p);
/* alpha-beta space vector of a filter quantity at the present instant. */
int plant_filter_probe(const plant_t *p, int quantity, double ab[2]);
/* Active filter: the drive's torque command, from which the reference
 * generator takes i_sq by S1 (50) (held until the next call). */
int plant_filter_set_torque_cmd(plant_t *p, double torque_nm);
/* Tests: hold the half-bridge states (1 = upper capacitor, 0 = lower) and
 * stop the hysteresis controller (sw == NULL: give control back). */
int plant_filter_set_switches(plant_t *p, const uint8_t *sw);

/* Flux maps: CSV "id_a,iq_a,psi_d_wb,psi_q_wb" (header line, then rows on a
 * full regular grid in any order). Returns PLANT_OK or PLANT_EINVAL with a
 * message (file, line) in err. plant_fluxmap_free releases the arrays. */
int plant_fluxmap_load(plant_fluxmap_t *m, const char *path, char *err, size_t errlen);
void plant_fluxmap_free(plant_fluxmap_t *m);
/* psi(i) by bilinear interpolation (clamped extrapolation is linear). */
void plant_fluxmap_psi(const plant_fluxmap_t *m, double id, double iq, double *psi_d,
                       double *psi_q);
/* i(psi) by damped Newton on the interpolant. *id, *iq on entry: initial
 * guess (used if finite, else the map's origin secant). Converges to
 * |psi(i) - psi| < 1e-12 Wb; returns PLANT_OK or PLANT_ERANGE. */
int plant_fluxmap_current(const plant_fluxmap_t *m, double psi_d, double psi_q, double *id,
                          double *iq);

#ifdef __cplusplus
}
#endif

#endif /* SIM_HOST_PLANT_H */
