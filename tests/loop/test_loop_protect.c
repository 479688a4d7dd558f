/*
 * Protections by fault injection in the host closed loop (FST, thesis SPMSM,
 * 750 r/min dynamometer, 1.8 N*m). Each test: run 10 ms to steady state,
 * inject, then assert the fault code, the reaction period, that the gates are
 * off afterwards, that the fault latches (also once the cause is gone) until
 * a clear command, and that the drive can be cleared and re-armed.
 */
#include <math.h>
#include <stdio.h>

#include "loop_util.h"
#include "unity.h"

void setUp(void)
{
}
static sim_run_t run;

void tearDown(void)
{
    sim_run_free(&run); /* also after a failed assertion */
}

static void start(void)
{
    sim_run_cfg_t c;
    loop_cfg(&c, "fst", 750.0, 1.8, 0.3, 0.0);
    loop_start(&run, &c);
    for (int k = 0; k < 200; k++) { /* 10 ms at 20 kHz */
        TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run));
    }
    TEST_ASSERT_EQUAL_INT(FW_STATE_RUNNING, fw_state(&run.fw));
    TEST_ASSERT_TRUE(hal_sim_gates_on(&run.hal));
}

/* Run periods until the firmware faults (at most n); returns the number of
 * periods run including the faulting one, or -1. */
static int until_fault(int n)
{
    for (int k = 1; k <= n; k++) {
        TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run));
        if (fw_state(&run.fw) == FW_STATE_FAULT) {
            return k;
        }
    }
    return -1;
}

/* The fault latches with the gates off for 100 periods (cause removed by the
 * caller or not), then clear -> ready (gates still off), arm -> running. */
static void latch_clear_rearm(uint32_t code)
{
    for (int k = 0; k < 100; k++) {
        TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run));
        TEST_ASSERT_EQUAL_INT(FW_STATE_FAULT, fw_state(&run.fw));
        TEST_ASSERT_EQUAL_UINT32(code, fw_fault(&run.fw));
        TEST_ASSERT_FALSE(hal_sim_gates_on(&run.hal));
    }
    fw_cmd_clear(&run.fw);
    TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run));
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&run.fw));
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_NONE, fw_fault(&run.fw));
    TEST_ASSERT_FALSE(hal_sim_gates_on(&run.hal));
    fw_cmd_arm(&run.fw);
    TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run)); /* arm at this ISR */
    TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run)); /* gates on from here */
    TEST_ASSERT_EQUAL_INT(FW_STATE_RUNNING, fw_state(&run.fw));
    TEST_ASSERT_TRUE(hal_sim_gates_on(&run.hal));
    for (int k = 0; k < 200; k++) {
        TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run));
    }
    TEST_ASSERT_EQUAL_INT(FW_STATE_RUNNING, fw_state(&run.fw));
}

/* Over-current: a short-circuit current rising 1 A per period on top of the
 * load current. The fault must come in the very period whose sample first
 * exceeds i_max, and that period already runs with the gates off. */
static void test_overcurrent_same_period(void)
{
    start();
    const q24_t i_max = run.fw.prot.cfg.i_max;
    hal_sim_inject_short(&run.hal, 2.0e4);
    long first_over = -1, fault_at = -1;
    for (int k = 0; k < 200 && fault_at < 0; k++) {
        const uint64_t period = hal_sim_period(&run.hal);
        TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run));
        const fw_telemetry_t *tm = fw_telemetry(&run.fw);
        const q24_t ic = fx_neg(fx_add(tm->i_a, tm->i_b));
        if (first_over < 0 &&
            (fx_abs(tm->i_a) > i_max || fx_abs(tm->i_b) > i_max || fx_abs(ic) > i_max)) {
            first_over = (long)period;
        }
        if (fw_state(&run.fw) == FW_STATE_FAULT) {
            fault_at = (long)period;
            /* The plant ran this whole period with every switch open. */
            TEST_ASSERT_FALSE(hal_sim_gates_on(&run.hal));
        }
    }
    printf("  over-current: sample above i_max in period %ld, fault in period %ld (reaction %ld "
           "periods)\n",
           first_over, fault_at, fault_at - first_over);
    TEST_ASSERT_TRUE(first_over >= 0);
    TEST_ASSERT_EQUAL_INT32((int32_t)first_over, (int32_t)fault_at);
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_OVERCURRENT, fw_fault(&run.fw));
    hal_sim_inject_short(&run.hal, 0.0);
    latch_clear_rearm(FW_FAULT_OVERCURRENT);
}

static void dc_link(double factor, uint32_t code)
{
    start();
    hal_sim_inject_vdc(&run.hal, factor * 220.0);
    const int n = until_fault(10);
    printf("  DC link x%.2f: %s after %d period(s)\n", factor, fw_fault_name(fw_fault(&run.fw)), n);
    /* The sag/surge is sampled at the next period start: one period. */
    TEST_ASSERT_EQUAL_INT(1, n);
    TEST_ASSERT_EQUAL_UINT32(code, fw_fault(&run.fw));
    TEST_ASSERT_FALSE(hal_sim_gates_on(&run.hal));
    /* Clear while the cause persists: the protection fires again. */
    fw_cmd_clear(&run.fw);
    TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run));
    TEST_ASSERT_EQUAL_INT(FW_STATE_FAULT, fw_state(&run.fw));
    TEST_ASSERT_EQUAL_UINT32(code, fw_fault(&run.fw));
    hal_sim_inject_vdc(&run.hal, 220.0);
    latch_clear_rearm(code);
}

/* Window 0.70 .. 1.25 Vdc (protect.h). */
static void test_dc_sag(void)
{
    dc_link(0.60, FW_FAULT_DC_UNDERVOLT);
}

static void test_dc_surge(void)
{
    dc_link(1.40, FW_FAULT_DC_OVERVOLT);
}

/* Stuck encoder at 750 r/min (6.25 counts per period): fault after
 * enc_stuck_periods periods without a count. */
static void test_encoder_stuck(void)
{
    start();
    const uint32_t n_stuck = run.fw.prot.cfg.enc_stuck_periods;
    hal_sim_inject_encoder_stuck(&run.hal, true);
    const int n = until_fault((int)n_stuck + 10);
    printf("  encoder stuck: %s after %d periods (threshold %u)\n",
           fw_fault_name(fw_fault(&run.fw)), n, (unsigned)n_stuck);
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_ENC_STUCK, fw_fault(&run.fw));
    /* The counter freezes at the last sampled value, so the first sample
     * after the injection already shows no motion: n_stuck periods. */
    TEST_ASSERT_EQUAL_INT((int)n_stuck, n);
    TEST_ASSERT_FALSE(hal_sim_gates_on(&run.hal));
    hal_sim_inject_encoder_stuck(&run.hal, false);
    latch_clear_rearm(FW_FAULT_ENC_STUCK);
}

/* Glitch of 500 counts (72 electrical degrees; the plausible change of the
 * per-period count is a_max Ts^2 = 0.27 count plus quantisation). */
static void test_encoder_glitch(void)
{
    start();
    hal_sim_inject_encoder_glitch(&run.hal, 500);
    const int n = until_fault(10);
    printf("  encoder glitch +500 counts: %s after %d period(s) (jump limit %d counts)\n",
           fw_fault_name(fw_fault(&run.fw)), n, (int)run.fw.prot.cfg.enc_jump_max);
    TEST_ASSERT_EQUAL_INT(1, n);
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_ENC_JUMP, fw_fault(&run.fw));
    TEST_ASSERT_FALSE(hal_sim_gates_on(&run.hal));
    /* The absolute position is lost: re-align the counter (as a homing
     * would) before the drive may run again. */
    hal_sim_inject_encoder_glitch(&run.hal, -500);
    latch_clear_rearm(FW_FAULT_ENC_JUMP);
}

#define PI_ 3.14159265358979
#define ONE_COUNT_E (4.0 * 2.0 * PI_ / 10000.0) /* electrical angle of one count */

/* Firmware angle at the last ISR minus the plant's at that instant, wrapped. */
static double angle_error(void)
{
    const double th_fw = (double)fw_telemetry(&run.fw)->theta_e * (2.0 * PI_ / 4294967296.0);
    const double th_pl = plant_theta_e(&run.plant) - plant_omega_e(&run.plant) / 20000.0;
    double d = fmod(th_fw - th_pl, 2.0 * PI_);
    if (d > PI_) {
        d -= 2.0 * PI_;
    }
    if (d < -PI_) {
        d += 2.0 * PI_;
    }
    return d;
}

/* A glitch below the plausibility limit (3 counts) is not a fault: the angle
 * is 3 counts off until the next index pulse (one turn = 80 ms at 750 r/min)
 * restores the position, then back to the counter's quantisation. */
static void test_encoder_index_resync(void)
{
    start();
    const uint32_t idx0 = run.hal.enc.index_count;
    hal_sim_inject_encoder_glitch(&run.hal, 3);
    for (int k = 0; k < 5; k++) {
        TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run));
    }
    TEST_ASSERT_EQUAL_UINT32(idx0, run.hal.enc.index_count); /* no index passed yet */
    const double before = angle_error();
    /* The counter floors the position: its angle lags by [0, 1] count (the
     * upper end reached when the true position is an integer up to rounding);
     * the glitch adds 3 counts. Margin 0.01 count for the float angle. */
    TEST_ASSERT_TRUE(before >= 1.99 * ONE_COUNT_E && before <= 3.01 * ONE_COUNT_E);
    for (int k = 0; k < 1700; k++) { /* 85 ms: more than one turn */
        TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run));
    }
    TEST_ASSERT_EQUAL_INT(FW_STATE_RUNNING, fw_state(&run.fw));
    TEST_ASSERT_TRUE(run.hal.enc.index_count != idx0);
    const double after = angle_error();
    printf("  index re-sync after a 3-count glitch: angle error %.2e rad before the index, "
           "%.2e rad after (one count %.2e)\n",
           before, after, ONE_COUNT_E);
    TEST_ASSERT_TRUE(after >= -1.01 * ONE_COUNT_E && after <= 0.01 * ONE_COUNT_E);
}

/* Overrun: the ISR's closing hal_cycles read is late by two period budgets. */
static void test_deadline_overrun(void)
{
    start();
    const uint32_t budget = run.fw.prot.cfg.deadline_cycles;
    TEST_ASSERT_TRUE(budget > 0u);
    hal_sim_inject_overrun(&run.hal, 2u * budget);
    const int n = until_fault(5);
    printf("  deadline overrun (%u cycles, budget %u): %s after %d period(s), measured %u\n",
           (unsigned)(2u * budget), (unsigned)budget, fw_fault_name(fw_fault(&run.fw)), n,
           (unsigned)fw_telemetry(&run.fw)->cycles);
    TEST_ASSERT_EQUAL_INT(1, n); /* detected at the end of the overrunning ISR */
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_DEADLINE, fw_fault(&run.fw));
    TEST_ASSERT_TRUE(fw_telemetry(&run.fw)->cycles > budget);
    TEST_ASSERT_FALSE(hal_sim_gates_on(&run.hal));
    latch_clear_rearm(FW_FAULT_DEADLINE);
}

/* Re-entry: the ISR runs while the previous one has not returned. */
static void test_deadline_reentry(void)
{
    start();
    hal_sim_period_begin(&run.hal);
    run.fw.busy = true; /* as if the previous ISR were still on the stack */
    fw_isr(&run.fw);
    TEST_ASSERT_EQUAL_INT(FW_STATE_FAULT, fw_state(&run.fw));
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_DEADLINE, fw_fault(&run.fw));
    TEST_ASSERT_FALSE(hal_sim_gates_on(&run.hal));
    run.fw.busy = false;
    TEST_ASSERT_EQUAL_INT(0, hal_sim_period_end(&run.hal));
    latch_clear_rearm(FW_FAULT_DEADLINE);
}

/* Watchdog: the main loop stops kicking; fault after wdg_periods periods. */
static void test_watchdog(void)
{
    start();
    const uint32_t w = run.fw.prot.cfg.wdg_periods;
    int n = -1;
    for (uint32_t k = 1; k <= w + 5u; k++) {
        hal_sim_period_begin(&run.hal);
        fw_isr(&run.fw); /* no fw_watchdog_kick */
        TEST_ASSERT_EQUAL_INT(0, hal_sim_period_end(&run.hal));
        if (fw_state(&run.fw) == FW_STATE_FAULT) {
            n = (int)k;
            break;
        }
    }
    printf("  watchdog: %s after %d periods without a kick (limit %u = 100 ms)\n",
           fw_fault_name(fw_fault(&run.fw)), n, (unsigned)w);
    TEST_ASSERT_EQUAL_INT((int)w + 1, n);
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_WATCHDOG, fw_fault(&run.fw));
    TEST_ASSERT_FALSE(hal_sim_gates_on(&run.hal));
    latch_clear_rearm(FW_FAULT_WATCHDOG);
}

/* Hardware trip comparator (HAL, 1.25 i_max... set below the firmware level
 * here so that it fires first): reaction in the same period as well. */
static void test_hw_trip(void)
{
    sim_run_cfg_t c;
    loop_cfg(&c, "fst", 750.0, 1.8, 0.3, 0.0);
    c.hal.trip_level_a = 6.0; /* below the 10.5 A firmware level */
    loop_start(&run, &c);
    for (int k = 0; k < 200; k++) {
        TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run));
    }
    TEST_ASSERT_EQUAL_INT(FW_STATE_RUNNING, fw_state(&run.fw));
    hal_sim_inject_short(&run.hal, 2.0e4);
    const int n = until_fault(50);
    TEST_ASSERT_TRUE(n > 0);
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_HW_TRIP, fw_fault(&run.fw));
    TEST_ASSERT_TRUE(hal_trip_active(&run.hal));
    TEST_ASSERT_FALSE(hal_sim_gates_on(&run.hal));
    hal_sim_inject_short(&run.hal, 0.0);
    latch_clear_rearm(FW_FAULT_HW_TRIP);
    TEST_ASSERT_FALSE(hal_trip_active(&run.hal)); /* cleared with the fault */
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_overcurrent_same_period);
    RUN_TEST(test_dc_sag);
    RUN_TEST(test_dc_surge);
    RUN_TEST(test_encoder_stuck);
    RUN_TEST(test_encoder_glitch);
    RUN_TEST(test_encoder_index_resync);
    RUN_TEST(test_deadline_overrun);
    RUN_TEST(test_deadline_reentry);
    RUN_TEST(test_watchdog);
    RUN_TEST(test_hw_trip);
    return UNITY_END();
}
