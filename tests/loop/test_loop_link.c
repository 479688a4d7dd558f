/*
 * The serial link on the host closed loop: command lines through the command
 * interpreter reach the pipeline (fw_link.c), and telemetry frames
 * come out at the requested decimation.
 */
#include <stdio.h>
#include <string.h>

#include "ctrl_units.h"
#include "fw_link.h"
#include "link_text.h"
#include "loop_util.h"
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

static void send(const char *line)
{
    link_text_send(&lt, &link, line);
}

static void periods(int n)
{
    link_text_periods(&run, &link, n);
}

static void test_commands_reach_the_pipeline(void)
{
    sim_run_cfg_t c;
    loop_cfg(&c, "fst", 750.0, 0.0, 0.3, 0.0);
    loop_start(&run, &c);
    fw_link_init(&link, &run.fw, link_text_capture, &lt);
    periods(2);
    send("status");
    TEST_ASSERT_NOT_NULL(strstr(lt.out, "state=running"));
    TEST_ASSERT_NOT_NULL(strstr(lt.out, "ctrl=fst"));

    send("ref torque 1.5");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "ok", 2));
    periods(1);
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 1.5,
                              ctrl_q24_to_double(run.fw.refs.torque) * run.fw.bases.torque_nm);
    send("ref torque 100");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "err 4", 5));

    send("ctrl select bst"); /* armed: refused */
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "err 8", 5));
    TEST_ASSERT_EQUAL_STRING("fst", run.fw.ctrl->name);

    send("disarm");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "ok", 2));
    periods(1);
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&run.fw));
    TEST_ASSERT_FALSE(hal_sim_gates_on(&run.hal));

    send("ctrl select bst");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "ok", 2));
    TEST_ASSERT_EQUAL_STRING("bst", run.fw.ctrl->name);
    send("param set h_T 0.1");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "ok", 2));
    double v = 0.0;
    TEST_ASSERT_EQUAL_INT(FW_OK, fw_tunable_get(&run.fw, "h_T", &v));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.1, v);
    send("param get nosuch");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "err 5", 5));

    /* A configuration the controller cannot represent: the answer names the
     * quantity, its value and its range (FOC: Kp in Q20 below 2048 pu; 20000
     * V/A over r_base 8.233 ohm = 2429 pu), the configuration in force stays. */
    send("ctrl select foc");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "ok", 2));
    send("param set Kp_q 20000");
    TEST_ASSERT_EQUAL_STRING(
        "err 10 failed current PI Kp / (r_base) = 2429 pu outside [0, 2047]\r\n", lt.out);
    TEST_ASSERT_EQUAL_INT(FW_OK, fw_tunable_get(&run.fw, "Kp_q", &v));
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 0.0, v); /* the default (0 = Lq wc) */
    /* A value inside the listed range the parameter still refuses (a switch
     * given a fraction): the answer gives the range and why (the fuzzer's
     * first finding: a bare "err 4 range"), the value in force stays. */
    send("ctrl select m2ptfc");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "ok", 2));
    send("param set centre 0.5");
    TEST_ASSERT_EQUAL_STRING("err 4 range [0, 1], whole numbers\r\n", lt.out);
    TEST_ASSERT_EQUAL_INT(FW_OK, fw_tunable_get(&run.fw, "centre", &v));
    TEST_ASSERT_TRUE(v == 0.0 || v == 1.0);
    send("ctrl select bst");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "ok", 2));

    send("arm");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "ok", 2));
    periods(2);
    TEST_ASSERT_EQUAL_INT(FW_STATE_RUNNING, fw_state(&run.fw));
    TEST_ASSERT_TRUE(hal_sim_gates_on(&run.hal));
}

/* "tel start torque every 10": one META frame, then one SAMPLE frame every 10
 * periods; each frame is delimited by two 0x00 bytes. */
static void test_telemetry_frames(void)
{
    sim_run_cfg_t c;
    loop_cfg(&c, "fst", 750.0, 1.8, 0.3, 0.0);
    loop_start(&run, &c);
    fw_link_init(&link, &run.fw, link_text_capture, &lt);
    periods(5);
    send("tel start torque every 10");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "ok tel", 6));
    lt.zeros = 0;
    periods(100);
    TEST_ASSERT_EQUAL_UINT32(0u, fw_tm_dropped(&run.fw));
    TEST_ASSERT_EQUAL_UINT32(2u * (1u + 10u), (uint32_t)lt.zeros);
    send("tel stop");
    lt.zeros = 0;
    periods(50);
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)lt.zeros);
}

/* A fault is reported and cleared over the link. */
static void test_fault_over_link(void)
{
    sim_run_cfg_t c;
    loop_cfg(&c, "fst", 750.0, 1.8, 0.3, 0.0);
    loop_start(&run, &c);
    fw_link_init(&link, &run.fw, link_text_capture, &lt);
    periods(5);
    hal_sim_inject_encoder_glitch(&run.hal, 500);
    periods(2);
    send("fault");
    TEST_ASSERT_NOT_NULL(strstr(lt.out, "encoder_jump"));
    send("arm");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "err 9", 5));
    hal_sim_inject_encoder_glitch(&run.hal, -500);
    send("fault clear");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "ok", 2));
    periods(1);
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&run.fw));
}

/* A board that holds its gates off for good (fw_link_set_hold: its gate
 * driver did not answer at start-up): arm, identification and bring-up are
 * refused with the board's reason as the detail of "err 8 state", the
 * drive stays disarmed; released, arm works again. */
static void test_board_hold_refuses_by_name(void)
{
    sim_run_cfg_t c;
    loop_cfg(&c, "fst", 750.0, 0.0, 0.3, 0.0);
    loop_start(&run, &c);
    fw_link_init(&link, &run.fw, link_text_capture, &lt);
    periods(2);
    send("disarm");
    periods(1);
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&run.fw));
    static const char why[] = "gates held off: DRV8301 no answer on SPI";
    fw_link_set_hold(&link, why);
    send("arm");
    TEST_ASSERT_EQUAL_STRING("err 8 state gates held off: DRV8301 no answer on SPI\r\n", lt.out);
    send("ident run");
    TEST_ASSERT_NOT_NULL(strstr(lt.out, "err 8 state gates held off: DRV8301 no answer on SPI"));
    send("bringup gates");
    TEST_ASSERT_NOT_NULL(strstr(lt.out, "err 8 state gates held off"));
    periods(2);
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&run.fw));
    fw_link_set_hold(&link, NULL);
    send("arm");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "ok armed", 8));
}

/* Application parameters (fw_link_set_params, e.g. a board's machine data):
 * listed after the controller's tunables, read and written by name, the
 * interpreter's range check applies, a read-only one answers err 11, the
 * setter's refusal (err 8 while running) passes through. */
static double app_value = 2.5;
static int app_get(void *ctx, const fw_link_param_t *p, double *v)
{
    (void)ctx;
    (void)p;
    *v = app_value;
    return CMD_OK;
}
static int app_set(void *ctx, const fw_link_param_t *p, double v)
{
    (void)p;
    const fw_t *fw = (const fw_t *)ctx;
    if (fw_state(fw) == FW_STATE_RUNNING) {
        return CMD_E_STATE;
    }
    app_value = v;
    return CMD_OK;
}
static const fw_link_param_t app_params[] = {
    {{"m.rs_ohm", "ohm", "stator resistance", false, 0.001, 100.0}, app_get, app_set},
    {{"b.temp_c", "C", "board temperature", true, 0.0, 0.0}, app_get, NULL},
};

static void test_application_parameters(void)
{
    sim_run_cfg_t c;
    loop_cfg(&c, "fst", 750.0, 0.0, 0.3, 0.0);
    loop_start(&run, &c);
    fw_link_init(&link, &run.fw, link_text_capture, &lt);
    fw_link_set_params(&link, app_params, 2u, &run.fw);
    periods(2);
    send("param list");
    const char *rs = strstr(lt.out, "  m.rs_ohm 2.5 ohm [0.001, 100]");
    const char *tc = strstr(lt.out, "  b.temp_c 2.5 C");
    TEST_ASSERT_NOT_NULL(rs);
    TEST_ASSERT_NOT_NULL(tc);
    TEST_ASSERT_NOT_NULL(strstr(tc, " ro "));
    TEST_ASSERT_TRUE(run.fw.ctrl->n_tunables > 0u);
    char first[40];
    (void)snprintf(first, sizeof first, "  %s ", run.fw.ctrl->tunables[0].name);
    TEST_ASSERT_TRUE(strstr(lt.out, first) != NULL && strstr(lt.out, first) < rs);
    send("param set m.rs_ohm 0.5"); /* armed */
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "err 8", 5));
    send("disarm");
    periods(1);
    send("param set m.rs_ohm 0.5");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "ok", 2));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.5, app_value);
    send("param get m.rs_ohm");
    TEST_ASSERT_NOT_NULL(strstr(lt.out, "ok m.rs_ohm 0.5 ohm"));
    send("param set m.rs_ohm 200");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "err 4", 5));
    send("param set b.temp_c 20");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "err 11", 6));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.5, app_value);
}

/* The thesis SPMSM's drive started (drr) and its machine data, to change. */
static ctrl_machine_t start_drr_machine(void)
{
    sim_run_cfg_t c;
    loop_cfg(&c, "drr", 0.0, 0.0, 0.3, 0.0);
    loop_start(&run, &c);
    return run.fw.machine_own;
}

/* fw_init of the running drive's configuration with machine data m. */
static int reinit_with_machine(const ctrl_machine_t *m)
{
    fw_config_t fc = run.fw.cfg;
    fc.machine = m;
    fc.ctrl = run.fw.ctrl;
    fc.ctrl_cfg = NULL;
    return fw_init(&run.fw, &run.hal, &fc);
}

/* A machine whose declared maximum speed is below its rated speed (thesis
 * SPMSM, 3750 r/min, rated set to 10000): the refusal names the quantity, its
 * value and the range, as "err 10 failed" passes it on (it came without a
 * reason: found by the link's fuzzer). */
static void test_max_speed_refusal_is_named(void)
{
    ctrl_machine_t m = start_drr_machine();
    TEST_ASSERT_TRUE(m.speed_max_rpm > 0.0);
    m.speed_rated_rpm = 10000.0;
    TEST_ASSERT_EQUAL_INT(FW_EINVAL, reinit_with_machine(&m));
    TEST_ASSERT_EQUAL_STRING("maximum speed", run.fw.why.quantity);
    TEST_ASSERT_EQUAL_DOUBLE(3750.0, run.fw.why.value);
    TEST_ASSERT_EQUAL_DOUBLE(10000.0, run.fw.why.min);
    TEST_ASSERT_FALSE(hal_sim_gates_on(&run.hal));
}

/* A machine whose overspeed level is beyond the Q24 speed's 127 x the speed
 * base (thesis SPMSM, rated speed 3000 r/min, the speed base, and a declared
 * maximum of 400000 r/min: 1.05 x 400000 / 3000 = 140 pu): the refusal
 * names the level, its value and the largest the check can represent (it
 * came without a reason: found by the link's fuzzer). */
static void test_overspeed_refusal_is_named(void)
{
    ctrl_machine_t m = start_drr_machine();
    m.speed_max_rpm = 400000.0;
    TEST_ASSERT_EQUAL_INT(FW_EINVAL, reinit_with_machine(&m));
    TEST_ASSERT_EQUAL_STRING("overspeed level", run.fw.why.quantity);
    TEST_ASSERT_EQUAL_DOUBLE(FW_OVERSPEED_REL * m.speed_max_rpm, run.fw.why.value);
    /* 127 pu of electrical speed in mechanical r/min */
    const double lim = ctrl_elec_to_rpm(127.0 * run.fw.bases.w_rad_s, m.pole_pairs);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9 * lim, lim, run.fw.why.max);
    TEST_ASSERT_TRUE(run.fw.why.value > run.fw.why.max);
    TEST_ASSERT_FALSE(hal_sim_gates_on(&run.hal));
}

/* A machine with an inertia of 1e-15 kg*m^2 (link fuzzer: param set m.j_kgm2
 * 1e-15): the encoder's plausible second difference, a_max Ts^2, is beyond
 * int32_t; the jump limit saturates instead of converting an out-of-range
 * double (undefined), and the other encoder limits stay as the physics gives
 * them. */
static void test_tiny_inertia_encoder_limits(void)
{
    sim_run_cfg_t c;
    loop_cfg(&c, "drr", 0.0, 0.0, 0.3, 0.0);
    loop_start(&run, &c);
    ctrl_machine_t m = run.fw.machine_own;
    m.inertia_kgm2 = 1e-15;
    fw_config_t fc = run.fw.cfg;
    fc.machine = &m;
    fc.ctrl = run.fw.ctrl;
    fc.ctrl_cfg = NULL;
    TEST_ASSERT_EQUAL_INT(FW_OK, fw_init(&run.fw, &run.hal, &fc));
    TEST_ASSERT_EQUAL_INT32(INT32_MAX, run.fw.prot.cfg.enc_jump_max);
    TEST_ASSERT_EQUAL_INT32(INT32_MAX, run.fw.prot.cfg.enc_rate_min_q16);
    TEST_ASSERT_EQUAL_UINT32(8u, run.fw.prot.cfg.enc_stuck_periods);
    /* The GBM5208 gimbal motor with as little: the speed PI's integral gain
     * sized from the inertia rounds to nothing; refused with the gain named
     * (the link answers with it; it answered a bare 'err 10 failed'). */
    static sim_machine_t g;
    char err[160];
    TEST_ASSERT_EQUAL_INT(
        0, sim_machine_load(PMSM_MACHINES_DIR "/gbm5208_gimbal.ini", &g, err, sizeof err));
    sim_run_config_default(&c, &g, run.fw.ctrl);
    c.speed_rpm = 0.0;
    c.auto_arm = false;
    loop_start(&run, &c);
    m = run.fw.machine_own;
    m.inertia_kgm2 = 1e-15;
    fc = run.fw.cfg;
    fc.machine = &m;
    fc.ctrl = run.fw.ctrl;
    fc.ctrl_cfg = NULL;
    TEST_ASSERT_EQUAL_INT(FW_ERANGE, fw_init(&run.fw, &run.hal, &fc));
    char buf[200];
    fw_explain(&run.fw, buf, sizeof buf);
    printf("  GBM5208, inertia 1e-15 kg*m^2: %s\n", buf);
    TEST_ASSERT_EQUAL_STRING("speed PI integral gain x loop period", run.fw.why.quantity);
    TEST_ASSERT_TRUE(run.fw.why.value < run.fw.why.min);
    TEST_ASSERT_FALSE(hal_sim_gates_on(&run.hal));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_commands_reach_the_pipeline);
    RUN_TEST(test_application_parameters);
    RUN_TEST(test_telemetry_frames);
    RUN_TEST(test_fault_over_link);
    RUN_TEST(test_board_hold_refuses_by_name);
    RUN_TEST(test_max_speed_refusal_is_named);
    RUN_TEST(test_overspeed_refusal_is_named);
    RUN_TEST(test_tiny_inertia_encoder_limits);
    return UNITY_END();
}
