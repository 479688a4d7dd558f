/*
 * Machine description files (INI, parsed with libinih): everything the plant
 * and the controller configuration need about one drive, in SI units.
 *
 * Sections and keys (all required unless marked optional):
 *   [machine]   name (text), pole_pairs, rs_ohm, ld_mh, lq_mh, psi_pm_wb
 *   [rated]     torque_nm, speed_rpm, current_a (peak), current_max_a (peak,
 *               over-current trip, > current_a), psi_ref_wb (optional, 0 = MTPA)
 *   [inverter]  vdc_v, fs_hz (default control/PWM frequency),
 *               dead_time_ns (optional, 0), v_fwd_v (optional, 0),
 *               dc_cap_uf (optional, 0 = stiff), dc_src_r_ohm (optional, needed if dc_cap_uf > 0)
 *   [rated]     ... speed_max_rpm (optional, >= speed_rpm; 0 = the firmware's
 *               default, where the back-EMF meets the DC link: fw_speed_max_rpm),
 *               overspeed_rpm (optional, 0 = 1.05 x the maximum speed: the
 *               firmware's overspeed trip level)
 *   [mechanics] inertia_kgm2, friction_nms (optional, 0: viscous B, N*m*s/rad);
 *               the optional non-ideal terms (0 = absent; sim_host/README.md):
 *               coulomb_nm (running friction), stiction_nm (break-away,
 *               >= coulomb_nm; default coulomb_nm), slots (stator slots),
 *               cogging_nm (peak of the cogging fundamental, lcm(slots,
 *               2 pole_pairs) periods per revolution; needs slots),
 *               cogging_phase_deg (its phase, degrees of the cogging period),
 *               cogging_harmonics_nm = a2 a3 ... (peaks of harmonics 2, 3, ...
 *               of the fundamental, up to PLANT_COG_MAX - 1 values),
 *               cogging_harmonics_deg = p2 p3 ... (their phases, same count;
 *               default 0), load_kind = none | constant | passive | time |
 *               speed, load_nm (constant: signed; passive: magnitude >= 0),
 *               load_profile = x:T x:T ... (time: x in s from the arm instant;
 *               speed: x in r/min, signed; linear between points, held
 *               outside; 2..PLANT_PROFILE_MAX points, x increasing)
 *   [fluxmap]   file (optional, CSV path relative to the INI file's folder)
 *   [speed_loop] (optional, firmware/isr/speed_loop.h) bandwidth_hz,
 *               phase_margin_deg (the sizing from the inertia; 0 = defaults),
 *               or explicit gains kp_nm_s_per_rad, ki_nm_per_rad (mechanical)
 *   [filter]    optional output filter (plant_filter.h; book chapter S1 §6):
 *               type = passive | active, current_sense = inverter | motor
 *               (optional, default inverter: where the drive's current
 *               sensors sit), and every key of the type:
 *               passive (S1 Table 5): trap_l1_uh trap_c1_uf trap_r1_ohm
 *                 trap_l2_mh trap_c2_uf trap_r2_ohm rlc_l3_mh rlc_r3s_ohm (r3)
 *                 rlc_r3_ohm rlc_c3_uf
 *               active (S1 Table 6): pri_l1_uh pri_c1_uf pri_r1_ohm sec_l2_uh
 *                 sec_c2_uf sec_r2_ohm af_lf_mh af_cf_uf af_cf_initial_v
 *                 af_sample_hz af_band_v af_ref_cutoff_hz
 *               A filter needs the linear model (no [fluxmap], no dead time,
 *               forward drop or DC-link capacitor).
 *   [sensors]   (optional) encoder_lines (lines per revolution, x4 counts;
 *               default 2500), encoder_offset_deg (electrical angle of the d
 *               axis where the encoder reads 0 and its index fires, i.e.
 *               theta_e = offset + direction x count angle; default 0),
 *               encoder_direction (1 or -1, default 1)
 * Unknown sections and unknown keys are REJECTED (a typo must not silently
 * fall back to a default). Values must be finite numbers in range.
 */
#ifndef SIM_HOST_SIM_MACHINE_H
#define SIM_HOST_SIM_MACHINE_H

#include <stddef.h>

#include "plant.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SIM_MACHINE_NAME_MAX 64
#define SIM_MACHINE_PATH_MAX 512

/* Where the drive's phase-current sensors sit (only differs with a filter). */
typedef enum {
    SIM_SENSE_INVERTER = 0, /* inverter output: shunts in the legs, as on a real board */
    SIM_SENSE_MOTOR = 1     /* motor terminals */
} sim_current_sense_t;

/* [mechanics] load_kind. */
typedef enum {
    SIM_LOAD_NONE = 0,
    SIM_LOAD_CONSTANT = 1, /* active, load_nm (from the arm instant in sim_run) */
    SIM_LOAD_PASSIVE = 2,  /* opposes the motion, holds at rest up to load_nm */
    SIM_LOAD_TIME = 3,     /* active profile in time (from the arm instant) */
    SIM_LOAD_SPEED = 4     /* active profile in speed */
} sim_load_kind_t;

typedef struct {
    char name[SIM_MACHINE_NAME_MAX];
    int pole_pairs;
    double rs_ohm, ld_h, lq_h, psi_pm_wb;
    double torque_rated_nm, speed_rated_rpm, current_rated_a, current_max_a, psi_ref_wb;
    double vdc_v;
    double fs_hz;
    double dead_time_s, v_fwd_v, dc_cap_f, dc_src_r_ohm;
    double inertia_kgm2, friction_nms;
    char fluxmap_path[SIM_MACHINE_PATH_MAX]; /* "" = none; resolved path */
    double overspeed_rpm;                    /* 0 = firmware default */
    double speed_max_rpm;                    /* 0 = firmware default (fw_speed_max_rpm) */
    double speed_bw_hz, speed_pm_deg;        /* 0 = firmware defaults */
    double speed_kp, speed_ki;               /* explicit gains; 0 = sized */
    plant_filter_cfg_t filter;               /* type NONE without [filter] */
    sim_current_sense_t current_sense;
    /* [mechanics] non-ideal terms (plant_config_t for their meaning) */
    double coulomb_nm, stiction_nm;
    int slots;
    double cogging_nm, cogging_phase_deg;
    int cog_harm_n, cog_harm_deg_n; /* values given */
    double cog_harm_nm[PLANT_COG_MAX - 1], cog_harm_deg[PLANT_COG_MAX - 1];
    sim_load_kind_t load_kind;
    double load_nm;
    plant_profile_t load_profile; /* plant units (s or rad/s, N*m) */
    char load_kind_text[SIM_MACHINE_NAME_MAX];
    char filter_type[SIM_MACHINE_NAME_MAX];        /* [filter] type as written */
    char current_sense_text[SIM_MACHINE_NAME_MAX]; /* [filter] current_sense as written */
    int encoder_lines;                             /* [sensors] */
    double encoder_offset_deg;
    int encoder_direction;
} sim_machine_t;

/* Returns 0 on success; otherwise -1 and a message naming the key (and the
 * line for malformed values) in err. */
int sim_machine_load(const char *path, sim_machine_t *out, char *err, size_t errlen);

/* Cogging periods per mechanical revolution, lcm(slots, 2 pole_pairs); 0
 * without slots. */
int sim_machine_cog_per_rev(const sim_machine_t *m);

/* 1 if the machine has Coulomb friction, stiction, cogging or a load. */
int sim_machine_nonideal(const sim_machine_t *m);

/* Fill a plant configuration from a machine (mechanics imposed, zero initial
 * state, no flux map: the caller loads m->fluxmap_path into cfg.fluxmap with
 * plant_fluxmap_load; sim_run and the CLI's replay do). The friction and
 * cogging are copied; so is the load: constant into load_torque_nm, passive
 * into load_passive_nm, a profile into load_profile. */
void sim_machine_to_plant(const sim_machine_t *m, plant_config_t *cfg);

#ifdef __cplusplus
}
#endif

#endif /* SIM_HOST_SIM_MACHINE_H */
