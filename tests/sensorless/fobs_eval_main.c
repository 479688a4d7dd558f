/*
 * fobs_eval: the flux observer beside an encoder-run closed loop (fobs_eval.h).
 *   fobs_eval --machine FILE [--controller NAME] [--fs HZ] [--speed-ref-rpm R]
 *             [--load-nm T] [--load-passive-nm T] [--scenario FILE]
 *             [--duration S] [--window A:B] [--rs-scale X] [--l-scale X]
 *             [--psi-scale X] [--dead-time-ns N] [--v-fwd V] [--compensate]
 *             [--noise COUNTS] [--k0 RAD_S] [--kappa K] [--kenc RAD_S]
 *             [--pll-hz HZ] [--psi-tau S] [--arm-delay PERIODS] [--csv FILE]
 * Prints one line of key=value results.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fobs_eval.h"

static char *slurp(const char *path)
{
    FILE *f = fopen(path, "r");
    if (f == NULL) {
        return NULL;
    }
    static char buf[65536];
    const size_t n = fread(buf, 1, sizeof buf - 1u, f);
    buf[n] = '\0';
    fclose(f);
    return buf;
}

int main(int argc, char **argv)
{
    fobs_eval_cfg_t c;
    fobs_eval_default(&c);
    ctrl_fobs_config_t *o = &c.fobs;
    int have_fobs = 0;
    double k0 = -1, kappa = -1, kenc = -1, pll = -1, psi_tau = -1;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
#define OPT(name) (strcmp(a, name) == 0 && v != NULL && (i++, 1))
        if (OPT("--machine")) {
            c.machine_path = v;
        } else if (OPT("--controller")) {
            c.controller = v;
        } else if (OPT("--fs")) {
            c.fs_hz = (unsigned)atoi(v);
        } else if (OPT("--speed-ref-rpm")) {
            c.speed_ref_rpm = atof(v);
        } else if (OPT("--load-nm")) {
            c.load_nm = atof(v);
        } else if (OPT("--load-passive-nm")) {
            c.load_passive_nm = atof(v);
        } else if (OPT("--scenario")) {
            c.scenario = slurp(v);
            if (c.scenario == NULL) {
                fprintf(stderr, "cannot read %s\n", v);
                return 2;
            }
        } else if (OPT("--duration")) {
            c.duration_s = atof(v);
            c.win_end_s = c.duration_s;
        } else if (OPT("--window")) {
            if (sscanf(v, "%lf:%lf", &c.win_start_s, &c.win_end_s) != 2) {
                return 2;
            }
        } else if (OPT("--rs-scale")) {
            c.rs_scale = atof(v);
        } else if (OPT("--l-scale")) {
            c.l_scale = atof(v);
        } else if (OPT("--psi-scale")) {
            c.psi_scale = atof(v);
        } else if (OPT("--dead-time-ns")) {
            c.dead_time_ns = atof(v);
        } else if (OPT("--v-fwd")) {
            c.v_fwd_v = atof(v);
        } else if (strcmp(a, "--compensate") == 0) {
            c.compensate = true;
        } else if (OPT("--stat-min")) {
            c.stat_min_speed = atof(v);
        } else if (OPT("--noise")) {
            c.noise_counts = atof(v);
        } else if (OPT("--k0")) {
            k0 = atof(v);
        } else if (OPT("--kappa")) {
            kappa = atof(v);
        } else if (OPT("--kenc")) {
            kenc = atof(v);
        } else if (OPT("--pll-hz")) {
            pll = atof(v);
        } else if (OPT("--psi-tau")) {
            psi_tau = atof(v);
        } else if (OPT("--arm-delay")) {
            c.arm_delay_periods = (unsigned)atoi(v);
        } else if (OPT("--csv")) {
            c.csv = fopen(v, "w");
        } else {
            fprintf(stderr, "fobs_eval: unknown or incomplete option %s\n", a);
            return 2;
        }
#undef OPT
    }
    if (c.machine_path == NULL) {
        fprintf(stderr, "fobs_eval: --machine FILE is required\n");
        return 2;
    }
    if (k0 >= 0 || kappa >= 0 || kenc >= 0 || pll >= 0 || psi_tau >= 0) {
        sim_machine_t m;
        char err[256];
        if (sim_machine_load(c.machine_path, &m, err, sizeof err) != 0) {
            fprintf(stderr, "%s\n", err);
            return 2;
        }
        ctrl_machine_t cm;
        sim_ctrl_machine_from(&m, &cm);
        ctrl_fobs_config_default(o, &cm);
        have_fobs = 1;
        if (k0 >= 0) {
            o->k0_rad_s = k0;
        }
        if (kappa >= 0) {
            o->kappa = kappa;
        }
        if (kenc >= 0) {
            o->kenc_rad_s = kenc;
        }
        if (pll >= 0) {
            o->pll_hz = pll;
        }
        if (psi_tau >= 0) {
            o->psi_tau_s = psi_tau;
        }
    }
    c.has_fobs = have_fobs != 0;
    if (c.csv != NULL) {
        fprintf(c.csv, "t,theta_true_deg,ang_err_deg,speed_rpm,spd_err_rpm,torque,tq_err,enc_tq_"
                       "err,psi_pm_est\n");
    }
    fobs_eval_res_t r;
    char err[512];
    if (fobs_eval_run(&c, &r, err, sizeof err) != 0) {
        fprintf(stderr, "fobs_eval: %s\n", err);
        return 1;
    }
    if (c.csv != NULL) {
        fclose(c.csv);
    }
    printf("ok=%d n=%lu ang_rms=%.3f ang_mean=%.3f ang_max=%.3f spd_rms=%.2f spd_max=%.2f "
           "tq_mean=%.4f tq_rms=%.4f enc_tq_mean=%.4f enc_tq_rms=%.4f cm_tq_mean=%.4f "
           "psi_pm_est=%.5f speed_end=%.1f fw_spd_rms=%.2f\n",
           r.ok, r.n, r.ang_rms_deg, r.ang_mean_deg, r.ang_max_deg, r.spd_rms_rpm, r.spd_max_rpm,
           r.tq_err_mean_nm, r.tq_err_rms_nm, r.enc_tq_err_mean_nm, r.enc_tq_err_rms_nm,
           r.cm_tq_err_mean_nm, r.psi_pm_est_wb, r.speed_end_rpm, r.fw_spd_rms_rpm);
    return r.ok ? 0 : 3;
}
