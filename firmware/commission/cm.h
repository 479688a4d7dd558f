/*
 * Commissioning: motor identification (Rs, Ld, Lq, psi_pm, encoder direction,
 * counts per revolution and electrical offset, optional inertia and friction)
 * and the bench bring-up checks, as steps of one framework that runs inside
 * the PWM interrupt (docs/identification.md).
 *
 * Per period the firmware's dispatch (pipeline.c, state COMMISSION) hands the
 * converted measurements to cm_period(), which returns what the inverter does
 * in the next period: gates off, three leg duties, or the selected controller
 * with a torque reference (the bring-up's first closed-loop run). Everything
 * per period is integer-only; SI enters once in cm_config.c.
 *
 * Step modules (one job each; the method each follows is cited in its file):
 *   cm_vbus.c     DC link and current-sensor offsets/noise with the gates off
 *   cm_probe.c    connection probe: open / shorted phase, coarse inductance
 *   cm_encoder.c  open-loop scan: direction, counts per revolution, offset
 *   cm_rs.c       Rs by DC injection at two levels (slope cancels the
 *                 inverter's dead-time and device-drop voltage) along each
 *                 phase's axis: phase balance
 *   cm_ldq.c      Ld, Lq at standstill: alternating pulses on a DC bias,
 *                 saliency
 *   cm_flux.c     psi_pm from the back-EMF at two held speeds; friction, inertia
 *   cm_gates.c    bring-up: gate test at low duty without a motor
 *   cm_sense.c    bring-up: current-sense polarity and gain, one pulse per phase
 *   cm_run.c      bring-up: first closed-loop run at 10 % of the rated torque
 *   cm_cogging.c  anti-cogging table: slow sweeps both ways under a position loop
 * Shared per-period machinery (frames, current regulator, modulation, the
 * applied-voltage record, rotor damping): cm_core.c / cm_internal.h.
 *
 * Formats: currents, voltages, speeds, resistances, inductances, flux Q24 per
 * unit of the drive's bases (ctrl_params.h) at the time of the measurement
 * (cm_results_t keeps a copy of those bases); angles fx_angle_t.
 */
#ifndef FIRMWARE_COMMISSION_CM_H
#define FIRMWARE_COMMISSION_CM_H

#include <stdbool.h>
#include <stdint.h>

#include "ctrl_params.h"
#include "fx.h"

/* 1: the flux step identifies the mechanics too (inertia, Coulomb and
 * viscous friction: cm_flux.c); 0 leaves them out of a flash-tight image
 * (CMake option PMSM_CM_MECH): psi_pm is measured the same way. */
#ifndef CM_MECH
#define CM_MECH 1
#endif

/* Steps. The numbers are sent in telemetry (signal cm_step): append only. */
typedef enum {
    CM_STEP_NONE = 0,
    CM_STEP_VBUS = 1,    /* DC link, sensor offsets and noise (gates off) */
    CM_STEP_PROBE = 2,   /* motor connected? coarse inductance */
    CM_STEP_ENCODER = 3, /* direction, counts per revolution, offset; phase balance */
    CM_STEP_RS = 4,      /* stator resistance */
    CM_STEP_LDQ = 5,     /* Ld, Lq, saliency */
    CM_STEP_FLUX = 6,    /* psi_pm, inertia, friction */
    CM_STEP_GATES = 7,   /* bring-up: gate test without a motor */
    CM_STEP_SENSE = 8,   /* bring-up: current-sense polarity and gain */
    CM_STEP_RUN = 9,     /* bring-up: first closed-loop run */
#if CTRL_COGGING
    CM_STEP_COGGING = 10, /* anti-cogging table (cm_cogging.h) */
#endif
    CM_STEP_COUNT
} cm_step_id_t;

/* Named errors (cm_err_name). Append only. */
typedef enum {
    CM_E_NONE = 0,
    CM_E_STOPPED,        /* stop command */
    CM_E_FAULT,          /* a drive protection fired (detail: fault code) */
    CM_E_VBUS_LOW,       /* DC link below what the test needs */
    CM_E_VBUS_HIGH,      /* DC link above the window */
    CM_E_OFFSET,         /* current reading with gates off not near zero */
    CM_E_NOISE,          /* current reading too noisy with gates off */
    CM_E_OPEN_PHASE,     /* no current at the largest test voltage */
    CM_E_SHORTED_PHASE,  /* current rises faster than any plausible winding */
    CM_E_UNBALANCED,     /* phase resistances differ */
    CM_E_VOLTAGE_LIMIT,  /* the regulator needed more than the voltage limit */
    CM_E_CURRENT_LIMIT,  /* a phase current above the rated current */
    CM_E_RS_RANGE,       /* resistance not plausible (<= 0 or out of Q range) */
    CM_E_L_RANGE,        /* inductance not plausible */
    CM_E_ENC_NO_MOTION,  /* encoder did not count while the field turned */
    CM_E_ENC_CPR,        /* counts per revolution differ from the configuration */
    CM_E_ENC_UNSTEADY,   /* rotor did not settle (still moving) */
    CM_E_SPEED_LOW,      /* could not reach a speed where the EMF is measurable */
    CM_E_OVERSPEED,      /* rotor faster than allowed during a test */
    CM_E_FLUX_RANGE,     /* flux linkage not plausible */
    CM_E_SENSE_POLARITY, /* a phase current has the wrong sign */
    CM_E_SENSE_GAIN,     /* a phase current far from what Rs and L predict */
    CM_E_SENSE_SUM,      /* the three currents do not sum to zero */
    CM_E_GATES_CURRENT,  /* current during the gate test: a motor or load is on */
    CM_E_GATES_VBUS,     /* DC link sagged during the gate test */
    CM_E_RUN_DIRECTION,  /* first run turned against the torque reference */
    CM_E_RUN_NO_ACCEL,   /* first run did not accelerate */
    CM_E_RUN_CURRENT,    /* first run drew far more current than the torque needs */
    CM_E_NEEDS,          /* a result this step needs is missing (detail: step) */
    CM_E_SUPPLY,         /* the supply cannot drive the smallest test current */
    CM_E_LOAD,           /* the rotor does not follow: more torque needed than the step makes */
#if CTRL_COGGING
    CM_E_COG_FOLLOW, /* cogging: the rotor does not follow the sweep (cm_cogging.h) */
    CM_E_COG_RANGE,  /* cogging: a bin beyond +-rated torque, or not reached */
    CM_E_COG_CONFIG, /* cogging: its loop does not fit (cm_cogging.h) */
#endif
    CM_E_COUNT
} cm_err_t;

/* cm_period output modes. */
typedef enum {
    CM_OUT_OFF = 0,  /* gates off */
    CM_OUT_LEGS = 1, /* legs[] for [k+1, k+2) */
    CM_OUT_CTRL = 2  /* run the selected controller with torque_ref */
} cm_out_mode_t;

/* Measurements of period k (converted by the pipeline). */
typedef struct {
    q24_t i_a, i_b, i_c; /* phase currents, Q24 pu (i_c measured when has_i_c) */
    q24_t vdc;           /* DC link, Q24 pu */
    fx_angle_t theta;    /* encoder electrical angle with the configured direction
                            and WITHOUT the configured offset */
    q24_t omega_est;     /* estimator speed, Q24 pu (only meaningful in CM_OUT_CTRL) */
    q24_t torque_est;    /* estimator torque, Q24 pu (idem) */
#if CTRL_COGGING
    uint32_t enc_pos; /* encoder position in [0, cpr), configured direction */
#endif
} cm_in_t;

typedef struct {
    uint8_t mode;       /* cm_out_mode_t */
    uint8_t ctrl_reset; /* CM_OUT_CTRL: reset controller and estimator first */
    q24_t legs[3];      /* CM_OUT_LEGS: duties in [0, FX_ONE], on the compare grid */
    q24_t torque_ref;   /* CM_OUT_CTRL: Q24 pu */
} cm_out_t;

/* Validity flags of cm_results_t. */
#define CM_HAVE_VBUS 0x001u
#define CM_HAVE_LPROBE 0x002u
#define CM_HAVE_ENC 0x004u
#define CM_HAVE_RS 0x008u
#define CM_HAVE_LDQ 0x010u
#define CM_HAVE_FLUX 0x020u
#define CM_HAVE_MECH 0x040u
#define CM_HAVE_BALANCE 0x080u

/* Share of a step's voltage limit its test current may take (the rest is
 * the current regulator's headroom and the inverter's error). */
#define CM_V_USE 0.8
#define CM_V_USE_Q24 13421773 /* 0.8 in Q24 */

/* What the steps found (pu of `bases`). */
typedef struct {
    uint32_t have;          /* CM_HAVE_* */
    ctrl_bases_t bases;     /* SI of 1 pu when the results were taken */
    q24_t vbus;             /* mean DC link, pu */
    q24_t i_off[3];         /* mean current reading with the gates off, pu */
    q24_t i_noise[3];       /* its standard deviation, pu */
    q24_t l_probe;          /* coarse inductance along alpha (probe), pu */
    int8_t enc_dir;         /* +1 / -1 relative to the configured direction */
    fx_angle_t enc_off;     /* theta_e = enc_off + enc_dir * theta (cm_in_t.theta) */
    uint32_t enc_cpr;       /* measured counts per revolution (rounded) */
    q24_t enc_cpr_ratio;    /* measured / configured counts, Q24 */
    q24_t unbalance;        /* spread of the three axes' resistances / Rs, Q24 */
    q24_t rs;               /* stator resistance, pu */
    q24_t v_inv;            /* inverter voltage error along the test axis at i_rs1, pu */
    q24_t ld, lq;           /* pu, after the saliency decision */
    q24_t ld_raw, lq_raw;   /* as measured */
    uint8_t salient;        /* 1: |Lq - Ld| above the saliency threshold */
    q24_t psi;              /* permanent-magnet flux linkage, pu */
    q24_t psi_pos, psi_neg; /* v_q / omega at +i_d and -i_d, pu */
    q24_t omega_flux;       /* speed of the flux measurement, pu electrical */
    /* Mechanics (cm_flux.c; SI in cm_config.c): the four speed windows
     * (0: w_lo +i_d, 1: w_hi +i_d, 2: w_hi -i_d, 3: w_lo -i_d) - mean v_q, speed
     * (pu electrical), i_q, the speed's change and the periods; the two transitions between them
     * (0: 0 -> 1, 1: 2 -> 3) - sum of i_q (pu x periods), rotor angle travelled (fx_angle_t units,
     * electrical), periods. */
    q24_t fw_vq[4], fw_w[4];
    q24_t fw_iq[4]; /* less the samples' dead-time offset (cm_flux.c) */
    q24_t fw_eq[4]; /* the inverter's error along q in each window (cm_flux.c), pu */
#if CM_MECH
    q24_t fw_dw[4];     /* the last block's mean speed less the first block's, pu */
    uint32_t fw_n[4];   /* periods between the two blocks' middles */
    uint32_t fw_len[4]; /* periods of the window */
    int64_t jx_iq[2], jx_th[2];
    uint32_t jx_n[2];
#endif
    q24_t i_fd; /* the windows' |i_d| */
} cm_results_t;

/* Limits and timings in pu and periods (cm_config.c fills them). */
typedef struct {
    uint32_t pwm_n;                        /* compare value for 100 % duty */
    uint32_t inv_n_q32;                    /* floor(2^32 / pwm_n) */
    uint32_t enc_cpr;                      /* configured counts per revolution */
    q24_t ts;                              /* control period, pu time */
    int32_t dangle_to_omega;               /* Q28, ctrl_params_t */
    q24_t i_lsb;                           /* one ADC count of current, pu */
    q24_t i_rated;                         /* rated current, pu */
    q24_t i_guard;                         /* abort above this phase current, pu */
    q24_t i_min;                           /* smallest test current a step accepts, pu */
    q24_t i_hold;                          /* alignment / scan / bias current, pu */
    q24_t i_hold_max, i_hold_max_nom;      /* the scan's current rises up to this, pu */
    q24_t i_hold_nom, i_acc_nom, i_fd_nom; /* configured levels before the voltage caps, pu */
    q24_t i_rs1, i_rs2;                    /* the two DC levels, pu */
    q24_t i_probe;                         /* probe target peak, pu */
    q24_t i_open;                          /* below this at the largest probe: open phase, pu */
    q24_t i_acc;              /* inertia: twice the q current over the friction's, pu */
    q24_t i_spin, i_spin_nom; /* flux step: the speed loop's q current limit, pu */
    q24_t i_fd;               /* +-d current of the flux step, pu */
    q24_t i_sense;            /* sense pulse target peak, pu */
    q24_t i_gate_max;         /* gate test: current above this = load connected, pu */
    q24_t v_lim;              /* standstill voltage limit per axis, pu */
    q24_t v_lim_run;          /* spinning voltage limit per axis, pu */
    q24_t v_probe0;           /* first probe amplitude, pu */
    q24_t vbus_min, vbus_max; /* test window, pu */
    q24_t l_min;              /* below: shorted phase, pu */
    q24_t l_max;              /* above: implausible, pu */
    q24_t loop_g;             /* current-loop crossover x Ts (rad), Q24 */
    int32_t damp_k;           /* rotor damping w_base / Omega, Q16 (i_q = -i slip_pu damp_k) */
    q24_t td;                 /* the inverter's dead time, pu time (cm_config_t.dead_time_s) */
    q24_t w_kp, w_ki;         /* flux step's speed loop: pu q current per pu speed error, and
                                 per period, Q24 */
    q24_t w_rated;            /* rated electrical speed, pu */
    q24_t w_flux;             /* flux-step target speed, pu */
    q24_t w_guard;            /* abort above this speed, pu */
    q24_t w_settle;           /* "at rest" below this slip speed, pu */
    q24_t torque_run;         /* bring-up run torque, pu */
    q24_t torque_rated;       /* pu */
    q24_t unbalance_max;      /* Q24 fraction */
    q24_t sense_lo, sense_hi; /* accepted measured/predicted ratio, Q24 */
    q24_t cpr_tol;            /* Q24 fraction */
    q24_t salient_min;        /* Q24 fraction */
    q24_t l_cfg_d, l_cfg_q;   /* configured inductances (bring-up predictions), pu */
    q24_t rs_cfg;             /* configured resistance, pu */
    q24_t psi_cfg;            /* configured flux linkage, pu */
    q24_t gate_duty;          /* gate test duty, Q24 */
    fx_angle_t scan_inc;      /* scan speed, angle per period */
    uint32_t n_turn;          /* periods of one electrical turn at scan_inc */
    uint32_t enc_count;       /* one encoder count, electrical fx_angle_t units */
    uint32_t n_vbus, n_ramp, n_settle, n_win, n_hold, n_hold_max, n_hf, n_scan_acc;
    uint32_t n_flux_max, n_flux_win, n_run, n_gate, n_rest;
    uint8_t has_i_c;
    uint8_t pole_pairs;
} cm_par_t;

/* Per-period machinery shared by the steps (cm_internal.h). */
typedef struct {
    q24_t kp, ki, integ, lim;
    uint8_t sat; /* output clamped in the last period */
} cm_pi_t;

#define CM_SPEED_AVG 16u /* periods of the moving-average speed */

typedef struct {
    /* measurements of this period */
    q24_t i_al, i_be;
    q24_t i_al_prev, i_be_prev;
    fx_angle_t th, th_prev; /* encoder angle (cm_in_t.theta) */
    int32_t dth;            /* th - th_prev */
    int32_t dth_ring[CM_SPEED_AVG];
    int64_t dth_sum; /* sum of the ring: angle per CM_SPEED_AVG periods */
    uint32_t ring_i;
    int64_t pos;                   /* unwrapped encoder angle since the step began */
    int32_t fr_ring[CM_SPEED_AVG]; /* frame increments (cm_hold), same window */
    int64_t fr_sum;
    q24_t vdc;
    /* applied voltage (from the compare values and the measured vdc), alpha-beta:
     * [2] commanded in this period (acts in [k+1, k+2)), [0] commanded at k-1
     * (acts in [k, k+1)), [1] commanded at k-2 (acted in [k-1, k): the one the
     * current change from k-1 to k reflects); shifted at each period start */
    q24_t va_al[3], va_be[3];
    uint8_t va_valid[3];
    uint8_t primed;
    uint8_t avg2; /* regulate on the mean of the last two samples (removes an
                     fs/2 ripple from the feedback) */
} cm_io_t;

/* Per-step scratch state (one step runs at a time). */
typedef struct {
    uint32_t n;
    int64_t s[12];
    q24_t a[8];
    int32_t k[6];
    fx_angle_t ang[3];
} cm_scratch_t;

typedef struct {
    cm_par_t par;
    cm_results_t res;
    /* sequence */
    uint8_t plan[CM_STEP_COUNT];
    uint8_t plan_n, plan_i;
    uint8_t step;      /* running step, CM_STEP_NONE when idle */
    uint8_t last_step; /* step of the last result or error */
    uint8_t active;
    uint8_t done;      /* the last sequence ended (ok or error) */
    uint8_t err;       /* cm_err_t of the last sequence */
    uint8_t apply;     /* a complete identification waits for fw_commission_poll */
    int32_t detail[3]; /* numbers for the error or verdict text (see cm_config.c) */
    uint16_t progress; /* per mille of the running step */
    uint32_t phase;    /* phase within the step */
    uint32_t t;        /* periods in this phase (0 in its first period) */
    uint8_t t_fresh;   /* the phase began in this period: t stays 0 */
    uint32_t t_step;   /* periods in this step */
    uint32_t t_total;  /* periods with gates on in this sequence */
    q24_t i_peak;      /* largest phase current seen, pu */
    /* hold frame: the stationary angle the rotor was aligned to */
    fx_angle_t hold_angle;
    q24_t hold_i; /* current magnitude of the last hold, pu */
    uint8_t hold_valid;
    cm_io_t io;
    q24_t mon_id, mon_iq; /* the regulated frame's measured currents (cm_monitor), pu */
    cm_pi_t pi_d, pi_q;
    cm_pi_t pi_w; /* the flux step's speed loop */
    cm_scratch_t x;
#if CTRL_COGGING
    /* the anti-cogging table and its step's state (cm_cogging.h; the
     * firmware's): last, to move no offset */
    struct cm_cog *cog;
#endif
} cm_t;

/* ---- per period (ISR) ---- */

/* Runs the active step; sets *out. Returns true while commissioning continues;
 * false when the sequence ended this period (cm->err tells how; the gates
 * are off in *out). */
bool cm_period(cm_t *cm, const cm_in_t *in, cm_out_t *out);

/* What the running step does, for telemetry (all Q24 pu): the measured
 * currents in the frame it regulates (*id along its field or the rotor's d
 * axis; 0 with the gates off), the rotor's electrical speed (the drive's
 * direction) and the torque psi i_q + (Ld - Lq) i_d i_q (the identified
 * values where known, else the configured ones) of the current in the rotor
 * frame - the identified one once the encoder step has passed, else the
 * drive's angle theta_drive. */
void cm_monitor(const cm_t *cm, fx_angle_t theta_drive, q24_t *id, q24_t *iq, q24_t *w,
                q24_t *torque);

/* A drive protection fired (gates already off): end with CM_E_FAULT, or the
 * step's diagnosis of it (an over-current during the probe is a shorted
 * phase). */
void cm_abort_fault(cm_t *cm, uint32_t fault_code);
/* Stop command. */
void cm_abort_stop(cm_t *cm);

/* ---- main loop ---- */

/* Prepare a sequence (plan of steps); checks each step's prerequisites in
 * order, counting results the earlier steps of the plan will produce.
 * Returns CM_E_NONE or CM_E_NEEDS with *missing the step that must run first. */
int cm_prepare(cm_t *cm, const uint8_t *steps, uint8_t n, uint8_t *missing);
/* Start the prepared plan (called by the ISR when it enters COMMISSION). */
void cm_begin(cm_t *cm);

const char *cm_step_name(uint8_t step);
const char *cm_err_name(uint8_t err);
/* Step by name ("vbus", ...), CM_STEP_NONE if unknown. */
uint8_t cm_step_find(const char *name);
/* Results this step produces (CM_HAVE_*) and needs. */
uint32_t cm_step_gives(uint8_t step);
uint32_t cm_step_needs(uint8_t step);

#endif /* FIRMWARE_COMMISSION_CM_H */
