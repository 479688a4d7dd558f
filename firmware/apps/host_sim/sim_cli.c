/*
 * Host simulator CLI (./tools/sim): closed loop of plant + HAL sim + firmware,
 * or open-loop replay of a switching sequence. `sim --help` lists the options.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "controller.h"
#include "sim_replay.h"
#include "sim_run.h"

#define SIM_MAX_SETS 32

static const char *const usage =
    "usage: sim --machine FILE [options]\n"
    "closed loop:\n"
    "  --controller NAME        controller from the registry (see --list-controllers)\n"
    "  --fs HZ                  sampling/PWM frequency (default: the controller's)\n"
    "  --control-machine FILE   configure the controller with another machine file\n"
    "  --speed-rpm R            dynamometer: imposed speed (default 0)\n"
    "  --free                   free mechanics (3.15), initial speed --speed-rpm\n"
    "  --load-nm T              load torque (free mechanics)\n"
    "  --torque-ref NM | --speed-ref-rpm R   reference (default torque 0)\n"
    "  --duration S             simulated time after arm (default 0.3)\n"
    "  --window START:END       metrics window in s (default 0.1:duration)\n"
    "  --scenario FILE          time/speed-triggered steps (firmware/host/sim_scenario.h)\n"
    "  --seed N                 ADC noise seed (default 1)\n"
    "  --trace FILE.csv         true signals on a Ts/10 grid\n"
    "  --trace-decimation N     keep every N-th trace row (default 1)\n"
    "  --trace-window START:END write trace rows only in this time span (s)\n"
    "  --metrics FILE.json      performance indices (also printed to stdout)\n"
    "  --set NAME=VALUE         controller tunable (repeatable)\n"
    "  --list-controllers       print name, fs_default_hz and title of each controller\n"
    "open-loop replay:\n"
    "  --replay FILE.csv --speed-rpm R [--theta0-elec RAD] [--id0 A] [--iq0 A] --trace FILE\n";

static int die(const char *fmt, const char *a, const char *b)
{
    fprintf(stderr, "sim: error: ");
    fprintf(stderr, fmt, a != NULL ? a : "", b != NULL ? b : "");
    fprintf(stderr, "\n");
    return 2;
}

/* Strict number: whole string, finite, within [lo, hi]. */
static int num_arg(const char *opt, const char *s, double lo, double hi, double *out)
{
    char *end = NULL;
    errno = 0;
    const double v = s != NULL ? strtod(s, &end) : 0.0;
    if (s == NULL || end == s || *end != '\0' || errno != 0 || !isfinite(v)) {
        fprintf(stderr, "sim: error: %s expects a number, got '%s'\n", opt, s ? s : "");
        return -1;
    }
    if (v < lo || v > hi) {
        fprintf(stderr, "sim: error: %s %s is out of range [%g, %g]\n", opt, s, lo, hi);
        return -1;
    }
    *out = v;
    return 0;
}

/* START:END with 0 <= START < END <= duration. */
static int parse_span(const char *opt, const char *arg, double duration, double *start,
                      double *end_out)
{
    char *end = NULL;
    errno = 0;
    const double ws = strtod(arg, &end);
    if (end == arg || *end != ':' || errno != 0) {
        fprintf(stderr, "sim: error: %s expects START:END in seconds, got '%s'\n", opt, arg);
        return -1;
    }
    const char *s2 = end + 1;
    const double we = strtod(s2, &end);
    if (end == s2 || *end != '\0' || errno != 0 || !isfinite(ws) || !isfinite(we) || ws < 0.0 ||
        we <= ws || we > duration + 1e-12) {
        fprintf(stderr, "sim: error: %s '%s' must satisfy 0 <= START < END <= duration\n", opt,
                arg);
        return -1;
    }
    *start = ws;
    *end_out = we;
    return 0;
}

static void list_controllers(void)
{
    for (size_t i = 0; i < ctrl_count(); i++) {
        const ctrl_desc_t *d = ctrl_at(i);
        printf("%s\t%u\t%s\n", d->name, (unsigned)d->fs_default_hz, d->title);
    }
}

static void print_metrics(FILE *f, const sim_run_t *r, const metrics_result_t *mp,
                          const metrics_result_t *mc)
{
    fprintf(f,
            "controller %s  fs %u Hz  window %.3f:%.3f s  state %s  fault %s\n"
            "  plant grid (Ts/10): T_mean %.4f N*m  T_rip %.4f N*m  psi_mean %.5f Wb  "
            "psi_rip %.5f Wb  T_sse %.4f N*m  f_av %.0f Hz  THD_I %.2f %%\n"
            "  control instants:   T_mean %.4f N*m  T_rip %.4f N*m  psi_rip %.5f Wb\n",
            r->cfg.ctrl->name, (unsigned)r->cfg.fs_hz, r->cfg.win_start_s, r->cfg.win_end_s,
            fw_state_name(fw_state(&r->fw)), fw_fault_name(fw_fault(&r->fw)), mp->torque_mean_nm,
            mp->torque_ripple_nm, mp->flux_mean_wb, mp->flux_ripple_wb, mp->torque_sse_nm,
            mp->f_av_hz, mp->thd_i_pct, mc->torque_mean_nm, mc->torque_ripple_nm,
            mc->flux_ripple_wb);
}

int main(int argc, char **argv)
{
    const char *machine_path = NULL, *ctrl_machine_path = NULL, *ctrl_name = NULL;
    const char *scenario_path = NULL, *trace_path = NULL, *metrics_path = NULL;
    const char *replay_path = NULL, *window = NULL, *trace_window = NULL;
    const char *sets[SIM_MAX_SETS];
    size_t n_sets = 0;
    double fs = 0.0, speed_rpm = 0.0, load_nm = 0.0, torque_ref = 0.0, speed_ref = 0.0;
    double duration = 0.3, seed = 1.0, decim = 1.0, theta0 = 0.0, id0 = 0.0, iq0 = 0.0;
    int free_mech = 0, have_tref = 0, have_sref = 0, have_load = 0, have_theta0 = 0;
    int have_id0 = 0, have_iq0 = 0, have_speed = 0;

    if (argc < 2) {
        fputs(usage, stderr);
        return 2;
    }
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = (i + 1 < argc) ? argv[i + 1] : NULL;
#define NEED_VALUE()                                                                               \
    do {                                                                                           \
        if (v == NULL) {                                                                           \
            return die("option %s needs a value%s", a, NULL);                                      \
        }                                                                                          \
        i++;                                                                                       \
    } while (0)
#define NUM(dst, lo, hi)                                                                           \
    do {                                                                                           \
        NEED_VALUE();                                                                              \
        if (num_arg(a, v, (lo), (hi), &(dst)) != 0) {                                              \
            return 2;                                                                              \
        }                                                                                          \
    } while (0)
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            fputs(usage, stdout);
            return 0;
        } else if (strcmp(a, "--list-controllers") == 0) {
            list_controllers();
            return 0;
        } else if (strcmp(a, "--machine") == 0) {
            NEED_VALUE();
            machine_path = v;
        } else if (strcmp(a, "--control-machine") == 0) {
            NEED_VALUE();
            ctrl_machine_path = v;
        } else if (strcmp(a, "--controller") == 0) {
            NEED_VALUE();
            ctrl_name = v;
        } else if (strcmp(a, "--fs") == 0) {
            NUM(fs, 1000.0, 200000.0);
        } else if (strcmp(a, "--speed-rpm") == 0) {
            NUM(speed_rpm, -100000.0, 100000.0);
            have_speed = 1;
        } else if (strcmp(a, "--free") == 0) {
            free_mech = 1;
        } else if (strcmp(a, "--load-nm") == 0) {
            NUM(load_nm, -1.0e5, 1.0e5);
            have_load = 1;
        } else if (strcmp(a, "--torque-ref") == 0) {
            NUM(torque_ref, -1.0e5, 1.0e5);
            have_tref = 1;
        } else if (strcmp(a, "--speed-ref-rpm") == 0) {
            NUM(speed_ref, -100000.0, 100000.0);
            have_sref = 1;
        } else if (strcmp(a, "--duration") == 0) {
            NUM(duration, 1.0e-4, 100.0);
        } else if (strcmp(a, "--window") == 0) {
            NEED_VALUE();
            window = v;
        } else if (strcmp(a, "--trace-window") == 0) {
            NEED_VALUE();
            trace_window = v;
        } else if (strcmp(a, "--scenario") == 0) {
            NEED_VALUE();
            scenario_path = v;
        } else if (strcmp(a, "--seed") == 0) {
            NUM(seed, 0.0, 9007199254740992.0);
            if (seed != floor(seed)) {
                return die("--seed expects an integer, got '%s'%s", v, NULL);
            }
        } else if (strcmp(a, "--trace") == 0) {
            NEED_VALUE();
            trace_path = v;
        } else if (strcmp(a, "--trace-decimation") == 0) {
            NUM(decim, 1.0, 1.0e6);
            if (decim != floor(decim)) {
                return die("--trace-decimation expects an integer, got '%s'%s", v, NULL);
            }
        } else if (strcmp(a, "--metrics") == 0) {
            NEED_VALUE();
            metrics_path = v;
        } else if (strcmp(a, "--set") == 0) {
            NEED_VALUE();
            if (n_sets >= SIM_MAX_SETS) {
                return die("too many --set options%s%s", NULL, NULL);
            }
            sets[n_sets++] = v;
        } else if (strcmp(a, "--replay") == 0) {
            NEED_VALUE();
            replay_path = v;
        } else if (strcmp(a, "--theta0-elec") == 0) {
            NUM(theta0, -1000.0, 1000.0);
            have_theta0 = 1;
        } else if (strcmp(a, "--id0") == 0) {
            NUM(id0, -1.0e5, 1.0e5);
            have_id0 = 1;
        } else if (strcmp(a, "--iq0") == 0) {
            NUM(iq0, -1.0e5, 1.0e5);
            have_iq0 = 1;
        } else {
            return die("unknown option '%s'%s (see --help)", a, NULL);
        }
#undef NUM
#undef NEED_VALUE
    }

    if (machine_path == NULL) {
        return die("--machine FILE is required%s%s", NULL, NULL);
    }
    char err[512];
    static sim_machine_t pm;
    if (sim_machine_load(machine_path, &pm, err, sizeof err) != 0) {
        return die("machine file: %s%s", err, NULL);
    }

    /* ---- open-loop replay ---- */
    if (replay_path != NULL) {
        if (ctrl_name != NULL || have_tref || have_sref || free_mech || scenario_path != NULL) {
            return die("--replay is open loop: no --controller, references, --free or "
                       "--scenario%s%s",
                       NULL, NULL);
        }
        if (!have_speed) {
            return die("--replay needs --speed-rpm%s%s", NULL, NULL);
        }
        if (trace_path == NULL) {
            return die("--replay needs --trace FILE%s%s", NULL, NULL);
        }
        plant_config_t base;
        sim_machine_to_plant(&pm, &base);
        sim_replay_opts_t o = {speed_rpm, have_theta0 ? theta0 : 0.0, have_id0 ? id0 : 0.0,
                               have_iq0 ? iq0 : 0.0};
        if (sim_replay_files(&base, &o, replay_path, trace_path, err, sizeof err) != 0) {
            return die("replay: %s%s", err, NULL);
        }
        printf("replay: %s -> %s\n", replay_path, trace_path);
        return 0;
    }
    if (have_theta0 || have_id0 || have_iq0) {
        return die("--theta0-elec, --id0 and --iq0 belong to --replay%s%s", NULL, NULL);
    }

    /* ---- closed loop ---- */
    if (ctrl_name == NULL) {
        return die("--controller NAME is required (see --list-controllers)%s%s", NULL, NULL);
    }
    const ctrl_desc_t *d = ctrl_find(ctrl_name);
    if (d == NULL) {
        return die("unknown controller '%s'%s (see --list-controllers)", ctrl_name, NULL);
    }
    if (have_tref && have_sref) {
        return die("give either --torque-ref or --speed-ref-rpm, not both%s%s", NULL, NULL);
    }
    if (have_load && !free_mech) {
        return die("--load-nm needs --free (a dynamometer imposes the speed)%s%s", NULL, NULL);
    }

    static sim_run_cfg_t cfg;
    sim_run_config_default(&cfg, &pm, d);
    static sim_machine_t cm;
    if (ctrl_machine_path != NULL) {
        if (sim_machine_load(ctrl_machine_path, &cm, err, sizeof err) != 0) {
            return die("control machine file: %s%s", err, NULL);
        }
        sim_ctrl_machine_from(&cm, &cfg.ctrl_machine);
    }
    cfg.fs_hz = fs > 0.0 ? (uint32_t)fs : d->fs_default_hz;
    cfg.free_mech = free_mech != 0;
    cfg.speed_rpm = speed_rpm;
    cfg.load_nm = load_nm;
    cfg.speed_mode = have_sref != 0;
    cfg.torque_ref_nm = torque_ref;
    cfg.speed_ref_rpm = speed_ref;
    cfg.duration_s = duration;
    cfg.win_start_s = duration > 0.1 ? duration / 3.0 : 0.0;
    cfg.win_end_s = duration;
    cfg.seed = (uint64_t)seed;
    cfg.trace_decimation = (uint32_t)decim;
    if (window != NULL &&
        parse_span("--window", window, duration, &cfg.win_start_s, &cfg.win_end_s) != 0) {
        return 2;
    }
    if (trace_window != NULL && parse_span("--trace-window", trace_window, duration,
                                           &cfg.trace_start_s, &cfg.trace_end_s) != 0) {
        return 2;
    }

    /* Controller configuration and tunables. */
    static union {
        max_align_t a;
        unsigned char b[CTRL_CFG_MAX];
    } ccfg;
    if (d->cfg_size > CTRL_CFG_MAX) {
        return die("controller '%s' configuration too large%s", d->name, NULL);
    }
    if (d->cfg_default != NULL) {
        d->cfg_default(ccfg.b, &cfg.ctrl_machine);
    }
    for (size_t k = 0; k < n_sets; k++) {
        char name[96];
        const char *eq = strchr(sets[k], '=');
        if (eq == NULL || eq == sets[k] || (size_t)(eq - sets[k]) >= sizeof name) {
            return die("--set expects NAME=VALUE, got '%s'%s", sets[k], NULL);
        }
        memcpy(name, sets[k], (size_t)(eq - sets[k]));
        name[eq - sets[k]] = '\0';
        double val = 0.0;
        if (num_arg("--set", eq + 1, -INFINITY, INFINITY, &val) != 0) {
            return 2;
        }
        const int rc = ctrl_tunable_set(d, ccfg.b, name, val);
        if (rc == CTRL_ENOENT) {
            return die("controller has no tunable '%s'%s", name, NULL);
        }
        if (rc != CTRL_OK) {
            return die("tunable value out of range: '%s'%s", sets[k], NULL);
        }
    }
    cfg.ctrl_cfg = ccfg.b;

    static sim_scenario_t scn;
    if (scenario_path != NULL) {
        if (sim_scenario_load(&scn, scenario_path, err, sizeof err) != 0) {
            return die("scenario: %s%s", err, NULL);
        }
        cfg.scenario = &scn;
    }
    FILE *trace = NULL;
    if (trace_path != NULL) {
        trace = fopen(trace_path, "w");
        if (trace == NULL) {
            return die("cannot write trace file '%s': %s", trace_path, strerror(errno));
        }
        cfg.trace = trace;
    }

    static sim_run_t run;
    int status = 0;
    if (sim_run_init(&run, &cfg, err, sizeof err) != 0 || sim_run_all(&run, err, sizeof err) != 0) {
        fprintf(stderr, "sim: error: %s\n", err);
        status = 1;
    }
    if (status == 0) {
        metrics_result_t mp, mc;
        if (sim_run_metrics(&run, &mp, &mc) != 0) {
            fprintf(stderr, "sim: error: no samples in the metrics window\n");
            status = 1;
        } else {
            print_metrics(stdout, &run, &mp, &mc);
            if (metrics_path != NULL) {
                FILE *mf = fopen(metrics_path, "w");
                if (mf == NULL) {
                    fprintf(stderr, "sim: error: cannot write metrics file '%s': %s\n",
                            metrics_path, strerror(errno));
                    status = 1;
                } else {
                    sim_run_write_metrics_json(mf, &run, &mp, &mc);
                    fclose(mf);
                }
            }
            if (fw_state(&run.fw) == FW_STATE_FAULT) {
                fprintf(stderr, "sim: warning: the firmware tripped: %s\n",
                        fw_fault_name(fw_fault(&run.fw)));
            }
        }
    }
    sim_run_free(&run);
    if (trace != NULL && fclose(trace) != 0) {
        fprintf(stderr, "sim: error: writing the trace failed\n");
        status = 1;
    }
    return status;
}
