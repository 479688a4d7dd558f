/*
 * libFuzzer target: command lines through the firmware's real serial link
 * (fw_link.c on cmd.c) into its configuration (controller selection,
 * tunables, references, arm/disarm, identification, telemetry) and the
 * machine data, with a few PWM periods of the closed loop (pipeline, HAL
 * simulation, plant) after every line.
 *
 * Machine data: "param set m.<field> V" re-initialises the firmware with the
 * changed machine as the board image does (esc1_reconfigure: fw_config_default,
 * fw_init, the previous data restored on a refusal). The link's own range for
 * them is the number syntax's (|v| <= 1e15): the core alone decides what it
 * can represent, so extreme values and ratios reach its conversions.
 *
 * Invariants (abort on violation; ASan and UBSan abort on their own, so a
 * float-to-integer conversion out of range or a signed overflow is a finding):
 *  - every response line starts with "ok" or "err ";
 *  - a refused value is named: "err 4" gives the range "[lo, hi]" of the value
 *    on the line, "err 10 failed" of a configuration op the core's
 *    "<quantity> = <value> ... outside [<lo>, <hi>]" (or "<quantity> missing");
 *  - gates off whenever the firmware is not running or commissioning, in
 *    particular after every refusal and in the fault state;
 *  - what the firmware accepted is representable: its bases and limits are
 *    finite and positive, the machine it runs with is the last one accepted.
 *
 * Input: byte 0 picks the machine (shipped files, loaded once), byte 1 the
 * controller and the starting state; the rest is link bytes. After each line
 * end the loop runs 1 + (byte 0 >> 4) % 4 periods (at most 64 per input).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "controller.h"
#include "fw_link.h"
#include "hal_sim.h"
#include "sim_run.h"

#define FZ_CHECK(cond)                                                                             \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "invariant failed: %s (line %d)\n", #cond, __LINE__);                  \
            fprintf(stderr, "last line: '%s'\nresponse: '%s'\n", fz.line, fz.resp);                \
            abort();                                                                               \
        }                                                                                          \
    } while (0)

#define FZ_MACHINES 3u
#define FZ_PERIODS_MAX 64u

static const char *const fz_machine_files[FZ_MACHINES] = {
    PMSM_MACHINES_DIR "/thesis_spmsm.ini", PMSM_MACHINES_DIR "/gbm5208_gimbal.ini",
    PMSM_MACHINES_DIR "/thesis_ipmsm_80kw.ini"};

typedef struct {
    sim_run_t run; /* first: the snapshots are copied into this very address */
    fw_link_t link;
    ctrl_machine_t machine; /* the machine data in force */
    char line[CMD_LINE_MAX + 8];
    size_t line_len;
    char resp[CMD_OUT_MAX + 8];
    size_t resp_len;
    int n_resp;
    int last_reconf; /* 1: last machine set accepted, -1 refused, 0 none */
} fz_t;

static fz_t fz;
/* Boot and calibration done once per machine x controller (ready, not armed). */
static sim_run_t *fz_snap;
static size_t fz_n_ctrl;
static sim_machine_t fz_machines[FZ_MACHINES];

static void fz_write(void *ctx, const uint8_t *b, size_t n)
{
    (void)ctx;
    for (size_t i = 0; i < n; i++) {
        if (fz.resp_len + 1u < sizeof fz.resp) {
            fz.resp[fz.resp_len++] = (char)b[i];
            fz.resp[fz.resp_len] = '\0';
        }
    }
}

/* ---- machine data over the link (as the board image's m.* parameters) ---- */

typedef struct {
    const char *name, *unit;
    size_t offset; /* double in ctrl_machine_t; SIZE_MAX: pole pairs */
} fz_field_t;

#define FZ_FIELD(n, u, f)                                                                          \
    {                                                                                              \
        n, u, offsetof(ctrl_machine_t, f)                                                          \
    }
static const fz_field_t fz_fields[] = {
    {"m.p", "-", SIZE_MAX},
    FZ_FIELD("m.rs_ohm", "ohm", rs_ohm),
    FZ_FIELD("m.ld_h", "H", ld_h),
    FZ_FIELD("m.lq_h", "H", lq_h),
    FZ_FIELD("m.psi_wb", "Wb", psi_pm_wb),
    FZ_FIELD("m.vdc_v", "V", vdc_v),
    FZ_FIELD("m.j_kgm2", "kg*m^2", inertia_kgm2),
    FZ_FIELD("m.t_rated_nm", "N*m", torque_rated_nm),
    FZ_FIELD("m.n_rated_rpm", "r/min", speed_rated_rpm),
    FZ_FIELD("m.n_max_rpm", "r/min", speed_max_rpm),
    FZ_FIELD("m.i_rated_a", "A", current_rated_a),
    FZ_FIELD("m.i_max_a", "A", current_max_a),
    FZ_FIELD("m.psi_ref_wb", "Wb", psi_ref_wb),
};
#define FZ_N_FIELDS (sizeof fz_fields / sizeof fz_fields[0])

static int fz_get(const fz_field_t *f, double *v)
{
    if (f->offset == SIZE_MAX) {
        *v = (double)fz.machine.pole_pairs;
    } else {
        memcpy(v, (const char *)&fz.machine + f->offset, sizeof *v);
    }
    return CMD_OK;
}

static int fz_set(const fz_field_t *f, double v)
{
    if (fw_state(&fz.run.fw) == FW_STATE_RUNNING) {
        return CMD_E_STATE;
    }
    fz.machine = fz.run.fw.machine_own; /* identification may have changed it */
    ctrl_machine_t m = fz.machine;
    if (f->offset == SIZE_MAX) {
        if (v != floor(v)) {
            return CMD_E_RANGE; /* whole numbers: the link says so */
        }
        m.pole_pairs = (int)v;
    } else {
        memcpy((char *)&m + f->offset, &v, sizeof v);
    }
    m.name = "fuzz_user";
    const ctrl_desc_t *ctrl = fz.run.fw.ctrl;
    fw_config_t fc = fz.run.fw.cfg;
    fc.machine = &m;
    fc.ctrl = ctrl;
    fc.ctrl_cfg = NULL;
    const int rc = fw_init(&fz.run.fw, &fz.run.hal, &fc);
    if (rc != FW_OK) {
        fw_link_set_why(&fz.link, &fz.run.fw.why);
        /* Refused: gates off before the restore. */
        FZ_CHECK(!hal_sim_gates_on(&fz.run.hal));
        fc = fz.run.fw.cfg;
        fc.machine = &fz.machine;
        fc.ctrl = ctrl;
        FZ_CHECK(fw_init(&fz.run.fw, &fz.run.hal, &fc) == FW_OK);
        fz.last_reconf = -1;
        return CMD_E_FAILED;
    }
    fz.machine = m;
    fz.last_reconf = 1;
    return CMD_OK;
}

/* One get and one set for every field: the entry's place in fz_params is the
 * field's in fz_fields. */
static fw_link_param_t fz_params[FZ_N_FIELDS];
static int fz_get_p(void *ctx, const fw_link_param_t *p, double *v)
{
    (void)ctx;
    return fz_get(&fz_fields[p - fz_params], v);
}
static int fz_set_p(void *ctx, const fw_link_param_t *p, double v)
{
    (void)ctx;
    return fz_set(&fz_fields[p - fz_params], v);
}

#define FZ_P(k)                                                                                    \
    {                                                                                              \
        {NULL, NULL, "machine data (re-initialises)", false, -1e15, 1e15}, fz_get_p, fz_set_p      \
    }
/* m.p: any int (the core decides which pole pairs it takes). */
#define FZ_P_INT(k)                                                                                \
    {                                                                                              \
        {NULL, NULL, "pole pairs (re-initialises)", false, -2147483648.0, 2147483647.0}, fz_get_p, \
            fz_set_p                                                                               \
    }
static fw_link_param_t fz_params[FZ_N_FIELDS] = {FZ_P_INT(0), FZ_P(1),  FZ_P(2), FZ_P(3), FZ_P(4),
                                                 FZ_P(5),     FZ_P(6),  FZ_P(7), FZ_P(8), FZ_P(9),
                                                 FZ_P(10),    FZ_P(11), FZ_P(12)};

/* ---- invariants ---- */

static void fz_check_safe(void)
{
    const fw_state_id_t s = fw_state(&fz.run.fw);
    if (s != FW_STATE_RUNNING && s != FW_STATE_COMMISSION) {
        FZ_CHECK(!hal_sim_gates_on(&fz.run.hal));
    }
}

static void fz_check_config(void)
{
    const fw_t *fw = &fz.run.fw;
    FZ_CHECK(fw->ctrl != NULL);
    const ctrl_bases_t *b = &fw->bases;
    FZ_CHECK(isfinite(b->torque_nm) && b->torque_nm > 0.0);
    FZ_CHECK(isfinite(b->w_rad_s) && b->w_rad_s > 0.0);
    FZ_CHECK(fw->torque_ref_max > 0);
    if (fz.last_reconf != 0) {
        /* the accepted data, or the previous ones after a refusal */
        FZ_CHECK(fw->machine_own.pole_pairs == fz.machine.pole_pairs);
        FZ_CHECK(memcmp(&fw->machine_own.rs_ohm, &fz.machine.rs_ohm, sizeof(double)) == 0);
        FZ_CHECK(memcmp(&fw->machine_own.psi_ref_wb, &fz.machine.psi_ref_wb, sizeof(double)) == 0);
    }
}

/* The line as typed (no editing bytes) starts with prefix. */
static int fz_line_is(const char *prefix)
{
    for (const char *p = fz.line; *p != '\0'; p++) {
        if ((unsigned char)*p < 0x20u || (unsigned char)*p > 0x7Eu) {
            return 0;
        }
    }
    return strncmp(fz.line, prefix, strlen(prefix)) == 0;
}

/* One complete response to the line just sent (after the echo's CR LF). */
static void fz_check_response(void)
{
    const char *r = fz.resp;
    while (*r == '\r' || *r == '\n') {
        r++;
    }
    if (*r == '\0') {
        return; /* an empty line */
    }
    FZ_CHECK(strncmp(r, "ok", 2) == 0 || strncmp(r, "err ", 4) == 0);
    const int set = fz_line_is("param set ") || fz_line_is("ref ");
    if (strncmp(r, "err 4 ", 6) == 0 && set) {
        /* the value and its quantity are on the line; the range here */
        FZ_CHECK((strstr(r, "[") != NULL && strstr(r, "]") != NULL) ||
                 strstr(r, " limits ") != NULL);
    }
    if (strncmp(r, "err 10 ", 7) == 0 && (fz_line_is("param set ") || fz_line_is("ctrl select "))) {
        FZ_CHECK((strstr(r, " = ") != NULL && strstr(r, " outside [") != NULL) ||
                 strstr(r, " missing") != NULL);
    }
    if (strncmp(r, "err ", 4) == 0) {
        fz_check_safe();
    }
    if (fz.last_reconf == -1) {
        FZ_CHECK(strncmp(r, "err 10 ", 7) == 0);
    }
    if (fz.last_reconf == 1) {
        FZ_CHECK(strncmp(r, "ok", 2) == 0);
    }
}

static void fz_periods(unsigned n, unsigned *budget)
{
    for (unsigned k = 0; k<n && * budget> 0u; k++, (*budget)--) {
        FZ_CHECK(sim_run_period(&fz.run) == 0);
        fw_link_poll(&fz.link);
        fz_check_safe();
    }
}

/* ---- libFuzzer ---- */

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    char err[512];
    for (size_t i = 0; i < FZ_MACHINES; i++) {
        if (sim_machine_load(fz_machine_files[i], &fz_machines[i], err, sizeof err) != 0) {
            fprintf(stderr, "fuzz_link: %s\n", err);
            abort();
        }
    }
    fz_n_ctrl = ctrl_count();
    fz_snap = calloc(FZ_MACHINES * fz_n_ctrl, sizeof *fz_snap);
    FZ_CHECK(fz_snap != NULL);
    for (size_t i = 0; i < FZ_MACHINES; i++) {
        for (size_t k = 0; k < fz_n_ctrl; k++) {
            const sim_machine_t *m = &fz_machines[i];
            sim_run_cfg_t c;
            sim_run_config_default(&c, m, ctrl_at(k));
            /* Dynamometer at rest: with the gates off and no current the
             * plant skips its (RK4) diode-conduction steps. */
            c.speed_rpm = 0.0;
            /* The plant's exact linear path (no dead time, no device drop):
             * the firmware's configuration is what is fuzzed, and the RK4
             * sub-steps would cost 100 evaluations per period. */
            c.plant_machine.dead_time_s = 0.0;
            c.plant_machine.v_fwd_v = 0.0;
            c.calib_samples = 16u;
            c.auto_arm = false;
            c.duration_s = 100.0;
            c.win_start_s = 99.0; /* no metrics: nothing allocated per input */
            c.win_end_s = 100.0;
            if (sim_run_init(&fz.run, &c, err, sizeof err) != 0) {
                fprintf(stderr, "fuzz_link: %s on %s: %s\n", ctrl_at(k)->name, m->name, err);
                abort();
            }
            fz_snap[i * fz_n_ctrl + k] = fz.run;
        }
    }
    for (size_t j = 0; j < FZ_N_FIELDS; j++) {
        fz_params[j].info.name = fz_fields[j].name;
        fz_params[j].info.unit = fz_fields[j].unit;
    }
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 2u) {
        return 0;
    }
    const size_t mi = data[0] % FZ_MACHINES;
    const size_t ci = data[1] % fz_n_ctrl;
    fz.run = fz_snap[mi * fz_n_ctrl + ci];
    fz.machine = fz.run.fw.machine_own;
    fz.machine.name = fz.run.cfg.ctrl_machine.name;
    fz.last_reconf = 0;
    fw_link_init(&fz.link, &fz.run.fw, fz_write, NULL);
    fw_link_set_params(&fz.link, fz_params, FZ_N_FIELDS, NULL);
    const unsigned per_line = 1u + (unsigned)(data[0] >> 4) % 4u;
    unsigned budget = FZ_PERIODS_MAX;
    fz.line_len = 0u;
    fz.resp_len = 0u;
    fz.resp[0] = '\0';
    if (data[1] & 0x80u) {
        /* start running */
        fw_cmd_arm(&fz.run.fw);
        fz_periods(2u, &budget);
    }
    for (size_t i = 2; i < size; i++) {
        const uint8_t b = data[i];
        if (b == '\r' || b == '\n') {
            fz.line[fz.line_len] = '\0';
            fz.resp_len = 0u;
            fz.resp[0] = '\0';
            fz.last_reconf = 0;
            fw_link_rx(&fz.link, b);
            fz_check_config();
            fz_check_response();
            fz.line_len = 0u;
            fz_periods(per_line, &budget);
        } else {
            if (fz.line_len < CMD_LINE_MAX) {
                fz.line[fz.line_len++] = (char)b;
            }
            fw_link_rx(&fz.link, b);
        }
    }
    return 0;
}
