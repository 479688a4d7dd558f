/*
 * Commissioning configuration (SI, read once) and the results in SI.
 * Floating point here only: configuration and reporting, never per period.
 */
#ifndef FIRMWARE_COMMISSION_CM_CONFIG_H
#define FIRMWARE_COMMISSION_CM_CONFIG_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "cm.h"
#include "ctrl_params.h"
#include "hal.h"

/* Test levels as fractions of the machine's ratings, times in seconds
 * (float: enough for every level and time, half the flash of the defaults).
 * Each step's current is the smaller of its level here and what the voltage
 * it may use drives through the configured machine (cm_configure; the steps
 * after "rs" with the measured Rs and inverter error), down to i_min. */
typedef struct {
    float i_hold;             /* alignment, scan and bias current / rated (0.3) */
    float i_hold_max;         /* the scan's current rises to this until the rotor follows (0.6) */
    float i_rs1, i_rs2;       /* the two DC levels / rated (0.25, 0.5) */
    float i_probe;            /* probe target / rated (0.1) */
    float i_open;             /* probe: less at the largest pattern = open / rated (0.02) */
    float i_acc;              /* inertia: twice the q current over the friction's / rated (0.5) */
    float i_spin;             /* flux step: q current limit of its speed loop / rated (0.8) */
    float i_fd;               /* +-d current of the flux step / rated (0.2) */
    float i_sense;            /* sense pulse target / rated (0.2) */
    float i_guard;            /* abort above this phase current / rated (1.0) */
    float i_gate_max;         /* gate test: current meaning "load connected" / rated (0.05) */
    float i_min;              /* smallest test current / rated (0.1); at least 64 ADC counts */
    float v_lim;              /* standstill voltage limit per axis / Vdc (0.25) */
    float v_lim_run;          /* spinning voltage limit per axis / Vdc (0.4) */
    float v_probe0;           /* first probe amplitude / Vdc (0.02) */
    float vbus_min, vbus_max; /* test window / nominal Vdc (0.8, 1.2) */
    float l_min_h, l_max_h;   /* plausible inductance (1 uH, 10 H) */
    float loop_g;             /* current-loop crossover x Ts, rad (0.2) */
    float damp_rad_s;         /* rotor damping rate Omega, rad/s electrical (30) */
    float w_flux; /* flux step: the higher speed / rated (0.5; less where the voltage ends it; the
                      test currents are sized for 3/5 of it); the lower a third */
    float w_loop_rad_s;       /* flux step: speed-loop crossover, rad/s (100) */
    float w_guard;            /* abort above / rated (0.8) */
    float w_settle;           /* at rest below / rated (0.01) */
    float torque_run;         /* first run torque / rated (0.1) */
    float unbalance_max;      /* (0.15) */
    float sense_lo, sense_hi; /* (0.75, 1.3) */
    float cpr_tol;            /* (0.03) */
    float salient_min;        /* (0.05) */
    float gate_duty;          /* (0.05) */
    float scan_hz;            /* encoder scan, electrical turns per second (4) */
    float t_vbus, t_ramp, t_settle, t_win, t_hold, t_hold_max, t_hf, t_scan_acc;
    float t_flux_max, t_flux_win, t_run, t_gate;
    float dead_time_s; /* the inverter's dead time (the drive's configuration; 0 unknown): the
                          mechanics take out the current samples' offset it causes */
} cm_config_t;

void cm_config_default(cm_config_t *c);

/* Fill cm->par from the configuration, the drive's parameters and the
 * hardware (results are kept). Returns 0, or -1 when a value does not fit
 * its format (the name of the quantity in *what). */
int cm_configure(cm_t *cm, const cm_config_t *c, const ctrl_params_t *p, const ctrl_bases_t *b,
                 const ctrl_machine_t *m, const hal_info_t *info, uint32_t enc_cpr,
                 const char **what);

/* Express the stored results in new bases (after the drive adopted new
 * machine parameters); enc_adopted: the drive now counts in the identified
 * direction (relative direction +1). */
void cm_rebase(cm_t *cm, const ctrl_bases_t *nb, bool enc_adopted);

/* The results in SI. enc_dir_cfg: the drive's configured direction (+1/-1). */
typedef struct {
    uint32_t have;
    double vbus_v, i_off_a[3], i_noise_a[3];
    double l_probe_h;
    int enc_dir;           /* absolute direction (configured x measured) */
    double enc_offset_deg; /* electrical, [0, 360) */
    uint32_t enc_cpr;      /* measured counts per revolution (rounded) */
    uint32_t enc_cpr_cfg;  /* configured (the measurement agreed with it) */
    double unbalance;      /* fraction */
    double rs_ohm, v_inv_v;
    double ld_h, lq_h, ld_raw_h, lq_raw_h;
    bool salient;
    double psi_wb, psi_pos_wb, psi_neg_wb, omega_flux_rad_s;
    double inertia_kgm2, friction_nms; /* NaN when not measured */
    double coulomb_nm;                 /* Coulomb friction and passive load, NaN idem */
} cm_si_t;

void cm_results_si(const cm_t *cm, int enc_dir_cfg, uint8_t pole_pairs, double ts_s, cm_si_t *o);

/* Whether r holds the results of the result bit `have` (CM_HAVE_*): measured,
 * and for the mechanics an inertia that is finite and > 0. */
bool cm_si_has(const cm_si_t *r, uint32_t have);

/* How a field of cm_si_t is read by cm_si_field. */
typedef enum {
    CM_FIELD_SI,    /* double, as stored */
    CM_FIELD_MILLI, /* double x 1e3 (H -> mH) */
    CM_FIELD_INT,   /* int */
    CM_FIELD_U32,   /* uint32_t */
    CM_FIELD_BOOL,  /* bool, as 0 or 1 */
    CM_FIELD_COUNT
} cm_field_t;

/* The field of r at byte offset off (offsetof(cm_si_t, field)) as a double,
 * read as kind says. */
double cm_si_field(const cm_si_t *r, size_t off, cm_field_t kind);

/* Item `index` (0..) of the machine-file fragment: section and key as in
 * sim_host's machine files, the value in the file's unit (integer: print
 * without decimals). Only measured values are listed. False past the end. */
typedef struct {
    const char *section, *key;
    double value;
    bool integer;
} cm_item_t;
bool cm_fragment_item(const cm_si_t *r, size_t index, cm_item_t *it);

/* The last outcome: verdict ("running", "pass", "fail", "stopped", "idle"),
 * the step it concerns, the error name ("none" on a pass) and up to three
 * labelled numbers in SI. */
typedef struct {
    const char *verdict, *step, *error;
    size_t n;
    const char *label[3];
    double value[3];
    const char *unit[3];
} cm_outcome_t;
void cm_outcome(const cm_t *cm, const ctrl_bases_t *b, cm_outcome_t *o);

#endif /* FIRMWARE_COMMISSION_CM_CONFIG_H */
