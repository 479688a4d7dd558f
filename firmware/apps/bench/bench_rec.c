/*
 * PC recorder of the interrupt-cost benchmark (tools/bench):
 *
 *   bench_rec record --machine INI --speed RPM --torque NM --periods N --outdir DIR
 *                    [--ctrl NAME] [--sensorless 0|1|2] [--fs HZ]
 *       For every registered controller (or NAME): a closed loop on the PC
 *       (plant, dynamometer at RPM + hal/sim + firmware) from fw_init through
 *       calibration and arm, then N running periods at the controller's
 *       default fs (or HZ); writes DIR/<name>_<rpm>.bin (bench_blob.h).
 *   bench_rec list
 *       The registered controllers, one per line.
 * (A separate program from bench_host: hal/sim and the replay HAL both define
 * the hal.h functions.)
 */
#define _POSIX_C_SOURCE 200809L
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_blob.h"
#include "controller.h"
#include "hal_sim.h"
#include "pipeline.h"
#include "plant.h"
#include "rec_loop.h"
#include "sim_machine.h"
#include "sim_num.h"
#include "sim_run.h"

_Static_assert(BENCH_CMD_TORQUE == PIL_CMD_TORQUE && BENCH_CMD_ARM == PIL_CMD_ARM,
               "the recorded command bits are the PIL ones");

static int die(const char *msg, const char *arg)
{
    fprintf(stderr, "bench_rec: %s%s\n", msg, arg != NULL ? arg : "");
    return 1;
}

static void put_name(char *dst, size_t n, const char *src)
{
    memset(dst, 0, n);
    strncpy(dst, src, n - 1u);
}

/* ---- record ------------------------------------------------------------ */

static int record_one(const ctrl_desc_t *d, const sim_machine_t *sm, double speed_rpm,
                      double torque_nm, uint32_t periods, unsigned sensorless, uint32_t fs_hz,
                      const char *outdir)
{
    static rec_loop_t loop;
    const uint32_t calib = 256u;
    ctrl_machine_t cm;
    sim_ctrl_machine_from(sm, &cm);
    const uint32_t fs = fs_hz != 0u              ? fs_hz
                        : d->fs_default_hz != 0u ? d->fs_default_hz
                                                 : (uint32_t)sm->fs_hz;
    const char *fail = rec_loop_init(&loop, d, sm, fs, speed_rpm, calib, sensorless);
    if (fail != NULL) {
        return die(fail, d->name);
    }
    const hal_info_t info = loop.info;
    const uint32_t max = calib + 32u + periods;
    const size_t bytes = sizeof(bench_hdr_t) + (size_t)max * sizeof(bench_rec_t);
    if (bytes > BENCH_BLOB_MAX) {
        return die("too many periods for the QEMU blob window", NULL);
    }
    unsigned char *blob = calloc(1u, bytes);
    if (blob == NULL) {
        return die("out of memory", NULL);
    }
    bench_hdr_t *h = (bench_hdr_t *)(void *)blob;
    bench_rec_t *rec = (bench_rec_t *)(void *)(h + 1);
    uint32_t n = 0u, after_arm = 0u;
    while (n < max && after_arm < periods) {
        pil_in_t in;
        rec_loop_isr(&loop, torque_nm, &in);
        if (in.cmd != 0u) {
            h->arm_index = n;
        }
        bench_rec_t *r = &rec[n];
        memcpy(r->adc, in.adc, sizeof r->adc);
        r->cmd = in.cmd; /* BENCH_CMD_* == PIL_CMD_* (asserted above) */
        r->index_seen = in.index_seen;
        r->trip = in.trip;
        r->enc_count = in.enc_count;
        r->index_count = in.index_count;
        r->state_after = (uint8_t)fw_state(&loop.fw);
        for (int x = 0; x < 3; x++) {
            r->cmp[x] = loop.hal.shadow.cmp[x];
        }
        if (rec_loop_end(&loop) != PLANT_OK) {
            free(blob);
            return die("plant failed for ", d->name);
        }
        n++;
        after_arm += loop.armed ? 1u : 0u;
    }
    if (!loop.armed) {
        fprintf(stderr, "bench_rec: %s: never armed (state %s, fault %s)\n", d->name,
                fw_state_name(fw_state(&loop.fw)), fw_fault_name(fw_fault(&loop.fw)));
        free(blob);
        return 1;
    }
    if (fw_state(&loop.fw) != FW_STATE_RUNNING) {
        /* Kept: the benchmark counts the running periods before the fault
         * and reports the fault (a property of the controller, not of the bench). */
        fprintf(stderr,
                "bench_rec: warning: %s at %.0f r/min: not running at the end (state %s, "
                "fault %s)\n",
                d->name, speed_rpm, fw_state_name(fw_state(&loop.fw)),
                fw_fault_name(fw_fault(&loop.fw)));
    }
    h->magic = BENCH_MAGIC;
    h->version = BENCH_VERSION;
    h->n = n;
    h->calib_samples = calib;
    h->torque_ref_q24 = loop.torque_ref_armed;
    h->speed_rpm = (uint32_t)(speed_rpm + 0.5);
    h->torque_mnm = (uint32_t)(torque_nm * 1000.0 + 0.5);
    put_name(h->ctrl_name, sizeof h->ctrl_name, d->name);
    h->pwm_freq_hz = info.pwm_freq_hz;
    h->period_counts = info.period_counts;
    h->encoder_counts_per_rev = info.encoder_counts_per_rev;
    h->cycle_clock_hz = info.cycle_clock_hz;
    h->adc_bits = info.adc_bits;
    h->has_i_c = info.has_i_c ? 1u : 0u;
    h->sensorless = sensorless; /* 2: with the injection (bench_blob.h) */
    h->adc_current_a_per_count = info.adc_current_a_per_count;
    h->adc_vdc_v_per_count = info.adc_vdc_v_per_count;
    h->pole_pairs = cm.pole_pairs;
    h->rs_ohm = cm.rs_ohm;
    h->ld_h = cm.ld_h;
    h->lq_h = cm.lq_h;
    h->psi_pm_wb = cm.psi_pm_wb;
    h->vdc_v = cm.vdc_v;
    h->inertia_kgm2 = cm.inertia_kgm2;
    h->torque_rated_nm = cm.torque_rated_nm;
    h->speed_rated_rpm = cm.speed_rated_rpm;
    h->current_rated_a = cm.current_rated_a;
    h->current_max_a = cm.current_max_a;
    h->psi_ref_wb = cm.psi_ref_wb;
    put_name(h->machine_name, sizeof h->machine_name, cm.name != NULL ? cm.name : "machine");
    h->dead_time_s = sm->dead_time_s; /* as rec_loop_init configured the drive */
    h->v_fwd_v = sm->v_fwd_v;
    char path[4096];
    snprintf(path, sizeof path, "%s/%s_%u.bin", outdir, d->name, h->speed_rpm);
    FILE *f = fopen(path, "wb");
    const size_t used = sizeof *h + (size_t)n * sizeof *rec;
    int rc = 0;
    if (f == NULL || fwrite(blob, 1u, used, f) != used) {
        rc = die("cannot write ", path);
    }
    if (f != NULL && fclose(f) != 0) {
        rc = die("cannot write ", path);
    }
    free(blob);
    return rc;
}

static int cmd_record(int argc, char **argv)
{
    const char *machine = NULL, *outdir = NULL, *only = NULL;
    double speed = 750.0, torque = 1.8;
    unsigned long periods = 2000u, fs = 0u;
    unsigned sensorless = 0u;
    for (int i = 0; i < argc; i += 2) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (v == NULL) {
            return die("missing value after ", a);
        }
        char *end = NULL;
        if (strcmp(a, "--machine") == 0) {
            machine = v;
        } else if (strcmp(a, "--outdir") == 0) {
            outdir = v;
        } else if (strcmp(a, "--ctrl") == 0) {
            only = v;
        } else if (strcmp(a, "--speed") == 0) {
            if (sim_num_parse(v, &speed) != 0 || !(speed >= 0.0) || speed > 20000.0) {
                return die("--speed expects 0 .. 20000 r/min, got ", v);
            }
        } else if (strcmp(a, "--torque") == 0) {
            if (sim_num_parse(v, &torque) != 0 || !(torque >= 0.0) || torque > 10000.0) {
                return die("--torque expects 0 .. 10000 N*m, got ", v);
            }
        } else if (strcmp(a, "--sensorless") == 0) {
            if (strcmp(v, "0") != 0 && strcmp(v, "1") != 0 && strcmp(v, "2") != 0) {
                return die("--sensorless expects 0, 1 or 2 (with the injection), got ", v);
            }
            sensorless = (unsigned)(v[0] - '0');
        } else if (strcmp(a, "--fs") == 0) {
            fs = strtoul(v, &end, 10);
            if (*end != '\0' || fs < 1000u || fs > 200000u) {
                return die("--fs expects 1000 .. 200000 Hz, got ", v);
            }
        } else if (strcmp(a, "--periods") == 0) {
            periods = strtoul(v, &end, 10);
            if (*end != '\0' || periods == 0u || periods > 20000u) {
                return die("--periods expects 1 .. 20000, got ", v);
            }
        } else {
            return die("unknown option ", a);
        }
    }
    if (machine == NULL || outdir == NULL) {
        return die("record needs --machine and --outdir", NULL);
    }
    sim_machine_t sm;
    char err[512];
    if (sim_machine_load(machine, &sm, err, sizeof err) != 0) {
        return die(err, NULL);
    }
    if (only != NULL) {
        const ctrl_desc_t *d = ctrl_find(only);
        if (d == NULL) {
            return die("unknown controller ", only);
        }
        return record_one(d, &sm, speed, torque, (uint32_t)periods, sensorless, (uint32_t)fs,
                          outdir);
    }
    for (size_t i = 0; i < ctrl_count(); i++) {
        if (record_one(ctrl_at(i), &sm, speed, torque, (uint32_t)periods, sensorless, (uint32_t)fs,
                       outdir) != 0) {
            return 1;
        }
    }
    return 0;
}

int main(int argc, char **argv)
{
    if (argc >= 2 && strcmp(argv[1], "record") == 0) {
        return cmd_record(argc - 2, argv + 2);
    }
    if (argc >= 2 && strcmp(argv[1], "list") == 0) {
        for (size_t i = 0; i < ctrl_count(); i++) {
            printf("%s\n", ctrl_at(i)->name);
        }
        return 0;
    }
    return die("usage: bench_rec record|list ... (see bench_rec.c)", NULL);
}
