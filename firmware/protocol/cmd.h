/*
 * Line-oriented ASCII command interpreter (PROTOCOL.md, "Commands").
 *
 * Bytes arrive one at a time (cmd_feed_byte, from the UART receive path in the
 * main loop). A line ends with CR or LF; an empty line (e.g. the LF of a CRLF)
 * is ignored. Backspace (0x08) and DEL (0x7F) erase the last character. A line
 * longer than CMD_LINE_MAX characters, or containing a byte outside
 * 0x20..0x7E (TAB counts as a space), is discarded entirely and answered with
 * an error; so is a line some of whose bytes the receiver lost (cmd_line_lost:
 * an overrun, a framing error), answered at its end of line. Every response to a line starts with
 * "ok" or "err <code> <reason>"; list responses are "ok <n>" followed by exactly n lines starting
 * with two spaces. Lines end with "\r\n" and never exceed CMD_OUT_MAX bytes; no response byte is
 * ever 0x00 (the telemetry frame delimiter).
 *
 * The interpreter reaches the firmware only through cmd_ops_t (implemented by
 * the firmware pipeline, a mock in the tests). A command is validated
 * completely (syntax, names, number ranges, state preconditions read with the
 * read-only ops) before any state-changing op is called; a rejected line
 * calls no state-changing op.
 *
 * No heap, no globals: all state is in cmd_t.
 */
#ifndef FIRMWARE_CMD_H
#define FIRMWARE_CMD_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define CMD_LINE_MAX 96 /* characters of one command line, terminator excluded */
#define CMD_OUT_MAX 120 /* bytes of one response line including "\r\n" */
#define CMD_MAX_TOKENS 24

/* Error codes of "err <code> <reason>" (also returned by the ops). */
typedef enum {
    CMD_OK = 0,
    CMD_E_UNKNOWN = 1,      /* unknown command */
    CMD_E_ARGS = 2,         /* missing or extra arguments */
    CMD_E_NUMBER = 3,       /* malformed number */
    CMD_E_RANGE = 4,        /* number out of range */
    CMD_E_NAME = 5,         /* unknown controller, parameter or signal */
    CMD_E_LONG = 6,         /* line longer than CMD_LINE_MAX */
    CMD_E_CHAR = 7,         /* byte outside 0x20..0x7E in the line */
    CMD_E_STATE = 8,        /* not allowed in the current state (e.g. armed) */
    CMD_E_FAULT = 9,        /* a fault is latched */
    CMD_E_FAILED = 10,      /* the firmware refused or failed */
    CMD_E_READONLY = 11,    /* parameter is read-only */
    CMD_E_UNSUPPORTED = 12, /* the firmware does not implement this op */
    CMD_E_LOST = 13,        /* bytes of the line were lost on reception */
    CMD_E_COUNT
} cmd_err_t;

typedef enum { CMD_MODE_TORQUE = 0, CMD_MODE_SPEED = 1 } cmd_mode_t;

/* Snapshot of the drive for "status", "fault" and for precondition checks. */
typedef struct {
    const char *state;      /* state name, e.g. "ready", "running", "fault" */
    bool armed;             /* gates enabled / controller in the loop */
    const char *ctrl;       /* selected controller name */
    uint32_t fault;         /* latched fault code, 0 = none */
    const char *fault_name; /* e.g. "overcurrent"; "none" when fault == 0 */
    cmd_mode_t mode;        /* which reference drives the loop */
    double speed_rpm;       /* measured mechanical speed */
    double torque_nm;       /* estimated torque */
    double torque_ref_nm;   /* active torque reference */
    double speed_ref_rpm;   /* active speed reference */
    double torque_max_nm;   /* |ref torque| limit accepted by "ref torque" (> 0) */
    double speed_max_rpm;   /* |ref speed| limit accepted by "ref speed" (> 0) */
    uint32_t tel_mask;      /* telemetry signal mask, 0 = stopped */
    uint32_t tel_every;     /* telemetry decimation */
    /* main stack: reserved bytes (0: not measured, the items are left out)
     * and the high-water mark since reset (fw_stack.h) */
    uint32_t stack_size, stack_used;
} cmd_status_t;

/* When a parameter can be written (cmd_param_info_t.access). */
typedef enum {
    CMD_PARAM_RW = 0,  /* with the gates off (the firmware refuses it while running: err 8) */
    CMD_PARAM_RO = 1,  /* never: read-only (err 11) */
    CMD_PARAM_LIVE = 2 /* also while the drive runs (listed with " live") */
} cmd_param_access_t;

/* One parameter as listed by the firmware (controller tunable or firmware parameter). */
typedef struct {
    const char *name; /* printable, no spaces, e.g. "h_T" */
    const char *unit; /* e.g. "N*m", "" when dimensionless */
    const char *help; /* one line (truncated in listings) */
    uint8_t access;   /* cmd_param_access_t; here, not last: the doubles then need no padding */
    double min, max;  /* accepted range (inclusive), checked before param_set */
} cmd_param_info_t;

#define CMD_CM_IDENT 1u   /* an identification step */
#define CMD_CM_BRINGUP 2u /* a bench bring-up check */

/* Commissioning status for "ident status" / "bringup status" (cm.h). */
typedef struct {
    const char *verdict; /* "idle", "running", "pass", "fail", "stopped" */
    const char *step;    /* step concerned ("vbus", ...) */
    const char *error;   /* error name ("none" on a pass) */
    size_t n;            /* labelled numbers */
    const char *label[3];
    double value[3];
    const char *unit[3];
} cmd_cm_status_t;

/* One item of the identified machine-file fragment ("ident ini"). */
typedef struct {
    const char *section, *key;
    double value;
    bool integer;
} cmd_cm_item_t;

/* One line of "config show": key and value (text, or a number when text is NULL). */
typedef struct {
    const char *key;
    const char *text;
    double num;
} cmd_config_item_t;

/*
 * The firmware behind the interpreter. Every function receives the context
 * pointer given to cmd_init. State-changing ops return CMD_OK or a cmd_err_t
 * code (anything else is reported as CMD_E_FAILED) and must leave the state
 * unchanged when they fail. A NULL op answers "err 12 unsupported".
 * Values are SI: N*m, r/min (mechanical), and the parameter's own unit.
 * Name arguments point into the interpreter's buffers and are valid only
 * during the call (copy them if needed).
 */
typedef struct {
    /* output of one complete response line (bytes, no NUL) */
    void (*write)(void *ctx, const char *text, size_t len);
    /* read-only */
    void (*get_status)(void *ctx, cmd_status_t *st);
    bool (*ctrl_at)(void *ctx, size_t index, const char **name, const char **title);
    bool (*param_at)(void *ctx, size_t index, cmd_param_info_t *info);
    int (*param_get)(void *ctx, const char *name, double *value);
    /* state-changing */
    int (*select_controller)(void *ctx, const char *name);
    int (*arm)(void *ctx);
    int (*disarm)(void *ctx);
    int (*set_torque_ref)(void *ctx, double nm);
    int (*set_speed_ref)(void *ctx, double rpm);
    int (*param_set)(void *ctx, const char *name, double value);
    int (*clear_fault)(void *ctx);
    /* telemetry: mask of TEL_SIG_* bits (telemetry.h), send every Nth sample */
    int (*telemetry_start)(void *ctx, uint32_t mask, uint32_t decimation);
    int (*telemetry_stop)(void *ctx);
    /* commissioning (PROTOCOL.md "Commissioning"); appended */
    /* read-only: step names in order (vbus, probe, ...), false past the end;
     * *kind: CMD_CM_IDENT ("ident step NAME") and/or CMD_CM_BRINGUP
     * ("bringup NAME") */
    bool (*cm_step_at)(void *ctx, size_t index, const char **name, unsigned *kind);
    void (*cm_status)(void *ctx, cmd_cm_status_t *st);
    /* identified values in SI ("ident result"), false past the end */
    bool (*cm_result_at)(void *ctx, size_t index, const char **key, double *value,
                         const char **unit);
    bool (*cm_ini_at)(void *ctx, size_t index, cmd_cm_item_t *item);
    /* state-changing: what = "run" (the whole identification), "resume" (its
     * first step without a result onward) or a step name. On CMD_E_STATE the
     * op may set *detail (e.g. "needs encoder"); on CMD_OK too (a note
     * appended to "ok bringup NAME"); it stays valid until the next op
     * call. */
    int (*cm_start)(void *ctx, const char *what, const char **detail);
    int (*cm_apply)(void *ctx);
    /* gates off now: ends commissioning or running */
    int (*stop)(void *ctx);
    /* optional: why the op that just returned CMD_E_FAILED failed (e.g. the
     * quantity the control core refused, its value and its range), or NULL;
     * appended to "err 10 failed" (cut at the line's end). Appended. */
    const char *(*failed_detail)(void *ctx);
    /* settings in flash (PROTOCOL.md "Settings"); appended. what: "save",
     * "erase", "default" (state-changing) or "read" (the stored record, for
     * config_item_at). *detail: what was done, or why not (valid until the
     * next op call). */
    int (*config)(void *ctx, const char *what, const char **detail);
    /* read-only: the record last read, line by line; false past the end */
    bool (*config_item_at)(void *ctx, size_t index, cmd_config_item_t *it);
    /* optional: the state an op that just returned CMD_E_STATE was refused
     * in ("in commission", "arm pending (ready)"), appended to "err 8 state".
     * Appended. */
    const char *(*state_detail)(void *ctx);
    /* optional: the anti-cogging feed-forward (docs/anticogging.md); what:
     * "on", "off" (state-changing) or "status". *detail: "on", "off" or
     * "none" (no table) on CMD_OK, why not on a refusal. Appended. */
    int (*cogging)(void *ctx, const char *what, const char **detail);
} cmd_ops_t;

typedef struct {
    const cmd_ops_t *ops;
    void *ctx;
    char line[CMD_LINE_MAX + 1]; /* current input line, NUL-terminated */
    size_t len;
    bool overflow;             /* the current line exceeded CMD_LINE_MAX */
    bool bad_char;             /* the current line contained a rejected byte */
    const char *lost;          /* why bytes of the current line were lost (NULL: none) */
    bool echo;                 /* echo input (for terminals without local echo) */
    uint8_t cm_kind;           /* CMD_CM_IDENT or _BRINGUP: what the last start began (0: none
                                  since reset); the other's status answers idle */
    char out[CMD_OUT_MAX + 1]; /* response line being built */
    size_t out_len;
} cmd_t;

void cmd_init(cmd_t *c, const cmd_ops_t *ops, void *ctx);

/* Feed one received byte; a complete line is executed immediately. Returns
 * true when the byte ended a line that was answered (executed or refused):
 * the main loop serves its watchdogs then, before the next line. */
bool cmd_feed_byte(cmd_t *c, uint8_t byte);

/* The receiver lost bytes before the next one fed (an overrun while the
 * core stalled, a framing error): the line being assembled is discarded up
 * to its end of line, which is answered "err 13 lost <why>" (why: a
 * sentence that outlives the line; the first loss of a line is named). */
void cmd_line_lost(cmd_t *c, const char *why);

/* Execute one line (without terminator; len <= CMD_LINE_MAX, printable
 * characters only). Used by cmd_feed_byte; exposed for scripted use. */
void cmd_execute(cmd_t *c, const char *line, size_t len);

#endif /* FIRMWARE_CMD_H */
