/*
 * Identification in the host simulator (./tools/sim --identify): the
 * firmware's commissioning sequence (firmware/commission) against the plant
 * on free mechanics, then the identified values beside the plant's truth.
 *
 * The plant runs free (no load; the rotor must be free to turn), from
 * sim_run_cfg_t.theta0_e_rad. The firmware is configured with the control
 * machine (its encoder settings from that file's [sensors]); the plant's
 * encoder follows the simulated machine's [sensors].
 */
#ifndef FIRMWARE_HOST_SIM_IDENT_H
#define FIRMWARE_HOST_SIM_IDENT_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "cm_config.h"
#include "sim_run.h"

/* Injected bad cases: each must end in its named error with the gates off. */
typedef enum {
    SIM_BAD_NONE = 0,
    SIM_BAD_OPEN,      /* motor not connected */
    SIM_BAD_SHORT,     /* a-b leads shorted through 1 uH */
    SIM_BAD_ENC_STUCK, /* encoder not counting */
    SIM_BAD_VBUS_LOW,  /* DC link at 75 % of nominal from the start */
    SIM_BAD_COUNT
} sim_bad_t;

typedef struct {
    bool finished;         /* the sequence ended before the time limit */
    uint8_t err;           /* cm_err_t */
    uint8_t step;          /* the step it ended in */
    uint32_t fault;        /* firmware fault latched (0 none) */
    bool gates_off;        /* the inverter's switches are open at the end */
    double motor_time_s;   /* sequence start to end, plant time */
    double gates_on_s;     /* periods with the gates on */
    double peak_current_a; /* largest true phase current (Ts/10 grid) */
    double peak_meas_a;    /* largest measured phase current (firmware) */
    cm_si_t res;           /* identified (SI) */
    bool applied;          /* the drive adopted the results (fw_commission_apply) */
} sim_ident_t;

/* The identification's test case on machine m, what the commissioning must
 * find out: the plant's encoder SIM_IDENT_CASE_OFFSET_DEG (electrical) off
 * and counting backwards; the drive configured with Rs x 1.3, Ld x 0.7,
 * Lq x 0.8 and psi_pm x 1.2 of m's. */
#define SIM_IDENT_CASE_OFFSET_DEG 137.0
void sim_ident_case(const sim_machine_t *m, sim_machine_t *plant, sim_machine_t *conf);

/* Configure and initialise a run for identification: the plant `plant` on
 * free mechanics from electrical angle theta0 at rest, the firmware
 * configured with `ctrl` (its parameters and [sensors]) and controller d,
 * booted and calibrated (state ready). Returns 0 or -1 with a message. */
int sim_ident_setup(sim_run_t *r, const sim_machine_t *plant, const sim_machine_t *ctrl,
                    const ctrl_desc_t *d, double theta0, uint64_t seed, char *err, size_t errlen);

/* Run `steps` (n of them) on a run initialised by sim_ident_setup; at most
 * t_max_s of plant time. Returns 0 (the outcome in *out), or -1 with a
 * message when the simulation itself failed. */
int sim_ident_run(sim_run_t *r, const uint8_t *steps, uint8_t n, double t_max_s, sim_bad_t bad,
                  sim_ident_t *out, char *err, size_t errlen);
/* Per-period trace of the run (every `every` periods; NULL = none): time,
 * step, phase, true phase currents and rotor angle/speed, the firmware's
 * encoder angle and the applied alpha-beta voltage. Set before the run. */
void sim_ident_trace(FILE *f, uint32_t every);

/* JSON object: "identify" (outcome), "identified", "truth", "error". */
void sim_ident_write_json(FILE *f, const sim_run_t *r, const sim_ident_t *id);
/* Human-readable table. */
void sim_ident_print(FILE *f, const sim_run_t *r, const sim_ident_t *id);
/* A complete machine file: `base` (the configured machine) with the
 * identified values in place. Returns 0 or -1 with a message. */
int sim_ident_write_ini(const char *path, const sim_machine_t *base, const sim_ident_t *id,
                        char *err, size_t errlen);

/* The whole identification plan (ident run). */
extern const uint8_t sim_ident_plan[];
extern const uint8_t sim_ident_plan_n;

#endif /* FIRMWARE_HOST_SIM_IDENT_H */
