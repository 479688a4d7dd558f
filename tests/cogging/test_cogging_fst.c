/*
 * FST with the anti-cogging feed-forward (docs/anticogging.md, "FST").
 * FST's operating-state logic (thesis §4.5.3, st_dtc.h) takes a change of its
 * torque reference beyond dT_step (0 by default: "Delta T_ref != 0") as a
 * reference step and leaves its steady-state mode (active vectors only, its
 * mean-torque-error integrator held) until the torque crosses the reference.
 * The feed-forward moves the reference at every encoder count; it is a known
 * cancellation of the cogging, not a command.
 *
 * Torque mode at 5 % of the rated torque on the dynamometer at 30 r/min, the
 * table the calibration would measure (the plant's cogging, half a count on),
 * the shaft torque Te + T_cog sampled once a period. Asserted: with the table
 * the shaft torque's sd is not above the one without it, the cogging's share
 * of it (independent ripples add in variance: the cogging's sd over a
 * revolution, the rest FST's own) reduced by 80 % as for every controller
 * (docs/anticogging.md, "Measured"), and FST spends no more periods in its
 * dynamic mode with the table than without.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cog_util.h"
#include "loop_util.h"
#include "st_dtc.h"
#include "unity.h"

void setUp(void)
{
}
void tearDown(void)
{
}

#define FST_PI 3.14159265358979323846

static int16_t tab[CTRL_COG_N];

typedef struct {
    double sd_nm;     /* shaft torque Te + T_cog, sd */
    uint64_t dynamic; /* periods FST ended in its dynamic mode */
    uint64_t n;       /* periods measured */
} fst_run_t;

static void fst_torque(const sim_machine_t *m, const int16_t *table, double settle_s,
                       double window_s, fst_run_t *o)
{
    static sim_run_t r;
    static sim_run_cfg_t c;
    char err[256];
    const ctrl_desc_t *d = ctrl_find("fst");
    TEST_ASSERT_NOT_NULL(d);
    plant_config_t pc;
    sim_machine_to_plant(m, &pc);
    sim_run_config_default(&c, m, d);
    c.fs_hz = d->fs_default_hz;
    c.hal.pwm_freq_hz = c.fs_hz;
    c.free_mech = false;
    c.speed_rpm = 30.0;
    c.torque_ref_nm = 0.05 * m->torque_rated_nm;
    const double per = 60.0 / 30.0 / (double)pc.cog_per_rev;
    c.duration_s = settle_s + ceil(window_s / per) * per;
    c.calib_samples = 64u;
    c.defer_start = true;
    if (sim_run_init(&r, &c, err, sizeof err) != 0) {
        TEST_FAIL_MESSAGE(err);
    }
    if (table != NULL) {
        TEST_ASSERT_EQUAL_INT(FW_OK, fw_cogging_load(&r.fw, table, CTRL_COG_N));
        TEST_ASSERT_EQUAL_INT(FW_OK, fw_cogging_enable(&r.fw, true));
    }
    const st_fst_state_t *s = fw_ctrl_state(&r.fw);
    TEST_ASSERT_NOT_NULL(s);
    double s1 = 0.0, s2 = 0.0;
    o->n = 0u;
    o->dynamic = 0u;
    while (!sim_run_done(&r)) {
        TEST_ASSERT_EQUAL_INT(0, sim_run_period(&r));
        if (r.armed && sim_run_time(&r) >= settle_s) {
            const double t = plant_torque(&r.plant) + cog_truth(&pc, plant_theta_m(&r.plant));
            s1 += t;
            s2 += t * t;
            o->n++;
            o->dynamic += s->logic.flag != 0u ? 1u : 0u;
        }
    }
    TEST_ASSERT_EQUAL_UINT32(0u, fw_fault(&r.fw));
    sim_run_free(&r);
    const double mean = s1 / (double)o->n;
    o->sd_nm = sqrt(fmax(s2 / (double)o->n - mean * mean, 0.0));
}

static void fst_case(const char *file)
{
    const sim_machine_t m = loop_machine_file(file);
    cog_table_counted(&m, tab);
    fst_run_t off, on;
    fst_torque(&m, NULL, 0.4, 0.25, &off);
    fst_torque(&m, tab, 0.4, 0.25, &on);
    /* the cogging's own sd over a revolution */
    plant_config_t pc;
    sim_machine_to_plant(&m, &pc);
    double c2 = 0.0;
    for (uint32_t i = 0; i < 4096u; i++) {
        const double t = cog_truth(&pc, 2.0 * FST_PI * (double)i / 4096.0);
        c2 += t * t;
    }
    const double cog_sd = sqrt(c2 / 4096.0);
    /* Independent ripples add in variance: without the table the cogging's
     * share is its own sd, the rest is FST's (off^2 - cog^2); with it the
     * share left is what exceeds that rest. */
    const double rest2 = off.sd_nm * off.sd_nm - cog_sd * cog_sd;
    const double left = sqrt(fmax(on.sd_nm * on.sd_nm - rest2, 0.0));
    printf("%s fst: shaft torque sd %.4f -> %.4f N*m (%.0f %%), the cogging's share %.4f -> %.4f "
           "N*m; dynamic mode %llu -> %llu of %llu periods\n",
           file, off.sd_nm, on.sd_nm, 100.0 * on.sd_nm / off.sd_nm, cog_sd, left,
           (unsigned long long)off.dynamic, (unsigned long long)on.dynamic,
           (unsigned long long)on.n);
    TEST_ASSERT_TRUE_MESSAGE(on.sd_nm <= off.sd_nm, "torque ripple with the table");
    TEST_ASSERT_TRUE_MESSAGE(left <= 0.2 * cog_sd, "the cogging's share reduced by 80 %");
    TEST_ASSERT_TRUE_MESSAGE(on.dynamic <= off.dynamic, "dynamic-mode periods with the table");
}

static void test_gimbal(void)
{
    fst_case("nonideal/gbm5208_gimbal_stress.ini");
}

static void test_thesis(void)
{
    fst_case("nonideal/thesis_spmsm_stress.ini");
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_gimbal);
    RUN_TEST(test_thesis);
    return UNITY_END();
}
