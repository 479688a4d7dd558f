/*
 * Identification on the host closed loop and the results in use: the thesis
 * SPMSM with an encoder at 137 deg counting backwards, the firmware configured
 * with wrong data (Rs x 1.3, Ld x 0.7, Lq x 0.8, psi_pm x 1.2, encoder at 0 deg
 * forwards). After "ident run" the drive adopts the results (controller and
 * estimator re-initialised): the machine it holds, its encoder angle and its
 * torque estimate match the plant, and the results read back in SI and as a
 * machine-file fragment. Ideal inverter and the plant's exact path (quick);
 * tests/ident/ident_accuracy.py covers the realistic inverter.
 */
#include <math.h>
#include <string.h>

#include "sim_ident.h"
#include "unity.h"

static sim_machine_t spm, plant, conf;
static sim_run_t run;
static sim_ident_t id;

void setUp(void)
{
}

void tearDown(void)
{
}

static double rel(double got, double want)
{
    return fabs(got - want) / fabs(want);
}

/* Electrical angle difference in degrees, wrapped to [-180, 180). */
static double ang_deg(double a, double b)
{
    double d = fmod((a - b) * 180.0 / 3.14159265358979323846, 360.0);
    d = d >= 180.0 ? d - 360.0 : (d < -180.0 ? d + 360.0 : d);
    return d;
}

static void test_identify_and_apply(void)
{
    char err[256];
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, sim_machine_load(PMSM_MACHINES_DIR "/thesis_spmsm.ini", &spm, err, sizeof err), err);
    sim_ident_case(&spm, &plant, &conf);
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, sim_ident_setup(&run, &plant, &conf, ctrl_find("m2ptfc"), 2.0, 1u, err, sizeof err),
        err);
    TEST_ASSERT_EQUAL_INT_MESSAGE(0,
                                  sim_ident_run(&run, sim_ident_plan, sim_ident_plan_n, 10.0,
                                                SIM_BAD_NONE, &id, err, sizeof err),
                                  err);
    TEST_ASSERT_TRUE(id.finished);
    TEST_ASSERT_EQUAL_STRING("none", cm_err_name(id.err));
    TEST_ASSERT_TRUE(id.applied);
    TEST_ASSERT_TRUE(id.motor_time_s <= 10.0);
    TEST_ASSERT_TRUE(id.peak_current_a <= spm.current_rated_a);
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&run.fw));

    /* The drive holds the identified machine (the identification accuracy bounds, docs/identification.md). */
    const ctrl_machine_t *m = run.fw.machine;
    TEST_ASSERT_TRUE(rel(m->rs_ohm, spm.rs_ohm) <= 0.03);
    TEST_ASSERT_TRUE(rel(m->ld_h, spm.ld_h) <= 0.05);
    TEST_ASSERT_TRUE(rel(m->lq_h, spm.lq_h) <= 0.05);
    TEST_ASSERT_TRUE(rel(m->psi_pm_wb, spm.psi_pm_wb) <= 0.02);
    TEST_ASSERT_TRUE(rel(m->inertia_kgm2, spm.inertia_kgm2) <= 0.05);
    /* The per-unit bases follow the new machine (psi_base = psi_pm). */
    TEST_ASSERT_TRUE(rel(run.fw.bases.psi_wb, m->psi_pm_wb) < 1e-12);

    /* Read back in SI, and as a machine-file fragment. */
    cm_si_t r;
    fw_commission_results(&run.fw, &r);
    TEST_ASSERT_EQUAL_INT(-1, r.enc_dir);
    TEST_ASSERT_TRUE(fabs(ang_deg(r.enc_offset_deg * 3.14159265358979323846 / 180.0,
                                  SIM_IDENT_CASE_OFFSET_DEG * 3.14159265358979323846 / 180.0)) <= 2.0);
    TEST_ASSERT_TRUE(rel(r.rs_ohm, m->rs_ohm) < 1e-6);
    bool seen_psi = false, seen_dir = false;
    cm_item_t it;
    for (size_t k = 0; cm_fragment_item(&r, k, &it); k++) {
        if (strcmp(it.key, "psi_pm_wb") == 0) {
            seen_psi = true;
            TEST_ASSERT_EQUAL_STRING("machine", it.section);
            TEST_ASSERT_TRUE(rel(it.value, spm.psi_pm_wb) <= 0.02);
        }
        if (strcmp(it.key, "encoder_direction") == 0) {
            seen_dir = true;
            TEST_ASSERT_EQUAL_STRING("sensors", it.section);
            TEST_ASSERT_TRUE(it.integer && it.value == -1.0);
        }
    }
    TEST_ASSERT_TRUE(seen_psi && seen_dir);

    /* The encoder angle the drive now computes is the rotor's. */
    for (int k = 0; k < 4; k++) {
        TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run));
    }
    const double th_fw =
        (double)fw_telemetry(&run.fw)->theta_e / 4294967296.0 * 2.0 * 3.14159265358979323846;
    TEST_ASSERT_TRUE(fabs(ang_deg(th_fw, plant_theta_e(&run.plant))) <= 2.0);

    /* Torque mode with the re-initialised controller: 0.5 N*m on the free
     * rotor; the estimate (from the identified psi_pm, Ld) matches the plant. */
    fw_set_torque_ref_nm(&run.fw, 0.5);
    fw_cmd_arm(&run.fw);
    double est = 0.0, tru = 0.0;
    int n = 0;
    for (int k = 0; k < 600; k++) { /* 30 ms */
        TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run));
        if (k >= 200) {
            est += ctrl_q24_to_double(run.fw.estimate.now.torque) * run.fw.bases.torque_nm;
            tru += plant_torque(&run.plant);
            n++;
        }
    }
    TEST_ASSERT_EQUAL_INT(FW_STATE_RUNNING, fw_state(&run.fw));
    est /= n;
    tru /= n;
    TEST_ASSERT_TRUE(fabs(tru - 0.5) <= 0.05 * 0.5);
    TEST_ASSERT_TRUE(fabs(est - tru) <= 0.03 * 0.5);
    sim_run_free(&run);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_identify_and_apply);
    return UNITY_END();
}
