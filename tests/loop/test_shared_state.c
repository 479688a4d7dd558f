/*
 * One writer per block of the state the main loop and the interrupt share
 * (docs/architecture.md, "State shared between the contexts"; pipeline.h,
 * fw_from_main_t and fw_to_main_t), checked around every period of closed-loop
 * runs that go through what the main loop does to a drive: references in
 * torque and speed mode, live changes (the speed loop's gains, a
 * controller's tunable), telemetry started, restarted and stopped, disarm,
 * arm, a fault and its clear, commissioning steps that drive the legs and the
 * controller (bringup gates, bringup run), the link's status.
 *
 * Before each period (the engine's link hook, right before the interrupt)
 * the blocks the interrupt owns must be as the last period left them: the
 * main loop did not write them. After it (the interrupt and, when due, the
 * medium task have run) the main loop's block must be as the main loop left
 * it: neither context wrote it. A second writer of either block fails the
 * test with the field's offset and the period.
 */
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "fw_link.h"
#include "link_text.h"
#include "loop_util.h"
#include "sim_ident.h"
#include "unity.h"

void setUp(void)
{
}

static sim_run_t run;
static fw_link_t link;
static link_text_t lt;

void tearDown(void)
{
    sim_run_free(&run);
}

/* What the interrupt owns beside fw_to_main_t: its counters and the
 * telemetry's decimation state (fw_t). */
typedef struct {
    fw_to_main_t isr;
    uint32_t period, tm_every, tm_count;
} isr_owned_t;

static struct {
    fw_from_main_t ml; /* the main loop's block before the period */
    isr_owned_t isr;   /* the interrupt's after the period */
    bool have_isr;
    uint32_t periods;
    uint32_t violations;
    char first[200];
} w;

/* Byte copies through volatile reads (the blocks have volatile members). */
static void vcopy(void *dst, const volatile void *src, size_t n)
{
    const volatile unsigned char *s = src;
    unsigned char *d = dst;
    for (size_t k = 0; k < n; k++) {
        d[k] = s[k];
    }
}

static void isr_owned(const fw_t *fw, isr_owned_t *o)
{
    memset(o, 0, sizeof *o);
    vcopy(&o->isr, &fw->isr, sizeof o->isr);
    o->period = fw->period;
    o->tm_every = fw->tm_every;
    o->tm_count = fw->tm_count;
}

static void violation(const char *who, const char *block, const void *a, const void *b, size_t n)
{
    const unsigned char *x = a;
    const unsigned char *y = b;
    size_t k = 0;
    while (k < n && x[k] == y[k]) {
        k++;
    }
    if (w.violations++ == 0u) {
        (void)snprintf(w.first, sizeof w.first, "%s wrote %s (byte %zu of %zu) before period %lu",
                       who, block, k, n, (unsigned long)run.fw.period + 1u);
    }
}

/* Right before the interrupt: the main loop since the last period left the
 * interrupt's blocks alone; the main loop's block as it is now. */
static int before_isr(void *ctx, sim_run_t *r)
{
    (void)ctx;
    if (w.have_isr) {
        isr_owned_t now;
        isr_owned(&r->fw, &now);
        if (memcmp(&now, &w.isr, sizeof now) != 0) {
            violation("the main loop", "the interrupt's state", &now, &w.isr, sizeof now);
        }
    }
    vcopy(&w.ml, &r->fw.ml, sizeof w.ml);
    return 0;
}

/* After the interrupt and the medium task: they left the main loop's block
 * alone. */
static int after_isr(void *ctx, sim_run_t *r)
{
    (void)ctx;
    fw_from_main_t now;
    vcopy(&now, &r->fw.ml, sizeof now);
    if (memcmp(&now, &w.ml, sizeof now) != 0) {
        violation("the interrupt", "the main loop's block", &now, &w.ml, sizeof now);
    }
    isr_owned(&r->fw, &w.isr);
    w.have_isr = true;
    w.periods++;
    return 0;
}

static int watch_setup(void *ctx, sim_run_t *r, const fw_config_t *fc, char *err, size_t errlen)
{
    (void)ctx;
    (void)r;
    (void)fc;
    (void)err;
    (void)errlen;
    return 0;
}

static const char *watch_error(void *ctx)
{
    (void)ctx;
    return "no error";
}

static const sim_link_t watch = {
    .ctx = NULL,
    .setup = watch_setup,
    .send = before_isr,
    .receive = after_isr,
    .error = watch_error,
};

static void send(const char *line)
{
    link_text_send(&lt, &link, line);
}

static void expect_ok(const char *line)
{
    send(line);
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, strncmp(lt.out, "ok", 2), lt.out);
}

static void periods(int n)
{
    link_text_periods(&run, &link, n);
}

/* Periods until the state is `st` (at most n). */
static void until_state(fw_state_id_t st, int n)
{
    for (int k = 0; k < n && fw_state(&run.fw) != st; k++) {
        periods(1);
    }
    TEST_ASSERT_EQUAL_INT(st, fw_state(&run.fw));
}

static void start(const char *ctrl, double duration_s)
{
    memset(&w, 0, sizeof w);
    sim_run_cfg_t c;
    loop_cfg(&c, ctrl, 750.0, 0.0, duration_s, 0.0);
    c.link = &watch;
    loop_start(&run, &c);
    fw_link_init(&link, &run.fw, link_text_capture, &lt);
}

static void test_running_and_telemetry(void)
{
    start("m2ptfc", 2.0);
    until_state(FW_STATE_RUNNING, 2000);
    expect_ok("ref torque 1");
    periods(40);
    expect_ok("tel start torque speed every 3");
    periods(30);
    expect_ok("ref speed 600");
    periods(200);
    /* live changes while running (pipeline.h): the speed loop's gains and a
     * tunable of the controller, each a request the interrupt takes */
    const fw_config_t *cfg = &run.fw.cfg;
    TEST_ASSERT_EQUAL_INT(FW_OK, fw_speed_retune(&run.fw, 0.8 * run.fw.speed_info.bandwidth_hz,
                                                 cfg->speed_pm_deg, 0.0, 0.0));
    TEST_ASSERT_EQUAL_INT(FW_OK, fw_tunable_set(&run.fw, "lambda", 0.5));
    TEST_ASSERT_TRUE(fw_cmd_pending(&run.fw, FW_REQ_CTRL_TUNE));
    periods(2);
    TEST_ASSERT_FALSE(fw_cmd_pending(&run.fw, FW_REQ_SPEED_TUNE));
    TEST_ASSERT_FALSE(fw_cmd_pending(&run.fw, FW_REQ_CTRL_TUNE));
    periods(100);
    expect_ok("tel start i_a i_b every 1"); /* a new stream drops the last one's records */
    periods(30);
    expect_ok("status");
    expect_ok("tel stop");
    expect_ok("ref torque 0.5");
    periods(20);
    expect_ok("disarm");
    until_state(FW_STATE_READY, 5);
    expect_ok("arm");
    periods(20);
    TEST_ASSERT_EQUAL_INT(FW_STATE_RUNNING, fw_state(&run.fw));
    expect_ok("disarm");
    periods(5);
    TEST_ASSERT_TRUE(w.periods > 300u);
    TEST_ASSERT_EQUAL_UINT32_MESSAGE(0u, w.violations, w.first);
}

static void start_run(void)
{
    const uint8_t runs[] = {CM_STEP_RUN};
    uint8_t missing = 0;
    TEST_ASSERT_EQUAL_INT(FW_OK, fw_commission_start(&run.fw, runs, 1u, &missing));
}

/* Commissioning: the steps drive the legs and then the controller with their
 * own torque reference (bringup run), which the interrupt used to write into
 * the main loop's reference; a fault and its clear. */
static void test_commissioning_and_fault(void)
{
    /* the thesis SPMSM on free mechanics, booted and calibrated (sim_ident.h) */
    memset(&w, 0, sizeof w);
    char err[256];
    TEST_ASSERT_EQUAL_INT_MESSAGE(0,
                                  sim_ident_setup(&run, loop_spmsm(), loop_spmsm(),
                                                  ctrl_find("m2ptfc"), 1.0, 1u, err, sizeof err),
                                  err);
    run.cfg.link = &watch;
    fw_link_init(&link, &run.fw, link_text_capture, &lt);
    until_state(FW_STATE_READY, 2000);
    expect_ok("ref torque 0.2");
    /* the first closed-loop run alone (the link's "bringup run" measures Rs
     * first) */
    start_run();
    until_state(FW_STATE_COMMISSION, 3);
    for (int k = 0; k < 40000 && fw_state(&run.fw) == FW_STATE_COMMISSION; k++) {
        periods(1);
    }
    send("bringup status");
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, strncmp(lt.out, "ok pass step=run", 16), lt.out);
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&run.fw));
    /* the main loop's reference is the main loop's: what it set */
    TEST_ASSERT_EQUAL_INT32(fw_torque_ref(&run.fw),
                            ctrl_q24_from_double(0.2 / run.fw.bases.torque_nm));
    /* the gate test, then a main loop that stops kicking the watchdog: the
     * fault after 100 ms of periods (the interrupt counts from the main
     * loop's stamp), and its clear once the kicks are back */
    expect_ok("bringup gates");
    until_state(FW_STATE_COMMISSION, 3);
    for (int k = 0; k < 40000 && fw_state(&run.fw) == FW_STATE_COMMISSION; k++) {
        periods(1);
    }
    if (fw_state(&run.fw) == FW_STATE_FAULT) {
        expect_ok("fault clear");
        until_state(FW_STATE_READY, 5);
    }
    run.cfg.kick_watchdog = false;
    const uint32_t wdg = run.fw.prot.cfg.wdg_periods;
    periods((int)wdg);
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&run.fw));
    periods(2);
    TEST_ASSERT_EQUAL_INT(FW_STATE_FAULT, fw_state(&run.fw));
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_WATCHDOG, fw_fault(&run.fw));
    run.cfg.kick_watchdog = true;
    periods(1);
    expect_ok("fault clear");
    until_state(FW_STATE_READY, 5);
    start_run(); /* and stopped midway */
    periods(200);
    TEST_ASSERT_EQUAL_INT(FW_STATE_COMMISSION, fw_state(&run.fw));
    expect_ok("stop");
    until_state(FW_STATE_READY, 5);
    TEST_ASSERT_TRUE(w.periods > 1000u);
    TEST_ASSERT_EQUAL_UINT32_MESSAGE(0u, w.violations, w.first);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_running_and_telemetry);
    RUN_TEST(test_commissioning_and_fault);
    return UNITY_END();
}
