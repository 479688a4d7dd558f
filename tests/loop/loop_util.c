#include "loop_util.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "fw_state.h"
#include "unity.h"

sim_machine_t loop_machine_file(const char *file)
{
    sim_machine_t m;
    char path[512];
    char err[256];
    (void)snprintf(path, sizeof path, "%s/%s", PMSM_MACHINES_DIR, file);
    if (sim_machine_load(path, &m, err, sizeof err) != 0) {
        TEST_FAIL_MESSAGE(err);
    }
    return m;
}

/* Machine file `file` into *m once (*loaded set). */
static const sim_machine_t *loop_machine(sim_machine_t *m, int *loaded, const char *file)
{
    if (!*loaded) {
        *m = loop_machine_file(file);
        *loaded = 1;
    }
    return m;
}

const sim_machine_t *loop_spmsm(void)
{
    static sim_machine_t m;
    static int loaded;
    return loop_machine(&m, &loaded, "thesis_spmsm.ini");
}

const sim_machine_t *loop_ipmsm80(void)
{
    static sim_machine_t m;
    static int loaded;
    return loop_machine(&m, &loaded, "thesis_ipmsm_80kw.ini");
}

void loop_cfg_machine(sim_run_cfg_t *c, const sim_machine_t *m, const char *name, uint32_t fs,
                      double speed_rpm, double torque_nm, double duration_s, double win_start_s)
{
    const ctrl_desc_t *d = ctrl_find(name);
    TEST_ASSERT_NOT_NULL_MESSAGE(d, name);
    sim_run_config_default(c, m, d);
    c->fs_hz = fs != 0u ? fs : d->fs_default_hz;
    c->hal.pwm_freq_hz = c->fs_hz;
    c->speed_rpm = speed_rpm;
    c->torque_ref_nm = torque_nm;
    c->duration_s = duration_s;
    c->win_start_s = win_start_s;
    c->win_end_s = duration_s;
    c->calib_samples = 64u;
}

void loop_cfg(sim_run_cfg_t *c, const char *name, double speed_rpm, double torque_nm,
              double duration_s, double win_start_s)
{
    loop_cfg_machine(c, loop_spmsm(), name, 0u, speed_rpm, torque_nm, duration_s, win_start_s);
}

void loop_start(sim_run_t *r, const sim_run_cfg_t *c)
{
    char err[256];
    if (sim_run_init(r, c, err, sizeof err) != 0) {
        TEST_FAIL_MESSAGE(err);
    }
}

void loop_run_metrics(sim_run_t *r, const sim_run_cfg_t *c, metrics_result_t *mp)
{
    loop_start(r, c);
    char err[256];
    if (sim_run_all(r, err, sizeof err) != 0) {
        TEST_FAIL_MESSAGE(err);
    }
    metrics_result_t mc;
    TEST_ASSERT_EQUAL_INT(0, sim_run_metrics(r, mp, &mc));
}

void loop_scenario(sim_scenario_t *s, const char *text, const char *name)
{
    FILE *f = tmpfile();
    TEST_ASSERT_NOT_NULL(f);
    fputs(text, f);
    rewind(f);
    char err[256];
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, sim_scenario_parse(s, f, name, err, sizeof err), err);
    fclose(f);
}

loop_reversal_t loop_reversal(sim_run_t *run, const sim_run_cfg_t *base, const char *scenario,
                              double fall_nm, double back_s, const char *label)
{
    static sim_scenario_t scn;
    loop_scenario(&scn, scenario, "reversal");
    sim_run_cfg_t c = *base;
    c.free_mech = true;
    c.load_nm = 0.0;
    c.scenario = &scn;
    loop_start(run, &c);

    loop_reversal_t r = {false, 1e9, NAN, NAN, NAN, NAN, 0u};
    const double ts = 1.0 / (double)c.fs_hz;
    double t_rev = -1.0;
    double t_end = c.duration_s;
    double t_stats = INFINITY; /* start of the backward statistics window */
    double acc = 0.0;
    double acc2 = 0.0;
    int n = 0;
    for (;;) {
        const double t = sim_run_time(run);
        if (t >= t_end || fw_state(&run->fw) == FW_STATE_FAULT) {
            break;
        }
        TEST_ASSERT_EQUAL_INT(0, sim_run_period(run));
        const double tq = plant_torque(&run->plant);
        const double rpm = plant_omega_m(&run->plant) * 60.0 / (2.0 * 3.14159265358979);
        if (isnan(r.t_rise_ms) && t > 0.002 && tq >= 0.9 * 2.0) {
            r.t_rise_ms = (t + ts - 0.002) * 1e3;
        }
        if (!r.reached && run->scn.next >= 3u) {
            r.reached = true;
            t_rev = t;
        }
        if (!r.reached) {
            continue;
        }
        if (isnan(r.t_fall_ms) && tq <= fall_nm) {
            r.t_fall_ms = (t + ts - t_rev) * 1e3;
        }
        r.min_rpm_after = fmin(r.min_rpm_after, rpm);
        if (rpm <= -1000.0 && isinf(t_stats)) {
            t_end = fmin(t_end, t + back_s);
            t_stats = t + back_s - 0.010 - 0.5 * ts; /* half a period: no rounding edge */
        }
        if (rpm <= -1000.0 && t >= t_stats) {
            acc += tq;
            acc2 += tq * tq;
            n++;
        }
    }
    r.fault = fw_fault(&run->fw);
    if (n > 0) {
        r.tq_back_mean = acc / n;
        r.tq_back_rip = sqrt(fmax(0.0, acc2 / n - r.tq_back_mean * r.tq_back_mean));
    }
    printf("  %s reversal: reached %d, rise %.3f ms, fall %.3f ms, min speed %.0f r/min, "
           "backward T_mean %.4f T_rip %.4f, fault %s\n",
           label, (int)r.reached, r.t_rise_ms, r.t_fall_ms, r.min_rpm_after, r.tq_back_mean,
           r.tq_back_rip, fw_fault_name(r.fault));
    sim_run_free(run);
    return r;
}
