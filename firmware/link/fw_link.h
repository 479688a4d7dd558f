/*
 * The firmware side of the serial link: connects the command interpreter
 * (cmd.h) to the pipeline (cmd_ops_t implemented on fw_t) and
 * feeds the telemetry producer (telemetry.h) from the pipeline's per-period
 * sample.
 *
 * Contexts: everything runs in the main loop (fw_link_rx: command
 * execution; fw_link_poll: telemetry samples from the interrupt's record ring,
 * fw_tm_peek, and the byte output); the interrupt only writes its records
 * (pipeline.h). The command ops run in the main loop: they only request
 * state changes (fw_cmd_*), and the configuration ops (controller selection,
 * tunables) are refused while the drive is running.
 */
#ifndef FIRMWARE_FW_LINK_H
#define FIRMWARE_FW_LINK_H

#include <stddef.h>
#include <stdint.h>

#include "cmd.h"
#include "fw_settings.h"
#include "pipeline.h"
#include "telemetry.h"

typedef void (*fw_link_write_fn)(void *ctx, const uint8_t *bytes, size_t len);

/* A parameter of the application (machine data, board values), listed by
 * "param list" after the controller's tunables and reached by "param get/set"
 * (PROTOCOL.md: "the firmware's own parameters"). Names must not collide with
 * tunables (use a prefix such as "m." or "b."). get/set return CMD_OK or a
 * cmd_err_t code; set is NULL when info.access is CMD_PARAM_RO. They run in the
 * main loop. */
typedef struct fw_link_param fw_link_param_t;
struct fw_link_param {
    cmd_param_info_t info;
    /* p: this entry; its place in the application's table says which value
     * (one function for many entries) */
    int (*get)(void *ctx, const fw_link_param_t *p, double *value);
    int (*set)(void *ctx, const fw_link_param_t *p, double value);
};

/* Tables of the firmware's configuration as parameters (fw_params.h). */
typedef struct fw_params_table fw_params_table_t;
#define FW_LINK_TABLES 2u

typedef struct fw_link fw_link_t;
struct fw_link {
    fw_t *fw;
    cmd_t cmd;
    tel_t tel;
    uint8_t send_meta;
    double speed_max_rpm;       /* |speed reference| limit (fw_speed_info_t: the rated speed) */
    char cm_detail[48];         /* detail of the last refused commissioning start */
    char state_text[80];        /* detail of the last "err 8 state" (op_state_detail) */
    char cm_note[80];           /* what "bringup sense" says when it starts (the offsets) */
    ctrl_diag_t why;            /* why the core refused the last configuration op (CTRL_OK: none) */
    char why_text[CMD_OUT_MAX]; /* its "err 10 failed" detail */
    fw_link_write_fn write;
    void *write_ctx;
    const fw_link_param_t *params; /* application parameters (fw_link_set_params) */
    size_t n_params;
    void *params_ctx;
    /* "config" commands (fw_link_set_settings in fw_settings.c), NULL: unsupported */
    fw_settings_t *settings;
    int (*settings_cmd)(fw_settings_t *st, fw_t *fw, const char *what, const char **detail);
    bool (*settings_item)(const fw_settings_t *st, size_t index, cmd_config_item_t *it);
    /* Why the board holds its gates off for good (a failed start-up: its
     * gate driver did not answer, the clock fell back), NULL: not held.
     * "arm", "ident ..." and "bringup ..." are then refused with it as the
     * detail of "err 8 state" (fw_link_set_hold). */
    const char *hold;
    /* The firmware's configuration as parameters (fw_params_attach; listed
     * after the tunables, before params): its tables and their ops, which
     * answer CMD_E_NAME for a name not theirs. */
    const fw_params_table_t *tables[FW_LINK_TABLES];
    size_t n_table_params;
    bool (*table_at)(const fw_link_t *l, size_t index, cmd_param_info_t *info);
    int (*table_get)(const fw_link_t *l, const char *name, double *value);
    int (*table_set)(fw_link_t *l, const char *name, double value);
    bool state_note; /* state_text is the detail of the err 8 just returned (op_param_set) */
    bool why_note;   /* why_text is the detail of the err 10 just returned */
    const uint32_t *stack_lo, *stack_hi; /* the painted main stack (fw_link_set_stack) */
};

void fw_link_init(fw_link_t *l, fw_t *fw, fw_link_write_fn write, void *write_ctx);
/* Application parameters (after fw_link_init; the table must outlive the link). */
void fw_link_set_params(fw_link_t *l, const fw_link_param_t *params, size_t n, void *ctx);
/* The settings store behind "config save|show|erase|default" (after
 * fw_link_init; it must outlive the link; NULL detaches it). In
 * fw_settings.c, so that an image without settings does not link them. */
void fw_link_set_settings(fw_link_t *l, fw_settings_t *st);
/* The board holds its gates off for good, for the reason `why` (a sentence
 * that outlives the link), or no longer (NULL). */
static inline void fw_link_set_hold(fw_link_t *l, const char *why)
{
    l->hold = why;
}
/* The main stack [lo, hi), painted at start-up (fw_stack.h): "status" then
 * gives its high-water mark (stack_used=<bytes> size=<bytes>). */
void fw_link_set_stack(fw_link_t *l, const uint32_t *lo, const uint32_t *hi);
/* For an application parameter's set (main loop) that fails because the core
 * refused the configuration: the reason (fw_t.why before the application
 * restores its previous data), sent as the detail of "err 10 failed". */
void fw_link_set_why(fw_link_t *l, const ctrl_diag_t *why);
/* The same as text (cut at the line's end). */
void fw_link_set_why_text(fw_link_t *l, const char *why);
/* "current offsets a b c counts, expected zero +- tol": the phase-current
 * offsets the calibration measured (Q8 counts, rounded to counts) and the
 * window it judges them by (hal_info_t). snprintf's result. */
int fw_link_offsets_text(const fw_t *fw, char *buf, size_t cap);
/* Main loop: one received byte. True when it ended a command line, which
 * has been answered: a main loop feeds the bytes up to there, then serves
 * its watchdogs before the next line (a queue of commands, each up to a
 * flash page erase long, would otherwise run back to back past them). */
bool fw_link_rx(fw_link_t *l, uint8_t byte);
/* Main loop: META frame after "tel start", then a sample frame for each
 * record the interrupt published (fw_tm_stream). */
void fw_link_poll(fw_link_t *l);

#endif /* FIRMWARE_FW_LINK_H */
