#include "cog_util.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "sim_ident.h"
#include "unity.h"

#define COG_PI 3.14159265358979323846

double cog_truth(const plant_config_t *pc, double th)
{
    double t = 0.0;
    for (int k = 0; k < pc->cog_n; k++) {
        t += pc->cog_amp_nm[k] * sin((double)(k + 1) * pc->cog_per_rev * th + pc->cog_phase_rad[k]);
    }
    return t;
}

void cog_table_truth(const sim_machine_t *m, int16_t *table)
{
    plant_config_t pc;
    sim_machine_to_plant(m, &pc);
    for (uint32_t i = 0; i < CTRL_COG_N; i++) {
        const double th = 2.0 * COG_PI * (double)i / (double)CTRL_COG_N;
        const double q = -cog_truth(&pc, th) / m->torque_rated_nm * 32768.0;
        table[i] = (int16_t)lround(q);
    }
}

void cog_table_counted(const sim_machine_t *m, int16_t *table)
{
    plant_config_t pc;
    sim_machine_to_plant(m, &pc);
    const double half = 0.5 / (4.0 * (double)m->encoder_lines); /* turns */
    for (uint32_t i = 0; i < CTRL_COG_N; i++) {
        const double th = 2.0 * COG_PI * ((double)i / (double)CTRL_COG_N + half);
        table[i] = (int16_t)lround(-cog_truth(&pc, th) / m->torque_rated_nm * 32768.0);
    }
}

/* RSS of the harmonics' amplitudes from the sums of x cos, x sin over n samples. */
static double cog_harmonics(const double *fc, const double *fs, int k_n, uint64_t n)
{
    double a2 = 0.0;
    for (int k = 0; k < k_n; k++) {
        const double a = 2.0 * hypot(fc[k], fs[k]) / (double)n;
        a2 += a * a;
    }
    return sqrt(a2);
}

static void cog_start(sim_run_t *r, sim_run_cfg_t *c, const int16_t *table)
{
    char err[256];
    c->defer_start = true;
    if (sim_run_init(r, c, err, sizeof err) != 0) {
        TEST_FAIL_MESSAGE(err);
    }
    if (table != NULL) {
        TEST_ASSERT_EQUAL_INT(FW_OK, fw_cogging_load(&r->fw, table, CTRL_COG_N));
        TEST_ASSERT_EQUAL_INT(FW_OK, fw_cogging_enable(&r->fw, true));
    }
}

void cog_ripple(const sim_machine_t *m, const char *ctrl, const int16_t *table, double settle_s,
                double window_s, cog_ripple_t *out)
{
    static sim_run_t r; /* large */
    static sim_run_cfg_t c;
    const ctrl_desc_t *d = ctrl_find(ctrl);
    TEST_ASSERT_NOT_NULL(d);
    plant_config_t pc;
    sim_machine_to_plant(m, &pc);
    const double n_cog = (double)pc.cog_per_rev;
    /* whole cogging periods at 30 r/min in the window */
    const double per = n_cog > 0.0 ? 1.0 / (0.5 * n_cog) : window_s;
    const double win = ceil(window_s / per) * per;

    /* speed ripple: free rotor, speed loop at 30 r/min */
    sim_run_config_default(&c, m, d);
    c.fs_hz = d->fs_default_hz;
    c.hal.pwm_freq_hz = c.fs_hz;
    c.free_mech = true;
    c.speed_mode = true;
    c.speed_ref_rpm = 30.0;
    c.duration_s = settle_s + win;
    c.calib_samples = 64u;
    c.theta0_e_rad = 0.0;
    cog_start(&r, &c, table);
    double s1 = 0.0, s2 = 0.0;
    uint64_t n = 0;
    double fc[PLANT_COG_MAX] = {0}, fs[PLANT_COG_MAX] = {0};
    while (!sim_run_done(&r)) {
        TEST_ASSERT_EQUAL_INT(0, sim_run_period(&r));
        if (r.armed && sim_run_time(&r) >= settle_s) {
            const double w = plant_omega_m(&r.plant) * 60.0 / (2.0 * COG_PI);
            const double th = plant_theta_m(&r.plant);
            s1 += w;
            s2 += w * w;
            n++;
            for (int k = 0; k < pc.cog_n; k++) {
                fc[k] += w * cos((double)(k + 1) * n_cog * th);
                fs[k] += w * sin((double)(k + 1) * n_cog * th);
            }
        }
    }
    TEST_ASSERT_EQUAL_UINT32(0u, fw_fault(&r.fw));
    sim_run_free(&r);
    out->speed_sd_rpm = sqrt(fmax(s2 / (double)n - (s1 / (double)n) * (s1 / (double)n), 0.0));
    out->speed_cog_rpm = cog_harmonics(fc, fs, pc.cog_n, n);

    /* torque ripple: dynamometer at 30 r/min, torque mode at 5 % rated */
    sim_run_config_default(&c, m, d);
    c.fs_hz = d->fs_default_hz;
    c.hal.pwm_freq_hz = c.fs_hz;
    c.free_mech = false;
    c.speed_rpm = 30.0;
    c.torque_ref_nm = 0.05 * m->torque_rated_nm;
    c.duration_s = settle_s + win;
    c.calib_samples = 64u;
    cog_start(&r, &c, table);
    s1 = s2 = 0.0;
    n = 0;
    memset(fc, 0, sizeof fc);
    memset(fs, 0, sizeof fs);
    while (!sim_run_done(&r)) {
        TEST_ASSERT_EQUAL_INT(0, sim_run_period(&r));
        if (r.armed && sim_run_time(&r) >= settle_s) {
            const double th = plant_theta_m(&r.plant);
            const double t = plant_torque(&r.plant) + cog_truth(&pc, th);
            s1 += t;
            s2 += t * t;
            n++;
            for (int k = 0; k < pc.cog_n; k++) {
                fc[k] += t * cos((double)(k + 1) * n_cog * th);
                fs[k] += t * sin((double)(k + 1) * n_cog * th);
            }
        }
    }
    TEST_ASSERT_EQUAL_UINT32(0u, fw_fault(&r.fw));
    sim_run_free(&r);
    out->torque_sd_nm = sqrt(fmax(s2 / (double)n - (s1 / (double)n) * (s1 / (double)n), 0.0));
    out->torque_cog_nm = cog_harmonics(fc, fs, pc.cog_n, n);
}

void cog_torque_phasor(const sim_machine_t *m, const char *ctrl, const int16_t *table, double rpm,
                       double frac, double settle_s, double window_s, double te[2], double cog[2])
{
    static sim_run_t r;
    static sim_run_cfg_t c;
    const ctrl_desc_t *d = ctrl_find(ctrl);
    TEST_ASSERT_NOT_NULL(d);
    plant_config_t pc;
    sim_machine_to_plant(m, &pc);
    const double n_cog = (double)pc.cog_per_rev;
    const double per = 60.0 / rpm / n_cog;
    sim_run_config_default(&c, m, d);
    c.fs_hz = d->fs_default_hz;
    c.hal.pwm_freq_hz = c.fs_hz;
    c.free_mech = false;
    c.speed_rpm = rpm;
    c.torque_ref_nm = frac * m->torque_rated_nm;
    c.duration_s = settle_s + ceil(window_s / per) * per;
    c.calib_samples = 64u;
    cog_start(&r, &c, table);
    double s[4] = {0.0, 0.0, 0.0, 0.0};
    uint64_t n = 0;
    while (!sim_run_done(&r)) {
        TEST_ASSERT_EQUAL_INT(0, sim_run_period(&r));
        if (r.armed && sim_run_time(&r) >= settle_s) {
            const double th = plant_theta_m(&r.plant);
            const double t = plant_torque(&r.plant), tc = -cog_truth(&pc, th);
            const double cs = cos(n_cog * th), sn = sin(n_cog * th);
            s[0] += t * cs;
            s[1] += t * sn;
            s[2] += tc * cs;
            s[3] += tc * sn;
            n++;
        }
    }
    TEST_ASSERT_EQUAL_UINT32(0u, fw_fault(&r.fw));
    sim_run_free(&r);
    /* x e^{-j n th}: re = sum x cos, im = -sum x sin (amplitude 2 |.| / n) */
    te[0] = 2.0 * s[0] / (double)n;
    te[1] = -2.0 * s[1] / (double)n;
    cog[0] = 2.0 * s[2] / (double)n;
    cog[1] = -2.0 * s[3] / (double)n;
}

int cog_calibrate(const sim_machine_t *m, double rpm, double bw_hz, int16_t *table,
                  double *friction_nm, double *peak_nm, double *seconds)
{
    static sim_run_t r;
    char err[256];
    const ctrl_desc_t *d = ctrl_find("foc");
    if (sim_ident_setup(&r, m, m, d, 0.3, 1u, err, sizeof err) != 0) {
        TEST_FAIL_MESSAGE(err);
    }
    const cm_cog_config_t cc = {rpm, bw_hz, 1u};
    fw_t *fw = &r.fw;
    TEST_ASSERT_EQUAL_INT(0, cm_cogging_configure(&fw->cog, &cc, fw->machine, &fw->params,
                                                  &fw->bases, fw->info.pwm_freq_hz, fw->enc_cpr));
    const uint8_t steps[1] = {CM_STEP_COGGING};
    sim_ident_t id;
    if (sim_ident_run(&r, steps, 1u, 600.0, SIM_BAD_NONE, &id, err, sizeof err) != 0) {
        TEST_FAIL_MESSAGE(err);
    }
    *seconds = id.motor_time_s;
    if (!id.finished || id.err != CM_E_NONE) {
        printf("cogging calibration: %s (%d %d %d)\n", cm_err_name(id.err), (int)fw->cm.detail[0],
               (int)fw->cm.detail[1], (int)fw->cm.detail[2]);
        sim_run_free(&r);
        return id.err != CM_E_NONE ? id.err : -1;
    }
    *peak_nm = fw->cm.detail[0] / 16777216.0 * fw->bases.torque_nm;
    *friction_nm = fw->cm.detail[1] / 16777216.0 * fw->bases.torque_nm;
    uint32_t n = 0;
    const int16_t *t = fw_cogging_table(fw, &n);
    TEST_ASSERT_NOT_NULL(t);
    memcpy(table, t, sizeof(int16_t) * CTRL_COG_N);
    sim_run_free(&r);
    return 0;
}

/* rms(table - truth) / rms(truth) */
static double cog_table_err(const int16_t *a, const int16_t *b)
{
    double e2 = 0.0, t2 = 0.0;
    for (uint32_t i = 0; i < CTRL_COG_N; i++) {
        e2 += ((double)a[i] - b[i]) * ((double)a[i] - b[i]);
        t2 += (double)b[i] * b[i];
    }
    return sqrt(e2 / t2);
}

static int16_t case_tab[CTRL_COG_N], case_truth[CTRL_COG_N];

/* Calibrate m at rpm / bw_hz, check the table and the friction it reports
 * (Coulomb + passive load + viscous at the sweep speed), then the ripple
 * without and with the table. */
void cog_case(const char *name, const sim_machine_t *m, double rpm, double bw_hz)
{
    double fr = 0.0, pk = 0.0, sec = 0.0;
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, cog_calibrate(m, rpm, bw_hz, case_tab, &fr, &pk, &sec), name);
    cog_table_truth(m, case_truth);
    const double err = cog_table_err(case_tab, case_truth);
    const double fr_true = m->coulomb_nm + (m->load_kind == SIM_LOAD_PASSIVE ? m->load_nm : 0.0) +
                           m->friction_nms * rpm * 6.283185307179586 / 60.0;
    printf("%s: calibration %.2f s at %.0f r/min: table error %.1f %% rms, peak %.4f N*m, "
           "friction %.4f N*m (true %.4f)\n",
           name, sec, rpm, 100.0 * err, pk, fr, fr_true);

    cog_ripple_t a, b, z;
    cog_ripple(m, "foc", NULL, 0.4, 0.25, &a);
    cog_ripple(m, "foc", case_tab, 0.4, 0.25, &b);
    /* the same motor without cogging: the speed ripple of everything else (the
     * speed loop on the encoder's quantised speed, friction), which no table
     * removes; independent causes add in variance */
    sim_machine_t m0 = *m;
    m0.cogging_nm = 0.0;
    m0.cog_harm_n = m0.cog_harm_deg_n = 0;
    cog_ripple(&m0, "foc", NULL, 0.4, 0.25, &z);
    const double cog_a =
        sqrt(fmax(a.speed_sd_rpm * a.speed_sd_rpm - z.speed_sd_rpm * z.speed_sd_rpm, 0.0));
    const double cog_b =
        sqrt(fmax(b.speed_sd_rpm * b.speed_sd_rpm - z.speed_sd_rpm * z.speed_sd_rpm, 0.0));
    printf("%s: speed sd %.3f -> %.3f r/min (%.3f without cogging: the cogging's share %.3f -> "
           "%.3f); torque sd %.4f -> %.4f N*m (%.4f without cogging), at the cogging harmonics "
           "%.4f -> %.4f N*m\n",
           name, a.speed_sd_rpm, b.speed_sd_rpm, z.speed_sd_rpm, cog_a, cog_b, a.torque_sd_nm,
           b.torque_sd_nm, z.torque_sd_nm, a.torque_cog_nm, b.torque_cog_nm);
    /* every figure printed first, then the checks: the table's error (the
     * loop's lag at the cogging's periods: within (f / bw)^2 + 10 %), the
     * friction, the ripple */
    TEST_ASSERT_TRUE_MESSAGE(err < 0.25, name);
    TEST_ASSERT_TRUE_MESSAGE(fabs(fr - fr_true) < 0.1 * fr_true, name);
    TEST_ASSERT_TRUE_MESSAGE(cog_b < 0.2 * cog_a, name);
    TEST_ASSERT_TRUE_MESSAGE(b.torque_sd_nm < 0.2 * a.torque_sd_nm, name);
    TEST_ASSERT_TRUE_MESSAGE(b.torque_cog_nm < 0.2 * a.torque_cog_nm, name);
}
