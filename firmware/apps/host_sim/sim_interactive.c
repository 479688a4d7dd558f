/*
 * Interactive host build: the firmware with the C plant of a machine file in
 * the loop, driven only by the command lines it receives on stdin
 * (firmware/PROTOCOL.md), answering and streaming telemetry on stdout - the
 * QEMU interactive image's program (firmware/apps/qemu_pil/pil_interactive.c)
 * built for the PC. tools/console --sim runs it (also under --web).
 *
 * The same engine (firmware/apps/engine) runs one PWM period at a time: the
 * firmware boots, calibrates its current offsets (gates off), then waits
 * ready; only the user arms or starts a commissioning step. The plant is the
 * machine file's free rotor with its [mechanics] (friction, stiction,
 * cogging, load); --load-passive-nm replaces the file's passive load.
 *
 * Time: the periods run in slices of 1 ms of plant time; between two slices
 * the main loop takes one command line at most (fw_link_rx says where it
 * ended), sends what the link has queued (replies, telemetry) and kicks the
 * watchdog, as a board's main loop does between its interrupts. --pace X
 * keeps plant time at X times wall time (default 1: the motor's own time);
 * 0 runs as fast as the PC goes (the identification's 6 s of plant time in
 * about a second on a Release build), which a person at the page would
 * find hard to follow but a test wants. A reader slower than the
 * telemetry (the pipe full) holds the periods back: the plant waits, it
 * does not lose time.
 *
 * Settings ("config save|show|erase|default"): the record in a RAM model of
 * the G4 flash's two pages (settings_flash_model.h), empty at each start.
 *
 * Exit: 0 when stdin closes; 2 on a bad option (named, with its range) or a
 * machine file or configuration the firmware refuses.
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "controller.h"
#include "fw_link.h"
#include "fw_params.h"
#include "fw_settings.h"
#include "pipeline.h"
#include "settings_flash_model.h"
#include "sim_num.h"
#include "sim_run.h"

#define SLICE_S 1.0e-3  /* plant time between two passes of the main loop */
#define WAIT_MAX_MS 20  /* longest wait for input while paced ahead */
#define PACE_MAX 1000.0 /* --pace range: [0, PACE_MAX] */
#define LOAD_MAX_NM 1e5 /* --load-passive-nm range: [0, LOAD_MAX_NM] */

static struct {
    sim_run_t run;
    fw_link_t link;
    sfm_t flash;
    fw_settings_t settings;
    ctrl_machine_t machine; /* the machine file's (config default) */
    const ctrl_desc_t *desc;
    uint8_t in[256]; /* bytes received and not yet given to the link */
    size_t in_at, in_n;
} app;

static void out_write(void *ctx, const uint8_t *bytes, size_t len)
{
    (void)ctx;
    while (len > 0u) {
        const ssize_t n = write(STDOUT_FILENO, bytes, len);
        if (n < 0 && errno == EINTR) {
            continue;
        }
        if (n <= 0) {
            exit(0); /* the reader is gone (EPIPE): nobody to drive the motor */
        }
        bytes += n;
        len -= (size_t)n;
    }
}

static void out_text(const char *s)
{
    out_write(NULL, (const uint8_t *)s, strlen(s));
}

/* A record's configuration on the running engine (between two slices). */
static int app_settings_apply(void *ctx, const settings_t *s, char *why, size_t cap)
{
    (void)ctx;
    return fw_settings_init(&app.run.fw, &app.run.hal, s, app.run.ctrl_cfg_buf, why, cap);
}

static int app_settings_default(void *ctx)
{
    (void)ctx;
    fw_config_t c;
    fw_config_default(&c, &app.machine, app.desc);
    return fw_init(&app.run.fw, &app.run.hal, &c) == FW_OK ? CMD_OK : CMD_E_FAILED;
}

static double wall_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int usage(const char *why)
{
    if (why != NULL) {
        fprintf(stderr, "sim_interactive: %s\n", why);
    }
    fprintf(
        stderr,
        "usage: sim_interactive --machine FILE [--controller NAME] [--pace X]\n"
        "                       [--load-passive-nm T] [--seed N]\n"
        "  --machine FILE        machine file (sim_host/machines/*.ini): the plant and the\n"
        "                        firmware's compiled-in machine\n"
        "  --controller NAME     controller at start-up (default fst; 'ctrl select' changes it)\n"
        "  --pace X              plant seconds per wall second, [0, %g] (default 1; 0: as\n"
        "                        fast as the PC goes)\n"
        "  --load-passive-nm T   passive load on the shaft, [0, %g] N*m (default: the\n"
        "                        machine file's [mechanics])\n"
        "  --seed N              noise seed (default 1)\n"
        "The command link (firmware/PROTOCOL.md) on stdin/stdout; tools/console --sim.\n",
        PACE_MAX, LOAD_MAX_NM);
    return 2;
}

/* A number option in [lo, hi]; 0 or -1 with the message printed. */
static int number_opt(const char *name, const char *text, double lo, double hi, double *out)
{
    double v = NAN;
    if (text == NULL || sim_num_parse(text, &v) != 0 || !(v >= lo && v <= hi)) {
        fprintf(stderr, "sim_interactive: %s %s: expected a number in [%g, %g]\n", name,
                text != NULL ? text : "(missing)", lo, hi);
        return -1;
    }
    *out = v;
    return 0;
}

/* Up to one command line of what stdin gave; waits at most wait_ms for input
 * when none is pending. Returns -1 once stdin has closed. */
static int take_input(int wait_ms)
{
    if (app.in_at == app.in_n) {
        struct pollfd p = {STDIN_FILENO, POLLIN, 0};
        const int r = poll(&p, 1, wait_ms);
        if (r > 0) {
            const ssize_t n = read(STDIN_FILENO, app.in, sizeof app.in);
            if (n == 0 || (n < 0 && errno != EINTR && errno != EAGAIN)) {
                return -1;
            }
            app.in_at = 0u;
            app.in_n = n > 0 ? (size_t)n : 0u;
        }
    }
    while (app.in_at < app.in_n) {
        if (fw_link_rx(&app.link, app.in[app.in_at++])) {
            break; /* one line per pass: the watchdog is served before the next */
        }
    }
    return 0;
}

int main(int argc, char **argv)
{
    const char *machine = NULL, *ctrl = "fst";
    double pace = 1.0, load = -1.0, seed = 1.0;
    for (int i = 1; i < argc; i++) {
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(argv[i], "--help") == 0) {
            (void)usage(NULL);
            return 0;
        } else if (strcmp(argv[i], "--machine") == 0 && v != NULL) {
            machine = v;
        } else if (strcmp(argv[i], "--controller") == 0 && v != NULL) {
            ctrl = v;
        } else if (strcmp(argv[i], "--pace") == 0) {
            if (number_opt("--pace", v, 0.0, PACE_MAX, &pace) != 0) {
                return 2;
            }
        } else if (strcmp(argv[i], "--load-passive-nm") == 0) {
            if (number_opt("--load-passive-nm", v, 0.0, LOAD_MAX_NM, &load) != 0) {
                return 2;
            }
        } else if (strcmp(argv[i], "--seed") == 0) {
            if (number_opt("--seed", v, 0.0, 4294967295.0, &seed) != 0 || seed != floor(seed)) {
                return usage("--seed expects a whole number in [0, 4294967295]");
            }
        } else {
            fprintf(stderr, "sim_interactive: unknown option or missing value '%s'\n", argv[i]);
            return usage(NULL);
        }
        i++;
    }
    if (machine == NULL) {
        return usage("--machine FILE is required");
    }
    app.desc = ctrl_find(ctrl);
    if (app.desc == NULL) {
        fprintf(stderr, "sim_interactive: --controller %s is not registered (ctrl list)\n", ctrl);
        return 2;
    }
    static sim_machine_t rig;
    char err[256];
    if (sim_machine_load(machine, &rig, err, sizeof err) != 0) {
        fprintf(stderr, "sim_interactive: %s\n", err);
        return 2;
    }
    if (load >= 0.0) {
        rig.load_kind = SIM_LOAD_PASSIVE;
        rig.load_nm = load;
    }
    static sim_run_cfg_t c;
    sim_run_config_default(&c, &rig, app.desc);
    c.fs_hz = app.desc->fs_default_hz;
    c.free_mech = true;
    c.seed = (uint64_t)seed;
    c.duration_s = 100.0; /* never reached: the engine is not armed by itself */
    c.win_start_s = 99.0; /* no metrics window */
    c.win_end_s = 100.0;
    c.defer_start = true;    /* every period from boot on, here */
    c.auto_arm = false;      /* only the user arms */
    c.kick_watchdog = false; /* the main loop kicks */
    c.skip_thd = true;
    if (sim_run_init(&app.run, &c, err, sizeof err) != 0) {
        fprintf(stderr, "sim_interactive: %s\n", err);
        return 2;
    }
    (void)signal(SIGPIPE, SIG_IGN); /* a closed stdout is an EPIPE: out_write ends */
    app.machine = app.run.fw.machine_own;
    sfm_init(&app.flash, 1u);
    sfm_flash(&app.flash, &app.settings.flash);
    app.settings.apply = app_settings_apply;
    app.settings.apply_default = app_settings_default;
    (void)fw_settings_boot(&app.settings);
    fw_link_init(&app.link, &app.run.fw, out_write, NULL);
    fw_link_set_settings(&app.link, &app.settings);
    fw_params_attach(&app.link, &fw_params_machine); /* through app_settings_apply */
    fw_params_attach(&app.link, &fw_params_drive);

    char line[384];
    (void)snprintf(line, sizeof line,
                   "pmsm-dtc on the host: %s, free rotor, passive load %.2f N*m; controller %s at "
                   "%u Hz; plant time at %g x wall time; calibrating, then 'arm' (PROTOCOL.md, "
                   "'help')\r\n%s (flash: RAM model)\r\n",
                   rig.name, c.load_passive_nm, app.desc->name, (unsigned)c.fs_hz, pace,
                   app.settings.msg);
    out_text(line);

    const uint32_t slice = (uint32_t)lround(SLICE_S * (double)c.fs_hz) > 0u
                               ? (uint32_t)lround(SLICE_S * (double)c.fs_hz)
                               : 1u;
    const double t0 = wall_s();
    uint64_t periods = 0u;
    int failed = 0;
    for (;;) {
        int wait_ms = 0;
        const double plant_s = (double)periods / (double)c.fs_hz;
        if (failed) {
            wait_ms = WAIT_MAX_MS;
        } else if (pace > 0.0) {
            const double ahead = plant_s / pace - (wall_s() - t0);
            if (ahead > 0.0) {
                wait_ms = (int)fmin(ceil(ahead * 1e3), WAIT_MAX_MS);
            }
        }
        if (take_input(wait_ms) != 0) {
            return 0;
        }
        fw_link_poll(&app.link);
        fw_watchdog_kick(&app.run.fw);
        if (failed || (pace > 0.0 && plant_s / pace > wall_s() - t0)) {
            continue;
        }
        for (uint32_t k = 0; k < slice; k++) {
            if (sim_run_period(&app.run) != 0) {
                failed = 1;
                (void)snprintf(line, sizeof line,
                               "interactive: the plant integration failed (code %d); the drive "
                               "is stopped\r\n",
                               app.run.plant_rc);
                out_text(line);
                break;
            }
            periods++;
        }
    }
}
