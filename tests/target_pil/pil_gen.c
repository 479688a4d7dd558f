/*
 * Host generator of pil_data.c (see pil_data.h), run by CMake at build time:
 *   pil_gen --machine FILE --out pil_data.c [--periods N] [--cl a,b,c] [--cl-duration S]
 * 1. For EVERY registered controller: a host closed loop (plant + hal/sim +
 *    firmware) on the machine at 750 r/min (dynamometer), 1.8 N*m, from fw_init
 *    through calibration and arm, then N periods (default 600); every ISR's
 *    inputs and outputs are written as const arrays.
 * 2. For the --cl controllers (default bst,fst,m2ptfc): the same scenario run
 *    by the host simulator library (sim_run) for --cl-duration seconds with the
 *    ADC noise off (the PIL default), its settings and metrics (--cl none: no
 *    closed loops, recordings only).
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "controller.h"
#include "hal_sim.h"
#include "metrics.h"
#include "pil_cl.h"
#include "pil_data.h"
#include "pipeline.h"
#include "plant.h"
#include "rec_loop.h"
#include "sim_machine.h"
#include "sim_run.h"

#define GEN_SPEED_RPM 750.0
#define GEN_TORQUE_NM 1.8
#define GEN_CALIB 256u
/* Calibration of the closed-loop scenarios: short, because with the gates open
 * the plant integrates by RK4 at 0.5 us (~4 M soft-float instructions per
 * period in QEMU); the offsets are exact either way (no ADC noise in PIL). */
#define GEN_CL_CALIB 16u
/* Recorded again without the encoder (fw_config_t.sensorless), for
 * GEN_SL_S of simulated time after arm each: long enough for the forced
 * start, its ramp and the handover to the observer (about 0.11 s on the
 * thesis SPMSM). */
static const char *const gen_sl[] = {"m2ptfc", "drr", "fst", "foc"};
#define GEN_SL_S 0.15

static int die(const char *msg, const char *arg)
{
    fprintf(stderr, "pil_gen: %s%s\n", msg, arg != NULL ? arg : "");
    return 1;
}

static void put_machine(FILE *f, const ctrl_machine_t *m)
{
    fprintf(f,
            "{\"%s\", %d, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g, "
            "%.17g, %.17g}",
            m->name, m->pole_pairs, m->rs_ohm, m->ld_h, m->lq_h, m->psi_pm_wb, m->vdc_v,
            m->inertia_kgm2, m->torque_rated_nm, m->speed_rated_rpm, m->current_rated_a,
            m->current_max_a, m->psi_ref_wb);
}

static void put_array(FILE *f, const char *name, const double *v, int n)
{
    fprintf(f, ", .%s = {", name);
    for (int i = 0; i < n; i++) {
        fprintf(f, "%s%.17g", i ? ", " : "", v[i]);
    }
    fprintf(f, "}");
}

/* A sim_machine_t initializer (designated, so new fields default to 0),
 * [mechanics]' non-ideal terms included (plant_config_t takes them from it). */
static void put_sim_machine(FILE *f, const sim_machine_t *m)
{
    fprintf(f,
            "{.name = \"%s\", .pole_pairs = %d, .rs_ohm = %.17g, .ld_h = %.17g, .lq_h = %.17g, "
            ".psi_pm_wb = %.17g, .torque_rated_nm = %.17g, .speed_rated_rpm = %.17g, "
            ".current_rated_a = %.17g, .current_max_a = %.17g, .psi_ref_wb = %.17g, "
            ".vdc_v = %.17g, .fs_hz = %.17g, .dead_time_s = %.17g, .v_fwd_v = %.17g, "
            ".dc_cap_f = %.17g, .dc_src_r_ohm = %.17g, .inertia_kgm2 = %.17g, "
            ".friction_nms = %.17g, .overspeed_rpm = %.17g, .speed_bw_hz = %.17g, "
            ".speed_pm_deg = %.17g, .speed_kp = %.17g, .speed_ki = %.17g",
            m->name, m->pole_pairs, m->rs_ohm, m->ld_h, m->lq_h, m->psi_pm_wb, m->torque_rated_nm,
            m->speed_rated_rpm, m->current_rated_a, m->current_max_a, m->psi_ref_wb, m->vdc_v,
            m->fs_hz, m->dead_time_s, m->v_fwd_v, m->dc_cap_f, m->dc_src_r_ohm, m->inertia_kgm2,
            m->friction_nms, m->overspeed_rpm, m->speed_bw_hz, m->speed_pm_deg, m->speed_kp,
            m->speed_ki);
    fprintf(f,
            ", .coulomb_nm = %.17g, .stiction_nm = %.17g, .slots = %d, .cogging_nm = %.17g, "
            ".cogging_phase_deg = %.17g, .cog_harm_n = %d, .cog_harm_deg_n = %d",
            m->coulomb_nm, m->stiction_nm, m->slots, m->cogging_nm, m->cogging_phase_deg,
            m->cog_harm_n, m->cog_harm_deg_n);
    put_array(f, "cog_harm_nm", m->cog_harm_nm, PLANT_COG_MAX - 1);
    put_array(f, "cog_harm_deg", m->cog_harm_deg, PLANT_COG_MAX - 1);
    fprintf(f, ", .load_kind = %d, .load_nm = %.17g, .load_profile = {.kind = %d, .n = %d",
            (int)m->load_kind, m->load_nm, (int)m->load_profile.kind, m->load_profile.n);
    put_array(f, "x", m->load_profile.x, PLANT_PROFILE_MAX);
    put_array(f, "y", m->load_profile.y, PLANT_PROFILE_MAX);
    fprintf(f, "}}");
}

static uint32_t fs_of(const ctrl_desc_t *d, const sim_machine_t *m)
{
    return d->fs_default_hz != 0u ? d->fs_default_hz : (uint32_t)m->fs_hz;
}

/* Records one controller; returns 0 or 1. */
static int record(FILE *f, size_t idx, const ctrl_desc_t *d, const sim_machine_t *sm,
                  uint32_t periods, bool sensorless, uint32_t *n_out, int32_t *tref_out,
                  hal_info_t *info_out)
{
    static rec_loop_t loop;
    /* Sensorless: the dynamometer at the forced start's final speed (5 % of
     * rated), so that the forced frame, the handover and the observer all
     * run within the recording. */
    const double rpm = sensorless ? 0.05 * sm->speed_rated_rpm : GEN_SPEED_RPM;
    const char *fail = rec_loop_init(&loop, d, sm, fs_of(d, sm), rpm, GEN_CALIB, sensorless);
    if (fail != NULL) {
        return die(fail, d->name);
    }
    *info_out = loop.info;
    const hal_t *hal = &loop.hal;
    const uint32_t max = GEN_CALIB + 32u + periods;
    pil_in_t *in = calloc(max, sizeof *in);
    pil_out_t *out = calloc(max, sizeof *out);
    if (in == NULL || out == NULL) {
        free(in);
        free(out);
        return die("out of memory", NULL);
    }
    uint32_t n = 0u, after_arm = 0u;
    while (n < max && after_arm < periods) {
        rec_loop_isr(&loop, GEN_TORQUE_NM, &in[n]);
        const fw_telemetry_t *tm = fw_telemetry(&loop.fw);
        pil_out_t *o = &out[n];
        for (int x = 0; x < 3; x++) {
            o->cmp[x] = hal->shadow.cmp[x];
            o->legs[x] = tm->legs[x];
        }
        o->gates = (hal->gates_on || hal->gate_enable_pending) ? 1u : 0u;
        o->state = tm->state;
        o->fault = tm->fault;
        o->vec = tm->vec;
        o->i_a = tm->i_a;
        o->i_b = tm->i_b;
        o->vdc = tm->vdc;
        o->i_d = tm->i_d;
        o->i_q = tm->i_q;
        o->psi_d = tm->psi_d;
        o->psi_q = tm->psi_q;
        o->torque = tm->torque;
        o->omega_e = tm->omega_e;
        o->torque_ref = tm->torque_ref;
        o->duty = tm->duty;
        o->theta_e = tm->theta_e;
        o->period = tm->period;
        o->cycles = tm->cycles;
        if (rec_loop_end(&loop) != PLANT_OK) {
            free(in);
            free(out);
            return die("plant failed for ", d->name);
        }
        n++;
        if (loop.armed) {
            after_arm++;
        }
    }
    if (!loop.armed) {
        fprintf(stderr, "pil_gen: %s: never became ready (state %s, fault %s)\n", d->name,
                fw_state_name(fw_state(&loop.fw)), fw_fault_name(fw_fault(&loop.fw)));
        free(in);
        free(out);
        return 1;
    }
    if (fw_state(&loop.fw) != FW_STATE_RUNNING) {
        /* Still a valid recording (the replay compares whatever happened), but
         * the controller did not hold the operating point: say so. */
        fprintf(stderr, "pil_gen: warning: %s: state %s, fault %s at the end of the recording\n",
                d->name, fw_state_name(fw_state(&loop.fw)), fw_fault_name(fw_fault(&loop.fw)));
    }
    fprintf(f, "static const pil_in_t rec%zu_in[%u] = {\n", idx, n);
    for (uint32_t k = 0; k < n; k++) {
        const pil_in_t *i = &in[k];
        fprintf(f, "{{%u,%u,%u,%u},%u,%u,%u,%uu,%uu},\n", i->adc[0], i->adc[1], i->adc[2],
                i->adc[3], i->cmd, i->index_seen, i->trip, i->enc_count, i->index_count);
    }
    fprintf(f, "};\nstatic const pil_out_t rec%zu_out[%u] = {\n", idx, n);
    for (uint32_t k = 0; k < n; k++) {
        const pil_out_t *o = &out[k];
        fprintf(f,
                "{{%uu,%uu,%uu},%u,%u,%u,%u,%ld,%ld,%ld,%ld,%ld,%ld,%ld,%ld,%ld,%ld,%ld,{%ld,%ld,%"
                "ld},%uu,%uu,"
                "%uu},\n",
                o->cmp[0], o->cmp[1], o->cmp[2], o->gates, o->state, o->fault, o->vec, (long)o->i_a,
                (long)o->i_b, (long)o->vdc, (long)o->i_d, (long)o->i_q, (long)o->psi_d,
                (long)o->psi_q, (long)o->torque, (long)o->omega_e, (long)o->torque_ref,
                (long)o->duty, (long)o->legs[0], (long)o->legs[1], (long)o->legs[2], o->theta_e,
                o->period, o->cycles);
    }
    fprintf(f, "};\n\n");
    free(in);
    free(out);
    *n_out = n;
    *tref_out = loop.torque_ref_armed;
    return 0;
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void put_num(FILE *f, double v)
{
    if (isfinite(v)) {
        fprintf(f, "%.17g, ", v);
    } else {
        fprintf(f, "(double)NAN, ");
    }
}

#define GEN_TOL_RUNS 6

/* One host run of the PIL scenario at speed_rpm; fills the metrics. */
static int cl_run(sim_run_t *r, const ctrl_desc_t *d, const sim_machine_t *sm, double duration,
                  double speed_rpm, pil_metrics_t *m)
{
    sim_run_cfg_t c;
    sim_run_config_default(&c, sm, d);
    c.fs_hz = fs_of(d, sm);
    c.speed_rpm = speed_rpm;
    c.torque_ref_nm = GEN_TORQUE_NM;
    c.duration_s = duration;
    c.win_start_s = 0.1;
    c.win_end_s = duration;
    c.calib_samples = GEN_CL_CALIB;
    c.hal.adc_noise_counts = 0.0; /* PIL default: no noise */
    char err[256];
    if (sim_run_init(r, &c, err, sizeof err) != 0 || sim_run_all(r, err, sizeof err) != 0) {
        return die("host closed loop: ", err);
    }
    metrics_result_t mp, mc;
    if (sim_run_metrics(r, &mp, &mc) != 0) {
        sim_run_free(r);
        return die("metrics failed for ", d->name);
    }
    m->torque_mean_nm = mp.torque_mean_nm;
    m->torque_ripple_nm = mp.torque_ripple_nm;
    m->flux_mean_wb = mp.flux_mean_wb;
    m->flux_ripple_wb = mp.flux_ripple_wb;
    m->torque_sse_nm = mp.torque_sse_nm;
    m->f_av_hz = mp.f_av_hz;
    m->thd_i_pct = mp.thd_i_pct;
    m->torque_mean_ctrl_nm = mc.torque_mean_nm;
    m->torque_ripple_ctrl_nm = mc.torque_ripple_nm;
    m->flux_mean_ctrl_wb = mc.flux_mean_wb;
    m->flux_ripple_ctrl_wb = mc.flux_ripple_wb;
    m->torque_sse_ctrl_nm = mc.torque_sse_nm;
    if (fw_state(&r->fw) != FW_STATE_RUNNING) {
        fprintf(stderr, "pil_gen: %s: host closed loop ended in state %s (%s)\n", d->name,
                fw_state_name(fw_state(&r->fw)), fw_fault_name(fw_fault(&r->fw)));
        sim_run_free(r);
        return 1;
    }
    return 0;
}

#define GEN_NMETRICS 12
static void metrics_vec(const pil_metrics_t *m, double v[GEN_NMETRICS])
{
    const double a[GEN_NMETRICS] = {
        m->torque_mean_nm,    m->torque_ripple_nm,    m->flux_mean_wb,
        m->flux_ripple_wb,    m->torque_sse_nm,       m->f_av_hz,
        m->thd_i_pct,         m->torque_mean_ctrl_nm, m->torque_ripple_ctrl_nm,
        m->flux_mean_ctrl_wb, m->flux_ripple_ctrl_wb, m->torque_sse_ctrl_nm};
    memcpy(v, a, sizeof a);
}

static void put_metrics(FILE *f, const double v[GEN_NMETRICS])
{
    fprintf(f, "{");
    for (size_t i = 0; i < GEN_NMETRICS; i++) {
        put_num(f, v[i]);
    }
    fprintf(f, "}");
}

/* Host closed loop of the PIL scenario (+ the perturbed runs for the
 * tolerance); writes one pil_cl_t initializer. */
static int closed_loop(FILE *f, const ctrl_desc_t *d, const sim_machine_t *sm, double duration)
{
    static sim_run_t r;
    pil_metrics_t nominal, pert;
    const double t0 = now_s();
    if (cl_run(&r, d, sm, duration, GEN_SPEED_RPM, &nominal) != 0) {
        return 1;
    }
    const double wall = now_s() - t0;
    double vn[GEN_NMETRICS], vp[GEN_NMETRICS], dev[GEN_NMETRICS] = {0};
    metrics_vec(&nominal, vn);
    for (int k = 1; k <= GEN_TOL_RUNS; k++) {
        static sim_run_t rp;
        if (cl_run(&rp, d, sm, duration, GEN_SPEED_RPM * (1.0 + 1e-12 * (double)k), &pert) != 0) {
            sim_run_free(&r);
            return 1;
        }
        sim_run_free(&rp);
        metrics_vec(&pert, vp);
        for (size_t i = 0; i < GEN_NMETRICS; i++) {
            const double e = fabs(vp[i] - vn[i]);
            if (isfinite(e) && e > dev[i]) {
                dev[i] = e;
            }
        }
    }
    for (size_t i = 0; i < GEN_NMETRICS; i++) {
        /* 3 x the observed spread, at least a relative 1e-9 of the value. */
        const double floor_tol = 1e-9 * fabs(vn[i]);
        dev[i] = 3.0 * dev[i] > floor_tol ? 3.0 * dev[i] : floor_tol;
    }
    const sim_run_cfg_t *rc = &r.cfg;
    fprintf(f, "{\"%s\", ", d->name);
    put_machine(f, &rc->ctrl_machine);
    fprintf(f, ",\n ");
    put_sim_machine(f, &rc->plant_machine);
    fprintf(f, ",\n ");
    put_num(f, rc->speed_rpm);
    fprintf(f, "\n %uu, %uu, %u, ", rc->fs_hz, rc->hal.timer_clock_hz, rc->hal.adc_bits);
    put_num(f, rc->hal.i_fullscale_a);
    put_num(f, rc->hal.vdc_fullscale_v);
    put_num(f, rc->hal.adc_noise_counts);
    put_num(f, rc->hal.trip_level_a);
    fprintf(f, "%uu, %u, %uu, ", rc->hal.enc_lines, rc->hal.enc_index ? 1u : 0u, rc->calib_samples);
    put_num(f, rc->torque_ref_nm);
    put_num(f, rc->duration_s);
    put_num(f, rc->win_start_s);
    put_num(f, rc->win_end_s);
    fprintf(f, "\n ");
    put_metrics(f, vn);
    fprintf(f, ",\n ");
    put_metrics(f, dev);
    fprintf(f, ", %u, %.3f},\n", GEN_TOL_RUNS, wall);
    fprintf(stderr,
            "pil_gen: host %s: T %.4f N*m ripple %.4f (tol %.2g), psi %.4f ripple %.5f, "
            "f_av %.0f Hz (tol %.2g), THD %.2f %%; ctrl-instant T %.4f ripple %.4f (%.2f s "
            "wall)\n",
            d->name, vn[0], vn[1], dev[1], vn[2], vn[3], vn[5], dev[5], vn[6], vn[7], vn[8], wall);
    sim_run_free(&r);
    return 0;
}

int main(int argc, char **argv)
{
    const char *machine = NULL, *out = NULL, *cl = "bst,fst,m2ptfc";
    unsigned long periods = 600u;
    double cl_duration = 0.5;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (v == NULL) {
            return die("missing value after ", a);
        }
        if (strcmp(a, "--machine") == 0) {
            machine = v;
        } else if (strcmp(a, "--out") == 0) {
            out = v;
        } else if (strcmp(a, "--periods") == 0) {
            char *end;
            periods = strtoul(v, &end, 10);
            if (*end != '\0' || periods == 0u || periods > 100000u) {
                return die("--periods expects 1..100000, got ", v);
            }
        } else if (strcmp(a, "--cl") == 0) {
            cl = v;
        } else if (strcmp(a, "--cl-duration") == 0) {
            char *end;
            cl_duration = strtod(v, &end);
            if (*end != '\0' || !(cl_duration > 0.1) || cl_duration > 10.0) {
                return die("--cl-duration expects 0.1 .. 10 s, got ", v);
            }
        } else {
            return die("unknown option ", a);
        }
        i++;
    }
    if (machine == NULL || out == NULL) {
        return die("usage: pil_gen --machine FILE --out FILE.c [--periods N] [--cl a,b] "
                   "[--cl-duration S]",
                   NULL);
    }
    sim_machine_t sm;
    char err[512];
    if (sim_machine_load(machine, &sm, err, sizeof err) != 0) {
        return die(err, NULL);
    }
    char tmp[4096];
    snprintf(tmp, sizeof tmp, "%s.tmp", out);
    FILE *f = fopen(tmp, "w");
    if (f == NULL) {
        return die("cannot write ", tmp);
    }
    fprintf(f,
            "/* Generated by pil_gen from %s: do not edit. */\n#include <math.h>\n\n"
            "#include \"pil_cl.h\"\n#include \"pil_data.h\"\n\n",
            machine);
    /* Every controller with the encoder, then those of gen_sl in this
     * registry without it. */
    const ctrl_desc_t *recs[64];
    bool rec_sl[64];
    size_t nc = 0u;
    for (size_t i = 0; i < ctrl_count() && nc < 64u; i++, nc++) {
        recs[nc] = ctrl_at(i);
        rec_sl[nc] = false;
    }
    for (size_t i = 0; i < sizeof gen_sl / sizeof gen_sl[0] && nc < 64u; i++) {
        const ctrl_desc_t *d = ctrl_find(gen_sl[i]);
        if (d != NULL) {
            recs[nc] = d;
            rec_sl[nc++] = true;
        }
    }
    uint32_t *n = calloc(nc, sizeof *n);
    int32_t *tref = calloc(nc, sizeof *tref);
    hal_info_t *info = calloc(nc, sizeof *info);
    int rc = (n == NULL || tref == NULL || info == NULL) ? 1 : 0;
    for (size_t i = 0; i < nc && rc == 0; i++) {
        const uint32_t np =
            rec_sl[i] ? (uint32_t)ceil(GEN_SL_S * (double)fs_of(recs[i], &sm)) : (uint32_t)periods;
        rc = record(f, i, recs[i], &sm, np, rec_sl[i], &n[i], &tref[i], &info[i]);
    }
    if (rc == 0) {
        ctrl_machine_t cm;
        sim_ctrl_machine_from(&sm, &cm);
        fprintf(f, "const pil_rec_t pil_recs[] = {\n");
        for (size_t i = 0; i < nc; i++) {
            const hal_info_t *h = &info[i];
            fprintf(f, "{\"%s\", {%uu, %uu, %u, %.17g, %.17g, %uu, %s, %uu},\n ", recs[i]->name,
                    h->pwm_freq_hz, h->period_counts, h->adc_bits, h->adc_current_a_per_count,
                    h->adc_vdc_v_per_count, h->encoder_counts_per_rev,
                    h->has_i_c ? "true" : "false", h->cycle_clock_hz);
            put_machine(f, &cm);
            fprintf(f, ", %uu, %ld, %uu, rec%zu_in, rec%zu_out, %u},\n", GEN_CALIB, (long)tref[i],
                    n[i], i, i, rec_sl[i] ? 1u : 0u);
        }
        fprintf(f, "};\nconst size_t pil_n_recs = %zu;\n\nconst pil_cl_t pil_cl[] = {\n", nc);
        char list[256];
        snprintf(list, sizeof list, "%s", cl);
        size_t ncl = 0u;
        for (char *tok = strtok(list, ","); tok != NULL && rc == 0; tok = strtok(NULL, ",")) {
            if (strcmp(tok, "none") == 0) {
                continue;
            }
            const ctrl_desc_t *d = ctrl_find(tok);
            if (d == NULL) {
                fprintf(stderr, "pil_gen: --cl: %s is not registered: skipped\n", tok);
                continue;
            }
            rc = closed_loop(f, d, &sm, cl_duration);
            ncl++;
        }
        /* A terminating entry keeps the array non-empty. */
        fprintf(
            f, "{NULL}};\nconst size_t pil_n_cl = %zu;\n\nconst sim_machine_t pil_machine = ", ncl);
        put_sim_machine(f, &sm);
        fprintf(f, ";\n");
    }
    free(n);
    free(tref);
    free(info);
    if (fclose(f) != 0 || rc != 0) {
        remove(tmp);
        return rc != 0 ? rc : die("write error on ", tmp);
    }
    if (rename(tmp, out) != 0) {
        return die("cannot rename to ", out);
    }
    return 0;
}
