/* Offline evaluation of the flux observer in an encoder-run closed loop (fobs_eval.h). */
#include "fobs_eval.h"

#include <math.h>
#include <string.h>

#include "ctrl_units.h"
#include "fw_state.h"
#include "transforms.h"

void fobs_eval_default(fobs_eval_cfg_t *c)
{
    memset(c, 0, sizeof *c);
    c->controller = "m2ptfc";
    c->duration_s = 0.3;
    c->win_start_s = 0.1;
    c->win_end_s = 0.3;
    c->rs_scale = c->l_scale = c->psi_scale = 1.0;
    c->noise_counts = 0.5;
    c->stat_min_speed = 0.1;
}

typedef struct {
    const fobs_eval_cfg_t *cfg;
    sim_run_t *run;
    ctrl_params_t p;     /* the observer's parameters (fw bases, scaled values) */
    ctrl_fobs_t sl, enc; /* sensorless and encoder-mode observers */
    bool primed;
    ctrl_legs_t legs_written; /* written at k-1: act in [k, k+1) */
    q24_t va, vb, va_e, vb_e; /* voltage of [k-1, k) */
    double w_rated_e;         /* rad/s */
    double ang_sum2, ang_max, ang_sum, spd_sum2, spd_max, tq_sum, tq_sum2, etq_sum, etq_sum2,
        cmtq_sum, fwspd_sum2;
    unsigned long n;
} ev_t;

static double q2d(q24_t x)
{
    return ctrl_q24_to_double(x);
}

/* The firmware's parameters with Rs, L and psi_pm scaled (same bases). */
static void ev_params(const ctrl_params_t *src, double sr, double sl, double sp, ctrl_params_t *d)
{
    *d = *src;
    d->rs = ctrl_q24_from_double(q2d(src->rs) * sr);
    d->ts_rs = ctrl_q24_from_double(q2d(src->ts) * q2d(src->rs) * sr);
    d->ld = ctrl_q24_from_double(q2d(src->ld) * sl);
    d->lq = ctrl_q24_from_double(q2d(src->lq) * sl);
    d->inv_ld = ctrl_q24_from_double(1.0 / (q2d(src->ld) * sl));
    d->inv_lq = ctrl_q24_from_double(1.0 / (q2d(src->lq) * sl));
    d->psi_pm = ctrl_q24_from_double(q2d(src->psi_pm) * sp);
    d->inv_psi_pm = ctrl_q24_from_double(1.0 / (q2d(src->psi_pm) * sp));
}

static double wrap_deg(double d)
{
    while (d >= 180.0) {
        d -= 360.0;
    }
    while (d < -180.0) {
        d += 360.0;
    }
    return d;
}

static void ev_hook(void *ctx)
{
    ev_t *e = (ev_t *)ctx;
    sim_run_t *r = e->run;
    if (fw_state(&r->fw) != FW_STATE_RUNNING) {
        e->primed = false;
        return;
    }
    const ctrl_meas_t *m = &fw_telemetry(&r->fw)->meas;
    q24_t ia;
    q24_t ib;
    ctrl_clarke(m->i_a, m->i_b, &ia, &ib);
    const double t = sim_run_time(r);
    const plant_t *pl = &r->plant;
    if (!e->primed) {
        /* Started at the encoder's angle (a known initial position). */
        ctrl_fobs_reset(&e->sl, &e->p, m->theta_e, 0, ia, ib);
        ctrl_fobs_reset(&e->enc, &e->p, m->theta_e, 0, ia, ib);
        memset(&e->legs_written, 0, sizeof e->legs_written);
        e->primed = true;
    } else {
        const fx_angle_t th = ctrl_fobs_update(&e->sl, &e->p, e->va, e->vb, ia, ib, m->theta_e);
        (void)ctrl_fobs_update(&e->enc, &e->p, e->va_e, e->vb_e, ia, ib, m->theta_e);
        const double th_d = (double)th * (360.0 / 4294967296.0);
        const double true_d = plant_theta_e(pl) * 180.0 / CTRL_PI;
        const double ang_err = wrap_deg(th_d - true_d);
        const double w_true = plant_omega_e(pl);
        const double w_est = q2d(ctrl_fobs_omega(&e->sl)) * r->fw.bases.w_rad_s;
        const double pp = (double)r->fw.params.pole_pairs;
        const double spd_err = (w_est - w_true) / pp * 60.0 / (2.0 * CTRL_PI);
        const double tb = r->fw.bases.torque_nm;
        const double tq_true = plant_torque(pl);
        const double tq = q2d(fx_cross(e->sl.psi_alpha, e->sl.psi_beta, ia, ib)) * tb - tq_true;
        const double etq = q2d(fx_cross(e->enc.psi_alpha, e->enc.psi_beta, ia, ib)) * tb - tq_true;
        const double cmtq = q2d(r->fw.estimate.now.torque) * tb - tq_true;
        const double fw_spd_err = (q2d(r->fw.estimate.omega_e) * r->fw.bases.w_rad_s - w_true) /
                                  pp * 60.0 / (2.0 * CTRL_PI);
        if (e->cfg->csv != NULL) {
            fprintf(e->cfg->csv, "%.6f,%.4f,%.4f,%.3f,%.3f,%.5f,%.5f,%.5f,%.6f\n", t, true_d,
                    ang_err, w_true / pp * 60.0 / (2.0 * CTRL_PI), spd_err, tq_true, tq, etq,
                    q2d(ctrl_fobs_psi_pm(&e->enc)) * r->fw.bases.psi_wb);
        }
        if (t >= e->cfg->win_start_s && t <= e->cfg->win_end_s &&
            fabs(w_true) >= e->cfg->stat_min_speed * e->w_rated_e) {
            e->n++;
            e->ang_sum += ang_err;
            e->ang_sum2 += ang_err * ang_err;
            e->ang_max = fmax(e->ang_max, fabs(ang_err));
            e->spd_sum2 += spd_err * spd_err;
            e->spd_max = fmax(e->spd_max, fabs(spd_err));
            e->tq_sum += tq;
            e->tq_sum2 += tq * tq;
            e->etq_sum += etq;
            e->etq_sum2 += etq * etq;
            e->cmtq_sum += cmtq;
            e->fwspd_sum2 += fw_spd_err * fw_spd_err;
        }
    }
    /* The voltage of [k, k+1) (legs written at k-1, DC link and current at k). */
    ctrl_fobs_voltage(&e->sl, &e->legs_written, m->vdc, m->i_a, m->i_b, &e->va, &e->vb);
    ctrl_fobs_voltage(&e->enc, &e->legs_written, m->vdc, m->i_a, m->i_b, &e->va_e, &e->vb_e);
    e->legs_written = r->fw.applied;
}

int fobs_eval_run(const fobs_eval_cfg_t *c, fobs_eval_res_t *res, char *err, size_t errlen)
{
    static sim_run_t run;
    static sim_scenario_t scn;
    static ev_t e;
    memset(res, 0, sizeof *res);
    sim_machine_t mach;
    if (sim_machine_load(c->machine_path, &mach, err, errlen) != 0) {
        return -1;
    }
    mach.dead_time_s = c->dead_time_ns * 1e-9;
    mach.v_fwd_v = c->v_fwd_v;
    const ctrl_desc_t *d = ctrl_find(c->controller);
    if (d == NULL) {
        (void)snprintf(err, errlen, "unknown controller %s", c->controller);
        return -1;
    }
    sim_run_cfg_t rc;
    sim_run_config_default(&rc, &mach, d);
    rc.fs_hz = c->fs_hz != 0u ? c->fs_hz : d->fs_default_hz;
    rc.hal.pwm_freq_hz = rc.fs_hz;
    rc.hal.adc_noise_counts = c->noise_counts;
    rc.free_mech = true;
    rc.speed_mode = true;
    rc.speed_ref_rpm = c->speed_ref_rpm;
    rc.load_nm = c->load_nm;
    rc.load_passive_nm = c->load_passive_nm;
    rc.duration_s = c->duration_s;
    rc.win_start_s = c->win_start_s;
    rc.win_end_s = c->win_end_s;
    rc.calib_samples = 256u;
    rc.arm_delay_periods = c->arm_delay_periods;
    /* The observers here take the duties the drive wrote (fw.applied) as the
     * inverter's input and model its error themselves: the drive's own
     * dead-time compensation off, so that fw.applied is what was written. */
    rc.dead_comp = false;
    if (c->scenario != NULL) {
        FILE *f = tmpfile();
        if (f == NULL) {
            (void)snprintf(err, errlen, "tmpfile failed");
            return -1;
        }
        fputs(c->scenario, f);
        rewind(f);
        const int prc = sim_scenario_parse(&scn, f, "scenario", err, errlen);
        fclose(f);
        if (prc != 0) {
            return -1;
        }
        rc.scenario = &scn;
    }
    memset(&e, 0, sizeof e);
    e.cfg = c;
    e.run = &run;
    rc.after_isr = ev_hook;
    rc.after_isr_ctx = &e;
    rc.stop_on_fault = true;
    if (sim_run_init(&run, &rc, err, errlen) != 0) {
        return -1;
    }
    ev_params(&run.fw.params, c->rs_scale, c->l_scale, c->psi_scale, &e.p);
    e.w_rated_e = mach.speed_rated_rpm * 2.0 * CTRL_PI / 60.0 * (double)mach.pole_pairs;
    ctrl_fobs_config_t fc;
    if (c->has_fobs) {
        fc = c->fobs;
    } else {
        ctrl_machine_t cm;
        sim_ctrl_machine_from(&mach, &cm);
        ctrl_fobs_config_default(&fc, &cm);
    }
    if (c->compensate) {
        fc.dead_time_s = mach.dead_time_s;
        fc.v_fwd_v = mach.v_fwd_v;
    }
    ctrl_diag_t why;
    memset(&why, 0, sizeof why);
    fc.mode = CTRL_FOBS_SENSORLESS;
    if (ctrl_fobs_init(&e.sl, &e.p, &run.fw.bases, &fc, &why) != CTRL_OK) {
        char msg[160];
        (void)ctrl_diag_format(&why, msg, sizeof msg);
        (void)snprintf(err, errlen, "observer configuration: %s", msg);
        sim_run_free(&run);
        return -1;
    }
    fc.mode = CTRL_FOBS_ENCODER;
    (void)ctrl_fobs_init(&e.enc, &e.p, &run.fw.bases, &fc, NULL);
    if (sim_run_all(&run, err, errlen) != 0) {
        sim_run_free(&run);
        return -1;
    }
    res->ok = !sim_run_faulted(&run);
    res->n = e.n;
    if (e.n > 0u) {
        const double n = (double)e.n;
        res->ang_rms_deg = sqrt(e.ang_sum2 / n);
        res->ang_mean_deg = e.ang_sum / n;
        res->ang_max_deg = e.ang_max;
        res->spd_rms_rpm = sqrt(e.spd_sum2 / n);
        res->spd_max_rpm = e.spd_max;
        res->tq_err_mean_nm = e.tq_sum / n;
        res->tq_err_rms_nm = sqrt(e.tq_sum2 / n);
        res->enc_tq_err_mean_nm = e.etq_sum / n;
        res->enc_tq_err_rms_nm = sqrt(e.etq_sum2 / n);
        res->cm_tq_err_mean_nm = e.cmtq_sum / n;
        res->fw_spd_rms_rpm = sqrt(e.fwspd_sum2 / n);
    }
    res->psi_pm_est_wb = q2d(ctrl_fobs_psi_pm(&e.enc)) * run.fw.bases.psi_wb;
    res->speed_end_rpm = plant_omega_m(&run.plant) * 60.0 / (2.0 * CTRL_PI);
    sim_run_free(&run);
    return 0;
}
