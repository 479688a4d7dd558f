/*
 * Optional inverter output filter of the plant (book chapter, A. A. Adam and
 * K. Gulez, "Torque Control of PMSM and Associated Harmonic Ripples", §6):
 *
 *  - PLANT_FILTER_PASSIVE: the compound trap filter (S1 Fig. 43, Π equivalent
 *    S1 (41)-(43)) cascaded with the RLC filter (S1 Fig. 48, S1 (44)-(47)),
 *    values of S1 Table 5.
 *  - PLANT_FILTER_ACTIVE: the series active filter of S1 §6.2 (IGBT half
 *    bridge with storage capacitors C_F and smoothing inductor L_F under
 *    sampled hysteresis voltage control, reference S1 (48)-(53)), the primary
 *    RLC filter (L1, R1-C1) and the 1:1 transformer, the secondary RLC filter
 *    (L2, R2-C2) at the motor terminals; values of S1 Table 6.
 *
 * Topologies as read from the chapter (the figures are not in its text; the
 * reading and its reasons are in sim_host/README.md, "Output filters"):
 *
 *   passive, per phase (node 1 = inverter terminal, 3 = motor terminal):
 *     1 --R2--L2-- 2                  low-pass branch
 *     1 --L1--C1-- X --C2-- 2         T part: the Π of S1 (41)-(43) is its
 *                  X --R1-- N         star-delta equivalent
 *     2 --L3--r3-- 3 --R3--C3-- N     RLC filter, S1 (44)
 *     3 -- motor
 *   active, per phase:
 *     inverter --[AF: +-v_CF]--L_F--L1-- P --R1--C1-- N1       primary RLC
 *     P = transformer primary; secondary S (ideal 1:1: v_S = v_P, i_S = i_P)
 *     S --L2-- M --R2--C2-- N2                                secondary RLC
 *     M -- motor
 *   N, N1, N2 are isolated star points: only the differential mode (the
 *   space vector) is modelled; the common mode drives no current.
 *
 * Integration: the filter and the machine form one linear system in the rotor
 * frame; with the electrical speed held over a plant step (one
 * plant_advance_period or plant_advance call) it is time invariant, and the
 * inverter's alpha-beta voltage (constant between switching instants) is a
 * phasor rotating at -omega in that frame. The state is augmented with that
 * phasor and the constant 1 (which carries the back-EMF), and each piece is
 * z(t + h) = exp(M h) z(t), M of size n + 3, exp by plant_expm (scaling and
 * squaring). Exact up to rounding; checked against Eigen
 * (tests/plant/ref_filter_expm.cpp).
 */
#ifndef SIM_HOST_PLANT_FILTER_H
#define SIM_HOST_PLANT_FILTER_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    PLANT_FILTER_NONE = 0,
    PLANT_FILTER_PASSIVE = 1, /* trap + RLC, S1 §6.1 */
    PLANT_FILTER_ACTIVE = 2   /* series active filter, S1 §6.2 */
} plant_filter_type_t;

/* S1 Fig. 43 / Fig. 48, symbols of S1 Table 5. All > 0. */
typedef struct {
    double l1_h, c1_f, r1_ohm; /* trap: L1-C1 branch 1 -> X, R1 from X to the star point */
    double l2_h, r2_ohm;       /* trap: low-pass branch R2-L2, 1 -> 2 */
    double c2_f;               /* trap: C2, X -> 2 */
    double l3_h, r3s_ohm;      /* RLC: series L3 and r3, 2 -> 3 */
    double r3_ohm, c3_f;       /* RLC: shunt R3-C3 at the motor terminals */
} plant_filter_passive_t;

/* S1 §6.2, symbols of S1 Table 6 and §6.2.5. */
typedef struct {
    double l1_h, r1_ohm, c1_f; /* primary RLC: series L1, shunt R1-C1 across the primary */
    double l2_h, r2_ohm, c2_f; /* secondary RLC: series L2, shunt R2-C2 at the motor */
    double lf_h;               /* smoothing inductor L_F (series, per phase) */
    double cf_f;               /* each of the two storage capacitors of a half bridge */
    double cf_v0_v;            /* their initial (pre-charge) voltage, > 0 */
    double sample_hz;          /* hysteresis controller sampling rate */
    double band_v;             /* hysteresis half band on the motor phase voltage, >= 0 */
    double ref_cutoff_hz;      /* low-pass of the torque command before d/dt in S1 (52) */
    /* Storage regulation (not in S1; 0 = none, S1's AF): a PI on the six
     * capacitors' energy against their pre-charge's, bandwidth dc_bw_hz, sets
     * the active power the AF draws from the line; it draws it as a series
     * resistance r_e (|r_e| <= dc_re_max_ohm) emulated in phase with the line
     * current, v* - r_e i, the usual DC-link control of series active filters. */
    double dc_bw_hz;      /* >= 0 */
    double dc_re_max_ohm; /* > 0 when dc_bw_hz > 0 */
} plant_filter_active_t;

typedef struct {
    plant_filter_type_t type;
    plant_filter_passive_t passive;
    plant_filter_active_t active;
    /* Gates off: the inverter terminals as this resistance to the star point
     * (all diodes blocking); 0 = default 1 MOhm. */
    double r_open_ohm;
} plant_filter_cfg_t;

/* Branch currents reported by plant_filter_stats (index into i2_int, i_peak).
 * Passive: */
enum {
    PLANT_FB_INVERTER = 0,  /* inverter output (passive: i_L1 + i_L2; active: i_LF) */
    PLANT_FB_MOTOR = 1,     /* motor terminals */
    PLANT_FB_TRAP_L1C1 = 2, /* passive: L1-C1 branch */
    PLANT_FB_TRAP_L2 = 3,   /* passive: R2-L2 branch */
    PLANT_FB_TRAP_C2 = 4,   /* passive: C2 */
    PLANT_FB_TRAP_R1 = 5,   /* passive: R1 to the star point */
    PLANT_FB_RLC_L3 = 6,    /* passive: L3-r3 */
    PLANT_FB_RLC_SHUNT = 7, /* passive: R3-C3 (S1 (47) i_CR3) */
    PLANT_FB_PRI_SHUNT = 2, /* active: R1-C1 across the primary (S1 (58) i_CR1) */
    PLANT_FB_TRANSF = 3,    /* active: transformer winding, L2 */
    PLANT_FB_SEC_SHUNT = 4, /* active: R2-C2 at the motor (S1 (58) i_CR2) */
    PLANT_FB_N = 8
};

/* Cumulative filter quantities since plant_init (differences over a window
 * give means). Currents are space vectors: per-phase RMS = sqrt(0.5 * mean
 * |i|^2) for zero-sum phase currents (amplitude-invariant Clarke); the peak
 * is the largest |i| seen at the piece ends and midpoints since the last
 * plant_filter_reset_peaks, an upper bound of every phase's |i_x|. */
typedef struct {
    plant_filter_type_t type;
    int n_branches;            /* valid entries of i2_int / i_peak */
    double i2_int[PLANT_FB_N]; /* integral |i|^2 dt, A^2 s */
    double i_peak[PLANT_FB_N]; /* A */
    double e_loss_j;           /* energy dissipated in the filter resistors, J */
    double e_stored_j;         /* energy stored in the filter L and C now, J */
    double cf_min_v, cf_max_v; /* active: storage capacitors since the peak reset */
    uint64_t af_transitions;   /* active: half-bridge transitions since init */
} plant_filter_stats_t;

/* Quantities for plant_filter_probe (alpha-beta space vectors). */
typedef enum {
    PLANT_FP_V_INV = 0,   /* inverter terminal voltage (differential) */
    PLANT_FP_V_MOTOR = 1, /* motor terminal voltage */
    PLANT_FP_I_INV = 2,   /* inverter output current */
    PLANT_FP_I_MOTOR = 3, /* motor current */
    PLANT_FP_V_NODE2 = 4, /* passive: trap output (node 2); active: transformer voltage v_P */
    PLANT_FP_V_NODEX = 5, /* passive: trap internal node X; active: AF capacitor voltage u */
    PLANT_FP_BRANCH0 = 6  /* + PLANT_FB_*: branch current */
} plant_filter_probe_t;

#define PLANT_FILTER_NX 14 /* largest filter + machine state (passive) */
#define PLANT_FILTER_NA (PLANT_FILTER_NX + 3)
#define PLANT_FILTER_CACHE 6

/* Filter state inside plant_t. Private: use the plant_filter_* functions. */
typedef struct {
    plant_filter_type_t type;
    int n;                     /* filter + machine states (dq pairs) */
    double x[PLANT_FILTER_NX]; /* see plant_filter.c for the order */
    /* system matrix for (w, wu, open) and exp(M h) for some h */
    int m_valid;
    double m_w, m_wu;
    int m_open;
    double m[PLANT_FILTER_NA * PLANT_FILTER_NA];
    struct {
        int valid;
        double h;
        double e[PLANT_FILTER_NA * PLANT_FILTER_NA];
    } cache[PLANT_FILTER_CACHE];
    int cache_next;
    /* active filter: half-bridge state per phase (1 = upper capacitor in the
     * line, u_x = +v_up; 0 = lower, u_x = -v_lo), the idle capacitor's
     * voltage, the zero-sequence part of u (no current), the controller */
    uint8_t sw[3];
    double v_up[3], v_lo[3];
    double u0;
    int64_t af_next;  /* index of the next sampling instant */
    double tq_cmd_nm; /* torque command for S1 (50) */
    double isq_f;     /* low-passed i_sq of S1 (50) */
    int af_manual;    /* tests: switches set by plant_filter_set_switches */
    double dc_int;    /* storage regulation: integral part of the power, W */
    double dc_i2;     /* its low-passed |i_inv|^2, A^2 */
    double dc_re;     /* its emulated series resistance, ohm */
    plant_filter_stats_t st;
} plant_filter_t;

/* ---- used by plant.c only (the public functions are in plant.h) ---- */
struct plant;

/* Input of one piece: the inverter (or test-source) voltage in the rotor
 * frame, W e^{j wu t} from the piece start; open = 1: gates off. */
typedef struct {
    int open;
    double wu;
    double w_d, w_q;
} plant_filter_input_t;

/* Validate p->cfg.filter against the machine and set the initial state. */
int plant_filter_setup(struct plant *p);
/* Advance the filter and machine currents by dt at the held electrical speed
 * w (theta_e and t are advanced by the caller). Adds the integral of the
 * torque to *te_int and of the motor alpha-beta voltage to vint[2]. */
int plant_filter_piece(struct plant *p, const plant_filter_input_t *in, double w, double dt,
                       double *te_int, double vint[2]);
/* Next sampling instant of the active filter's controller (INFINITY if none)
 * and the controller's action at that instant (p->t is the instant). */
double plant_filter_next_event(const struct plant *p);
void plant_filter_event(struct plant *p);
/* Motor current (dq) of the filter state. */
void plant_filter_motor_current(const struct plant *p, double *id, double *iq);

#ifdef __cplusplus
}
#endif

#endif /* SIM_HOST_PLANT_FILTER_H */
