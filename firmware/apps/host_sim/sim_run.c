/* Closed loop on the host (see sim_run.h). */
#include "sim_run.h"

#include <math.h>
#include <string.h>

#define SIM_PI 3.14159265358979323846
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
    out->current_rated_a = m->current_rated_a;
    out->current_max_a = m->current_max_a;
    out->psi_ref_wb = m->psi_ref_wb;
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
    hal_sim_config_default(&c->hal, c->fs_hz, m->current_max_a, m->vdc_v);
}

static double sim_torque_ref_nm(const sim_run_t *r)
{
    return ctrl_q24_to_double(r->fw.refs.torque) * r->fw.bases.torque_nm;
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
    if (t >= r->cfg.win_start_s && t <= r->cfg.win_end_s) {
        metrics_add(&r->m_plant, t, tq, tref, psi, i_abc[0]);
        r->speed_sum_rpm += plant_omega_m(p) * 60.0 / (2.0 * SIM_PI);
        r->speed_n++;
    }
    if (r->cfg.trace != NULL && (r->obs_count % r->cfg.trace_decimation) == 0u &&
        t >= r->cfg.trace_start_s && t <= r->cfg.trace_end_s) {
        double id, iq;
        plant_i_dq(p, &id, &iq);
        const fw_telemetry_t *tm = fw_telemetry(&r->fw);
        fprintf(r->cfg.trace, "%.9g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%u,%.4f,%u\n", t,
                i_abc[0], i_abc[1], i_abc[2], id, iq, psi, tq,
                plant_omega_m(p) * 60.0 / (2.0 * SIM_PI), tref, (unsigned)r->vec_now, r->duty_now,
                (unsigned)tm->state);
    }
    r->obs_count++;
}

static void sim_apply_event(sim_run_t *r, const sim_event_t *e)
{
    if (e->set & SIM_SET_TORQUE_REF) {
        fw_set_torque_ref_nm(&r->fw, e->torque_ref_nm);
    }
    if (e->set & SIM_SET_SPEED_REF) {
        fw_set_speed_ref_rpm(&r->fw, e->speed_ref_rpm);
    }
    if (e->set & SIM_SET_LOAD) {
        plant_set_load_torque(&r->plant, e->load_nm);
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
        const double rpm = plant_omega_m(&r->plant) * 60.0 / (2.0 * SIM_PI);
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
        s->next++;
    }
}

/* One period without the scenario/metrics bookkeeping (boot phase too). */
static int sim_period_raw(sim_run_t *r)
{
    /* The plan chosen at k-1 acts in this period (gates on) or nothing does. */
    const ctrl_plan_t *a = &r->fw.applied;
    const bool on = fw_state(&r->fw) == FW_STATE_RUNNING && a->n_seg > 0u;
    r->vec_now = on ? a->vec[0] : 0u;
    r->duty_now = on ? ctrl_q24_to_double(a->dur[0]) : 0.0;
    hal_sim_period_begin(&r->hal);
    fw_isr(&r->fw);
    /* The host main loop: kicks the watchdog once per period. */
    fw_watchdog_kick(&r->fw);
    const int rc = hal_sim_period_end(&r->hal);
    if (rc != PLANT_OK) {
        r->plant_rc = rc;
        return -1;
    }
    return 0;
}

/* Leg transitions between the window start and t (period boundaries). */
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

int sim_run_period(sim_run_t *r)
{
    const double t = sim_run_time(r);
    sim_observer_update(r, t);
    sim_scenario_step(r, t);
    if (t >= r->cfg.win_start_s && !r->win_started) {
        r->win_started = true;
        r->tr_win_start = plant_transitions(&r->plant);
        r->t_win_start = t;
    }
    if (t >= r->cfg.win_end_s && r->win_started && !r->win_done) {
        r->win_done = true;
        sim_count_transitions(r, t);
    }
    if (t >= r->cfg.win_start_s && t <= r->cfg.win_end_s) {
        double i_abc[3];
        plant_i_abc(&r->plant, i_abc);
        metrics_add(&r->m_ctrl, t, plant_torque(&r->plant), sim_torque_ref_nm(r),
                    plant_psi_amp(&r->plant), i_abc[0]);
    }
    return sim_period_raw(r);
}

int sim_run_init(sim_run_t *r, const sim_run_cfg_t *cfg, char *err, size_t errlen)
{
    memset(r, 0, sizeof *r);
    r->cfg = *cfg;
    sim_run_cfg_t *c = &r->cfg;
    /* The controller's machine name points into the copied plant machine. */
    if (cfg->ctrl_machine.name == cfg->plant_machine.name) {
        c->ctrl_machine.name = c->plant_machine.name;
    }
    if (c->ctrl == NULL) {
        return sim_err(err, errlen, "no controller");
    }
    if (c->fs_hz < 1000u || c->fs_hz > 200000u) {
        return sim_err(err, errlen, "sampling frequency out of range (1 kHz .. 200 kHz)");
    }
    if (!(c->duration_s > 0.0) || c->duration_s > 100.0) {
        return sim_err(err, errlen, "duration out of range (0 .. 100 s)");
    }
    if (!(c->win_start_s >= 0.0) || !(c->win_end_s > c->win_start_s)) {
        return sim_err(err, errlen, "metrics window must satisfy 0 <= start < end");
    }
    if (c->trace_decimation == 0u) {
        return sim_err(err, errlen, "trace decimation must be >= 1");
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
    /* The load is applied at the arm instant: a constant load torque on a free
     * rotor during the calibration (no motor torque) would spin it backwards. */
    pc.load_torque_nm = 0.0;
    if (plant_init(&r->plant, &pc) != PLANT_OK) {
        return sim_err(err, errlen, "plant rejected the machine configuration");
    }
    c->hal.pwm_freq_hz = c->fs_hz;
    c->hal.seed = c->seed;
    if (hal_sim_init(&r->hal, &c->hal, &r->plant) != HAL_SIM_OK) {
        return sim_err(err, errlen, "HAL simulation rejected its configuration");
    }
    fw_config_t fc;
    fw_config_default(&fc, &c->ctrl_machine, c->ctrl);
    fc.ctrl_cfg = c->ctrl_cfg;
    fc.calib_samples = c->calib_samples;
    const int frc = fw_init(&r->fw, &r->hal, &fc);
    if (frc != FW_OK) {
        char msg[200];
        (void)snprintf(msg, sizeof msg, "firmware init failed: %s", fw_strerror(frc));
        return sim_err(err, errlen, msg);
    }

    const double ts = 1.0 / (double)c->fs_hz;
    r->obs_dt = ts / (double)SIM_OBS_PER_PERIOD;
    double f1 = fabs(c->speed_rpm) * (double)c->plant_machine.pole_pairs / 60.0;
    if (c->free_mech) {
        f1 = 1.0; /* placeholder: samples are kept, f1 set from the mean speed later */
    }
    metrics_init(&r->m_plant, METRICS_SAMPLING_PLANT, f1);
    metrics_init(&r->m_ctrl, METRICS_SAMPLING_CONTROL, 0.0);

    /* Boot and offset calibration with the gates off. */
    const uint32_t max_boot = c->calib_samples + 16u;
    for (uint32_t k = 0; k < max_boot && fw_state(&r->fw) != FW_STATE_READY; k++) {
        if (sim_period_raw(r) != 0) {
            return sim_err(err, errlen, "plant failed during calibration");
        }
        if (fw_state(&r->fw) == FW_STATE_FAULT) {
            char msg[200];
            (void)snprintf(msg, sizeof msg, "firmware fault during calibration: %s",
                           fw_fault_name(fw_fault(&r->fw)));
            return sim_err(err, errlen, msg);
        }
    }
    if (fw_state(&r->fw) != FW_STATE_READY) {
        return sim_err(err, errlen, "firmware did not finish calibration");
    }
    if (c->speed_mode) {
        fw_set_speed_ref_rpm(&r->fw, c->speed_ref_rpm);
    } else {
        fw_set_torque_ref_nm(&r->fw, c->torque_ref_nm);
    }
    fw_cmd_arm(&r->fw);
    if (c->free_mech) {
        plant_set_load_torque(&r->plant, c->load_nm);
    }
    r->t_arm = plant_time(&r->plant);
    r->t_end = c->duration_s;
    r->obs_on = false;
    if (c->trace != NULL) {
        fprintf(c->trace,
                "t,i_a,i_b,i_c,i_d,i_q,psi_s,torque,speed_rpm,torque_ref,vec,duty,state\n");
    }
    return 0;
}

int sim_run_all(sim_run_t *r, char *err, size_t errlen)
{
    const double half = 0.5 / (double)r->cfg.fs_hz;
    while (sim_run_time(r) + half < r->t_end) {
        if (sim_run_period(r) != 0) {
            char msg[200];
            (void)snprintf(msg, sizeof msg, "plant integration failed at t = %.6f s (code %d)",
                           sim_run_time(r), r->plant_rc);
            return sim_err(err, errlen, msg);
        }
    }
    return 0;
}

int sim_run_metrics(sim_run_t *r, metrics_result_t *plant, metrics_result_t *ctrl)
{
    if (!r->win_done && r->win_started) {
        sim_count_transitions(r, sim_run_time(r));
    }
    if (r->cfg.free_mech) {
        const double mean_rpm = r->speed_n > 0u ? r->speed_sum_rpm / (double)r->speed_n : 0.0;
        r->m_plant.f1_hz = fabs(mean_rpm) * (double)r->cfg.plant_machine.pole_pairs / 60.0;
    }
    const int a = metrics_finish(&r->m_plant, plant);
    const int b = metrics_finish(&r->m_ctrl, ctrl);
    return (a == 0 && b == 0) ? 0 : -1;
}

static void sim_json_num(FILE *f, const char *key, double v, bool comma)
{
    if (isfinite(v)) {
        fprintf(f, "  \"%s\": %.9g%s\n", key, v, comma ? "," : "");
    } else {
        fprintf(f, "  \"%s\": null%s\n", key, comma ? "," : "");
    }
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
    sim_json_num(f, "fs_hz", (double)c->fs_hz, true);
    sim_json_num(f, "torque_mean_nm", mp->torque_mean_nm, true);
    sim_json_num(f, "torque_ripple_nm", mp->torque_ripple_nm, true);
    sim_json_num(f, "flux_mean_wb", mp->flux_mean_wb, true);
    sim_json_num(f, "flux_ripple_wb", mp->flux_ripple_wb, true);
    sim_json_num(f, "torque_sse_nm", mp->torque_sse_nm, true);
    sim_json_num(f, "f_av_hz", mp->f_av_hz, true);
    sim_json_num(f, "thd_i_pct", mp->thd_i_pct, true);
    sim_json_num(f, "torque_mean_ctrl_nm", mc->torque_mean_nm, true);
    sim_json_num(f, "torque_ripple_ctrl_nm", mc->torque_ripple_nm, true);
    sim_json_num(f, "flux_mean_ctrl_wb", mc->flux_mean_wb, true);
    sim_json_num(f, "flux_ripple_ctrl_wb", mc->flux_ripple_wb, true);
    sim_json_num(f, "torque_sse_ctrl_nm", mc->torque_sse_nm, true);
    const double mean_rpm = r->speed_n > 0u ? r->speed_sum_rpm / (double)r->speed_n : NAN;
    sim_json_num(f, "speed_mean_rpm", mean_rpm, true);
    sim_json_num(f, "speed_end_rpm", plant_omega_m(&r->plant) * 60.0 / (2.0 * SIM_PI), true);
    fprintf(f, "  \"state\": \"%s\",\n", fw_state_name(fw_state(&r->fw)));
    fprintf(f, "  \"fault\": \"%s\"\n", fw_fault_name(fw_fault(&r->fw)));
    fprintf(f, "}\n");
}

void sim_run_free(sim_run_t *r)
{
    if (r != NULL) {
        metrics_free(&r->m_plant);
        metrics_free(&r->m_ctrl);
        /* Idempotent: a second call finds nothing to free. */
        memset(&r->m_plant, 0, sizeof r->m_plant);
        memset(&r->m_ctrl, 0, sizeof r->m_ctrl);
    }
}
