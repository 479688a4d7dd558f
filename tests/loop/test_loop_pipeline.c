/*
 * The pipeline with a trivial open-loop test controller (not registered):
 * one-period delay of a real drive, compare values of a plan, ADC offset
 * calibration; and the state machine and protection checks in isolation.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "loop_util.h"
#include "plan.h"
#include "unity.h"

void setUp(void)
{
}

static sim_run_t run;

void tearDown(void)
{
    sim_run_free(&run);
}

/* ---- open-loop test controller: V(1 + k mod 6) for duty (k mod 4 + 1)/8,
 * recording its plans ---- */
#define OL_HIST 16
typedef struct {
    uint32_t k;
    ctrl_plan_t out[OL_HIST];
} ol_state_t;

static void ol_cfg_default(void *cfg, const ctrl_machine_t *m)
{
    (void)cfg;
    (void)m;
}
static int ol_init(void *state, const void *cfg, const ctrl_setup_t *su)
{
    (void)cfg;
    (void)su;
    memset(state, 0, sizeof(ol_state_t));
    return CTRL_OK;
}
static void ol_reset(void *state)
{
    memset(state, 0, sizeof(ol_state_t));
}
static void ol_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out)
{
    (void)ctx;
    ol_state_t *s = (ol_state_t *)state;
    ctrl_out_active_zero(out, (uint8_t)(1u + s->k % 6u), (q24_t)((s->k % 4u + 1u) * (FX_ONE / 8)));
    if (s->k < OL_HIST) {
        s->out[s->k] = out->plan;
    }
    s->k++;
}
static const ctrl_desc_t ol_desc = {
    .name = "test_ol",
    .title = "open-loop test sequence",
    .fs_default_hz = 20000u,
    .state_size = sizeof(ol_state_t),
    .cfg_size = 8u,
    .cfg_default = ol_cfg_default,
    .init = ol_init,
    .reset = ol_reset,
    .step = ol_step,
};

static void legs_equal(const ctrl_legs_t *a, const ctrl_legs_t *b)
{
    for (unsigned x = 0; x < 3u; x++) {
        TEST_ASSERT_EQUAL_INT32(a->duty[x], b->duty[x]);
    }
}

/* The plan chosen at k is applied by the PWM in period k+1 and handed to the
 * estimator as the applied leg duties at k+1. */
static void test_one_period_delay(void)
{
    TEST_ASSERT_TRUE(sizeof(ol_state_t) <= CTRL_STATE_MAX);
    sim_run_cfg_t c;
    loop_cfg(&c, "bst", 300.0, 0.0, 0.3, 0.0);
    c.ctrl = &ol_desc;
    c.ctrl_cfg = NULL;
    loop_start(&run, &c);
    const uint32_t n = run.hal.period_counts;
    TEST_ASSERT_EQUAL_UINT32(2500u, n); /* 100 MHz / (2 * 20 kHz) */
    /* First step after arm: the gates were off, nothing applied (all legs low). */
    const ctrl_legs_t none = {{0, 0, 0}};
    legs_equal(&none, &run.fw.applied);
    const ol_state_t *s = (const ol_state_t *)fw_ctrl_state(&run.fw);
    for (uint32_t k = 0; k < OL_HIST; k++) {
        TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run));
        /* After period k the duties of the plan chosen at k are the applied
         * ones of period k+1. */
        TEST_ASSERT_EQUAL_UINT32(k + 1u, s->k);
        ctrl_legs_t want;
        ctrl_plan_legs(&s->out[k], &want);
        legs_equal(&want, &run.fw.applied);
    }
    TEST_ASSERT_EQUAL_STRING("none", fw_fault_name(fw_fault(&run.fw)));
    /* The compare values active in the last period realise the plan chosen one
     * period earlier: V(x) with duty d -> legs of Table 4.2 at d*N counts. */
    hal_pwm_t act;
    hal_sim_pwm_active(&run.hal, &act);
    const ctrl_plan_t *p = &s->out[s->k - 2u];
    ctrl_legs_t legs;
    ctrl_plan_legs(p, &legs);
    for (int x = 0; x < 3; x++) {
        const uint32_t want = (uint32_t)(((uint64_t)(uint32_t)legs.duty[x] * n + (1u << 23)) >> 24);
        TEST_ASSERT_EQUAL_UINT32(want, act.cmp[x]);
    }
    /* The active vector was V1..V6 for (k mod 4 + 1)/8: exactly one leg
     * pattern away from the zero vector, duties in {0, d, 1}... check V(x). */
    TEST_ASSERT_TRUE(p->vec[0] >= 1u && p->vec[0] <= 6u);
}

/* ADC offsets: +30 / -20 counts on i_a / i_b (noise 0.5 count rms, 256
 * samples -> standard error 0.03 count); the firmware's averaged offset must
 * match within 0.25 count (8 standard errors + Q8 rounding). */
static void test_offset_calibration(void)
{
    sim_run_cfg_t c;
    loop_cfg(&c, "bst", 750.0, 0.0, 0.3, 0.0);
    c.calib_samples = 256u;
    c.hal.adc_offset_counts[0] = 30.0;
    c.hal.adc_offset_counts[1] = -20.0;
    loop_start(&run, &c);
    const double mid = 2048.0;
    TEST_ASSERT_DOUBLE_WITHIN(0.25, mid + 30.0, run.fw.off_q8[0] / 256.0);
    TEST_ASSERT_DOUBLE_WITHIN(0.25, mid - 20.0, run.fw.off_q8[1] / 256.0);
    /* The first ISR after calibration samples a zero current (gates were off,
     * back-EMF 30 V < Vdc: no diode conduction): converted within 2 counts of
     * 7.7 mA (i_fullscale 15.75 A, 12 bit) despite the offsets. */
    TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run));
    const double lsb_pu = 2.0 * 15.75 / 4096.0 / run.fw.bases.i_a;
    const fw_telemetry_t *tm = fw_telemetry(&run.fw);
    TEST_ASSERT_DOUBLE_WITHIN(2.0 * lsb_pu, 0.0, ctrl_q24_to_double(tm->i_a));
    TEST_ASSERT_DOUBLE_WITHIN(2.0 * lsb_pu, 0.0, ctrl_q24_to_double(tm->i_b));
    TEST_ASSERT_EQUAL_INT(FW_STATE_RUNNING, fw_state(&run.fw));
}

/* An offset beyond 1/16 of full scale (128 counts) is a calibration fault. */
static void test_offset_calibration_fault(void)
{
    sim_run_cfg_t c;
    loop_cfg(&c, "bst", 0.0, 0.0, 0.3, 0.0);
    c.hal.adc_offset_counts[0] = 300.0;
    char err[256];
    TEST_ASSERT_NOT_EQUAL(0, sim_run_init(&run, &c, err, sizeof err));
    TEST_ASSERT_EQUAL_INT(FW_STATE_FAULT, fw_state(&run.fw));
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_CALIB, fw_fault(&run.fw));
    TEST_ASSERT_FALSE(hal_sim_gates_on(&run.hal));
}

/* ---- state machine ---- */
static void test_state_machine(void)
{
    fw_state_t s;
    fw_state_init(&s);
    TEST_ASSERT_EQUAL_INT(FW_STATE_BOOT, s.state);
    /* Commands are ignored before calibration. */
    TEST_ASSERT_FALSE(fw_state_event(&s, FW_EV_ARM, 0));
    TEST_ASSERT_TRUE(fw_state_event(&s, FW_EV_START, 0));
    TEST_ASSERT_EQUAL_INT(FW_STATE_CALIB, s.state);
    TEST_ASSERT_FALSE(fw_state_gates_allowed(&s));
    TEST_ASSERT_FALSE(fw_state_event(&s, FW_EV_ARM, 0));
    TEST_ASSERT_TRUE(fw_state_event(&s, FW_EV_CALIB_DONE, 0));
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, s.state);
    TEST_ASSERT_FALSE(fw_state_gates_allowed(&s));
    TEST_ASSERT_FALSE(fw_state_event(&s, FW_EV_CLEAR, 0)); /* nothing to clear */
    TEST_ASSERT_TRUE(fw_state_event(&s, FW_EV_ARM, 0));
    TEST_ASSERT_TRUE(fw_state_gates_allowed(&s));
    TEST_ASSERT_TRUE(fw_state_event(&s, FW_EV_DISARM, 0));
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, s.state);
    TEST_ASSERT_TRUE(fw_state_event(&s, FW_EV_ARM, 0));
    /* Fault: first code latches, commands other than clear are ignored. */
    TEST_ASSERT_TRUE(fw_state_event(&s, FW_EV_FAULT, FW_FAULT_DC_OVERVOLT));
    TEST_ASSERT_FALSE(fw_state_event(&s, FW_EV_FAULT, FW_FAULT_WATCHDOG));
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_DC_OVERVOLT, s.fault_code);
    TEST_ASSERT_FALSE(fw_state_event(&s, FW_EV_ARM, 0));
    TEST_ASSERT_FALSE(fw_state_event(&s, FW_EV_DISARM, 0));
    TEST_ASSERT_FALSE(fw_state_gates_allowed(&s));
    TEST_ASSERT_TRUE(fw_state_event(&s, FW_EV_CLEAR, 0));
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, s.state);
    TEST_ASSERT_EQUAL_UINT32(0u, s.fault_code);
    /* A fault during calibration: clear restarts the calibration. */
    fw_state_init(&s);
    (void)fw_state_event(&s, FW_EV_START, 0);
    (void)fw_state_event(&s, FW_EV_FAULT, FW_FAULT_CALIB);
    TEST_ASSERT_TRUE(fw_state_event(&s, FW_EV_CLEAR, 0));
    TEST_ASSERT_EQUAL_INT(FW_STATE_CALIB, s.state);
    TEST_ASSERT_EQUAL_STRING("running", fw_state_name(FW_STATE_RUNNING));
}

/* ---- protection checks with synthetic inputs ---- */
static void test_protect_checks(void)
{
    fw_protect_cfg_t cfg = {FX_ONE / 2, FX_ONE + FX_ONE / 4, FX_ONE * 7 / 10, 5, 8, 65536, 1000u,
                            10u};
    fw_protect_t p;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, fw_protect_init(&p, &cfg));
    TEST_ASSERT_EQUAL_UINT32(0u, fw_protect_current(&p, FX_ONE / 4, -FX_ONE / 4));
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_OVERCURRENT, fw_protect_current(&p, FX_ONE / 2 + 1, 0));
    /* i_c = -(i_a + i_b) is checked too. */
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_OVERCURRENT,
                             fw_protect_current(&p, FX_ONE * 3 / 10, FX_ONE * 3 / 10));
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_DC_OVERVOLT, fw_protect_vdc(&p, FX_ONE * 13 / 10));
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_DC_UNDERVOLT, fw_protect_vdc(&p, FX_ONE * 6 / 10));
    TEST_ASSERT_EQUAL_UINT32(0u, fw_protect_vdc(&p, FX_ONE));
    /* Encoder: steady 3 counts per period across the 2^32 wrap, then a jump. */
    uint32_t c = UINT32_MAX - 10u;
    for (int k = 0; k < 20; k++) {
        TEST_ASSERT_EQUAL_UINT32(0u, fw_protect_encoder(&p, c));
        c += 3u;
    }
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_ENC_JUMP, fw_protect_encoder(&p, c + 9u));
    /* Stuck: rate 3 >= 1 count/period, 8 periods without motion. */
    fw_protect_reset(&p);
    for (int k = 0; k < 5; k++) {
        (void)fw_protect_encoder(&p, c);
        c += 3u;
    }
    TEST_ASSERT_EQUAL_UINT32(0u, fw_protect_encoder(&p, c)); /* last move */
    for (int k = 1; k < 8; k++) {
        TEST_ASSERT_EQUAL_UINT32(0u, fw_protect_encoder(&p, c));
    }
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_ENC_STUCK, fw_protect_encoder(&p, c));
    /* Slow rotation (1 count every 4 periods, below the armed rate): no fault. */
    fw_protect_reset(&p);
    for (int k = 0; k < 200; k++) {
        TEST_ASSERT_EQUAL_UINT32(0u, fw_protect_encoder(&p, c));
        if (k % 4 == 3) {
            c++;
        }
    }
    /* A rotor resting on a count edge: the count toggles +1, -1 a period
     * apart (as fast as 1 count/period), then rests. The toggles prove no
     * speed: no fault however long it rests. */
    fw_protect_reset(&p);
    for (int k = 0; k < 6; k++) {
        TEST_ASSERT_EQUAL_UINT32(0u, fw_protect_encoder(&p, c + (uint32_t)(k & 1)));
    }
    for (int k = 0; k < 100; k++) {
        TEST_ASSERT_EQUAL_UINT32(0u, fw_protect_encoder(&p, c));
    }
    /* A reversal by 3 counts in one period (after +1) proves more than 2
     * counts: rate 2 / 2 >= 1 count/period, armed; 8 periods without motion
     * are stuck. */
    fw_protect_reset(&p);
    (void)fw_protect_encoder(&p, c);
    (void)fw_protect_encoder(&p, c + 1u);
    TEST_ASSERT_EQUAL_UINT32(0u, fw_protect_encoder(&p, c + 2u));
    c -= 1u;
    TEST_ASSERT_EQUAL_UINT32(0u, fw_protect_encoder(&p, c));
    for (int k = 1; k < 8; k++) {
        TEST_ASSERT_EQUAL_UINT32(0u, fw_protect_encoder(&p, c));
    }
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_ENC_STUCK, fw_protect_encoder(&p, c));
    TEST_ASSERT_EQUAL_UINT32(0u, fw_protect_deadline(&p, 1000u));
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_DEADLINE, fw_protect_deadline(&p, 1001u));
    /* watchdog: 10 periods since the last kick allowed, 11 not */
    for (uint32_t k = 0; k <= 10u; k++) {
        TEST_ASSERT_EQUAL_UINT32(0u, fw_protect_watchdog_tick(&p, k));
    }
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_WATCHDOG, fw_protect_watchdog_tick(&p, 11u));
    for (uint32_t f = 0; f < (uint32_t)FW_FAULT_COUNT; f++) {
        TEST_ASSERT_NOT_NULL(fw_fault_name(f));
        TEST_ASSERT_TRUE(strcmp(fw_fault_name(f), "unknown") != 0);
    }
    TEST_ASSERT_EQUAL_STRING("unknown", fw_fault_name(999u));
}

/* Bad configuration: NULLs and a controller without functions are rejected. */
/* Telemetry ring: one record published in `every` periods, the first at the
 * next period; the published records are the periods' own (period numbers
 * `every` apart, the last record equal to fw_telemetry); a main loop that
 * takes nothing leaves FW_TM_RING - 1 records and counts the rest as dropped;
 * stopping publishes nothing and empties the ring. */
static void test_telemetry_ring(void)
{
    sim_run_cfg_t c;
    loop_cfg(&c, "bst", 750.0, 0.0, 0.3, 0.0);
    loop_start(&run, &c);
    fw_t *fw = &run.fw;
    TEST_ASSERT_NULL(fw_tm_peek(fw)); /* nothing published before a stream */
    const uint32_t every = 3u;
    fw_tm_stream(fw, every);
    const uint32_t first = fw->period + 1u;
    uint32_t taken = 0u;
    for (uint32_t k = 0; k < 60u; k++) {
        TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run));
        const fw_telemetry_t *r;
        while ((r = fw_tm_peek(fw)) != NULL) {
            TEST_ASSERT_EQUAL_UINT32(first + taken * every, r->period);
            TEST_ASSERT_EQUAL_UINT8(FW_STATE_RUNNING, r->state);
            if (r->period == fw->period) {
                TEST_ASSERT_TRUE(r == fw_telemetry(fw));
            }
            fw_tm_release(fw);
            taken++;
        }
    }
    TEST_ASSERT_EQUAL_UINT32(20u, taken);
    TEST_ASSERT_EQUAL_UINT32(0u, fw_tm_dropped(fw));
    /* nobody reads: the ring fills to FW_TM_RING - 1, the rest is dropped */
    fw_tm_stream(fw, 1u);
    for (uint32_t k = 0; k < FW_TM_RING + 5u; k++) {
        TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run));
    }
    TEST_ASSERT_EQUAL_UINT32(FW_TM_RING - 1u, fw->isr.tm_head - fw->ml.tm_tail);
    TEST_ASSERT_EQUAL_UINT32(6u, fw_tm_dropped(fw));
    fw_tm_stream(fw, 0u);
    TEST_ASSERT_NULL(fw_tm_peek(fw));
    TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run));
    TEST_ASSERT_NULL(fw_tm_peek(fw));
    fw_tm_release(fw); /* nothing to release: no change */
    TEST_ASSERT_EQUAL_UINT32(fw->isr.tm_head, fw->ml.tm_tail);
}

static void test_init_rejects(void)
{
    fw_t fw;
    TEST_ASSERT_EQUAL_INT(FW_EINVAL, fw_init(NULL, NULL, NULL));
    fw_config_t fc;
    fw_config_default(&fc, NULL, &ol_desc);
    TEST_ASSERT_EQUAL_INT(FW_EINVAL, fw_init(&fw, (hal_t *)&run.hal, &fc));
    TEST_ASSERT_NOT_NULL(fw_strerror(FW_ECTRL));
    /* A machine the core cannot represent at this rate: refused, and
     * fw_explain names the quantity, its value and the accepted range
     * (60000 r/min, 4 pole pairs, 20 kHz: 1.26 rad per period at rated speed). */
    ctrl_machine_t m = run.cfg.ctrl_machine;
    m.speed_rated_rpm = 60000.0;
    fw_config_default(&fc, &m, ctrl_find("bst"));
    TEST_ASSERT_EQUAL_INT(FW_EINVAL, fw_init(&fw, (hal_t *)&run.hal, &fc));
    char why[200];
    TEST_ASSERT_TRUE(fw_explain(&fw, why, sizeof why) > 0u);
    TEST_MESSAGE(why);
    TEST_ASSERT_NOT_NULL(strstr(why, "rated electrical speed x Ts = 1.25664"));
    TEST_ASSERT_NOT_NULL(strstr(why, "[0.001, 1]"));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_one_period_delay);
    RUN_TEST(test_offset_calibration);
    RUN_TEST(test_offset_calibration_fault);
    RUN_TEST(test_state_machine);
    RUN_TEST(test_protect_checks);
    RUN_TEST(test_init_rejects);
    RUN_TEST(test_telemetry_ring);
    return UNITY_END();
}
