/*
 * Identification within the voltage available (firmware/commission:
 * cm_configure, cm_refit_currents; docs/identification.md).
 *
 * The gimbal-class motor of sim_host/machines/gimbal_12v.ini (11 pole pairs,
 * Rs 5.6 ohm, Ld = Lq 1.9 mH, psi_pm 5 mWb, rated 1.5 A, 12 V, 500 ns dead
 * time) as shipped: the rs step's configured upper level, half the rated
 * current, needs 0.75 A x 5.6 ohm = 4.2 V, more than the standstill limit
 * (a quarter of 12 V = 3 V), so every step must take its current from the
 * voltage. Bounds (the identification accuracy requirement): |dRs| <= 3 %,
 * |dLd|, |dLq| <= 5 %, |dpsi_pm| <= 2 %, encoder offset within 2 deg, and
 * the true phase current never above the rated one.
 * The same motor wound for 30 ohm: the smallest test current (10 % of rated,
 * 0.15 A) needs 4.5 V: the first step that drives a current ends with
 * `supply`, naming that current, the voltage it needs and the limit; gates
 * off, fault latched.
 * Host closed loop (plant, hal/sim, firmware), rotor at rest at 1 rad.
 */
#include <math.h>
#include <string.h>

#include "sim_ident.h"
#include "unity.h"

static sim_machine_t gim;
static sim_run_t run;
static sim_ident_t id;

void setUp(void)
{
    char err[256];
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, sim_machine_load(PMSM_MACHINES_DIR "/gimbal_12v.ini", &gim, err, sizeof err), err);
}

void tearDown(void)
{
    sim_run_free(&run);
}

static void ident(const sim_machine_t *m)
{
    char err[256];
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, sim_ident_setup(&run, m, m, ctrl_find("m2ptfc"), 1.0, 1u, err, sizeof err), err);
    TEST_ASSERT_EQUAL_INT_MESSAGE(0,
                                  sim_ident_run(&run, sim_ident_plan, sim_ident_plan_n, 10.0,
                                                SIM_BAD_NONE, &id, err, sizeof err),
                                  err);
}

static double pct(double x, double truth)
{
    return 100.0 * (x - truth) / truth;
}

static void test_gimbal_identified(void)
{
    /* the premise: the configured levels do not fit the voltage */
    TEST_ASSERT_TRUE(0.5 * gim.current_rated_a * gim.rs_ohm > 0.25 * gim.vdc_v);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 500e-9, gim.dead_time_s);
    ident(&gim);
    printf("  gimbal_12v: %s (step %u), Rs %+.3f %%, Ld %+.3f %%, Lq %+.3f %%, psi_pm %+.3f %%, "
           "offset %+.3f deg, peak %.3f A, %.2f s\n",
           cm_err_name(id.err), id.step, pct(id.res.rs_ohm, gim.rs_ohm),
           pct(id.res.ld_h, gim.ld_h), pct(id.res.lq_h, gim.lq_h),
           pct(id.res.psi_wb, gim.psi_pm_wb), id.res.enc_offset_deg - gim.encoder_offset_deg,
           id.peak_current_a, id.motor_time_s);
    TEST_ASSERT_TRUE(id.finished);
    TEST_ASSERT_EQUAL_STRING("none", cm_err_name(id.err));
    TEST_ASSERT_TRUE(fabs(pct(id.res.rs_ohm, gim.rs_ohm)) <= 3.0);
    TEST_ASSERT_TRUE(fabs(pct(id.res.ld_h, gim.ld_h)) <= 5.0);
    TEST_ASSERT_TRUE(fabs(pct(id.res.lq_h, gim.lq_h)) <= 5.0);
    TEST_ASSERT_TRUE(fabs(pct(id.res.psi_wb, gim.psi_pm_wb)) <= 2.0);
    double off = fmod(id.res.enc_offset_deg - gim.encoder_offset_deg + 540.0, 360.0) - 180.0;
    TEST_ASSERT_TRUE(fabs(off) <= 2.0);
    TEST_ASSERT_TRUE(id.peak_current_a <= gim.current_rated_a);
}

static void test_supply_too_low(void)
{
    sim_machine_t m = gim;
    m.rs_ohm = 30.0;
    ident(&m);
    TEST_ASSERT_TRUE(id.finished);
    TEST_ASSERT_EQUAL_STRING("supply", cm_err_name(id.err));
    TEST_ASSERT_EQUAL_UINT8(CM_STEP_ENCODER, id.step);
    TEST_ASSERT_TRUE(id.gates_off);
    TEST_ASSERT_FALSE(hal_sim_gates_on(&run.hal));
    TEST_ASSERT_EQUAL_INT(FW_STATE_FAULT, fw_state(&run.fw));
    cm_outcome_t o;
    cm_outcome(&run.fw.cm, &run.fw.bases, &o);
    TEST_ASSERT_EQUAL_UINT(3u, (unsigned)o.n);
    TEST_ASSERT_EQUAL_STRING("current_min", o.label[0]);
    TEST_ASSERT_DOUBLE_WITHIN(0.01, 0.1 * m.current_rated_a, o.value[0]);
    TEST_ASSERT_DOUBLE_WITHIN(0.05, 0.1 * m.current_rated_a * m.rs_ohm, o.value[1]);
    TEST_ASSERT_DOUBLE_WITHIN(0.05, 0.25 * m.vdc_v, o.value[2]);
    TEST_ASSERT_TRUE(o.value[1] > o.value[2]);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_gimbal_identified);
    RUN_TEST(test_supply_too_low);
    return UNITY_END();
}
