/*
 * Line-oriented command interpreter (see cmd.h and PROTOCOL.md). Every
 * command is parsed and checked completely before the one state-changing op
 * it may call; a rejected line leaves the firmware untouched.
 */
#include "cmd.h"

#include <string.h>

#include "cmd_num.h"
#include "help_text.h"
#include "telemetry.h"

#define CMD_SIG_DIGITS 7u /* significant digits of printed values */

typedef struct {
    const char *s;
    size_t len;
} cmd_tok_t;

/* Reason word of each error code, in the "err <code> <reason>" line. */
static const char *const cmd_reasons[CMD_E_COUNT] = {
    "ok",   "unknown", "args",  "number", "range",    "name",        "long",
    "char", "state",   "fault", "failed", "readonly", "unsupported", "lost",
};

/* ---- output: one line at a time, printable only, truncated to CMD_OUT_MAX ---- */

static void cmd_out_reset(cmd_t *c)
{
    c->out_len = 0;
}

static void cmd_out_char(cmd_t *c, char ch)
{
    /* keep room for "\r\n"; anything non-printable becomes '?' so a response
     * never contains 0x00 (telemetry delimiter) nor a line break */
    if (c->out_len + 2u < CMD_OUT_MAX) {
        c->out[c->out_len++] = (ch >= 0x20 && ch <= 0x7E) ? ch : '?';
    }
}

static void cmd_out_str(cmd_t *c, const char *s)
{
    if (s == NULL) {
        s = "?";
    }
    for (; *s != '\0'; s++) {
        cmd_out_char(c, *s);
    }
}

static void cmd_out_tok(cmd_t *c, cmd_tok_t t)
{
    for (size_t i = 0; i < t.len; i++) {
        cmd_out_char(c, t.s[i]);
    }
}

static void cmd_out_u32(cmd_t *c, uint32_t v)
{
    char d[10];
    unsigned n = 0;
    do {
        d[n++] = (char)('0' + (int)(v % 10u));
        v /= 10u;
    } while (v != 0u);
    while (n > 0u) {
        cmd_out_char(c, d[--n]);
    }
}

static void cmd_out_hex32(cmd_t *c, uint32_t v)
{
    static const char hex[] = "0123456789abcdef";
    cmd_out_str(c, "0x");
    for (int sh = 28; sh >= 0; sh -= 4) {
        cmd_out_char(c, hex[(v >> (unsigned)sh) & 0xFu]);
    }
}

static void cmd_out_num(cmd_t *c, double v)
{
    char b[32];
    if (cmd_num_format(b, sizeof b, v, CMD_SIG_DIGITS) == 0) {
        cmd_out_str(c, "?");
    } else {
        cmd_out_str(c, b);
    }
}

static void cmd_out_flush(cmd_t *c)
{
    c->out[c->out_len++] = '\r';
    c->out[c->out_len++] = '\n';
    if (c->ops != NULL && c->ops->write != NULL) {
        c->ops->write(c->ctx, c->out, c->out_len);
    }
    c->out_len = 0;
}

/* "err <code> <reason>[ <detail>]" */
/* "err <code> <reason>", the line left open for a detail. */
static void cmd_err_begin(cmd_t *c, int code)
{
    if (code <= 0 || code >= (int)CMD_E_COUNT) {
        code = CMD_E_FAILED;
    }
    cmd_out_reset(c);
    cmd_out_str(c, "err ");
    cmd_out_u32(c, (uint32_t)code);
    cmd_out_char(c, ' ');
    cmd_out_str(c, cmd_reasons[code]);
}

static void cmd_err(cmd_t *c, int code, const char *detail)
{
    cmd_err_begin(c, code);
    if (detail != NULL) {
        cmd_out_char(c, ' ');
        cmd_out_str(c, detail);
    }
    cmd_out_flush(c);
}

/* "ok <n>": header of a list of n continuation lines. */
static void cmd_ok_list(cmd_t *c, uint32_t n)
{
    cmd_out_reset(c);
    cmd_out_str(c, "ok ");
    cmd_out_u32(c, n);
    cmd_out_flush(c);
}

/* Start a line "ok ..." (caller appends and flushes). */
static void cmd_ok_begin(cmd_t *c)
{
    cmd_out_reset(c);
    cmd_out_str(c, "ok");
}

/* Start a continuation line of a list. */
static void cmd_item_begin(cmd_t *c)
{
    cmd_out_reset(c);
    cmd_out_str(c, "  ");
}

/* ---- helpers ---- */

static bool cmd_tok_is(cmd_tok_t t, const char *word)
{
    const size_t n = strlen(word);
    return t.len == n && memcmp(t.s, word, n) == 0;
}

static bool cmd_str_eq_tok(const char *s, cmd_tok_t t)
{
    return s != NULL && strlen(s) == t.len && memcmp(s, t.s, t.len) == 0;
}

/* Status with safe defaults for anything the firmware leaves unset. */
static bool cmd_status(cmd_t *c, cmd_status_t *st)
{
    memset(st, 0, sizeof *st);
    st->state = "?";
    st->ctrl = "?";
    st->fault_name = "none";
    if (c->ops->get_status == NULL) {
        return false;
    }
    c->ops->get_status(c->ctx, st);
    return true;
}

/* Result of a state-changing op: true when it succeeded (an error was sent otherwise). */
static bool cmd_op_ok(cmd_t *c, int rc)
{
    if (rc == CMD_OK) {
        return true;
    }
    const int code = (rc > 0 && rc < (int)CMD_E_COUNT) ? rc : CMD_E_FAILED;
    const char *detail = NULL;
    if (code == CMD_E_FAILED && c->ops->failed_detail != NULL) {
        detail = c->ops->failed_detail(c->ctx);
    } else if (code == CMD_E_STATE && c->ops->state_detail != NULL) {
        detail = c->ops->state_detail(c->ctx);
    }
    cmd_err(c, code, detail);
    return false;
}

/* Parse a number token; sends the error and returns false when malformed/out of limits. */
static bool cmd_number(cmd_t *c, cmd_tok_t t, double *v)
{
    cmd_num_t n;
    const cmd_num_status_t st = cmd_num_parse(t.s, t.len, &n);
    if (st == CMD_NUM_SYNTAX) {
        cmd_err(c, CMD_E_NUMBER, NULL);
        return false;
    }
    if (st == CMD_NUM_RANGE) {
        cmd_err(c, CMD_E_RANGE, "limits 1e-15..1e15, 18 digits");
        return false;
    }
    *v = cmd_num_to_double(&n);
    return true;
}

/* "err 4 range [min, max]", with ", whole numbers" when set (the value was
 * inside the range and refused for its fraction). */
static void cmd_err_range_of(cmd_t *c, double lo, double hi, bool whole)
{
    cmd_out_reset(c);
    cmd_out_str(c, "err ");
    cmd_out_u32(c, CMD_E_RANGE);
    cmd_out_str(c, " range [");
    cmd_out_num(c, lo);
    cmd_out_str(c, ", ");
    cmd_out_num(c, hi);
    cmd_out_char(c, ']');
    if (whole) {
        cmd_out_str(c, ", whole numbers");
    }
    cmd_out_flush(c);
}

static void cmd_err_range(cmd_t *c, double lo, double hi)
{
    cmd_err_range_of(c, lo, hi, false);
}

/* Find a parameter by name through the iterator. */
static bool cmd_param_find(cmd_t *c, cmd_tok_t name, cmd_param_info_t *info)
{
    if (c->ops->param_at == NULL) {
        return false;
    }
    for (size_t i = 0; c->ops->param_at(c->ctx, i, info); i++) {
        if (cmd_str_eq_tok(info->name, name)) {
            return true;
        }
    }
    return false;
}

/* ---- commands ---- */

/* Syntax and what it does; the description is help text (help_text.h: left
 * to the PC's documentation, PROTOCOL.md, where the image leaves it out). */
static const struct {
    const char *syntax;
    const char *text;
} cmd_help_lines[] = {
    {"help", HELP_TEXT("this list")},
    {"status", HELP_TEXT("drive state, controller, fault, speed, torque")},
    {"arm | disarm | stop", HELP_TEXT("enable / disable the gates (stop: any activity)")},
    {"ctrl list | ctrl select NAME", HELP_TEXT("controllers (select only when disarmed)")},
    {"ref torque NM | ref speed RPM", HELP_TEXT("set the reference (and the control mode)")},
    {"param list | param get NAME | param set NAME VALUE", NULL},
    {"fault | fault clear", HELP_TEXT("latched fault; clear when disarmed")},
    {"tel list | tel stop", HELP_TEXT("telemetry signals / stop streaming")},
    {"tel start SIG... [every N]", HELP_TEXT("stream signals (or 'all') every Nth period")},
    {"echo on | echo off", HELP_TEXT("echo typed characters")},
    {"ident run | resume | step NAME", HELP_TEXT("motor identification (ident status)")},
    {"ident status | result | ini | apply", HELP_TEXT("progress, values, machine file")},
    {"bringup NAME | bringup status", HELP_TEXT("bench checks: vbus gates sense encoder run")},
    {"config save | show | erase | default", HELP_TEXT("settings kept in flash")},
#if CTRL_COGGING
    {"ident cogging | cogging on | off | status", HELP_TEXT("anti-cogging table, feed-forward")},
#endif
};

static void cmd_help(cmd_t *c)
{
    const size_t n = sizeof cmd_help_lines / sizeof cmd_help_lines[0];
    cmd_ok_list(c, (uint32_t)n);
    for (size_t i = 0; i < n; i++) {
        cmd_item_begin(c);
        cmd_out_str(c, cmd_help_lines[i].syntax);
        if (cmd_help_lines[i].text != NULL) {
            /* the descriptions in one column, at least two spaces after the syntax */
            do {
                cmd_out_char(c, ' ');
            } while (c->out_len < 32u || c->out[c->out_len - 2u] != ' ');
            cmd_out_str(c, cmd_help_lines[i].text);
        }
        cmd_out_flush(c);
    }
}

/* One "key=value" item of a list reply. */
static void cmd_item_str(cmd_t *c, const char *key, const char *value)
{
    cmd_item_begin(c);
    cmd_out_str(c, key);
    cmd_out_str(c, value);
    cmd_out_flush(c);
}

static void cmd_item_num(cmd_t *c, const char *key, double value)
{
    cmd_item_begin(c);
    cmd_out_str(c, key);
    cmd_out_num(c, value);
    cmd_out_flush(c);
}

static void cmd_status_cmd(cmd_t *c)
{
    cmd_status_t st;
    if (!cmd_status(c, &st)) {
        cmd_err(c, CMD_E_UNSUPPORTED, NULL);
        return;
    }
    cmd_ok_list(c, st.stack_size != 0u ? 11u : 10u);
    cmd_item_str(c, "state=", st.state);
    cmd_item_str(c, "armed=", st.armed ? "1" : "0");
    cmd_item_str(c, "ctrl=", st.ctrl);
    cmd_item_begin(c);
    cmd_out_str(c, "fault=");
    cmd_out_u32(c, st.fault);
    cmd_out_char(c, ' ');
    cmd_out_str(c, st.fault == 0u ? "none" : st.fault_name);
    cmd_out_flush(c);
    cmd_item_str(c, "mode=", st.mode == CMD_MODE_SPEED ? "speed" : "torque");
    cmd_item_num(c, "speed_rpm=", st.speed_rpm);
    cmd_item_num(c, "torque_nm=", st.torque_nm);
    cmd_item_num(c, "speed_ref_rpm=", st.speed_ref_rpm);
    cmd_item_num(c, "torque_ref_nm=", st.torque_ref_nm);
    cmd_item_begin(c);
    cmd_out_str(c, "tel_mask=");
    cmd_out_hex32(c, st.tel_mask);
    cmd_out_str(c, " every=");
    cmd_out_u32(c, st.tel_every);
    cmd_out_flush(c);
    if (st.stack_size != 0u) {
        cmd_item_begin(c);
        cmd_out_str(c, "stack_used=");
        cmd_out_u32(c, st.stack_used);
        cmd_out_str(c, " size=");
        cmd_out_u32(c, st.stack_size);
        cmd_out_flush(c);
    }
}

static void cmd_ctrl(cmd_t *c, const cmd_tok_t *tok, size_t n)
{
    if (n >= 2 && cmd_tok_is(tok[1], "list")) {
        if (n != 2) {
            cmd_err(c, CMD_E_ARGS, "ctrl list");
            return;
        }
        if (c->ops->ctrl_at == NULL) {
            cmd_err(c, CMD_E_UNSUPPORTED, NULL);
            return;
        }
        cmd_status_t st;
        (void)cmd_status(c, &st);
        const char *name;
        const char *title;
        uint32_t count = 0;
        while (c->ops->ctrl_at(c->ctx, count, &name, &title) && count < 1000u) {
            count++;
        }
        cmd_ok_list(c, count);
        for (uint32_t i = 0; i < count; i++) {
            name = NULL;
            title = NULL;
            (void)c->ops->ctrl_at(c->ctx, i, &name, &title);
            const bool sel = (name != NULL && st.ctrl != NULL && strcmp(name, st.ctrl) == 0);
            cmd_item_begin(c);
            cmd_out_str(c, sel ? "* " : "- ");
            cmd_out_str(c, name);
            cmd_out_char(c, ' ');
            cmd_out_str(c, title == NULL ? "" : title);
            cmd_out_flush(c);
        }
        return;
    }
    if (n >= 2 && cmd_tok_is(tok[1], "select")) {
        if (n != 3) {
            cmd_err(c, CMD_E_ARGS, "ctrl select NAME");
            return;
        }
        if (c->ops->ctrl_at == NULL || c->ops->select_controller == NULL) {
            cmd_err(c, CMD_E_UNSUPPORTED, NULL);
            return;
        }
        bool found = false;
        const char *name = NULL;
        const char *title = NULL;
        for (size_t i = 0; i < 1000u && c->ops->ctrl_at(c->ctx, i, &name, &title); i++) {
            if (cmd_str_eq_tok(name, tok[2])) {
                found = true;
                break;
            }
        }
        if (!found) {
            /* by name: an image holds the controllers its preset lists
             * (PMSM_CONTROLLERS), not every one of the core */
            cmd_err_begin(c, CMD_E_NAME);
            cmd_out_char(c, ' ');
            cmd_out_tok(c, tok[2]);
            cmd_out_str(c, ": not in this image");
            cmd_out_flush(c);
            return;
        }
        cmd_status_t st;
        if (!cmd_status(c, &st)) {
            cmd_err(c, CMD_E_UNSUPPORTED, NULL);
            return;
        }
        if (st.armed) {
            cmd_err(c, CMD_E_STATE, "disarm first");
            return;
        }
        /* tok[2] is NUL-terminated by the tokenizer */
        if (cmd_op_ok(c, c->ops->select_controller(c->ctx, tok[2].s))) {
            cmd_ok_begin(c);
            cmd_out_str(c, " ctrl ");
            cmd_out_tok(c, tok[2]);
            cmd_out_flush(c);
        }
        return;
    }
    cmd_err(c, CMD_E_ARGS, "ctrl list | ctrl select NAME");
}

static void cmd_arm(cmd_t *c, size_t n)
{
    if (n != 1) {
        cmd_err(c, CMD_E_ARGS, "arm");
        return;
    }
    cmd_status_t st;
    if (c->ops->arm == NULL || !cmd_status(c, &st)) {
        cmd_err(c, CMD_E_UNSUPPORTED, NULL);
        return;
    }
    if (st.fault != 0u) {
        cmd_err(c, CMD_E_FAULT, st.fault_name);
        return;
    }
    if (st.armed || cmd_op_ok(c, c->ops->arm(c->ctx))) {
        cmd_ok_begin(c);
        cmd_out_str(c, " armed");
        cmd_out_flush(c);
    }
}

/* A command without arguments that runs one operation: "<name>" -> "ok <done>". */
static void cmd_run_op(cmd_t *c, size_t n, const char *name, int (*op)(void *ctx), const char *done)
{
    if (n != 1) {
        cmd_err(c, CMD_E_ARGS, name);
        return;
    }
    if (op == NULL) {
        cmd_err(c, CMD_E_UNSUPPORTED, NULL);
        return;
    }
    if (cmd_op_ok(c, op(c->ctx))) {
        cmd_ok_begin(c);
        cmd_out_str(c, done);
        cmd_out_flush(c);
    }
}

static void cmd_disarm(cmd_t *c, size_t n)
{
    cmd_run_op(c, n, "disarm", c->ops->disarm, " disarmed");
}

static void cmd_ref(cmd_t *c, const cmd_tok_t *tok, size_t n)
{
    const bool torque = (n >= 2 && cmd_tok_is(tok[1], "torque"));
    const bool speed = (n >= 2 && cmd_tok_is(tok[1], "speed"));
    if (n != 3 || (!torque && !speed)) {
        cmd_err(c, CMD_E_ARGS, "ref torque NM | ref speed RPM");
        return;
    }
    if ((torque && c->ops->set_torque_ref == NULL) || (speed && c->ops->set_speed_ref == NULL)) {
        cmd_err(c, CMD_E_UNSUPPORTED, NULL);
        return;
    }
    double v;
    if (!cmd_number(c, tok[2], &v)) {
        return;
    }
    cmd_status_t st;
    if (!cmd_status(c, &st)) {
        cmd_err(c, CMD_E_UNSUPPORTED, NULL);
        return;
    }
    const double lim = torque ? st.torque_max_nm : st.speed_max_rpm;
    if (!(v >= -lim && v <= lim)) { /* also rejects a NaN limit */
        cmd_err_range(c, -lim, lim);
        return;
    }
    const int rc = torque ? c->ops->set_torque_ref(c->ctx, v) : c->ops->set_speed_ref(c->ctx, v);
    if (cmd_op_ok(c, rc)) {
        cmd_ok_begin(c);
        cmd_out_str(c, torque ? " ref torque " : " ref speed ");
        cmd_out_num(c, v);
        cmd_out_flush(c);
    }
}

static void cmd_param_line(cmd_t *c, const cmd_param_info_t *info)
{
    double v = 0.0;
    cmd_item_begin(c);
    cmd_out_str(c, info->name);
    cmd_out_char(c, ' ');
    if (c->ops->param_get != NULL && c->ops->param_get(c->ctx, info->name, &v) == CMD_OK) {
        cmd_out_num(c, v);
    } else {
        cmd_out_char(c, '?');
    }
    cmd_out_char(c, ' ');
    cmd_out_str(c, (info->unit == NULL || info->unit[0] == '\0') ? "-" : info->unit);
    cmd_out_str(c, " [");
    cmd_out_num(c, info->min);
    cmd_out_str(c, ", ");
    cmd_out_num(c, info->max);
    cmd_out_str(c, info->access == CMD_PARAM_RO     ? "] ro "
                   : info->access == CMD_PARAM_LIVE ? "] live "
                                                    : "] ");
    cmd_out_str(c, info->help == NULL ? "" : info->help);
    cmd_out_flush(c);
}

static void cmd_param(cmd_t *c, const cmd_tok_t *tok, size_t n)
{
    cmd_param_info_t info;
    if (c->ops->param_at == NULL || c->ops->param_get == NULL) {
        cmd_err(c, CMD_E_UNSUPPORTED, NULL);
        return;
    }
    if (n == 2 && cmd_tok_is(tok[1], "list")) {
        uint32_t count = 0;
        while (count < 1000u && c->ops->param_at(c->ctx, count, &info)) {
            count++;
        }
        cmd_ok_list(c, count);
        for (uint32_t i = 0; i < count; i++) {
            memset(&info, 0, sizeof info);
            (void)c->ops->param_at(c->ctx, i, &info);
            cmd_param_line(c, &info);
        }
        return;
    }
    if (n == 3 && cmd_tok_is(tok[1], "get")) {
        double v = 0.0;
        if (!cmd_param_find(c, tok[2], &info)) {
            cmd_err(c, CMD_E_NAME, "see param list");
            return;
        }
        const int rc = c->ops->param_get(c->ctx, info.name, &v);
        if (cmd_op_ok(c, rc)) {
            cmd_ok_begin(c);
            cmd_out_char(c, ' ');
            cmd_out_str(c, info.name);
            cmd_out_char(c, ' ');
            cmd_out_num(c, v);
            cmd_out_char(c, ' ');
            cmd_out_str(c, (info.unit == NULL || info.unit[0] == '\0') ? "-" : info.unit);
            cmd_out_flush(c);
        }
        return;
    }
    if (n == 4 && cmd_tok_is(tok[1], "set")) {
        double v;
        if (c->ops->param_set == NULL) {
            cmd_err(c, CMD_E_UNSUPPORTED, NULL);
            return;
        }
        if (!cmd_param_find(c, tok[2], &info)) {
            cmd_err(c, CMD_E_NAME, "see param list");
            return;
        }
        if (info.access == CMD_PARAM_RO) {
            cmd_err(c, CMD_E_READONLY, NULL);
            return;
        }
        if (!cmd_number(c, tok[3], &v)) {
            return;
        }
        if (!(v >= info.min && v <= info.max)) {
            cmd_err_range(c, info.min, info.max);
            return;
        }
        const int rc = c->ops->param_set(c->ctx, info.name, v);
        if (rc == CMD_E_RANGE) {
            /* Inside [min, max] and still refused (a switch given 0.5, a
             * count given a fraction): the range again, and what else the
             * value lacks where the parser can tell. */
            cmd_err_range_of(c, info.min, info.max, v != (double)(int64_t)v); /* |v| <= 1e15 */
            return;
        }
        if (cmd_op_ok(c, rc)) {
            cmd_ok_begin(c);
            cmd_out_char(c, ' ');
            cmd_out_str(c, info.name);
            cmd_out_char(c, ' ');
            cmd_out_num(c, v);
            cmd_out_flush(c);
        }
        return;
    }
    cmd_err(c, CMD_E_ARGS, "param list | param get NAME | param set NAME VALUE");
}

static void cmd_fault(cmd_t *c, const cmd_tok_t *tok, size_t n)
{
    cmd_status_t st;
    const bool clear = (n == 2 && cmd_tok_is(tok[1], "clear"));
    if (n != 1 && !clear) {
        cmd_err(c, CMD_E_ARGS, "fault | fault clear");
        return;
    }
    if (!cmd_status(c, &st) || (clear && c->ops->clear_fault == NULL)) {
        cmd_err(c, CMD_E_UNSUPPORTED, NULL);
        return;
    }
    if (clear && st.fault != 0u) {
        if (st.armed) {
            cmd_err(c, CMD_E_STATE, "disarm first");
            return;
        }
        if (!cmd_op_ok(c, c->ops->clear_fault(c->ctx))) {
            return;
        }
        (void)cmd_status(c, &st);
    }
    cmd_ok_begin(c);
    cmd_out_str(c, " fault ");
    cmd_out_u32(c, st.fault);
    cmd_out_char(c, ' ');
    cmd_out_str(c, st.fault == 0u ? "none" : st.fault_name);
    cmd_out_flush(c);
}

static void cmd_tel(cmd_t *c, const cmd_tok_t *tok, size_t n)
{
    if (n == 2 && cmd_tok_is(tok[1], "list")) {
        cmd_ok_list(c, (uint32_t)TEL_SIG_COUNT);
        for (size_t i = 0; i < (size_t)TEL_SIG_COUNT; i++) {
            const tel_signal_t *s = tel_signal_at(i);
            cmd_item_begin(c);
            cmd_out_u32(c, (uint32_t)i);
            cmd_out_char(c, ' ');
            cmd_out_str(c, s->name);
            cmd_out_char(c, ' ');
            cmd_out_str(c, s->unit[0] == '\0' ? "-" : s->unit);
            cmd_out_char(c, ' ');
            cmd_out_str(c, s->help == NULL ? "" : s->help);
            cmd_out_flush(c);
        }
        return;
    }
    if (n == 2 && cmd_tok_is(tok[1], "stop")) {
        if (c->ops->telemetry_stop == NULL) {
            cmd_err(c, CMD_E_UNSUPPORTED, NULL);
            return;
        }
        if (cmd_op_ok(c, c->ops->telemetry_stop(c->ctx))) {
            cmd_ok_begin(c);
            cmd_out_str(c, " tel stopped");
            cmd_out_flush(c);
        }
        return;
    }
    if (n >= 2 && cmd_tok_is(tok[1], "start")) {
        size_t last = n; /* one past the last signal token */
        uint32_t every = 1;
        if (c->ops->telemetry_start == NULL) {
            cmd_err(c, CMD_E_UNSUPPORTED, NULL);
            return;
        }
        if (n >= 4 && cmd_tok_is(tok[n - 2u], "every")) {
            const cmd_num_status_t st = cmd_num_parse_u32(tok[n - 1u].s, tok[n - 1u].len, &every);
            if (st == CMD_NUM_SYNTAX) {
                cmd_err(c, CMD_E_NUMBER, "every N: digits");
                return;
            }
            if (st != CMD_NUM_OK || every < 1u || every > TEL_EVERY_MAX) {
                cmd_err_range(c, 1.0, (double)TEL_EVERY_MAX);
                return;
            }
            last = n - 2u;
        }
        if (last < 3u) {
            cmd_err(c, CMD_E_ARGS, "tel start SIG... [every N]");
            return;
        }
        uint32_t mask = 0;
        for (size_t i = 2; i < last; i++) {
            if (cmd_tok_is(tok[i], "all")) {
                mask |= TEL_MASK_ALL;
                continue;
            }
            const int k = tel_signal_find(tok[i].s, tok[i].len);
            if (k < 0) {
                cmd_out_reset(c);
                cmd_out_str(c, "err ");
                cmd_out_u32(c, CMD_E_NAME);
                cmd_out_str(c, " name ");
                cmd_out_tok(c, tok[i]);
                cmd_out_flush(c);
                return;
            }
            mask |= (uint32_t)1u << (unsigned)k;
        }
        if (cmd_op_ok(c, c->ops->telemetry_start(c->ctx, mask, every))) {
            cmd_ok_begin(c);
            cmd_out_str(c, " tel mask=");
            cmd_out_hex32(c, mask);
            cmd_out_str(c, " every=");
            cmd_out_u32(c, every);
            cmd_out_str(c, " bytes=");
            cmd_out_u32(c, (uint32_t)tel_wire_size(mask));
            cmd_out_flush(c);
        }
        return;
    }
    cmd_err(c, CMD_E_ARGS, "tel list | tel start SIG... [every N] | tel stop");
}

static void cmd_echo(cmd_t *c, const cmd_tok_t *tok, size_t n)
{
    const bool on = (n == 2 && cmd_tok_is(tok[1], "on"));
    const bool off = (n == 2 && cmd_tok_is(tok[1], "off"));
    if (!on && !off) {
        cmd_err(c, CMD_E_ARGS, "echo on | echo off");
        return;
    }
    cmd_ok_begin(c);
    cmd_out_str(c, on ? " echo on" : " echo off");
    cmd_out_flush(c);
    c->echo = on; /* after the response: the mode applies from the next byte */
}

/* ---- commissioning ---- */

/* The step named tok if it is of `kind` (CMD_CM_*), else NULL. */
static const char *cmd_cm_find(cmd_t *c, cmd_tok_t tok, unsigned kind)
{
    const char *name = NULL;
    unsigned k = 0u;
    for (size_t i = 0; i < 64u && c->ops->cm_step_at(c->ctx, i, &name, &k); i++) {
        if (cmd_str_eq_tok(name, tok)) {
            return (k & kind) != 0u ? name : NULL;
        }
    }
    return NULL;
}

/* "ok <verdict> step=<s> [error=<e>] [<label>=<value>[<unit>]]..."; "ok idle
 * step=none" for `kind` (CMD_CM_*) when the last start was the other kind's
 * (a page polling both shows the one that runs). */
static void cmd_cm_status_line(cmd_t *c, unsigned kind)
{
    cmd_cm_status_t st;
    memset(&st, 0, sizeof st);
    st.verdict = "idle";
    st.step = "none";
    st.error = "none";
    if (c->cm_kind == 0u || c->cm_kind == kind) {
        c->ops->cm_status(c->ctx, &st);
    }
    cmd_ok_begin(c);
    cmd_out_char(c, ' ');
    cmd_out_str(c, st.verdict);
    cmd_out_str(c, " step=");
    cmd_out_str(c, st.step);
    if (st.error != NULL && strcmp(st.error, "none") != 0) {
        cmd_out_str(c, " error=");
        cmd_out_str(c, st.error);
    }
    for (size_t k = 0; k < st.n && k < 3u; k++) {
        cmd_out_char(c, ' ');
        cmd_out_str(c, st.label[k]);
        cmd_out_char(c, '=');
        cmd_out_num(c, st.value[k]);
        if (st.unit[k] != NULL && st.unit[k][0] != '\0') {
            cmd_out_str(c, st.unit[k]);
        }
    }
    cmd_out_flush(c);
}

/* Start `what` (validated); "ok <word> <what>" or the op's error. */
static void cmd_cm_start(cmd_t *c, const char *word, const char *what)
{
    cmd_status_t st;
    if (!cmd_status(c, &st)) {
        cmd_err(c, CMD_E_UNSUPPORTED, NULL);
        return;
    }
    if (st.fault != 0u) {
        cmd_err(c, CMD_E_FAULT, st.fault_name);
        return;
    }
    if (st.armed) {
        cmd_err(c, CMD_E_STATE, "disarm first");
        return;
    }
    const char *detail = NULL;
    const int rc = c->ops->cm_start(c->ctx, what, &detail);
    if (rc != CMD_OK) {
        cmd_err(c, (rc > 0 && rc < (int)CMD_E_COUNT) ? rc : CMD_E_FAILED, detail);
        return;
    }
    c->cm_kind = (uint8_t)(word[0] == 'i' ? CMD_CM_IDENT : CMD_CM_BRINGUP);
    cmd_ok_begin(c);
    cmd_out_char(c, ' ');
    cmd_out_str(c, word);
    cmd_out_char(c, ' ');
    cmd_out_str(c, what);
    if (detail != NULL) {
        cmd_out_char(c, ' ');
        cmd_out_str(c, detail);
    }
    cmd_out_flush(c);
}

/* Lines of the machine-file fragment: "[section]" whenever it changes. */
static uint32_t cmd_cm_ini(cmd_t *c, bool print)
{
    cmd_cm_item_t it;
    const char *sec = NULL;
    uint32_t n = 0;
    for (size_t i = 0; i < 64u && c->ops->cm_ini_at(c->ctx, i, &it); i++) {
        if (sec == NULL || strcmp(sec, it.section) != 0) {
            sec = it.section;
            n++;
            if (print) {
                cmd_item_begin(c);
                cmd_out_char(c, '[');
                cmd_out_str(c, sec);
                cmd_out_char(c, ']');
                cmd_out_flush(c);
            }
        }
        n++;
        if (print) {
            cmd_item_begin(c);
            cmd_out_str(c, it.key);
            cmd_out_str(c, " = ");
            if (it.integer) {
                const double a = it.value < 0.0 ? -it.value : it.value;
                if (it.value < 0.0) {
                    cmd_out_char(c, '-');
                }
                cmd_out_u32(c, (uint32_t)(a + 0.5));
            } else {
                cmd_out_num(c, it.value);
            }
            cmd_out_flush(c);
        }
    }
    return n;
}

static void cmd_ident(cmd_t *c, const cmd_tok_t *tok, size_t n)
{
    static const char usage[] = "ident run|resume|step NAME|status|result|ini|apply";
    if (c->ops->cm_step_at == NULL || c->ops->cm_status == NULL || c->ops->cm_start == NULL ||
        c->ops->cm_result_at == NULL || c->ops->cm_ini_at == NULL || c->ops->cm_apply == NULL) {
        cmd_err(c, CMD_E_UNSUPPORTED, NULL);
        return;
    }
    if (n == 2 && (cmd_tok_is(tok[1], "run") || cmd_tok_is(tok[1], "resume"))) {
        cmd_cm_start(c, "ident", cmd_tok_is(tok[1], "run") ? "run" : "resume");
        return;
    }
    if (n == 3 && cmd_tok_is(tok[1], "step")) {
        const char *name = cmd_cm_find(c, tok[2], CMD_CM_IDENT);
        if (name == NULL) {
            cmd_err(c, CMD_E_NAME, "vbus probe encoder rs ldq flux");
            return;
        }
        cmd_cm_start(c, "ident", name);
        return;
    }
    if (n == 2 && cmd_tok_is(tok[1], "status")) {
        cmd_cm_status_line(c, CMD_CM_IDENT);
        return;
    }
#if CTRL_COGGING
    if (n == 2 && cmd_tok_is(tok[1], "cogging")) {
        cmd_cm_start(c, "ident", "cogging"); /* = ident step cogging */
        return;
    }
#endif
    if (n == 2 && cmd_tok_is(tok[1], "result")) {
        const char *key = NULL;
        const char *unit = NULL;
        double v = 0.0;
        uint32_t count = 0;
        while (count < 64u && c->ops->cm_result_at(c->ctx, count, &key, &v, &unit)) {
            count++;
        }
        cmd_ok_list(c, count);
        for (uint32_t i = 0; i < count; i++) {
            key = unit = NULL;
            (void)c->ops->cm_result_at(c->ctx, i, &key, &v, &unit);
            cmd_item_begin(c);
            cmd_out_str(c, key);
            cmd_out_char(c, ' ');
            cmd_out_num(c, v);
            cmd_out_char(c, ' ');
            cmd_out_str(c, (unit == NULL || unit[0] == '\0') ? "-" : unit);
            cmd_out_flush(c);
        }
        return;
    }
    if (n == 2 && cmd_tok_is(tok[1], "ini")) {
        cmd_ok_list(c, cmd_cm_ini(c, false));
        (void)cmd_cm_ini(c, true);
        return;
    }
    if (n == 2 && cmd_tok_is(tok[1], "apply")) {
        cmd_status_t st;
        if (!cmd_status(c, &st)) {
            cmd_err(c, CMD_E_UNSUPPORTED, NULL);
            return;
        }
        if (st.armed) {
            cmd_err(c, CMD_E_STATE, "disarm first");
            return;
        }
        if (cmd_op_ok(c, c->ops->cm_apply(c->ctx))) {
            cmd_ok_begin(c);
            cmd_out_str(c, " ident applied");
            cmd_out_flush(c);
        }
        return;
    }
    cmd_err(c, CMD_E_ARGS, usage);
}

#if CTRL_COGGING
/* "cogging on | off | status": the anti-cogging feed-forward. */
static void cmd_cogging(cmd_t *c, const cmd_tok_t *tok, size_t n)
{
    if (c->ops->cogging == NULL) {
        cmd_err(c, CMD_E_UNSUPPORTED, NULL);
        return;
    }
    const char *what = n == 2 && cmd_tok_is(tok[1], "on")       ? "on"
                       : n == 2 && cmd_tok_is(tok[1], "off")    ? "off"
                       : n == 2 && cmd_tok_is(tok[1], "status") ? "status"
                                                                : NULL;
    if (what == NULL) {
        cmd_err(c, CMD_E_ARGS, "cogging on|off|status");
        return;
    }
    const char *detail = NULL;
    const int rc = c->ops->cogging(c->ctx, what, &detail);
    if (rc != CMD_OK) {
        cmd_err(c, rc, detail);
        return;
    }
    cmd_ok_begin(c);
    cmd_out_str(c, " cogging ");
    cmd_out_str(c, detail != NULL ? detail : what);
    cmd_out_flush(c);
}
#endif

static void cmd_bringup(cmd_t *c, const cmd_tok_t *tok, size_t n)
{
    if (c->ops->cm_step_at == NULL || c->ops->cm_status == NULL || c->ops->cm_start == NULL) {
        cmd_err(c, CMD_E_UNSUPPORTED, NULL);
        return;
    }
    if (n != 2) {
        cmd_err(c, CMD_E_ARGS, "bringup vbus|gates|sense|encoder|run|status");
        return;
    }
    if (cmd_tok_is(tok[1], "status")) {
        cmd_cm_status_line(c, CMD_CM_BRINGUP);
        return;
    }
    const char *name = cmd_cm_find(c, tok[1], CMD_CM_BRINGUP);
    if (name == NULL) {
        cmd_err(c, CMD_E_NAME, "vbus gates sense encoder run");
        return;
    }
    cmd_cm_start(c, "bringup", name);
}

/* "config save|show|erase|default": the settings record in flash. The op
 * refuses each with the gates on or about to go on (a flash page erase
 * stalls the CPU for tens of ms; an ECC error in a read takes the NMI, which
 * turns the gates off), saying why. */
static void cmd_config(cmd_t *c, const cmd_tok_t *tok, size_t n)
{
    static const char usage[] = "config save|show|erase|default";
    if (c->ops->config == NULL || c->ops->config_item_at == NULL) {
        cmd_err(c, CMD_E_UNSUPPORTED, NULL);
        return;
    }
    if (n != 2) {
        cmd_err(c, CMD_E_ARGS, usage);
        return;
    }
    const char *what = NULL;
    if (cmd_tok_is(tok[1], "save")) {
        what = "save";
    } else if (cmd_tok_is(tok[1], "erase")) {
        what = "erase";
    } else if (cmd_tok_is(tok[1], "default")) {
        what = "default";
    } else if (cmd_tok_is(tok[1], "show")) {
        what = "read";
    } else {
        cmd_err(c, CMD_E_ARGS, usage);
        return;
    }
    const char *detail = NULL;
    const int rc = c->ops->config(c->ctx, what, &detail);
    if (rc != CMD_OK) {
        cmd_err(c, rc, detail);
        return;
    }
    if (what[0] != 'r') {
        cmd_ok_begin(c);
        if (detail != NULL) {
            cmd_out_char(c, ' ');
            cmd_out_str(c, detail);
        }
        cmd_out_flush(c);
        return;
    }
    cmd_config_item_t it;
    uint32_t count = 0;
    while (count < 256u && c->ops->config_item_at(c->ctx, count, &it)) {
        count++;
    }
    cmd_ok_list(c, count);
    for (uint32_t i = 0; i < count; i++) {
        memset(&it, 0, sizeof it);
        (void)c->ops->config_item_at(c->ctx, i, &it);
        cmd_item_begin(c);
        cmd_out_str(c, it.key);
        cmd_out_char(c, '=');
        if (it.text != NULL) {
            cmd_out_str(c, it.text);
        } else {
            cmd_out_num(c, it.num);
        }
        cmd_out_flush(c);
    }
}

static void cmd_stop(cmd_t *c, size_t n)
{
    cmd_run_op(c, n, "stop", c->ops->stop, " stopped");
}

/* ---- line handling ---- */

void cmd_init(cmd_t *c, const cmd_ops_t *ops, void *ctx)
{
    if (c == NULL) {
        return;
    }
    memset(c, 0, sizeof *c);
    c->ops = ops;
    c->ctx = ctx;
}

void cmd_execute(cmd_t *c, const char *line, size_t len)
{
    char work[CMD_LINE_MAX + 1];
    cmd_tok_t tok[CMD_MAX_TOKENS];
    size_t n = 0;
    if (c == NULL || c->ops == NULL || line == NULL) {
        return;
    }
    if (len > CMD_LINE_MAX) {
        cmd_err(c, CMD_E_LONG, NULL);
        return;
    }
    for (size_t i = 0; i < len; i++) {
        const char ch = line[i];
        if (ch == '\t') {
            work[i] = ' ';
        } else if (ch < 0x20 || ch > 0x7E) {
            cmd_err(c, CMD_E_CHAR, NULL);
            return;
        } else {
            work[i] = ch;
        }
    }
    work[len] = '\0';
    /* split on spaces, NUL-terminating each token in place */
    size_t i = 0;
    while (i < len) {
        while (i < len && work[i] == ' ') {
            i++;
        }
        if (i >= len) {
            break;
        }
        if (n >= CMD_MAX_TOKENS) {
            cmd_err(c, CMD_E_ARGS, "too many words");
            return;
        }
        tok[n].s = &work[i];
        while (i < len && work[i] != ' ') {
            i++;
        }
        tok[n].len = (size_t)(&work[i] - tok[n].s);
        work[i] = '\0'; /* i == len writes the terminator already there */
        n++;
        i++;
    }
    if (n == 0 || tok[0].s[0] == '#') {
        return; /* empty line or comment: no response */
    }
    if (cmd_tok_is(tok[0], "help")) {
        if (n != 1) {
            cmd_err(c, CMD_E_ARGS, "help");
        } else {
            cmd_help(c);
        }
    } else if (cmd_tok_is(tok[0], "status")) {
        if (n != 1) {
            cmd_err(c, CMD_E_ARGS, "status");
        } else {
            cmd_status_cmd(c);
        }
    } else if (cmd_tok_is(tok[0], "ctrl")) {
        cmd_ctrl(c, tok, n);
    } else if (cmd_tok_is(tok[0], "arm")) {
        cmd_arm(c, n);
    } else if (cmd_tok_is(tok[0], "disarm")) {
        cmd_disarm(c, n);
    } else if (cmd_tok_is(tok[0], "ref")) {
        cmd_ref(c, tok, n);
    } else if (cmd_tok_is(tok[0], "param")) {
        cmd_param(c, tok, n);
    } else if (cmd_tok_is(tok[0], "fault")) {
        cmd_fault(c, tok, n);
    } else if (cmd_tok_is(tok[0], "tel")) {
        cmd_tel(c, tok, n);
    } else if (cmd_tok_is(tok[0], "echo")) {
        cmd_echo(c, tok, n);
    } else if (cmd_tok_is(tok[0], "ident")) {
        cmd_ident(c, tok, n);
    } else if (cmd_tok_is(tok[0], "bringup")) {
        cmd_bringup(c, tok, n);
    } else if (cmd_tok_is(tok[0], "stop")) {
        cmd_stop(c, n);
    } else if (cmd_tok_is(tok[0], "config")) {
        cmd_config(c, tok, n);
#if CTRL_COGGING
    } else if (cmd_tok_is(tok[0], "cogging")) {
        cmd_cogging(c, tok, n);
#endif
    } else {
        cmd_err(c, CMD_E_UNKNOWN, "try help");
    }
}

static void cmd_echo_out(cmd_t *c, const char *s, size_t n)
{
    if (c->echo && c->ops != NULL && c->ops->write != NULL) {
        c->ops->write(c->ctx, s, n);
    }
}

bool cmd_feed_byte(cmd_t *c, uint8_t byte)
{
    if (c == NULL) {
        return false;
    }
    if (byte == '\r' || byte == '\n') {
        const bool had = (c->len != 0u || c->overflow || c->bad_char || c->lost != NULL);
        if (had) {
            cmd_echo_out(c, "\r\n", 2);
        }
        if (c->lost != NULL) {
            cmd_err(c, CMD_E_LOST, c->lost);
        } else if (c->overflow) {
            cmd_err(c, CMD_E_LONG, NULL);
        } else if (c->bad_char) {
            cmd_err(c, CMD_E_CHAR, NULL);
        } else if (c->len != 0u) {
            cmd_execute(c, c->line, c->len);
        }
        c->len = 0;
        c->overflow = false;
        c->bad_char = false;
        c->lost = NULL;
        c->line[0] = '\0';
        return had;
    }
    if (c->lost != NULL) {
        return false; /* a line with a hole: nothing of it counts */
    }
    if (byte == 0x08u || byte == 0x7Fu) {
        /* erase one character; a discarded line stays discarded */
        if (c->len > 0u && !c->overflow && !c->bad_char) {
            c->len--;
            c->line[c->len] = '\0';
            cmd_echo_out(c, "\b \b", 3);
        }
        return false;
    }
    if (c->overflow || c->bad_char) {
        return false;
    }
    if (byte != '\t' && (byte < 0x20u || byte > 0x7Eu)) {
        c->bad_char = true;
        return false;
    }
    if (c->len >= CMD_LINE_MAX) {
        c->overflow = true;
        return false;
    }
    c->line[c->len++] = (char)byte;
    c->line[c->len] = '\0';
    const char ch = (byte == '\t') ? ' ' : (char)byte; /* echo printable only */
    cmd_echo_out(c, &ch, 1);
    return false;
}

void cmd_line_lost(cmd_t *c, const char *why)
{
    if (c != NULL && c->lost == NULL) {
        c->lost = why != NULL ? why : "on reception";
    }
}
