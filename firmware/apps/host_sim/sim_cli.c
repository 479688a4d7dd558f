/*
 * Host simulator CLI (./tools/sim): closed loop of plant + HAL sim + firmware,
 * or open-loop replay of a switching sequence. `sim --help` lists the options.
 *
 * Adding an option: one row of k_opts (name, kind, allowed range and unit,
 * mode, needs/excludes, help with its default) and, when it needs more than
 * its row says, one rule in cli_check. Every value is validated before the
 * run starts; an error names the option, the value and the allowed range and
 * exits with SIM_EXIT_USAGE. Clamps and inputs that do not act as written are
 * warnings (stderr and the metrics JSON).
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "controller.h"
#include "sim_diag.h"
#include "sim_ident.h"
#include "sim_num.h"
#include "sim_pil.h"
#include "sim_replay.h"
#include "sim_run.h"

/* Exit status (documented in --help and docs/simulator.md). */
enum {
    SIM_EXIT_OK = 0,    /* the run completed, the drive did not fault */
    SIM_EXIT_RUN = 1,   /* the run could not complete (plant failure, I/O error) */
    SIM_EXIT_USAGE = 2, /* invalid input: nothing was simulated */
    SIM_EXIT_FAULT = 3  /* the drive faulted (tripped); metrics and trace up to the fault */
};

typedef enum { K_FLAG, K_REAL, K_UINT, K_TEXT, K_SPAN, K_SET, K_ABC } cli_kind_t;
/* Which kind of run an option belongs to. */
typedef enum { M_ANY, M_LOOP, M_REPLAY, M_INFO, M_IDENT } cli_mode_t;
/* Closed-loop options that also apply to --identify. */
static const char *const k_ident_loop_opts[] = {
    "--control-machine", "--controller",       "--seed",
    "--metrics",         "--trace-decimation", "--load-passive-nm"};

typedef struct {
    double start, end;
} cli_span_t;

/* One value per phase (K_ABC: "A,B,C", each in the option's range). */
typedef struct {
    double v[3];
} cli_abc_t;

/* Parsed values (one field per option, kind by k_opts). */
typedef struct {
    const char *machine, *control_machine, *controller, *scenario, *trace, *metrics, *replay;
    const char *list_tunables, *current_sense;
    const char *identify_out, *identify_steps, *inject;
    const char *target, *pil_image, *pil_transport;
    double link_timeout_ms, baud;
    int identify;
    double fs, speed_rpm, load_nm, load_passive_nm, torque_ref, speed_ref, duration, seed;
    double decim, theta0, id0, iq0;
    double speed_bw, speed_pm, speed_kp, speed_ki, overspeed, tq_follow_fault;
    double comp_dead_time_ns;
    cli_abc_t current_gain_err;
    cli_span_t window, trace_window;
    int free_mech, help, list_controllers, continue_on_fault, no_psi_adapt, no_dead_comp,
        sensorless, hfi;
    sim_set_t sets[SIM_MAX_SETS];
    size_t n_sets;
} cli_t;

typedef struct {
    const char *name, *metavar;
    cli_kind_t kind;
    double lo, hi;    /* K_REAL, K_UINT: allowed range (inclusive) */
    const char *unit; /* in messages */
    cli_mode_t mode;
    const char *needs;    /* another option that must be given with it, or NULL */
    const char *excludes; /* an option that must not be given with it, or NULL */
    size_t off;           /* field in cli_t */
    const char *help;     /* one line, with the default */
} cli_opt_t;

#define F(x) offsetof(cli_t, x)
static const cli_opt_t k_opts[] = {
    {"--machine", "FILE", K_TEXT, 0, 0, "", M_ANY, NULL, NULL, F(machine),
     "machine file (sim_host/machines/*.ini); required except for --list-*"},
    {"--controller", "NAME", K_TEXT, 0, 0, "", M_LOOP, NULL, NULL, F(controller),
     "controller from the registry (see --list-controllers); required"},
    {"--fs", "HZ", K_UINT, 1000, 200000, "Hz", M_LOOP, NULL, NULL, F(fs),
     "sampling/PWM frequency, whole Hz (default: the controller's)"},
    {"--control-machine", "FILE", K_TEXT, 0, 0, "", M_LOOP, NULL, NULL, F(control_machine),
     "configure the controller with another machine file (parameter mismatch)"},
    {"--speed-rpm", "R", K_REAL, -1e5, 1e5, "r/min", M_ANY, NULL, NULL, F(speed_rpm),
     "dynamometer: imposed speed; --free: initial speed; --replay: speed (default 0)"},
    {"--free", NULL, K_FLAG, 0, 0, "", M_LOOP, NULL, NULL, F(free_mech),
     "free mechanics (3.15) instead of the dynamometer"},
    {"--load-nm", "T", K_REAL, -1e5, 1e5, "N*m", M_LOOP, "--free", NULL, F(load_nm),
     "constant (active) load torque from arm on, instead of the machine file's (default: its "
     "[mechanics] load_kind = constant, else 0)"},
    {"--load-passive-nm", "T", K_REAL, 0, 1e5, "N*m", M_LOOP, "--free", NULL, F(load_passive_nm),
     "passive load of this magnitude: opposes the rotation, never drives it (default: the "
     "machine file's [mechanics] load_kind = passive, else 0)"},
    {"--torque-ref", "NM", K_REAL, -1e5, 1e5, "N*m", M_LOOP, NULL, "--speed-ref-rpm", F(torque_ref),
     "torque reference, torque mode (default 0)"},
    {"--speed-ref-rpm", "R", K_REAL, -1e5, 1e5, "r/min", M_LOOP, "--free", "--torque-ref",
     F(speed_ref), "speed reference: speed mode (outer PI), needs --free"},
    {"--speed-bw-hz", "HZ", K_REAL, 0.01, 1e4, "Hz", M_LOOP, NULL, "--speed-kp", F(speed_bw),
     "speed-loop bandwidth (crossover) of the sizing from the inertia (default: machine "
     "file, else firmware/isr/speed_loop.h)"},
    {"--speed-pm-deg", "DEG", K_REAL, 20, 80, "deg", M_LOOP, NULL, "--speed-kp", F(speed_pm),
     "speed-loop phase margin of the sizing (default: machine file, else 60)"},
    {"--speed-kp", "K", K_REAL, 1e-12, 1e9, "N*m*s/rad", M_LOOP, NULL, NULL, F(speed_kp),
     "explicit speed PI gain, per mechanical rad/s (instead of the sizing)"},
    {"--speed-ki", "K", K_REAL, 0, 1e12, "N*m/rad", M_LOOP, "--speed-kp", NULL, F(speed_ki),
     "explicit speed PI integral gain, per mechanical rad (default 0 with --speed-kp)"},
    {"--overspeed-rpm", "R", K_REAL, 1, 1e6, "r/min", M_LOOP, NULL, NULL, F(overspeed),
     "overspeed trip level (default: machine file, else 1.05 x its maximum speed)"},
    {"--torque-follow-fault", "N", K_UINT, 0, 1000, "windows", M_LOOP, NULL, NULL,
     F(tq_follow_fault),
     "fault after N consecutive 50 ms windows of the mean torque estimate off the applied "
     "reference by more than max(5 %, 2 % of rated) (default 0: telemetry warning only)"},
    {"--duration", "S", K_REAL, 1e-4, 100, "s", M_LOOP, NULL, NULL, F(duration),
     "simulated time after arm (default 0.3)"},
    {"--window", "START:END", K_SPAN, 0, 0, "s", M_LOOP, NULL, NULL, F(window),
     "metrics window (default duration/3 : duration)"},
    {"--scenario", "FILE", K_TEXT, 0, 0, "", M_LOOP, NULL, NULL, F(scenario),
     "time/speed-triggered steps (format: docs/simulator.md, sim_scenario.h)"},
    {"--seed", "N", K_UINT, 0, 9007199254740992.0, "", M_LOOP, NULL, NULL, F(seed),
     "ADC noise seed, integer (default 1)"},
    {"--trace", "FILE.csv", K_TEXT, 0, 0, "", M_ANY, NULL, NULL, F(trace),
     "closed loop: true signals on a Ts/10 grid; replay: the output trace"},
    {"--trace-decimation", "N", K_UINT, 1, 1e6, "", M_LOOP, "--trace", NULL, F(decim),
     "keep every N-th trace row (default 1)"},
    {"--trace-window", "START:END", K_SPAN, 0, 0, "s", M_LOOP, "--trace", NULL, F(trace_window),
     "write trace rows only in this time span (default: the whole run)"},
    {"--metrics", "FILE.json", K_TEXT, 0, 0, "", M_LOOP, NULL, NULL, F(metrics),
     "performance indices, settings and warnings (also printed to stdout)"},
    {"--set", "NAME=VALUE", K_SET, 0, 0, "", M_LOOP, NULL, NULL, F(sets),
     "controller tunable (repeatable; see --list-tunables NAME)"},
    {"--current-sense", "WHERE", K_TEXT, 0, 0, "", M_LOOP, NULL, NULL, F(current_sense),
     "inverter | motor: where the drive's current sensors sit, with a machine [filter] "
     "(default: the machine file's current_sense, else inverter)"},
    {"--no-psi-adapt", NULL, K_FLAG, 0, 0, "", M_LOOP, NULL, NULL, F(no_psi_adapt),
     "keep the configured psi_pm: no PM flux from the voltage model above 10 % of rated speed "
     "(docs/algorithms.md)"},
    {"--no-dead-comp", NULL, K_FLAG, 0, 0, "", M_LOOP, NULL, NULL, F(no_dead_comp),
     "no dead-time and device-drop compensation of the duties (the machine file's [inverter] "
     "dead_time_ns, v_fwd_v; docs/algorithms.md)"},
    {"--comp-dead-time-ns", "NS", K_REAL, 0, 1e5, "ns", M_LOOP, NULL, "--no-dead-comp",
     F(comp_dead_time_ns),
     "the dead time the firmware's compensation assumes (default: the machine file's, a "
     "perfectly known inverter; a production spread varies the file's and keeps this nominal)"},
    {"--current-gain-err", "A,B,C", K_ABC, -0.25, 0.25, "", M_LOOP, NULL, NULL, F(current_gain_err),
     "relative gain error of the current sensors of phases a, b, c: each reads (1 + g) i "
     "(default 0,0,0)"},
    {"--sensorless", NULL, K_FLAG, 0, 0, "", M_LOOP, NULL, NULL, F(sensorless),
     "no encoder: angle and speed from the stator-flux observer, forced-angle start-up "
     "(docs/algorithms.md, \"Sensorless start-up\")"},
    {"--hfi", NULL, K_FLAG, 0, 0, "", M_LOOP, "--sensorless", NULL, F(hfi),
     "with --sensorless: high-frequency injection at and near standstill, the observer above "
     "(salient machines; foc, m2ptfc, drr; settings --set hfi.NAME=V, --list-tunables hfi; "
     "docs/algorithms.md, \"High-frequency injection\")"},
    {"--continue-on-fault", NULL, K_FLAG, 0, 0, "", M_LOOP, NULL, NULL, F(continue_on_fault),
     "keep simulating after a fault (gates off) to the end; the exit status stays 3"},
    {"--list-controllers", NULL, K_FLAG, 0, 0, "", M_INFO, NULL, NULL, F(list_controllers),
     "print name, default fs and title of each controller"},
    {"--list-tunables", "NAME", K_TEXT, 0, 0, "", M_INFO, NULL, NULL, F(list_tunables),
     "print each tunable of a controller: unit, range, default (for --machine)"},
    {"--replay", "FILE.csv", K_TEXT, 0, 0, "", M_REPLAY, "--trace", NULL, F(replay),
     "open loop: replay a switching sequence (needs --speed-rpm and --trace)"},
    {"--theta0-elec", "RAD", K_REAL, -1000, 1000, "rad", M_ANY, NULL, NULL, F(theta0),
     "replay, identify: initial electrical rotor angle (default 0)"},
    {"--id0", "A", K_REAL, -1e5, 1e5, "A", M_REPLAY, "--replay", NULL, F(id0),
     "replay: initial d current (default 0)"},
    {"--iq0", "A", K_REAL, -1e5, 1e5, "A", M_REPLAY, "--replay", NULL, F(iq0),
     "replay: initial q current (default 0)"},
    {"--identify", NULL, K_FLAG, 0, 0, "", M_IDENT, NULL, NULL, F(identify),
     "run the firmware's identification (free rotor; of the machine file's [mechanics] the "
     "friction, cogging and passive load act, no active load): Rs, Ld, Lq, psi_pm, encoder; "
     "--metrics writes \"identified\" beside the truth"},
    {"--identify-out", "FILE.ini", K_TEXT, 0, 0, "", M_IDENT, "--identify", NULL, F(identify_out),
     "write the configured machine with the identified values"},
    {"--identify-steps", "A,B,..", K_TEXT, 0, 0, "", M_IDENT, "--identify", NULL, F(identify_steps),
     "only these steps: vbus probe encoder rs ldq flux gates sense run"},
    {"--inject", "CASE", K_TEXT, 0, 0, "", M_IDENT, "--identify", NULL, F(inject),
     "bad case: open (motor not connected), short (a-b leads), encoder_stuck, vbus_low"},
    {"--target", "WHERE", K_TEXT, 0, 0, "", M_LOOP, NULL, NULL, F(target),
     "host (default) | qemu | board:DEVICE: where the firmware runs; the plant stays here "
     "(processor in the loop, hal/qemu_mps2/README-pil.md)"},
    {"--pil-image", "FILE.elf", K_TEXT, 0, 0, "", M_LOOP, "--target", NULL, F(pil_image),
     "--target qemu: the target image (tools/sim builds and passes pil_target.elf)"},
    {"--pil-transport", "HOW", K_TEXT, 0, 0, "", M_LOOP, "--target", NULL, F(pil_transport),
     "--target qemu: semihosting (default, faster) | socket (UART0 on a chardev socket)"},
    {"--link-timeout-ms", "MS", K_UINT, 1, 600000, "ms", M_LOOP, "--target", NULL,
     F(link_timeout_ms),
     "PIL: a frame later than this is the link fault 'time-out' (default 2000)"},
    {"--baud", "N", K_UINT, 9600, 12000000, "baud", M_LOOP, "--target", NULL, F(baud),
     "--target board:DEVICE: serial rate (default 921600)"},
    {"--help", NULL, K_FLAG, 0, 0, "", M_INFO, NULL, NULL, F(help), "this text"},
};
#undef F
#define N_OPTS (sizeof k_opts / sizeof k_opts[0])

static const char *const k_help_tail =
    "exit status: 0 the run completed without a fault; 1 the run could not complete\n"
    "  (plant failure, I/O error, a link fault with --target); 2 invalid input,\n"
    "  nothing simulated; 3 the drive faulted (the run stops there unless\n"
    "  --continue-on-fault; metrics and trace are written up to it).\n"
    "Warnings (clamped references, events that never fire, ...) go to stderr and\n"
    "to the \"warnings\" list of the metrics JSON. Undefined indices print n/a\n"
    "(null in JSON).\n";

static int die(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static int die(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "sim: error: ");
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, "\n");
    va_end(ap);
    return SIM_EXIT_USAGE;
}

static void usage(FILE *f)
{
    fprintf(f, "usage: sim --machine FILE --controller NAME [options]     closed loop\n"
               "       sim --machine FILE --replay FILE.csv --speed-rpm R --trace FILE   "
               "open loop\n"
               "       sim --machine FILE --identify [--control-machine FILE] [--metrics F.json]"
               "   identification\n"
               "       sim --list-controllers | --list-tunables NAME [--machine FILE]\n"
               "options:\n");
    for (size_t i = 0; i < N_OPTS; i++) {
        const cli_opt_t *o = &k_opts[i];
        char lhs[48];
        (void)snprintf(lhs, sizeof lhs, "%s%s%s", o->name, o->metavar ? " " : "",
                       o->metavar ? o->metavar : "");
        fprintf(f, "  %-26s %s", lhs, o->help);
        if (o->kind == K_REAL || o->kind == K_UINT || o->kind == K_ABC) {
            if (o->hi < 1e15) {
                fprintf(f, " [%g, %g]%s%s", o->lo, o->hi, o->unit[0] ? " " : "", o->unit);
            }
        }
        fprintf(f, "\n");
    }
    fputs(k_help_tail, f);
}

static const cli_opt_t *opt_find(const char *name)
{
    for (size_t i = 0; i < N_OPTS; i++) {
        if (strcmp(k_opts[i].name, name) == 0) {
            return &k_opts[i];
        }
    }
    return NULL;
}

static int parse_value(const cli_opt_t *o, const char *v, cli_t *c)
{
    void *dst = (char *)c + o->off;
    switch (o->kind) {
    case K_TEXT:
        if (v[0] == '\0') {
            return die("%s expects %s, got an empty string", o->name, o->metavar);
        }
        *(const char **)dst = v;
        return 0;
    case K_REAL:
    case K_UINT: {
        double x;
        if (sim_num_parse(v, &x) != 0) {
            return die("%s expects a number in [%g, %g]%s%s, got '%s'", o->name, o->lo, o->hi,
                       o->unit[0] ? " " : "", o->unit, v);
        }
        if (o->kind == K_UINT && x != floor(x)) {
            return die("%s %s: must be a whole number%s%s (allowed range [%g, %g])", o->name, v,
                       o->unit[0] ? " of " : "", o->unit, o->lo, o->hi);
        }
        if (x < o->lo || x > o->hi) {
            return die("%s %s is out of range: allowed [%g, %g]%s%s", o->name, v, o->lo, o->hi,
                       o->unit[0] ? " " : "", o->unit);
        }
        *(double *)dst = x;
        return 0;
    }
    case K_SPAN: {
        cli_span_t *sp = dst;
        const char *colon = strchr(v, ':');
        char a[64];
        if (colon == NULL || (size_t)(colon - v) >= sizeof a) {
            return die("%s expects START:END in seconds, 0 <= START < END <= the duration, "
                       "got '%s'",
                       o->name, v);
        }
        memcpy(a, v, (size_t)(colon - v));
        a[colon - v] = '\0';
        if (sim_num_parse(a, &sp->start) != 0 || sim_num_parse(colon + 1, &sp->end) != 0) {
            return die("%s expects START:END in seconds, 0 <= START < END <= the duration, "
                       "got '%s'",
                       o->name, v);
        }
        return 0;
    }
    case K_ABC: {
        cli_abc_t *abc = dst;
        char buf[192];
        if (strlen(v) >= sizeof buf) {
            return die("%s expects %s, got '%.40s...'", o->name, o->metavar, v);
        }
        memcpy(buf, v, strlen(v) + 1);
        char *p = buf;
        for (int k = 0; k < 3; k++) {
            char *comma = strchr(p, ',');
            if ((k < 2) != (comma != NULL)) {
                return die("%s expects three numbers %s, got '%s'", o->name, o->metavar, v);
            }
            if (comma != NULL) {
                *comma = '\0';
            }
            if (sim_num_parse(p, &abc->v[k]) != 0) {
                return die("%s expects three numbers %s, got '%s'", o->name, o->metavar, v);
            }
            if (abc->v[k] < o->lo || abc->v[k] > o->hi) {
                return die("%s %s: phase %c's %g is out of range: allowed [%g, %g]", o->name, v,
                           'a' + k, abc->v[k], o->lo, o->hi);
            }
            p = comma != NULL ? comma + 1 : p;
        }
        return 0;
    }
    case K_SET: {
        const char *eq = strchr(v, '=');
        if (eq == NULL || eq == v || (size_t)(eq - v) >= SIM_SET_NAME_MAX) {
            return die("--set expects NAME=VALUE, got '%s'", v);
        }
        if (c->n_sets >= SIM_MAX_SETS) {
            return die("--set given more than %u times", (unsigned)SIM_MAX_SETS);
        }
        sim_set_t *st = &c->sets[c->n_sets];
        memcpy(st->name, v, (size_t)(eq - v));
        st->name[eq - v] = '\0';
        for (size_t k = 0; k < c->n_sets; k++) {
            if (strcmp(c->sets[k].name, st->name) == 0) {
                return die("--set %s given twice", st->name);
            }
        }
        if (sim_num_parse(eq + 1, &st->value) != 0) {
            return die("--set %s expects a number, got '%s' (its unit and range: --list-tunables "
                       "CONTROLLER)",
                       st->name, eq + 1);
        }
        c->n_sets++;
        return 0;
    }
    case K_FLAG:
    default:
        *(int *)dst = 1;
        return 0;
    }
}

/* Parse argv into c and given[] (option index -> given). */
static int cli_parse(int argc, char **argv, cli_t *c, int *given)
{
    for (int i = 1; i < argc; i++) {
        const cli_opt_t *o = opt_find(argv[i]);
        if (o == NULL) {
            return die("unknown option '%s' (see --help)", argv[i]);
        }
        const size_t idx = (size_t)(o - k_opts);
        if (given[idx] && o->kind != K_SET) {
            return die("%s given twice", o->name);
        }
        given[idx] = 1;
        if (o->kind == K_FLAG) {
            (void)parse_value(o, NULL, c);
            continue;
        }
        if (i + 1 >= argc) {
            return die("option %s needs a value (%s)", o->name, o->metavar);
        }
        const int rc = parse_value(o, argv[++i], c);
        if (rc != 0) {
            return rc;
        }
    }
    return 0;
}

static int is_given(const int *given, const char *name)
{
    const cli_opt_t *o = opt_find(name);
    return o != NULL && given[o - k_opts];
}

/* Rules between options (the table's needs/excludes/mode, then the rest). */
static int cli_check(cli_t *c, const int *given)
{
    const int replay = is_given(given, "--replay");
    const int ident = is_given(given, "--identify");
    for (size_t i = 0; i < N_OPTS; i++) {
        const cli_opt_t *o = &k_opts[i];
        if (!given[i]) {
            continue;
        }
        if (ident && o->mode == M_LOOP) {
            bool ok = false;
            for (size_t k = 0; k < sizeof k_ident_loop_opts / sizeof k_ident_loop_opts[0]; k++) {
                ok = ok || strcmp(o->name, k_ident_loop_opts[k]) == 0;
            }
            if (!ok) {
                return die("--identify runs the commissioning sequence: %s does not apply to it",
                           o->name);
            }
        }
        if (ident && o->mode == M_REPLAY) {
            return die("give either --identify or --replay, not both");
        }
        /* The identification always runs on free mechanics. */
        if (o->needs != NULL && !is_given(given, o->needs) &&
            !(ident && strcmp(o->needs, "--free") == 0)) {
            return die("%s needs %s%s", o->name, o->needs,
                       strcmp(o->needs, "--free") == 0
                           ? " (a dynamometer imposes the speed: no load, no speed loop)"
                           : "");
        }
        if (o->excludes != NULL && is_given(given, o->excludes)) {
            return die("give either %s or %s, not both", o->name, o->excludes);
        }
        if (replay && o->mode == M_LOOP) {
            return die("--replay is open loop: %s does not apply to it", o->name);
        }
        if (!replay && o->mode == M_REPLAY) {
            return die("%s belongs to --replay", o->name);
        }
    }
    /* Where the firmware runs, and the options of that place only. */
    const char *t = c->target != NULL ? c->target : "host";
    const int qemu = strcmp(t, "qemu") == 0;
    const int board = strncmp(t, "board:", 6) == 0;
    /* exec:PROGRAM: a target on the pipes of a program (sim_pil.c; the pil_link tests
     * only, not offered in --help). */
    const int exec = strncmp(t, "exec:", 5) == 0 && t[5] != '\0';
    if (!qemu && !board && !exec && strcmp(t, "host") != 0) {
        return die("--target '%s': allowed values host, qemu or board:DEVICE", t);
    }
    if (board && t[6] == '\0') {
        return die("--target '%s': board:DEVICE needs the serial device, e.g. "
                   "board:/dev/ttyACM0",
                   t);
    }
    if (c->pil_transport != NULL && strcmp(c->pil_transport, "semihosting") != 0 &&
        strcmp(c->pil_transport, "socket") != 0) {
        return die("--pil-transport '%s': allowed values semihosting or socket", c->pil_transport);
    }
    if (!qemu && (c->pil_transport != NULL || c->pil_image != NULL)) {
        return die("%s applies to --target qemu only (--target %s)",
                   c->pil_image != NULL ? "--pil-image" : "--pil-transport", t);
    }
    if (!board && is_given(given, "--baud")) {
        return die("--baud applies to --target board:DEVICE only (--target %s)", t);
    }
    if (replay) {
        if (!is_given(given, "--speed-rpm")) {
            return die("--replay needs --speed-rpm");
        }
        return 0;
    }
    if (ident) {
        if (is_given(given, "--speed-rpm")) {
            return die("--identify starts from rest: --speed-rpm does not apply to it");
        }
        return 0;
    }
    if (is_given(given, "--theta0-elec")) {
        return die("--theta0-elec belongs to --replay or --identify");
    }
    if (!is_given(given, "--window")) {
        c->window.start = c->duration / 3.0;
        c->window.end = c->duration;
    }
    if (!(c->window.start >= 0.0 && c->window.start < c->window.end &&
          c->window.end <= c->duration * (1.0 + 1e-12))) {
        return die("--window %g:%g must satisfy 0 <= START < END <= duration (%g s)",
                   c->window.start, c->window.end, c->duration);
    }
    if (is_given(given, "--trace-window") &&
        !(c->trace_window.start >= 0.0 && c->trace_window.start < c->trace_window.end &&
          c->trace_window.end <= c->duration * (1.0 + 1e-12))) {
        return die("--trace-window %g:%g must satisfy 0 <= START < END <= duration (%g s)",
                   c->trace_window.start, c->trace_window.end, c->duration);
    }
    return 0;
}

static void list_controllers(void)
{
    for (size_t i = 0; i < ctrl_count(); i++) {
        const ctrl_desc_t *d = ctrl_at(i);
        printf("%s\t%u\t%s\n", d->name, (unsigned)d->fs_default_hz, d->title);
    }
}

static int list_tunables(const char *name, const sim_machine_t *m)
{
    /* "hfi": the injection's settings (--set hfi.NAME=V) */
    const bool hfi = strcmp(name, "hfi") == 0;
    const ctrl_desc_t *d = hfi ? &ctrl_hfi_desc : ctrl_find(name);
    if (d == NULL) {
        return die("unknown controller '%s' (see --list-controllers; hfi: the injection)", name);
    }
    static union {
        max_align_t a;
        unsigned char b[CTRL_CFG_MAX];
    } cfg;
    ctrl_machine_t cm;
    sim_ctrl_machine_from(m, &cm);
    memset(cfg.b, 0, sizeof cfg.b);
    if (d->cfg_default != NULL && d->cfg_size <= CTRL_CFG_MAX) {
        d->cfg_default(cfg.b, &cm);
    }
    if (hfi) {
        ctrl_hfi_config_default((ctrl_hfi_config_t *)(void *)cfg.b, &cm);
    }
    printf("# %s: %s\n# defaults for machine %s; a computed parameter shows 0 "
           "(computed from the machine at init)\n",
           d->name, d->title, m->name);
    int w = 4;
    for (size_t i = 0; i < d->n_tunables; i++) {
        const int n = (int)strlen(d->tunables[i].name);
        w = n > w ? n : w;
    }
    printf("%-*s %-16s %-24s %-12s %s\n", w, "name", "unit", "range", "default", "help");
    for (size_t i = 0; i < d->n_tunables; i++) {
        const ctrl_tunable_t *t = &d->tunables[i];
        double v = NAN;
        (void)ctrl_tunable_get(d, cfg.b, t->name, &v);
        char range[48];
        if (strcmp(t->unit, "0/1") == 0) {
            (void)snprintf(range, sizeof range, "{0, 1}");
        } else {
            (void)snprintf(range, sizeof range, "[%g, %g]", t->min, t->max);
        }
        printf("%-*s %-16s %-24s %-12g %s\n", w, t->name, t->unit, range, v, t->help);
    }
    return SIM_EXIT_OK;
}

/* One value with its unit, "n/a" when undefined. */
static const char *fmt_num(char *buf, size_t len, const char *f, double v)
{
    if (isfinite(v)) {
        (void)snprintf(buf, len, f, v);
    } else {
        (void)snprintf(buf, len, "n/a");
    }
    return buf;
}

static void print_metrics(FILE *f, const sim_run_t *r, const metrics_result_t *mp,
                          const metrics_result_t *mc)
{
    char b[12][32];
    fprintf(f, "controller %s  fs %u Hz  window %.3f:%.3f s  state %s  fault %s\n",
            r->cfg.ctrl->name, (unsigned)r->cfg.fs_hz, r->cfg.win_start_s, r->cfg.win_end_s,
            fw_state_name(fw_state(&r->fw)), fw_fault_name(fw_fault(&r->fw)));
    fprintf(f,
            "  plant grid (Ts/10): T_mean %s  T_rip %s  psi_mean %s  psi_rip %s  T_sse %s  "
            "f_av %s  THD_I %s\n",
            fmt_num(b[0], 32, "%.4f N*m", mp->torque_mean_nm),
            fmt_num(b[1], 32, "%.4f N*m", mp->torque_ripple_nm),
            fmt_num(b[2], 32, "%.5f Wb", mp->flux_mean_wb),
            fmt_num(b[3], 32, "%.5f Wb", mp->flux_ripple_wb),
            fmt_num(b[4], 32, "%.4f N*m", mp->torque_sse_nm),
            fmt_num(b[5], 32, "%.0f Hz", mp->f_av_hz), fmt_num(b[6], 32, "%.2f %%", mp->thd_i_pct));
    fprintf(f, "                      T_pp %s  THD_V %s (motor phase voltage)\n",
            fmt_num(b[10], 32, "%.4f N*m", mp->torque_pp_nm),
            fmt_num(b[11], 32, "%.2f %%", mp->thd_v_pct));
    fprintf(f, "  control instants:   T_mean %s  T_rip %s  psi_rip %s\n",
            fmt_num(b[7], 32, "%.4f N*m", mc->torque_mean_nm),
            fmt_num(b[8], 32, "%.4f N*m", mc->torque_ripple_nm),
            fmt_num(b[9], 32, "%.5f Wb", mc->flux_ripple_wb));
    const double mean_rpm = r->speed_n > 0u ? r->speed_sum_rpm / (double)r->speed_n : NAN;
    if (r->cfg.speed_mode) {
        fprintf(f, "  speed mode: reference %.1f r/min, window mean %s, at the end %s\n",
                sim_run_speed_ref_now(r), fmt_num(b[10], 32, "%.1f r/min", mean_rpm),
                fmt_num(b[11], 32, "%.1f r/min", sim_run_speed_rpm(r)));
    } else if (r->lim_n > 0u) {
        /* the mean torque against the request and the reference applied */
        const double applied = r->tref_sum_nm / (double)r->lim_n;
        fprintf(f,
                "  torque mode: requested %.4g N*m, applied %.4g N*m (mean); T_mean - request %s, "
                "T_mean - applied %s\n",
                r->torque_ref_requested_nm, applied,
                fmt_num(b[10], 32, "%+.4f N*m", mp->torque_mean_nm - r->torque_ref_requested_nm),
                fmt_num(b[11], 32, "%+.4f N*m", mp->torque_mean_nm - applied));
    }
    if (!r->cfg.speed_mode && r->cfg.free_mech) {
        fprintf(f, "  free mechanics: speed window mean %s, at the end %s\n",
                fmt_num(b[10], 32, "%.1f r/min", mean_rpm),
                fmt_num(b[11], 32, "%.1f r/min", sim_run_speed_rpm(r)));
    }
    sim_mech_summary_t ms;
    sim_run_mech_summary(r, &ms);
    if (ms.present) {
        fprintf(f,
                "  mechanics: at rest (held by friction) %.4f s (%.1f %%), %llu break-aways, %llu "
                "stops, %llu reversals; friction %s (%s), load %s (means over the angle "
                "turned)\n",
                ms.stuck_s, 100.0 * ms.stuck_frac, (unsigned long long)ms.breakaways,
                (unsigned long long)ms.stops, (unsigned long long)ms.reversals,
                fmt_num(b[0], 32, "%.4f N*m", ms.friction_nm),
                fmt_num(b[1], 32, "%.3f W", ms.friction_w),
                fmt_num(b[2], 32, "%.4f N*m", ms.load_nm));
    }
    double ea;
    double em;
    double es;
    sim_run_est_errors(r, &ea, &em, &es);
    fprintf(f,
            "  estimator (|speed| >= 10 %% rated): angle error rms %s max %s, speed error rms %s\n",
            fmt_num(b[0], 32, "%.3f deg", ea), fmt_num(b[1], 32, "%.3f deg", em),
            fmt_num(b[2], 32, "%.2f r/min", es));
    if (r->cfg.hfi || r->est_lo_n > 0u) {
        sim_run_est_errors_low(r, &ea, &em);
        fprintf(f, "  estimator (|speed| < 10 %% rated): angle error rms %s max %s",
                fmt_num(b[0], 32, "%.3f deg", ea), fmt_num(b[1], 32, "%.3f deg", em));
#if CTRL_SL_HFI
        if (r->cfg.hfi) {
            const uint8_t st = fw_telemetry(&r->fw)->sl_state;
            static const char *const pol[4] = {"unknown", "d-axis saturation", "first motion", "?"};
            fprintf(f, "; injection clamped in %lu periods, polarity from %s",
                    (unsigned long)r->fw.hfi_clipped, pol[(st >> 5) & 3u]);
        }
#endif
        fprintf(f, "\n");
    }
    if (!isnan(r->fault_time_s)) {
        fprintf(f, "  fault %s at t = %.6f s\n", fw_fault_name(fw_fault(&r->fw)), r->fault_time_s);
    }
}

static int replay_main(const cli_t *c, const sim_machine_t *pm)
{
    char err[512];
    plant_config_t base;
    sim_machine_to_plant(pm, &base);
    static plant_fluxmap_t map;
    if (pm->fluxmap_path[0] != '\0') {
        if (plant_fluxmap_load(&map, pm->fluxmap_path, err, sizeof err) != PLANT_OK) {
            return die("flux map: %s", err);
        }
        base.fluxmap = &map;
    }
    sim_replay_opts_t o = {c->speed_rpm, c->theta0, c->id0, c->iq0};
    const int rc = sim_replay_files(&base, &o, c->replay, c->trace, err, sizeof err);
    plant_fluxmap_free(&map);
    if (rc != 0) {
        fprintf(stderr, "sim: error: replay: %s\n", err);
        return rc == SIM_REPLAY_EINPUT ? SIM_EXIT_USAGE : SIM_EXIT_RUN;
    }
    printf("replay: %s -> %s\n", c->replay, c->trace);
    return SIM_EXIT_OK;
}

/* Steps "a,b,c" -> step ids; returns the count or -1 (message printed). */
static int parse_steps(const char *list, uint8_t *steps, size_t cap)
{
    size_t n = 0;
    const char *p = list;
    while (*p != '\0') {
        const char *e = strchr(p, ',');
        const size_t len = e != NULL ? (size_t)(e - p) : strlen(p);
        char name[32];
        if (len == 0u || len >= sizeof name || n >= cap) {
            fprintf(stderr, "sim: error: --identify-steps '%s': expected NAME[,NAME...]\n", list);
            return -1;
        }
        memcpy(name, p, len);
        name[len] = '\0';
        const uint8_t s = cm_step_find(name);
        if (s == CM_STEP_NONE) {
            fprintf(stderr,
                    "sim: error: --identify-steps: unknown step '%s' (vbus probe encoder "
                    "rs ldq flux gates sense run)\n",
                    name);
            return -1;
        }
        steps[n++] = s;
        p += len;
        if (*p == ',') {
            p++;
        }
    }
    return (int)n;
}

static int identify_main(const cli_t *c, const sim_machine_t *pm, bool load_given)
{
    const char *ctrl_machine_path = c->control_machine, *ctrl_name = c->controller;
    const char *steps_arg = c->identify_steps, *inject = c->inject, *out_ini = c->identify_out;
    const char *metrics_path = c->metrics;
    const double theta0 = c->theta0, seed = c->seed;
    char err[512];
    static sim_machine_t cm;
    cm = *pm;
    if (ctrl_machine_path != NULL &&
        sim_machine_load(ctrl_machine_path, &cm, err, sizeof err) != 0) {
        return die("control machine file: %s", err);
    }
    const ctrl_desc_t *d = ctrl_name != NULL ? ctrl_find(ctrl_name) : ctrl_find("m2ptfc");
    if (d == NULL) {
        d = ctrl_at(0);
    }
    if (d == NULL) {
        return die("unknown controller '%s' (see --list-controllers)", ctrl_name);
    }
    sim_bad_t bad = SIM_BAD_NONE;
    if (inject != NULL) {
        static const char *const names[SIM_BAD_COUNT] = {"none", "open", "short", "encoder_stuck",
                                                         "vbus_low"};
        bad = SIM_BAD_COUNT;
        for (int k = 0; k < (int)SIM_BAD_COUNT; k++) {
            if (strcmp(inject, names[k]) == 0) {
                bad = (sim_bad_t)k;
            }
        }
        if (bad == SIM_BAD_COUNT) {
            return die("--inject '%s': expected open, short, encoder_stuck or vbus_low", inject);
        }
    }
    uint8_t steps[CM_STEP_COUNT];
    int n = (int)sim_ident_plan_n;
    memcpy(steps, sim_ident_plan, sim_ident_plan_n);
    if (steps_arg != NULL && (n = parse_steps(steps_arg, steps, sizeof steps)) < 0) {
        return SIM_EXIT_USAGE;
    }
    FILE *tf = NULL;
    if (c->trace != NULL && (tf = fopen(c->trace, "w")) == NULL) {
        return die("cannot write trace file '%s': %s", c->trace, strerror(errno));
    }
    sim_ident_trace(tf, (uint32_t)c->decim);
    static sim_run_t run;
    if (sim_ident_setup(&run, pm, &cm, d, theta0, (uint64_t)seed, err, sizeof err) != 0) {
        fprintf(stderr, "sim: error: %s\n", err);
        if (tf != NULL) {
            fclose(tf);
        }
        return SIM_EXIT_USAGE;
    }
    /* A passive load on the shaft (a brake, a gearbox's friction), instead of
     * the machine file's: the identification must move it. */
    if (load_given) {
        plant_set_load_passive(&run.plant, c->load_passive_nm);
    }
    static sim_ident_t id;
    if (sim_ident_run(&run, steps, (uint8_t)n, 30.0, bad, &id, err, sizeof err) != 0) {
        fprintf(stderr, "sim: error: %s\n", err);
        sim_run_free(&run);
        if (tf != NULL) {
            fclose(tf);
        }
        return SIM_EXIT_RUN;
    }
    sim_ident_print(stdout, &run, &id);
    /* A step that ends in its named error is a fault of the drive (exit 3). */
    int status = (id.finished && id.err == CM_E_NONE) ? SIM_EXIT_OK : SIM_EXIT_FAULT;
    if (metrics_path != NULL) {
        FILE *mf = fopen(metrics_path, "w");
        if (mf == NULL) {
            fprintf(stderr, "sim: error: cannot write metrics file '%s': %s\n", metrics_path,
                    strerror(errno));
            status = SIM_EXIT_RUN;
        } else {
            sim_ident_write_json(mf, &run, &id);
            fclose(mf);
        }
    }
    if (out_ini != NULL && sim_ident_write_ini(out_ini, &cm, &id, err, sizeof err) != 0) {
        fprintf(stderr, "sim: error: %s: %s\n", out_ini, err);
        status = SIM_EXIT_RUN;
    }
    sim_run_free(&run);
    if (tf != NULL && fclose(tf) != 0) {
        fprintf(stderr, "sim: error: writing the trace failed\n");
        status = SIM_EXIT_RUN;
    }
    return status;
}

int main(int argc, char **argv)
{
    static cli_t c;
    static int given[N_OPTS];
    memset(&c, 0, sizeof c);
    c.duration = 0.3;
    c.seed = 1.0;
    c.decim = 1.0;
    if (argc < 2) {
        usage(stderr);
        return SIM_EXIT_USAGE;
    }
    int rc = cli_parse(argc, argv, &c, given);
    if (rc != 0) {
        return rc;
    }
    if (c.help) {
        usage(stdout);
        return SIM_EXIT_OK;
    }
    if (c.list_controllers) {
        list_controllers();
        return SIM_EXIT_OK;
    }
    char err[2048];
    static sim_machine_t pm;
    const char *mpath = c.machine;
    if (c.list_tunables != NULL && mpath == NULL) {
        mpath = PMSM_MACHINES_DIR "/thesis_spmsm.ini";
    }
    if (mpath == NULL) {
        return die("--machine FILE is required");
    }
    if (sim_machine_load(mpath, &pm, err, sizeof err) != 0) {
        return die("machine file: %s", err);
    }
    if (c.list_tunables != NULL) {
        return list_tunables(c.list_tunables, &pm);
    }
    rc = cli_check(&c, given);
    if (rc != 0) {
        return rc;
    }
    if (c.replay != NULL) {
        return replay_main(&c, &pm);
    }
    if (c.identify) {
        return identify_main(&c, &pm, is_given(given, "--load-passive-nm"));
    }

    /* ---- closed loop: everything is checked before the run starts ---- */
    if (c.controller == NULL) {
        return die("--controller NAME is required (see --list-controllers)");
    }
    const ctrl_desc_t *d = ctrl_find(c.controller);
    if (d == NULL) {
        return die("unknown controller '%s' (see --list-controllers)", c.controller);
    }
    static sim_warnings_t warnings;
    static sim_run_cfg_t cfg;
    sim_run_config_default(&cfg, &pm, d);
    static sim_machine_t cm;
    if (c.control_machine != NULL) {
        if (sim_machine_load(c.control_machine, &cm, err, sizeof err) != 0) {
            return die("control machine file: %s", err);
        }
        sim_ctrl_machine_from(&cm, &cfg.ctrl_machine);
        sim_run_ctrl_sensors_from(&cfg, &cm);
    }
    if (c.current_sense != NULL) {
        if (strcmp(c.current_sense, "inverter") != 0 && strcmp(c.current_sense, "motor") != 0) {
            return die("--current-sense '%s': expected inverter or motor", c.current_sense);
        }
        cfg.hal.sense_motor_side = strcmp(c.current_sense, "motor") == 0;
    }
    cfg.fs_hz = is_given(given, "--fs") ? (uint32_t)c.fs : d->fs_default_hz;
    cfg.free_mech = c.free_mech != 0;
    cfg.speed_rpm = c.speed_rpm;
    if (is_given(given, "--load-nm")) { /* else the machine file's */
        cfg.load_nm = c.load_nm;
    }
    if (is_given(given, "--load-passive-nm")) {
        cfg.load_passive_nm = c.load_passive_nm;
    }
    cfg.speed_mode = is_given(given, "--speed-ref-rpm");
    cfg.torque_ref_nm = c.torque_ref;
    cfg.speed_ref_rpm = c.speed_ref;
    cfg.duration_s = c.duration;
    cfg.win_start_s = c.window.start;
    cfg.win_end_s = c.window.end;
    cfg.seed = (uint64_t)c.seed;
    cfg.trace_decimation = (uint32_t)c.decim;
    if (is_given(given, "--trace-window")) {
        cfg.trace_start_s = c.trace_window.start;
        cfg.trace_end_s = c.trace_window.end;
    }
    memcpy(cfg.sets, c.sets, sizeof c.sets);
    cfg.n_sets = c.n_sets;
    cfg.stop_on_fault = !c.continue_on_fault;
    cfg.psi_adapt = !c.no_psi_adapt;
    cfg.dead_comp = c.no_dead_comp == 0;
    if (is_given(given, "--comp-dead-time-ns")) {
        cfg.comp_dead_time_s = c.comp_dead_time_ns * 1e-9;
    }
    for (int k = 0; k < 3; k++) {
        cfg.hal.adc_gain_err[k] = c.current_gain_err.v[k];
    }
    cfg.sensorless = c.sensorless != 0;
    cfg.hfi = c.hfi != 0;
    if (is_given(given, "--speed-bw-hz") || is_given(given, "--speed-pm-deg")) {
        /* The command line's sizing replaces the machine file's speed loop. */
        cfg.speed_kp = cfg.speed_ki = 0.0;
        if (is_given(given, "--speed-bw-hz")) {
            cfg.speed_bw_hz = c.speed_bw;
        }
        if (is_given(given, "--speed-pm-deg")) {
            cfg.speed_pm_deg = c.speed_pm;
        }
    }
    if (is_given(given, "--speed-kp")) {
        cfg.speed_kp = c.speed_kp;
        cfg.speed_ki = c.speed_ki;
        cfg.speed_bw_hz = cfg.speed_pm_deg = 0.0;
    }
    if (is_given(given, "--torque-follow-fault")) {
        cfg.torque_follow_fault_windows = (uint32_t)c.tq_follow_fault;
    }
    if (is_given(given, "--overspeed-rpm")) {
        if (!(c.overspeed > pm.speed_rated_rpm)) {
            return die("--overspeed-rpm %g must exceed the rated speed %g r/min of %s", c.overspeed,
                       pm.speed_rated_rpm, pm.name);
        }
        cfg.overspeed_rpm = c.overspeed;
    }
    cfg.warnings = &warnings;

    static sim_scenario_t scn;
    if (c.scenario != NULL) {
        if (sim_scenario_load(&scn, c.scenario, err, sizeof err) != 0) {
            return die("scenario: %s", err);
        }
        cfg.scenario = &scn;
    }
    /* Output files are opened before the run: a path that cannot be written
     * fails now, not after the simulation. */
    FILE *trace = NULL;
    FILE *mf = NULL;
    if (c.trace != NULL) {
        trace = fopen(c.trace, "w");
        if (trace == NULL) {
            return die("cannot write trace file '%s': %s", c.trace, strerror(errno));
        }
        cfg.trace = trace;
    }
    if (c.metrics != NULL) {
        mf = fopen(c.metrics, "w");
        if (mf == NULL) {
            const int e = errno;
            if (trace != NULL) {
                fclose(trace);
            }
            return die("cannot write metrics file '%s': %s", c.metrics, strerror(e));
        }
    }

    sim_pil_t *pil = NULL;
    if (c.target != NULL && strcmp(c.target, "host") != 0) {
        const sim_pil_opts_t po = {c.target, c.pil_image, c.pil_transport,
                                   (uint32_t)c.link_timeout_ms, (uint32_t)c.baud};
        pil = sim_pil_open(&po, err, sizeof err);
        if (pil == NULL) {
            if (trace != NULL) {
                fclose(trace);
            }
            if (mf != NULL) {
                fclose(mf);
                (void)remove(c.metrics);
            }
            fprintf(stderr, "sim: error: %s\n", err);
            return SIM_EXIT_RUN;
        }
        cfg.link = sim_pil_link(pil);
    }

    static sim_run_t run;
    int status = SIM_EXIT_OK;
    if (sim_run_init(&run, &cfg, err, sizeof err) != 0) {
        fprintf(stderr, "sim: error: %s\n", err);
        /* A link fault is not the input's: the run could not complete. */
        status = run.link_failed ? SIM_EXIT_RUN : SIM_EXIT_USAGE;
    } else if (sim_run_all(&run, err, sizeof err) != 0) {
        fprintf(stderr, "sim: error: %s\n", err);
        status = SIM_EXIT_RUN;
    }
    if (pil != NULL) {
        if (status == SIM_EXIT_OK) {
            sim_pil_report(pil, stderr);
        }
        if (sim_pil_close(pil) != 0 && status == SIM_EXIT_OK) {
            fprintf(stderr, "sim: error: the PIL target did not stop cleanly\n");
            status = SIM_EXIT_RUN;
        }
    }
    if (status == SIM_EXIT_OK) {
        metrics_result_t mp, mc;
        const int have = sim_run_metrics(&run, &mp, &mc) == 0;
        if (!have && !sim_run_faulted(&run)) {
            fprintf(stderr, "sim: error: no samples in the metrics window\n");
            status = SIM_EXIT_RUN;
        } else {
            if (!have) {
                sim_warn(&warnings,
                         "the drive faulted before the metrics window (%g s): no "
                         "indices",
                         cfg.win_start_s);
            }
            print_metrics(stdout, &run, &mp, &mc);
            if (mf != NULL) {
                sim_run_write_metrics_json(mf, &run, &mp, &mc);
            }
            if (sim_run_faulted(&run)) {
                fprintf(stderr,
                        "sim: error: the drive faulted at t = %.6f s: %s (exit status %d)\n",
                        run.fault_time_s, fw_fault_name(fw_fault(&run.fw)), SIM_EXIT_FAULT);
                status = SIM_EXIT_FAULT;
            }
        }
    }
    sim_run_free(&run);
    if (mf != NULL) {
        if (fclose(mf) != 0) {
            fprintf(stderr, "sim: error: writing the metrics file failed\n");
            status = SIM_EXIT_RUN;
        }
        if (status == SIM_EXIT_RUN || status == SIM_EXIT_USAGE) {
            (void)remove(c.metrics); /* no stale or empty result file */
        }
    }
    if (trace != NULL && fclose(trace) != 0) {
        fprintf(stderr, "sim: error: writing the trace failed\n");
        status = SIM_EXIT_RUN;
    }
    return status;
}
