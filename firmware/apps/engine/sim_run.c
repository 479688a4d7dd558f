/* Closed loop on the host (see sim_run.h). */
#include "sim_run.h"

#include "ctrl_units.h"
#include "field_weak_config.h"
#include "speed_loop.h"

#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#define SIM_OBS_PER_PERIOD 10u

static int sim_err(char *err, size_t errlen, const char *msg)
{
    if (err != NULL && errlen > 0u) {
        (void)snprintf(err, errlen, "%s", msg);
    }
    return -1;
}

void sim_ctrl_machine_from(const sim_machine_t *m, ctrl_machine_t *out)
{
    memset(out, 0, sizeof *out);
    out->name = m->name;
    out->pole_pairs = m->pole_pairs;
    out->rs_ohm = m->rs_ohm;
    out->ld_h = m->ld_h;
    out->lq_h = m->lq_h;
    out->psi_pm_wb = m->psi_pm_wb;
    out->vdc_v = m->vdc_v;
    out->inertia_kgm2 = m->inertia_kgm2;
    out->torque_rated_nm = m->torque_rated_nm;
    out->speed_rated_rpm = m->speed_rated_rpm;
    out->speed_max_rpm = m->speed_max_rpm;
    out->current_rated_a = m->current_rated_a;
    out->current_max_a = m->current_max_a;
    out->psi_ref_wb = m->psi_ref_wb;
}

void sim_run_ctrl_sensors_from(sim_run_cfg_t *c, const sim_machine_t *m)
{
    c->ctrl_enc_lines = m->encoder_lines;
    c->ctrl_enc_offset_deg = m->encoder_offset_deg;
    c->ctrl_enc_dir = m->encoder_direction;
}

void sim_run_config_default(sim_run_cfg_t *c, const sim_machine_t *m, const ctrl_desc_t *ctrl)
{
    memset(c, 0, sizeof *c);
    c->plant_machine = *m;
    sim_ctrl_machine_from(&c->plant_machine, &c->ctrl_machine);
    c->ctrl = ctrl;
    c->fs_hz = (uint32_t)m->fs_hz;
    c->duration_s = 0.3;
    c->win_start_s = 0.1;
    c->win_end_s = 0.3;
    c->seed = 1u;
    c->trace_decimation = 1u;
    c->trace_start_s = 0.0;
    c->trace_end_s = 1.0e9;
    c->calib_samples = 256u;
    c->stop_on_fault = false;
    c->psi_adapt = true;
    c->dead_comp = true;
    c->comp_dead_time_s = -1.0;
    c->sensorless = false;
    c->speed_bw_hz = m->speed_bw_hz;
    c->speed_pm_deg = m->speed_pm_deg;
    c->speed_kp = m->speed_kp;
    c->speed_ki = m->speed_ki;
    c->overspeed_rpm = m->overspeed_rpm;
    /* The load's one home is the machine file; the run may replace it. */
    c->load_nm = m->load_kind == SIM_LOAD_CONSTANT ? m->load_nm : 0.0;
    c->load_passive_nm = m->load_kind == SIM_LOAD_PASSIVE ? m->load_nm : 0.0;
    c->auto_arm = true;
    c->kick_watchdog = true;
    engine_hal_config_default(&c->hal, c->fs_hz, m->current_max_a, m->vdc_v);
    c->hal.sense_motor_side = m->current_sense == SIM_SENSE_MOTOR;
    sim_run_ctrl_sensors_from(c, m);
}

static double sim_torque_ref_nm(const sim_run_t *r)
{
    return ctrl_q24_to_double(r->fw.torque_ref_now) * r->fw.bases.torque_nm;
}

/* One period of the window: the field-weakening limit and whether it clipped
 * the request (fw_telemetry_t.fieldweak_limit bit 2), and the reference applied. */
static void sim_limit_add(sim_run_t *r)
{
    const fw_telemetry_t *tm = fw_telemetry(&r->fw);
    const double tmax = ctrl_q24_to_double(tm->torque_max) * r->fw.bases.torque_nm;
    if (r->lim_n == 0u || tmax < r->lim_min_nm) {
        r->lim_min_nm = tmax;
    }
    if ((tm->fieldweak_limit & 4u) != 0u) {
        r->lim_clipped_n++;
        r->lim_last = tm->fieldweak_limit;
    }
    if ((tm->fieldweak_limit & 8u) != 0u) {
        r->lim_weak_n++;
    }
    r->tref_sum_nm += sim_torque_ref_nm(r);
    r->lim_n++;
}

double sim_run_speed_ref_now(const sim_run_t *r)
{
    if (fw_ref_mode(&r->fw) != FW_REF_SPEED) {
        return NAN;
    }
    return ctrl_q24_to_double(fw_speed_ref(&r->fw)) * r->fw.bases.w_rad_s /
           (double)r->fw.params.pole_pairs * 60.0 / (2.0 * CTRL_PI);
}

static void sim_observer(void *ctx, const plant_t *p)
{
    sim_run_t *r = (sim_run_t *)ctx;
    const double t = plant_time(p) - r->t_arm;
    if (t < 0.0) {
        return;
    }
    const double tq = plant_torque(p);
    const double psi = plant_psi_amp(p);
    double i_abc[3];
    plant_i_abc(p, i_abc);
    const double tref = sim_torque_ref_nm(r);
    double v_abc[3];
    plant_v_motor_mean_abc(p, v_abc);
    if (t >= r->cfg.win_start_s && t <= r->cfg.win_end_s) {
        metrics_add(&r->m_plant, t, tq, tref, psi, i_abc[0]);
        metrics_add_voltage(&r->m_plant, t, v_abc[0]);
        const double rpm = plant_omega_m(p) * 60.0 / (2.0 * CTRL_PI);
        r->speed_sum_rpm += rpm;
        r->speed_n++;
        if (r->cfg.speed_mode) {
            const double e = rpm - sim_run_speed_ref_now(r);
            r->speed_err_sum2 += e * e;
            r->speed_err_max = fmax(r->speed_err_max, fabs(e));
        }
    }
    if (r->cfg.trace != NULL && (r->obs_count % r->cfg.trace_decimation) == 0u &&
        t >= r->cfg.trace_start_s && t <= r->cfg.trace_end_s) {
        double id, iq;
        plant_i_dq(p, &id, &iq);
        const fw_telemetry_t *tm = fw_telemetry(&r->fw);
        const double load = r->cfg.free_mech ? plant_load_torque(p) : NAN;
        double i_inv[3];
        plant_i_inverter_abc(p, i_inv);
        fprintf(r->cfg.trace,
                "%.9g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%u,%.4f,%u,%.6g,%.6g,%.6g,%.6g,"
                "%.6g,%.6g\n",
                t, i_abc[0], i_abc[1], i_abc[2], id, iq, psi, tq,
                plant_omega_m(p) * 60.0 / (2.0 * CTRL_PI), tref, (unsigned)r->vec_now, r->duty_now,
                (unsigned)tm->state, sim_run_speed_ref_now(r), load, v_abc[0], v_abc[1], v_abc[2],
                i_inv[0]);
    }
    r->obs_count++;
}

static void sim_apply_event(sim_run_t *r, const sim_event_t *e)
{
    if (e->set & SIM_SET_TORQUE_REF) {
        fw_set_torque_ref_nm(&r->fw, e->torque_ref_nm);
        r->torque_ref_requested_nm = e->torque_ref_nm;
    }
    if (e->set & SIM_SET_SPEED_REF) {
        fw_set_speed_ref_rpm(&r->fw, e->speed_ref_rpm);
    }
    if (e->set & SIM_SET_LOAD) {
        plant_set_load_torque(&r->plant, e->load_nm);
    }
    if (e->set & SIM_SET_LOAD_PASSIVE) {
        plant_set_load_passive(&r->plant, e->load_passive_nm);
    }
    if (e->set & SIM_SET_SPEED) {
        plant_set_speed_rpm(&r->plant, e->speed_rpm);
    }
}

static void sim_scenario_step(sim_run_t *r, double t)
{
    if (!r->has_scn) {
        return;
    }
    sim_scenario_t *s = &r->scn;
    while (s->next < s->n) {
        const sim_event_t *e = &s->ev[s->next];
        const double rpm = plant_omega_m(&r->plant) * 60.0 / (2.0 * CTRL_PI);
        bool fire = false;
        switch (e->trig) {
        case SIM_TRIG_AT:
            /* Half a period of tolerance against the accumulated time grid. */
            fire = t + 0.5 / (double)r->cfg.fs_hz > e->level;
            break;
        case SIM_TRIG_SPEED_GE:
            fire = rpm >= e->level;
            break;
        case SIM_TRIG_SPEED_LE:
            fire = rpm <= e->level;
            break;
        default:
            break;
        }
        if (!fire) {
            break;
        }
        sim_apply_event(r, e);
        r->scn_fired_s[s->next] = t;
        s->next++;
    }
}

/* One period without the scenario/metrics bookkeeping (boot phase too). */
static int sim_period_raw(sim_run_t *r)
{
    /* The plan chosen at k-1 acts in this period (gates on) or nothing does
     * (its segment 0 from the last period's telemetry; 0 for leg duties). */
    const fw_telemetry_t *tm = fw_telemetry(&r->fw);
    const bool on = fw_state(&r->fw) == FW_STATE_RUNNING;
    r->vec_now = on ? tm->vec : 0u;
    r->duty_now = on ? ctrl_q24_to_double(tm->duty) : 0.0;
    engine_hal_begin(&r->hal);
    const sim_link_t *link = r->cfg.link;
    if (link != NULL && link->send(link->ctx, r) != 0) {
        r->link_failed = true;
        return -1;
    }
    if (fw_isr_fast(&r->fw)) {
        engine_medium(&r->fw);
    }
    if (link != NULL && link->receive(link->ctx, r) != 0) {
        r->link_failed = true;
        return -1;
    }
    if (r->cfg.plant_machine.filter.type == PLANT_FILTER_ACTIVE) {
        /* the active filter's reference generator follows the drive's torque
         * setting, S1 (50) (0 while the drive is not running) */
        (void)plant_filter_set_torque_cmd(
            &r->plant, fw_state(&r->fw) == FW_STATE_RUNNING ? sim_torque_ref_nm(r) : 0.0);
    }
    if (r->cfg.after_isr != NULL) {
        r->cfg.after_isr(r->cfg.after_isr_ctx);
    }
    if (r->cfg.kick_watchdog) {
        /* The host's main loop: kicks the watchdog once per period. */
        fw_watchdog_kick(&r->fw);
    }
    const int rc = engine_hal_end(&r->hal);
    if (rc != PLANT_OK) {
        r->plant_rc = rc;
        return -1;
    }
    return 0;
}

/* The arm instant (scenario time 0): the references and loads of the run. */
static void sim_arm(sim_run_t *r)
{
    const sim_run_cfg_t *c = &r->cfg;
    if (c->speed_mode) {
        fw_set_speed_ref_rpm(&r->fw, c->speed_ref_rpm);
        r->torque_ref_requested_nm = NAN;
    } else {
        fw_set_torque_ref_nm(&r->fw, c->torque_ref_nm);
        r->torque_ref_requested_nm = c->torque_ref_nm;
    }
    fw_cmd_arm(&r->fw);
    if (c->free_mech) {
        plant_set_load_torque(&r->plant, c->load_nm);
        plant_set_load_passive(&r->plant, c->load_passive_nm);
        plant_load_profile_enable(&r->plant, 1); /* its time from the arm instant */
    }
    r->t_arm = plant_time(&r->plant);
    r->armed = true;
}

/* Leg transitions between the window start and t (period boundaries). */
static void sim_filter_window_end(sim_run_t *r, double t)
{
    if (plant_filter_stats(&r->plant, &r->flt_w1) == PLANT_OK) {
        r->flt_t1 = t;
        r->flt_w1_set = true;
    }
    plant_mech_stats(&r->plant, &r->mech_w1);
    r->mech_t1 = t;
}

void sim_run_mech_summary(const sim_run_t *r, sim_mech_summary_t *m)
{
    memset(m, 0, sizeof *m);
    m->present = r->cfg.free_mech && sim_machine_nonideal(&r->cfg.plant_machine) && r->win_started;
    m->stuck_frac = m->friction_nm = m->load_nm = m->friction_w = NAN;
    if (!m->present) {
        return;
    }
    const plant_mech_stats_t *a = &r->mech_w0, *b = &r->mech_w1;
    const double span = r->mech_t1 - r->mech_t0;
    const double angle = b->abs_angle_rad - a->abs_angle_rad;
    m->stuck_s = b->stuck_s - a->stuck_s;
    m->stuck_frac = span > 0.0 ? m->stuck_s / span : NAN;
    m->breakaways = b->breakaways - a->breakaways;
    m->stops = b->stops - a->stops;
    m->reversals = b->reversals - a->reversals;
    if (angle > 0.0) {
        m->friction_nm = (b->e_friction_j - a->e_friction_j) / angle;
        m->load_nm = (b->e_load_j - a->e_load_j) / angle;
    }
    m->friction_w = span > 0.0 ? (b->e_friction_j - a->e_friction_j) / span : NAN;
}

static void sim_count_transitions(sim_run_t *r, double t)
{
    const uint64_t n = plant_transitions(&r->plant) - r->tr_win_start;
    metrics_set_transitions(&r->m_plant, n, t - r->t_win_start);
    metrics_set_transitions(&r->m_ctrl, n, t - r->t_win_start);
}

double sim_run_time(const sim_run_t *r)
{
    return plant_time(&r->plant) - r->t_arm;
}

/* The Ts/10 observer costs most of the run time (it splits every period into
 * ten exact sub-steps): keep it on only while the metrics window or the trace
 * needs samples (from one period before). */
static void sim_observer_update(sim_run_t *r, double t)
{
    const double ts = 1.0 / (double)r->cfg.fs_hz;
    const bool in_win = t + ts >= r->cfg.win_start_s && t <= r->cfg.win_end_s;
    const bool in_trace =
        r->cfg.trace != NULL && t + ts >= r->cfg.trace_start_s && t <= r->cfg.trace_end_s;
    const bool want = in_win || in_trace;
    if (want != r->obs_on) {
        plant_set_observer(&r->plant, want ? sim_observer : NULL, r, want ? r->obs_dt : 0.0);
        r->obs_on = want;
    }
}

/* The estimator's angle and speed at k against the plant's (sim_run_est_errors). */
static void sim_est_error_add(sim_run_t *r, double t, double th_true, double w_true)
{
    const sim_machine_t *m = &r->cfg.plant_machine;
    const double w_rated = m->speed_rated_rpm * 2.0 * CTRL_PI / 60.0 * (double)m->pole_pairs;
    if (t < r->cfg.win_start_s || t > r->cfg.win_end_s || fw_state(&r->fw) != FW_STATE_RUNNING) {
        return;
    }
    const ctrl_estimate_t *e = &r->fw.estimate;
    double d = (double)e->now.theta_e * (2.0 * CTRL_PI / 4294967296.0) - th_true;
    d -= 2.0 * CTRL_PI * floor((d + CTRL_PI) / (2.0 * CTRL_PI)); /* [-pi, pi) */
    const double deg = d * 180.0 / CTRL_PI;
    if (fabs(w_true) < 0.1 * w_rated) {
        /* low speed and standstill: the injection's range (sim_run_est_errors_low) */
        r->est_lo_sum2 += deg * deg;
        r->est_lo_max = fmax(r->est_lo_max, fabs(deg));
        r->est_lo_n++;
        return;
    }
    const double w_est = ctrl_q24_to_double(e->omega_e) * r->fw.bases.w_rad_s;
    const double rpm = (w_est - w_true) / (double)m->pole_pairs * 60.0 / (2.0 * CTRL_PI);
    r->est_ang_sum2 += deg * deg;
    r->est_ang_max = fmax(r->est_ang_max, fabs(deg));
    r->est_spd_sum2 += rpm * rpm;
    r->est_n++;
}

void sim_run_est_errors(const sim_run_t *r, double *ang_rms_deg, double *ang_max_deg,
                        double *spd_rms_rpm)
{
    const double n = (double)r->est_n;
    *ang_rms_deg = r->est_n > 0u ? sqrt(r->est_ang_sum2 / n) : NAN;
    *ang_max_deg = r->est_n > 0u ? r->est_ang_max : NAN;
    *spd_rms_rpm = r->est_n > 0u ? sqrt(r->est_spd_sum2 / n) : NAN;
}

void sim_run_est_errors_low(const sim_run_t *r, double *ang_rms_deg, double *ang_max_deg)
{
    const double n = (double)r->est_lo_n;
    *ang_rms_deg = r->est_lo_n > 0u ? sqrt(r->est_lo_sum2 / n) : NAN;
    *ang_max_deg = r->est_lo_n > 0u ? r->est_lo_max : NAN;
}

bool sim_run_done(const sim_run_t *r)
{
    return r->armed && sim_run_time(r) + 0.5 / (double)r->cfg.fs_hz >= r->t_end;
}

int sim_run_period(sim_run_t *r)
{
    if (!r->armed) {
        /* Boot and calibration: gates off, no bookkeeping; armed (with the
         * run's references) right after the period that ends the
         * calibration, or arm_delay_periods periods later, so the first
         * gated period is the next one. */
        const int rc = sim_period_raw(r);
        if (rc == 0 && r->cfg.auto_arm && fw_state(&r->fw) == FW_STATE_READY &&
            r->ready_periods++ >= r->cfg.arm_delay_periods) {
            sim_arm(r);
        }
        return rc;
    }
    const double t = sim_run_time(r);
    sim_observer_update(r, t);
    sim_scenario_step(r, t);
    if (t >= r->cfg.win_start_s && !r->win_started) {
        r->win_started = true;
        r->tr_win_start = plant_transitions(&r->plant);
        r->t_win_start = t;
        if (plant_filter_stats(&r->plant, &r->flt_w0) == PLANT_OK) {
            (void)plant_filter_reset_peaks(&r->plant);
            r->flt_t0 = t;
        }
        plant_mech_stats(&r->plant, &r->mech_w0);
        r->mech_t0 = t;
    }
    if (t >= r->cfg.win_end_s && r->win_started && !r->win_done) {
        r->win_done = true;
        sim_count_transitions(r, t);
        sim_filter_window_end(r, t);
    }
    if (t >= r->cfg.win_start_s && t <= r->cfg.win_end_s) {
        double i_abc[3];
        plant_i_abc(&r->plant, i_abc);
        metrics_add(&r->m_ctrl, t, plant_torque(&r->plant), sim_torque_ref_nm(r),
                    plant_psi_amp(&r->plant), i_abc[0]);
    }
    /* The truth at t_k, for the estimate the interrupt forms from the samples at k. */
    const double th_true = plant_theta_e(&r->plant);
    const double w_true = plant_omega_e(&r->plant);
    const int rc = sim_period_raw(r);
    sim_est_error_add(r, t, th_true, w_true);
    if (t >= r->cfg.win_start_s && t <= r->cfg.win_end_s && fw_state(&r->fw) == FW_STATE_RUNNING) {
        sim_limit_add(r);
    }
    if (isnan(r->fault_time_s) && fw_state(&r->fw) == FW_STATE_FAULT) {
        r->fault_time_s = t;
    }
    return rc;
}

/* The controller's SI configuration: cfg_default for the controller's machine,
 * then the tunables set by name. Returns 0, or -1 with the tunable named. */
static int sim_ctrl_cfg_build(const sim_run_cfg_t *c, const ctrl_machine_t *m, unsigned char *buf,
                              char *err, size_t errlen)
{
    const ctrl_desc_t *d = c->ctrl;
    memset(buf, 0, CTRL_CFG_MAX);
    if (d->cfg_size > CTRL_CFG_MAX) {
        (void)snprintf(err, errlen, "controller %s: configuration of %zu bytes, at most %u",
                       d->name, d->cfg_size, (unsigned)CTRL_CFG_MAX);
        return -1;
    }
    if (d->cfg_default != NULL) {
        d->cfg_default(buf, m);
    }
    for (size_t k = 0; k < c->n_sets; k++) {
        const sim_set_t *st = &c->sets[k];
        const bool hfi = strncmp(st->name, "hfi.", 4u) == 0; /* sim_run_fw_config's */
        static ctrl_hfi_config_t hc;                         /* only checked here */
        const int rc = hfi ? ctrl_tunable_set(&ctrl_hfi_desc, &hc, st->name, st->value)
                           : ctrl_tunable_set(d, buf, st->name, st->value);
        if (hfi && rc == CTRL_ENOENT) {
            (void)snprintf(err, errlen,
                           "the injection has no setting '%s' (see --list-tunables hfi)", st->name);
            return -1;
        }
        if (hfi && rc != CTRL_OK) {
            const ctrl_tunable_t *t = NULL;
            for (size_t i = 0; i < ctrl_hfi_desc.n_tunables; i++) {
                if (strcmp(ctrl_hfi_desc.tunables[i].name, st->name) == 0) {
                    t = &ctrl_hfi_desc.tunables[i];
                }
            }
            (void)snprintf(err, errlen, "%s = %g is out of range [%g, %g]%s%s", st->name, st->value,
                           t != NULL ? t->min : 0.0, t != NULL ? t->max : 0.0,
                           t != NULL && t->unit[0] != '\0' ? " " : "", t != NULL ? t->unit : "");
            return -1;
        }
        if (hfi) {
            continue;
        }
        if (rc == CTRL_ENOENT) {
            (void)snprintf(err, errlen,
                           "controller %s has no tunable '%s' (see --list-tunables %s)", d->name,
                           st->name, d->name);
            return -1;
        }
        if (rc != CTRL_OK) {
            const ctrl_tunable_t *t = NULL;
            for (size_t i = 0; i < d->n_tunables; i++) {
                if (strcmp(d->tunables[i].name, st->name) == 0) {
                    t = &d->tunables[i];
                }
            }
            if (t != NULL && strcmp(t->unit, "0/1") == 0) {
                (void)snprintf(err, errlen,
                               "%s tunable %s = %g: a 0/1 switch, allowed values 0 or 1", d->name,
                               st->name, st->value);
            } else if (t != NULL) {
                /* Dimensionless units ("1", "-") are not repeated after numbers. */
                const char *u =
                    (strcmp(t->unit, "1") == 0 || strcmp(t->unit, "-") == 0) ? "" : t->unit;
                (void)snprintf(err, errlen, "%s tunable %s = %g%s%s is out of range [%g, %g]%s%s",
                               d->name, st->name, st->value, u[0] ? " " : "", u, t->min, t->max,
                               u[0] ? " " : "", u);
            } else {
                (void)snprintf(err, errlen, "%s tunable %s = %g rejected", d->name, st->name,
                               st->value);
            }
            return -1;
        }
    }
    return 0;
}

void sim_run_fw_config(const sim_run_cfg_t *c, const ctrl_machine_t *m, fw_config_t *fc)
{
    fw_config_default(fc, m, c->ctrl);
    fc->calib_samples = c->calib_samples;
    fc->speed_bw_hz = c->speed_bw_hz;
    fc->speed_pm_deg = c->speed_pm_deg;
    if (c->speed_kp > 0.0) {
        fc->speed_kp = c->speed_kp;
        fc->speed_ki = c->speed_ki;
        fc->speed_unit = CTRL_SPEED_UNIT_RAD_S_MECH;
    }
    fc->overspeed_rpm = c->overspeed_rpm;
    fc->torque_follow_fault_windows = c->torque_follow_fault_windows;
    /* With an output filter the leg voltages are not the motor's: no voltage model. */
    fc->psi_adapt = c->psi_adapt && c->plant_machine.filter.type == PLANT_FILTER_NONE;
    /* The inverter's dead time and device drop, known to the firmware. */
    fc->sensorless = c->sensorless;
    fc->dead_time_s =
        c->comp_dead_time_s >= 0.0 ? c->comp_dead_time_s : c->plant_machine.dead_time_s;
    fc->hfi = c->hfi;
#if CTRL_SL_HFI
    for (size_t k = 0; k < c->n_sets; k++) {
        /* the injection's settings by name (checked by sim_ctrl_cfg_build) */
        if (strncmp(c->sets[k].name, "hfi.", 4u) == 0) {
            (void)ctrl_tunable_set(&ctrl_hfi_desc, &fc->hfi_cfg, c->sets[k].name, c->sets[k].value);
        }
    }
#endif
    fc->v_fwd_v = c->plant_machine.v_fwd_v;
    fc->dead_comp = c->dead_comp;
    /* The firmware's encoder configuration (the control machine's [sensors]). */
    double off = fmod(c->ctrl_enc_offset_deg, 360.0);
    off = off < 0.0 ? off + 360.0 : off;
    double u = floor(off / 360.0 * 4294967296.0 + 0.5);
    u = u >= 4294967296.0 ? u - 4294967296.0 : u;
    fc->enc_offset = (fx_angle_t)(uint32_t)u;
    fc->enc_direction = c->ctrl_enc_dir < 0 ? -1 : 1;
    fc->enc_cpr = c->ctrl_enc_lines > 0 ? 4u * (uint32_t)c->ctrl_enc_lines : 0u;
}

#if !defined(ENGINE_PORT_QEMU)
/* fw_init on a scratch pipeline for (machine, fs): the same steps as the run,
 * plant not touched. Returns FW_OK or the fw_init code. */
static int sim_fw_trial(const sim_run_cfg_t *c, const ctrl_machine_t *m, uint32_t fs_hz)
{
    static unsigned char buf[CTRL_CFG_MAX] __attribute__((aligned(16)));
    static fw_t fw;
    static hal_t hal;
    static plant_t dummy;
    char err[SIM_WARN_LEN];
    if (c->ctrl_cfg == NULL && sim_ctrl_cfg_build(c, m, buf, err, sizeof err) != 0) {
        return FW_EINVAL;
    }
    engine_hal_config_t hc = c->hal;
    hc.pwm_freq_hz = fs_hz;
    if (engine_hal_init(&hal, &hc, &dummy) != 0) {
        return FW_EINVAL;
    }
    fw_config_t fc;
    sim_run_fw_config(c, m, &fc);
    fc.ctrl_cfg = c->ctrl_cfg != NULL ? c->ctrl_cfg : buf;
    return fw_init(&fw, &hal, &fc);
}

/* The quantities the explanation varies, one at a time. */
typedef struct {
    const char *name, *unit;
    size_t offset; /* double in ctrl_machine_t; SIZE_MAX: fs */
    double scale;  /* shown = stored * scale */
} sim_qty_t;

#define SIM_QTY(f, n, u, k)                                                                        \
    {                                                                                              \
        n, u, offsetof(ctrl_machine_t, f), k                                                       \
    }
static const sim_qty_t sim_qtys[] = {
    SIM_QTY(rs_ohm, "rs", "ohm", 1.0),
    SIM_QTY(ld_h, "Ld", "mH", 1e3),
    SIM_QTY(lq_h, "Lq", "mH", 1e3),
    SIM_QTY(psi_pm_wb, "psi_pm", "Wb", 1.0),
    SIM_QTY(vdc_v, "Vdc", "V", 1.0),
    SIM_QTY(inertia_kgm2, "inertia", "kg*m^2", 1.0),
    SIM_QTY(torque_rated_nm, "rated torque", "N*m", 1.0),
    SIM_QTY(speed_rated_rpm, "rated speed", "r/min", 1.0),
    SIM_QTY(current_rated_a, "rated current", "A", 1.0),
    SIM_QTY(current_max_a, "current_max", "A", 1.0),
    SIM_QTY(psi_ref_wb, "psi_ref", "Wb", 1.0),
    {"fs", "Hz", SIZE_MAX, 1.0},
};

static int sim_trial_scaled(const sim_run_cfg_t *c, const sim_qty_t *q, double v)
{
    ctrl_machine_t m = c->ctrl_machine;
    uint32_t fs = c->fs_hz;
    if (q->offset == SIZE_MAX) {
        if (!(v >= 1.0 && v <= 4.0e9)) {
            return FW_EINVAL;
        }
        fs = (uint32_t)floor(v + 0.5);
    } else {
        memcpy((char *)&m + q->offset, &v, sizeof v);
    }
    return sim_fw_trial(c, &m, fs);
}

/*
 * Why fw_init refused: for each quantity, the accepted values with every other
 * one unchanged (log-scale search over factors 2^+-16, then bisection to 0.1 %
 * of the boundary). Names the quantity, its value and the accepted range.
 */
static void sim_explain_reject(const sim_run_cfg_t *c, int fw_rc, const char *why, char *err,
                               size_t errlen)
{
    (void)snprintf(err, errlen,
                   "the firmware refuses this drive: %s (controller %s, machine %s, fs %u Hz)",
                   fw_strerror(fw_rc), c->ctrl->name, c->ctrl_machine.name, (unsigned)c->fs_hz);
    if (strcmp(why, "ok") != 0) {
        sim_appendf(err, errlen, ": %s", why); /* the core's diagnosis (fw_explain) */
    }
    int found = 0;
    for (size_t k = 0; k < sizeof sim_qtys / sizeof sim_qtys[0]; k++) {
        const sim_qty_t *q = &sim_qtys[k];
        double v0;
        if (q->offset == SIZE_MAX) {
            v0 = (double)c->fs_hz;
        } else {
            memcpy(&v0, (const char *)&c->ctrl_machine + q->offset, sizeof v0);
        }
        if (!(v0 > 0.0) || !isfinite(v0)) {
            continue;
        }
        /* Nearest accepted factor 2^(+-j). */
        double ok_v = NAN;
        for (int j = 1; j <= 16 && isnan(ok_v); j++) {
            const double up = v0 * ldexp(1.0, j);
            const double dn = v0 * ldexp(1.0, -j);
            if (sim_trial_scaled(c, q, dn) == FW_OK) {
                ok_v = dn;
            } else if (sim_trial_scaled(c, q, up) == FW_OK) {
                ok_v = up;
            }
        }
        if (isnan(ok_v)) {
            continue;
        }
        double bad = v0;
        double good = ok_v;
        for (int it = 0; it < 40 && fabs(good / bad - 1.0) > 1e-3; it++) {
            const double mid = sqrt(bad * good);
            if (sim_trial_scaled(c, q, mid) == FW_OK) {
                good = mid;
            } else {
                bad = mid;
            }
        }
        sim_appendf(err, errlen, "%s %s = %.4g %s is outside the accepted range (%s %.4g %s)",
                    found ? ";" : ". With every other value unchanged:", q->name, v0 * q->scale,
                    q->unit, good > v0 ? ">=" : "<=", good * q->scale, q->unit);
        found = 1;
    }
    /* A tunable whose default would be accepted. */
    static sim_run_cfg_t alt;
    for (size_t k = 0; c->ctrl_cfg == NULL && k < c->n_sets; k++) {
        alt = *c;
        alt.sets[k] = alt.sets[alt.n_sets - 1u];
        alt.n_sets--;
        if (sim_fw_trial(&alt, &alt.ctrl_machine, alt.fs_hz) == FW_OK) {
            sim_appendf(err, errlen,
                        "%s tunable %s = %g is refused with this drive (its default "
                        "is accepted)",
                        found ? ";" : ".", c->sets[k].name, c->sets[k].value);
            found = 1;
        }
    }
    if (!found) {
        sim_appendf(err, errlen,
                    ". No single machine value, fs or tunable changed alone makes it acceptable");
    }
}

#else
/* The QEMU port has one instance of the HAL models: no trial configurations. */
static void sim_explain_reject(const sim_run_cfg_t *c, int fw_rc, const char *why, char *err,
                               size_t errlen)
{
    (void)snprintf(err, errlen, "the firmware refuses this drive: %s (controller %s, fs %u Hz): %s",
                   fw_strerror(fw_rc), c->ctrl->name, (unsigned)c->fs_hz, why);
}
#endif

static const char *sim_trig_text(const sim_event_t *e, char *buf, size_t len)
{
    if (e->trig == SIM_TRIG_AT) {
        (void)snprintf(buf, len, "at %g", e->level);
    } else {
        (void)snprintf(buf, len, "when speed%s%g",
                       e->trig == SIM_TRIG_SPEED_GE ? ">=" : "<=", e->level);
    }
    return buf;
}

/* The scenario against the run: an assignment that cannot act as written is
 * an error; one the firmware clamps, or that never fires, a warning. */
static int sim_scenario_check(sim_run_t *r, char *err, size_t errlen)
{
    const sim_run_cfg_t *c = &r->cfg;
    for (size_t i = 0; i < r->scn.n; i++) {
        const sim_event_t *e = &r->scn.ev[i];
        char trig[48];
        (void)sim_trig_text(e, trig, sizeof trig);
        if (!c->free_mech && (e->set & (SIM_SET_LOAD | SIM_SET_LOAD_PASSIVE))) {
            (void)snprintf(err, errlen,
                           "scenario line %d (%s): load= and load_passive= act on free mechanics "
                           "only; this run has a dynamometer (give --free)",
                           e->line, trig);
            return -1;
        }
        if (c->free_mech && (e->set & SIM_SET_SPEED)) {
            (void)snprintf(err, errlen,
                           "scenario line %d (%s): speed= imposes the dynamometer speed; this run "
                           "has free mechanics (drop --free)",
                           e->line, trig);
            return -1;
        }
        if (!c->speed_mode && (e->set & SIM_SET_SPEED_REF)) {
            (void)snprintf(err, errlen,
                           "scenario line %d (%s): speed_ref= in a torque-mode run (start the "
                           "run in speed mode with --speed-ref-rpm)",
                           e->line, trig);
            return -1;
        }
        if (c->speed_mode && (e->set & SIM_SET_TORQUE_REF)) {
            (void)snprintf(err, errlen,
                           "scenario line %d (%s): torque_ref= in a speed-mode run (the speed "
                           "loop sets the torque reference; start in torque mode with "
                           "--torque-ref)",
                           e->line, trig);
            return -1;
        }
        if ((e->set & SIM_SET_TORQUE_REF) && fabs(e->torque_ref_nm) > r->torque_limit_nm) {
            sim_warn(c->warnings,
                     "scenario line %d (%s): torque_ref=%g N*m is outside the drive's torque "
                     "limit [-%g, %g] N*m: the firmware clamps it to %g N*m",
                     e->line, trig, e->torque_ref_nm, r->torque_limit_nm, r->torque_limit_nm,
                     copysign(r->torque_limit_nm, e->torque_ref_nm));
        }
        const fw_speed_info_t *si = &r->fw.speed_info;
        if ((e->set & SIM_SET_SPEED_REF) && fabs(e->speed_ref_rpm) > si->speed_ref_max_rpm) {
            sim_warn(c->warnings,
                     "scenario line %d (%s): speed_ref=%g r/min is outside the drive's speed "
                     "limit [-%g, %g] r/min: the firmware clamps it to %g r/min",
                     e->line, trig, e->speed_ref_rpm, si->speed_ref_max_rpm, si->speed_ref_max_rpm,
                     copysign(si->speed_ref_max_rpm, e->speed_ref_rpm));
        }
        if ((e->set & SIM_SET_SPEED) && fabs(e->speed_rpm) > si->overspeed_rpm) {
            sim_warn(c->warnings,
                     "scenario line %d (%s): speed=%g r/min is above the overspeed trip level "
                     "%g r/min",
                     e->line, trig, e->speed_rpm, si->overspeed_rpm);
        }
        if (e->trig == SIM_TRIG_AT && e->level >= c->duration_s) {
            sim_warn(c->warnings,
                     "scenario line %d (%s): after the end of the run (duration %g s), never fires",
                     e->line, trig, c->duration_s);
        }
    }
    return 0;
}

int sim_run_init(sim_run_t *r, const sim_run_cfg_t *cfg, char *err, size_t errlen)
{
    memset(r, 0, sizeof *r);
    r->cfg = *cfg;
    sim_run_cfg_t *c = &r->cfg;
    r->fault_time_s = NAN;
    for (size_t i = 0; i < SIM_SCN_MAX_EVENTS; i++) {
        r->scn_fired_s[i] = NAN;
    }
    /* The controller's machine name points into the copied plant machine. */
    if (cfg->ctrl_machine.name == cfg->plant_machine.name) {
        c->ctrl_machine.name = c->plant_machine.name;
    }
    if (c->ctrl == NULL) {
        return sim_err(err, errlen, "no controller");
    }
    if (c->fs_hz < 1000u || c->fs_hz > 200000u) {
        char msg[120];
        (void)snprintf(msg, sizeof msg, "fs = %u Hz is out of range [1000, 200000] Hz",
                       (unsigned)c->fs_hz);
        return sim_err(err, errlen, msg);
    }
    if (!(c->duration_s > 0.0) || c->duration_s > 100.0) {
        return sim_err(err, errlen, "duration out of range (0, 100] s");
    }
    if (!(c->win_start_s >= 0.0) || !(c->win_end_s > c->win_start_s)) {
        return sim_err(err, errlen, "metrics window must satisfy 0 <= start < end");
    }
    if (c->trace_decimation == 0u) {
        return sim_err(err, errlen, "trace decimation must be >= 1");
    }
    if (c->arm_delay_periods > SIM_ARM_DELAY_MAX) {
        char msg[96];
        (void)snprintf(msg, sizeof msg, "arm delay %lu periods out of range [0, %u]",
                       (unsigned long)c->arm_delay_periods, (unsigned)SIM_ARM_DELAY_MAX);
        return sim_err(err, errlen, msg);
    }
    if (!(c->load_passive_nm >= 0.0) || !isfinite(c->load_passive_nm)) {
        return sim_err(err, errlen, "passive load must be a finite magnitude >= 0 N*m");
    }
    /* On the dynamometer the machine file's own load is the dynamometer's
     * to hold; a load the run asks for is refused. */
    const sim_machine_t *pm = &c->plant_machine;
    if (!c->free_mech &&
        (c->load_nm != (pm->load_kind == SIM_LOAD_CONSTANT ? pm->load_nm : 0.0) ||
         c->load_passive_nm != (pm->load_kind == SIM_LOAD_PASSIVE ? pm->load_nm : 0.0))) {
        return sim_err(err, errlen,
                       "a load torque needs free mechanics (a dynamometer imposes "
                       "the speed)");
    }
    if (c->n_sets > SIM_MAX_SETS) {
        return sim_err(err, errlen, "too many tunables set");
    }
    if (cfg->scenario != NULL) {
        r->scn = *cfg->scenario;
        r->scn.next = 0u;
        r->has_scn = true;
    }

    plant_config_t pc;
    sim_machine_to_plant(&c->plant_machine, &pc);
    pc.mech = c->free_mech ? PLANT_MECH_FREE : PLANT_MECH_IMPOSED;
    pc.speed0_rpm = c->speed_rpm;
    pc.theta0_e_rad = c->theta0_e_rad;
    /* The load is applied at the arm instant: a constant load torque on a free
     * rotor during the calibration (no motor torque) would spin it backwards. */
    pc.load_torque_nm = 0.0;
    if (c->plant_machine.fluxmap_path[0] != '\0') {
#if defined(ENGINE_PORT_QEMU)
        return sim_err(err, errlen, "flux maps are files: the QEMU images have none");
#else
        /* Saturation: the plant integrates in flux coordinates with the map. */
        if (plant_fluxmap_load(&r->fluxmap, c->plant_machine.fluxmap_path, err, errlen) !=
            PLANT_OK) {
            return -1;
        }
        pc.fluxmap = &r->fluxmap;
#endif
    }
    if (plant_init(&r->plant, &pc) != PLANT_OK) {
        return sim_err(err, errlen, "plant rejected the machine configuration");
    }
    /* The active load profile starts with the constant load, at arm. */
    plant_load_profile_enable(&r->plant, 0);
    c->hal.pwm_freq_hz = c->fs_hz;
    c->hal.seed = c->seed;
    /* The plant's encoder: the simulated machine's [sensors]. */
    if (c->plant_machine.encoder_lines > 0) {
        c->hal.enc_lines = (uint32_t)c->plant_machine.encoder_lines;
    }
    c->hal.enc_zero_rad =
        c->plant_machine.encoder_offset_deg * CTRL_PI / 180.0 / (double)c->plant_machine.pole_pairs;
    c->hal.enc_dir = c->plant_machine.encoder_direction < 0 ? -1 : 1;
    if (engine_hal_init(&r->hal, &c->hal, &r->plant) != 0) {
        return sim_err(err, errlen, "HAL simulation rejected its configuration");
    }
    fw_config_t fc;
    sim_run_fw_config(c, &c->ctrl_machine, &fc);
    if (!(c->speed_kp > 0.0)) {
        /* The speed-loop design named before fw_init (which only says no). */
        fw_speed_design_t sd = {c->speed_bw_hz, c->speed_pm_deg, 0.0, 0.0, 0.0, 0.0};
        const uint32_t div = (c->fs_hz + fc.speed_loop_hz / 2u) / fc.speed_loop_hz;
        const double lpf = CTRL_SPEED_LPF_HZ_DEFAULT < 0.45 * (double)c->fs_hz
                               ? CTRL_SPEED_LPF_HZ_DEFAULT
                               : 0.45 * (double)c->fs_hz;
        if (fw_speed_loop_design(&sd, &c->ctrl_machine, (double)c->fs_hz / (double)div, lpf, err,
                                 errlen) != CTRL_OK) {
            return -1;
        }
    }
    if (c->ctrl_cfg == NULL) {
        if (sim_ctrl_cfg_build(c, &c->ctrl_machine, r->ctrl_cfg_buf, err, errlen) != 0) {
            return -1;
        }
        fc.ctrl_cfg = r->ctrl_cfg_buf;
    } else {
        fc.ctrl_cfg = c->ctrl_cfg;
    }
    const int frc = fw_init(&r->fw, &r->hal, &fc);
    if (frc != FW_OK) {
        char why[200];
        (void)fw_explain(&r->fw, why, sizeof why);
        sim_explain_reject(c, frc, why, err, errlen);
        return -1;
    }
    r->torque_limit_nm = ctrl_q24_to_double(r->fw.torque_ref_max) * r->fw.bases.torque_nm;
    r->torque_limit_brake_nm =
        fmin(r->torque_limit_nm, fw_torque_limit_brake_nm(&c->ctrl_machine, c->ctrl, NULL));
    if (r->has_scn && sim_scenario_check(r, err, errlen) != 0) {
        return -1;
    }
    const fw_speed_info_t *si = &r->fw.speed_info;
    if (c->speed_mode && fabs(c->speed_ref_rpm) > si->speed_ref_max_rpm) {
        sim_warn(c->warnings,
                 "speed reference %g r/min is outside the drive's speed limit [-%g, %g] r/min "
                 "(the maximum speed; the overspeed trip is at %g r/min): the firmware clamps "
                 "it to %g r/min",
                 c->speed_ref_rpm, si->speed_ref_max_rpm, si->speed_ref_max_rpm, si->overspeed_rpm,
                 copysign(si->speed_ref_max_rpm, c->speed_ref_rpm));
    }
    if (!c->free_mech && fabs(c->speed_rpm) > si->overspeed_rpm) {
        sim_warn(c->warnings,
                 "imposed speed %g r/min is above the overspeed trip level %g r/min: the drive "
                 "will trip when armed",
                 c->speed_rpm, si->overspeed_rpm);
    }
    if (!c->speed_mode && fabs(c->torque_ref_nm) > r->torque_limit_nm) {
        double t_flux = 0.0;
        const double t_lim = fw_torque_limit_nm(&c->ctrl_machine, c->ctrl, &t_flux);
        char why[160];
        if (t_flux > 0.0 && t_lim < c->ctrl_machine.torque_rated_nm) {
            (void)snprintf(why, sizeof why,
                           "%g %% of %.4g N*m, the most %s gives at its flux reference %g Wb",
                           100.0 * FW_TORQUE_FLUX_MARGIN, t_flux, c->ctrl_machine.name,
                           c->ctrl_machine.psi_ref_wb);
        } else {
            (void)snprintf(why, sizeof why, "rated torque of %s", c->ctrl_machine.name);
        }
        sim_warn(c->warnings,
                 "torque reference %g N*m is outside the drive's torque limit [-%g, %g] N*m "
                 "(%s): the firmware clamps it to %g N*m",
                 c->torque_ref_nm, r->torque_limit_nm, r->torque_limit_nm, why,
                 copysign(r->torque_limit_nm, c->torque_ref_nm));
    }
    /* Regenerative braking (the imposed or initial speed against the torque)
     * on a fixed flux: the field weakening's period limit holds the lower
     * braking margin (field_weak.h). */
    const double t_brake = r->torque_limit_brake_nm;
    if (!c->speed_mode && c->speed_rpm * c->torque_ref_nm < 0.0 &&
        fabs(c->torque_ref_nm) > t_brake && t_brake < r->torque_limit_nm) {
        double t_flux = 0.0;
        (void)fw_torque_limit_brake_nm(&c->ctrl_machine, c->ctrl, &t_flux);
        sim_warn(c->warnings,
                 "torque reference %g N*m is outside the drive's braking torque limit %g N*m at "
                 "%g r/min (%g %% of %.4g N*m, the most %s gives at its flux reference %g Wb: "
                 "braking, the zero vector carries the load angle toward the pull-out): the "
                 "firmware limits it to %g N*m",
                 c->torque_ref_nm, t_brake, c->speed_rpm,
                 100.0 * CTRL_FIELDWEAK_TORQUE_MARGIN_BRAKE_DEFAULT, t_flux, c->ctrl_machine.name,
                 c->ctrl_machine.psi_ref_wb, copysign(t_brake, c->torque_ref_nm));
    }

    const double ts = 1.0 / (double)c->fs_hz;
    r->obs_dt = ts / (double)SIM_OBS_PER_PERIOD;
    double f1 = fabs(c->speed_rpm) * (double)c->plant_machine.pole_pairs / 60.0;
    if (c->free_mech) {
        f1 = 1.0; /* placeholder: samples are kept, f1 set from the mean speed later */
    }
    if (c->skip_thd) {
        f1 = 0.0;
    }
    metrics_init(&r->m_plant, METRICS_SAMPLING_PLANT, f1);
    metrics_init(&r->m_ctrl, METRICS_SAMPLING_CONTROL, 0.0);
    /* THD is a distortion ratio only where there is a fundamental to refer
     * to: below 5 % of the rated current it measures the ripple (at zero
     * torque it reached ~1000 %), so it is reported as undefined. */
    r->m_plant.thd_i1_min_a = 0.05 * c->plant_machine.current_rated_a;

    r->t_end = c->duration_s;
    r->obs_on = false;
    if (c->trace != NULL) {
        fprintf(c->trace, "t,i_a,i_b,i_c,i_d,i_q,psi_s,torque,speed_rpm,torque_ref,vec,duty,state,"
                          "speed_ref_rpm,load_nm,v_a,v_b,v_c,i_inv_a\n");
    }
    if (c->link != NULL && c->link->setup(c->link->ctx, r, &fc, err, errlen) != 0) {
        r->link_failed = true;
        return -1;
    }
    if (c->defer_start) {
        return 0; /* the caller runs the periods from boot on (sim_run_period) */
    }
    /* Boot and offset calibration with the gates off, then the arm. */
    const uint32_t max_boot = c->calib_samples + 16u + c->arm_delay_periods;
    for (uint32_t k = 0; k < max_boot && !r->armed; k++) {
        if (sim_run_period(r) != 0) {
            if (r->link_failed) {
                (void)snprintf(err, errlen, "PIL link during calibration: %s",
                               c->link->error(c->link->ctx));
                return -1;
            }
            return sim_err(err, errlen, "plant failed during calibration");
        }
        if (fw_state(&r->fw) == FW_STATE_FAULT) {
            char msg[200];
            (void)snprintf(msg, sizeof msg, "firmware fault during calibration: %s",
                           fw_fault_name(fw_fault(&r->fw)));
            return sim_err(err, errlen, msg);
        }
    }
    if (!r->armed && c->auto_arm) {
        return sim_err(err, errlen, "firmware did not finish calibration");
    }
    return 0;
}

bool sim_run_faulted(const sim_run_t *r)
{
    return !isnan(r->fault_time_s) || fw_state(&r->fw) == FW_STATE_FAULT;
}

int sim_run_all(sim_run_t *r, char *err, size_t errlen)
{
    while (!sim_run_done(r)) {
        if (sim_run_period(r) != 0) {
            char msg[400];
            if (r->link_failed) {
                (void)snprintf(msg, sizeof msg, "PIL link at t = %.6f s: %s", sim_run_time(r),
                               r->cfg.link->error(r->cfg.link->ctx));
                return sim_err(err, errlen, msg);
            }
            (void)snprintf(msg, sizeof msg, "plant integration failed at t = %.6f s (code %d)",
                           sim_run_time(r), r->plant_rc);
            return sim_err(err, errlen, msg);
        }
        if (r->cfg.stop_on_fault && !isnan(r->fault_time_s)) {
            break;
        }
    }
    if (r->has_scn) {
        for (size_t i = 0; i < r->scn.n; i++) {
            const sim_event_t *e = &r->scn.ev[i];
            if (isnan(r->scn_fired_s[i]) && !(e->trig == SIM_TRIG_AT && e->level >= r->t_end)) {
                char trig[48];
                sim_warn(r->cfg.warnings, "scenario line %d (%s) never fired", e->line,
                         sim_trig_text(e, trig, sizeof trig));
            }
        }
    }
    return 0;
}

/* The tolerance of torque following: max(5 % of the reference, 2 % of the
 * rated torque), the floor for small references whose mean the ripple
 * resolves no better. */
static double sim_torque_tolerance_nm(double tref_nm, double rated_nm)
{
    return fmax(0.05 * fabs(tref_nm), 0.02 * fabs(rated_nm));
}

/* Appends "; " (unless first) and the formatted text to buf of size cap. */
static void sim_why_add(char *buf, size_t cap, const char *fmt, ...)
{
    const size_t n = strlen(buf);
    if (n + 2u >= cap) {
        return;
    }
    size_t k = n;
    if (n > 0u) {
        buf[k++] = ';';
        buf[k++] = ' ';
        buf[k] = '\0';
    }
    va_list ap;
    va_start(ap, fmt);
    (void)vsnprintf(buf + k, cap - k, fmt, ap);
    va_end(ap);
}

/* Torque mode, no fault: the plant's mean torque over the window against the
 * mean reference applied (after the drive's limits). The simulator knows the
 * true torque, the drive only its estimate: a miss is reported with the
 * mechanisms known to cause one, so that no wrong torque goes without a
 * word. */
static void sim_torque_follow_check(sim_run_t *r, const metrics_result_t *mp)
{
    const sim_run_cfg_t *c = &r->cfg;
    if (c->speed_mode || r->lim_n == 0u || !isnan(r->fault_time_s) ||
        !isfinite(mp->torque_mean_nm)) {
        return;
    }
    const double applied = r->tref_sum_nm / (double)r->lim_n;
    const double miss = mp->torque_mean_nm - applied;
    if (fabs(miss) <= sim_torque_tolerance_nm(applied, c->plant_machine.torque_rated_nm)) {
        return;
    }
    char why[400] = "";
    if (strcmp(c->ctrl->name, "fst") == 0) {
        sim_why_add(why, sizeof why,
                    "FST's offset of one vector per period (docs/algorithms.md; tunable f_i)");
    }
    if (r->lim_weak_n > 0u) {
        sim_why_add(why, sizeof why, "the voltage limit (flux weakened in %.0f %% of the periods)",
                    100.0 * (double)r->lim_weak_n / (double)r->lim_n);
    }
    if (c->plant_machine.filter.type != PLANT_FILTER_NONE) {
        sim_why_add(why, sizeof why, "the output filter between inverter and motor (%s)",
                    c->plant_machine.filter.type == PLANT_FILTER_PASSIVE ? "passive" : "active");
    }
    if (c->plant_machine.dead_time_s > 0.0 || c->plant_machine.v_fwd_v > 0.0) {
        sim_why_add(why, sizeof why, "the inverter's dead time (%.0f ns) and device drop (%.3g V)",
                    c->plant_machine.dead_time_s * 1e9, c->plant_machine.v_fwd_v);
    }
    sim_warn(c->warnings,
             "torque not followed: controller %s, plant mean torque %.4g N*m against the applied "
             "reference %.4g N*m (%+.1f %%, tolerance %.3g N*m: max(5 %%, 2 %% of rated)), "
             "requested %.4g N*m; known mechanism: %s",
             c->ctrl->name, mp->torque_mean_nm, applied,
             applied != 0.0 ? 100.0 * miss / fabs(applied) : 0.0,
             sim_torque_tolerance_nm(applied, c->plant_machine.torque_rated_nm),
             r->torque_ref_requested_nm, why[0] != '\0' ? why : "none known");
}

int sim_run_metrics(sim_run_t *r, metrics_result_t *plant, metrics_result_t *ctrl)
{
    if (!r->win_done && r->win_started) {
        sim_count_transitions(r, sim_run_time(r));
        sim_filter_window_end(r, sim_run_time(r));
    }
    if (r->cfg.free_mech && !r->cfg.skip_thd) {
        const double mean_rpm = r->speed_n > 0u ? r->speed_sum_rpm / (double)r->speed_n : 0.0;
        r->m_plant.f1_hz = fabs(mean_rpm) * (double)r->cfg.plant_machine.pole_pairs / 60.0;
    }
    if (!r->cfg.speed_mode && r->lim_clipped_n > 0u && !r->lim_warned) {
        /* Not a silent clamp: T_sse is against the reference the drive could
         * apply, so say that it differs from the one asked for. */
        static const char *const lim_names[CTRL_FIELDWEAK_LIMIT_COUNT] = {
            "the current limit", "the voltage limit", "MTPV", "the flux reference's torque"};
        sim_warn(r->cfg.warnings,
                 "torque reference %g N*m was limited to %.4g N*m (mean; down to %.4g N*m) by %s "
                 "in %.0f %% of the window's periods: T_sse and torque_ref_applied_nm are "
                 "against the limited reference",
                 r->torque_ref_requested_nm, r->tref_sum_nm / (double)r->lim_n, r->lim_min_nm,
                 lim_names[r->lim_last & 3u], 100.0 * (double)r->lim_clipped_n / (double)r->lim_n);
        r->lim_warned = true;
    }
    const int a = metrics_finish(&r->m_plant, plant);
    const int b = metrics_finish(&r->m_ctrl, ctrl);
    if (a == 0) {
        sim_torque_follow_check(r, plant);
    }
    return (a == 0 && b == 0) ? 0 : -1;
}

double sim_run_speed_rpm(const sim_run_t *r)
{
    return plant_omega_m(&r->plant) * 60.0 / (2.0 * CTRL_PI);
}

static void sim_json_num(FILE *f, const char *key, double v)
{
    if (isfinite(v)) {
        fprintf(f, "  \"%s\": %.9g,\n", key, v);
    } else {
        fprintf(f, "  \"%s\": null,\n", key);
    }
}

/* "filter": {...} over the metrics window: type, current sensing, losses,
 * per-phase RMS and peak of each branch current, the active filter's
 * capacitor range and half-bridge switching frequency (per leg). */
static void sim_write_filter_json(FILE *f, const sim_run_t *r)
{
    const plant_filter_stats_t *a = &r->flt_w0, *b = &r->flt_w1;
    const double w = r->flt_t1 - r->flt_t0;
    if (r->cfg.plant_machine.filter.type == PLANT_FILTER_NONE || !r->flt_w1_set || !(w > 0.0)) {
        return;
    }
    fprintf(f, "  \"filter\": {\n    \"type\": \"%s\",\n    \"current_sense\": \"%s\",\n",
            b->type == PLANT_FILTER_PASSIVE ? "passive" : "active",
            r->cfg.hal.sense_motor_side ? "motor" : "inverter");
    fprintf(f, "    \"loss_w\": %.6g,\n", (b->e_loss_j - a->e_loss_j) / w);
    fprintf(f, "    \"branches\": {");
    for (int k = 0; k < b->n_branches; ++k) {
        const double rms = sqrt(fmax(0.5 * (b->i2_int[k] - a->i2_int[k]) / w, 0.0));
        fprintf(f, "%s\n      \"%s\": {\"i_rms_a\": %.6g, \"i_peak_a\": %.6g}", k ? "," : "",
                plant_filter_branch_name((int)b->type, k), rms, b->i_peak[k]);
    }
    fprintf(f, "\n    }");
    if (b->type == PLANT_FILTER_ACTIVE) {
        fprintf(f, ",\n    \"af_cf_min_v\": %.6g,\n    \"af_cf_max_v\": %.6g", b->cf_min_v,
                b->cf_max_v);
        fprintf(f, ",\n    \"af_switching_hz\": %.6g",
                (double)(b->af_transitions - a->af_transitions) / (2.0 * 3.0 * w));
    }
    fprintf(f, "\n  },\n");
}

void sim_run_write_metrics_json(FILE *f, const sim_run_t *r, const metrics_result_t *mp,
                                const metrics_result_t *mc)
{
    const sim_run_cfg_t *c = &r->cfg;
    fprintf(f, "{\n");
    fprintf(f, "  \"controller\": \"%s\",\n", c->ctrl->name);
    fprintf(f, "  \"machine\": \"%s\",\n", c->plant_machine.name);
    fprintf(f, "  \"window\": [%.9g, %.9g],\n", c->win_start_s, c->win_end_s);
    fprintf(f, "  \"sampling\": \"plant grid Ts/%u (true signals); *_ctrl: control instants\",\n",
            SIM_OBS_PER_PERIOD);
    fprintf(f, "  \"mode\": \"%s\",\n", c->speed_mode ? "speed" : "torque");
    fprintf(f, "  \"mechanics\": \"%s\",\n", c->free_mech ? "free" : "dynamometer");
    sim_json_num(f, "fs_hz", (double)c->fs_hz);
    sim_json_num(f, "torque_ref_requested_nm", c->speed_mode ? NAN : r->torque_ref_requested_nm);
    /* Torque mode: the mean reference the controller got over the window,
     * after the static clamp and the field-weakening limit. */
    sim_json_num(f, "torque_ref_applied_nm",
                 c->speed_mode || r->lim_n == 0u ? NAN : r->tref_sum_nm / (double)r->lim_n);
    sim_json_num(f, "torque_ref_clipped_frac",
                 c->speed_mode || r->lim_n == 0u ? NAN
                                                 : (double)r->lim_clipped_n / (double)r->lim_n);
    sim_json_num(f, "torque_limit_nm", r->torque_limit_nm);
    sim_json_num(f, "torque_limit_brake_nm", r->torque_limit_brake_nm);
    {
        /* Field weakening at the end of the run (pipeline.h fw_telemetry_t):
         * the torque limit of the last period and what set it. */
        static const char *const lim_names[CTRL_FIELDWEAK_LIMIT_COUNT] = {"current", "voltage",
                                                                          "mtpv", "flux"};
        const fw_telemetry_t *tm = fw_telemetry(&r->fw);
        sim_json_num(f, "torque_max_nm",
                     ctrl_q24_to_double(tm->torque_max) * r->fw.bases.torque_nm);
        fprintf(f, "  \"fieldweak_limit\": \"%s\",\n", lim_names[tm->fieldweak_limit & 3u]);
        fprintf(f, "  \"fieldweak_clipped\": %u,\n  \"fieldweak_active\": %u,\n",
                (tm->fieldweak_limit >> 2) & 1u, (tm->fieldweak_limit >> 3) & 1u);
        /* the firmware's torque supervision (torque_follow.h) at the end */
        fprintf(f, "  \"torque_follow_warning\": %u,\n", (tm->fieldweak_limit >> 4) & 1u);
    }
    sim_json_num(f, "speed_ref_rpm", sim_run_speed_ref_now(r));
    sim_json_num(f, "speed_imposed_rpm", c->free_mech ? NAN : sim_run_speed_rpm(r));
    sim_json_num(f, "load_nm", c->free_mech ? r->plant.load_torque_nm : NAN);
    sim_json_num(f, "load_passive_nm", c->free_mech ? r->plant.load_passive_nm : NAN);
    const fw_speed_info_t *si = &r->fw.speed_info;
    sim_json_num(f, "speed_kp_nm_s_per_rad", si->kp_nm_s_rad);
    sim_json_num(f, "speed_ki_nm_per_rad", si->ki_nm_rad);
    sim_json_num(f, "speed_bandwidth_hz", si->bandwidth_hz > 0.0 ? si->bandwidth_hz : NAN);
    sim_json_num(f, "speed_phase_margin_deg",
                 si->phase_margin_deg > 0.0 ? si->phase_margin_deg : NAN);
    sim_json_num(f, "overspeed_rpm", si->overspeed_rpm);
    sim_json_num(f, "torque_mean_nm", mp->torque_mean_nm);
    sim_json_num(f, "torque_ripple_nm", mp->torque_ripple_nm);
    sim_json_num(f, "flux_mean_wb", mp->flux_mean_wb);
    sim_json_num(f, "flux_ripple_wb", mp->flux_ripple_wb);
    sim_json_num(f, "torque_sse_nm", mp->torque_sse_nm);
    /* The mean torque's error against the request as well as against the
     * applied (limited) reference of T_sse: a drive that delivers nothing
     * because its limit said so has T_sse 0 but not this. */
    sim_json_num(f, "torque_err_request_nm",
                 c->speed_mode ? NAN : mp->torque_mean_nm - r->torque_ref_requested_nm);
    sim_json_num(f, "torque_err_applied_nm",
                 c->speed_mode || r->lim_n == 0u
                     ? NAN
                     : mp->torque_mean_nm - r->tref_sum_nm / (double)r->lim_n);
    sim_json_num(f, "f_av_hz", mp->f_av_hz);
    sim_json_num(f, "thd_i_pct", mp->thd_i_pct);
    sim_json_num(f, "i1_amp_a", mp->i1_amp_a);
    sim_json_num(f, "torque_ripple_pp_nm", mp->torque_pp_nm);
    sim_json_num(f, "thd_v_pct", mp->thd_v_pct);
    sim_json_num(f, "v1_amp_v", mp->v1_amp_v);
    sim_write_filter_json(f, r);
    sim_mech_summary_t ms;
    sim_run_mech_summary(r, &ms);
    if (ms.present) {
        /* only for a machine with non-ideal mechanics on a free rotor */
        sim_json_num(f, "mech_stuck_s", ms.stuck_s);
        sim_json_num(f, "mech_stuck_frac", ms.stuck_frac);
        sim_json_num(f, "mech_breakaways", (double)ms.breakaways);
        sim_json_num(f, "mech_stops", (double)ms.stops);
        sim_json_num(f, "mech_reversals", (double)ms.reversals);
        sim_json_num(f, "mech_friction_torque_nm", ms.friction_nm);
        sim_json_num(f, "mech_load_torque_nm", ms.load_nm);
        sim_json_num(f, "mech_friction_power_w", ms.friction_w);
    }
    sim_json_num(f, "torque_mean_ctrl_nm", mc->torque_mean_nm);
    sim_json_num(f, "torque_ripple_ctrl_nm", mc->torque_ripple_nm);
    sim_json_num(f, "flux_mean_ctrl_wb", mc->flux_mean_wb);
    sim_json_num(f, "flux_ripple_ctrl_wb", mc->flux_ripple_wb);
    sim_json_num(f, "torque_sse_ctrl_nm", mc->torque_sse_nm);
    const double mean_rpm = r->speed_n > 0u ? r->speed_sum_rpm / (double)r->speed_n : NAN;
    sim_json_num(f, "speed_mean_rpm", mean_rpm);
    sim_json_num(f, "speed_end_rpm", sim_run_speed_rpm(r));
    const bool spd_err = c->speed_mode && r->speed_n > 0u;
    sim_json_num(f, "speed_err_rms_rpm",
                 spd_err ? sqrt(r->speed_err_sum2 / (double)r->speed_n) : NAN);
    sim_json_num(f, "speed_err_max_rpm", spd_err ? r->speed_err_max : NAN);
    double ea;
    double em;
    double es;
    sim_run_est_errors(r, &ea, &em, &es);
    sim_json_num(f, "est_angle_err_rms_deg", ea);
    sim_json_num(f, "est_angle_err_max_deg", em);
    sim_json_num(f, "est_speed_err_rms_rpm", es);
    sim_run_est_errors_low(r, &ea, &em);
    sim_json_num(f, "est_angle_err_low_rms_deg", ea);
    sim_json_num(f, "est_angle_err_low_max_deg", em);
#if CTRL_SL_HFI
    sim_json_num(f, "hfi_clipped_periods", (double)r->fw.hfi_clipped);
    if (r->cfg.sensorless) {
        /* where the start's polarity came from (sensorless.h, CTRL_SL_POL_*) */
        static const char *const pol[4] = {"unknown", "saturation", "motion", "unknown"};
        fprintf(f, "  \"sensorless_polarity\": \"%s\",\n",
                pol[(fw_telemetry(&r->fw)->sl_state >> 5) & 3u]);
    }
#endif
    sim_json_num(f, "fault_time_s", r->fault_time_s);
    fprintf(f, "  \"scenario_fired_s\": [");
    for (size_t i = 0; r->has_scn && i < r->scn.n; i++) {
        if (isnan(r->scn_fired_s[i])) {
            fprintf(f, "%snull", i ? ", " : "");
        } else {
            fprintf(f, "%s%.9g", i ? ", " : "", r->scn_fired_s[i]);
        }
    }
    fprintf(f, "],\n");
    fprintf(f, "  \"warnings\": ");
    sim_warnings_json(f, c->warnings);
    fprintf(f, ",\n");
    fprintf(f, "  \"state\": \"%s\",\n", fw_state_name(fw_state(&r->fw)));
    fprintf(f, "  \"fault\": \"%s\"\n", fw_fault_name(fw_fault(&r->fw)));
    fprintf(f, "}\n");
}

void sim_run_free(sim_run_t *r)
{
    if (r != NULL) {
        metrics_free(&r->m_plant);
        metrics_free(&r->m_ctrl);
        plant_fluxmap_free(&r->fluxmap);
        /* Idempotent: a second call finds nothing to free. */
        memset(&r->m_plant, 0, sizeof r->m_plant);
        memset(&r->m_ctrl, 0, sizeof r->m_ctrl);
    }
}
