/*
 * Commissioning through the serial link (PROTOCOL.md "Commissioning"): the
 * command lines reach the firmware's steps on the host closed loop, refusals
 * say why, progress shows in "ident status" and in the telemetry signals
 * cm_step / cm_progress, "stop" ends a step with the gates off, a failed
 * bring-up check answers "fail" with its reason, and the results read back
 * as values and as a machine-file fragment. While a step runs, the
 * telemetry's i_d, i_q, speed and torque and "status" show what it does
 * (not zeros, not the last run's estimate), and "bringup status" answers
 * idle while an identification runs (a page polling both shows "ident").
 * After a stop, "status" follows the rotor (a motor with friction stops),
 * not the last run's speed and torque.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ctrl_units.h"
#include "fw_link.h"
#include "link_text.h"
#include "sim_ident.h"
#include "unity.h"

static sim_machine_t spm;
static sim_run_t run;
static fw_link_t link;
static link_text_t lt;

void setUp(void)
{
    char err[256];
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, sim_machine_load(PMSM_MACHINES_DIR "/thesis_spmsm.ini", &spm, err, sizeof err), err);
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, sim_ident_setup(&run, &spm, &spm, ctrl_find("m2ptfc"), 1.0, 1u, err, sizeof err), err);
    fw_link_init(&link, &run.fw, NULL, NULL);
}

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

/* The number after `key` in the captured reply. */
static double reply_num(const char *key)
{
    const char *p = strstr(lt.out, key);
    TEST_ASSERT_NOT_NULL_MESSAGE(p, lt.out);
    return strtod(p + strlen(key), NULL);
}

/* The true rotor speed, r/min. */
static double true_rpm(void)
{
    return plant_omega_m(&run.plant) * 30.0 / CTRL_PI;
}

static void test_ident_commands(void)
{
    link.write = link_text_capture;
    link.write_ctx = &lt;
    send("ident step rs");
    TEST_ASSERT_EQUAL_STRING("err 8 state needs encoder\r\n", lt.out);
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&run.fw));
    send("ident step gates");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "err 5 name", 10));
    send("ident step vbus");
    TEST_ASSERT_EQUAL_STRING("ok ident vbus\r\n", lt.out);
    periods(2);
    TEST_ASSERT_EQUAL_INT(FW_STATE_COMMISSION, fw_state(&run.fw));
    send("arm");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "err 8", 5));
    send("ident status");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "ok running step=vbus progress=", 30));
    periods(2000);
    send("ident status");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "ok pass step=vbus vbus=", 23));
    send("ident result");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "ok 1\r\n  vbus_v ", 15));
    TEST_ASSERT_DOUBLE_WITHIN(2.2, 220.0, strtod(lt.out + 15, NULL)); /* 1 % of the link */

    /* The probe, then the encoder scan, stopped half-way. */
    send("ident step probe");
    periods(2000);
    send("ident step encoder");
    TEST_ASSERT_EQUAL_STRING("ok ident encoder\r\n", lt.out);
    send("tel start cm_step cm_progress state every 1");
    periods(6000);
    TEST_ASSERT_EQUAL_UINT8(CM_STEP_ENCODER, fw_telemetry(&run.fw)->cm_step);
    TEST_ASSERT_TRUE(fw_telemetry(&run.fw)->cm_progress > 0u);
    TEST_ASSERT_TRUE(hal_sim_gates_on(&run.hal));
    /* The scan's field current is the frame's i_d (the regulator holds it
     * within a few per cent), the speed the rotor's over the same 16 periods
     * (the encoder's average: 1 count in 16 periods is 7.5 r/min); the
     * bring-up status is idle. Sampled over the scan's moves. */
    const double i_b = run.fw.bases.i_a, w_b = run.fw.bases.w_rad_s;
    const double p = (double)run.fw.params.pole_pairs;
    double w_max = 0.0;
    for (int k = 0; k < 40; k++) {
        periods(500 - (int)CM_SPEED_AVG);
        const double th0 = run.plant.theta_m;
        periods((int)CM_SPEED_AVG);
        /* the rotor's true mean speed over the firmware's speed window */
        const double w_true = (run.plant.theta_m - th0) / ((double)CM_SPEED_AVG / run.cfg.fs_hz);
        const fw_telemetry_t *r = fw_telemetry(&run.fw);
        const double id = ctrl_q24_to_double(r->i_d) * i_b;
        const double hold = ctrl_q24_to_double(run.fw.cm.hold_i) * i_b;
        TEST_ASSERT_DOUBLE_WITHIN(0.1 * hold, hold, id);
        const double rpm = ctrl_q24_to_double(r->omega_e) * w_b / p * 30.0 / CTRL_PI;
        TEST_ASSERT_DOUBLE_WITHIN(10.0, w_true * 30.0 / CTRL_PI, rpm);
        w_max = fmax(w_max, fabs(rpm));
        send("status");
        TEST_ASSERT_DOUBLE_WITHIN(0.01, rpm, reply_num("speed_rpm="));
    }
    TEST_ASSERT_TRUE(w_max > 30.0); /* the scan turns at 4 Hz electrical: 60 r/min */
    send("bringup status");
    TEST_ASSERT_EQUAL_STRING("ok idle step=none\r\n", lt.out);
    send("ident status");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "ok running step=encoder", 23));
    send("tel stop");
    send("stop");
    TEST_ASSERT_EQUAL_STRING("ok stopped\r\n", lt.out);
    periods(1);
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&run.fw));
    TEST_ASSERT_FALSE(hal_sim_gates_on(&run.hal));
    send("ident status");
    TEST_ASSERT_EQUAL_STRING("ok stopped step=encoder error=stopped\r\n", lt.out);
    /* resume: from the first step without a result (the encoder) */
    send("ident resume");
    TEST_ASSERT_EQUAL_STRING("ok ident resume\r\n", lt.out);
    periods(2);
    TEST_ASSERT_EQUAL_UINT8(CM_STEP_ENCODER, run.fw.cm.step);
    send("stop");
    periods(2);
}

static void test_bringup_fail_and_ini(void)
{
    link.write = link_text_capture;
    link.write_ctx = &lt;
    /* The gate test with the motor connected: fail, with the reason. */
    send("bringup gates");
    TEST_ASSERT_EQUAL_STRING("ok bringup gates\r\n", lt.out);
    periods(1000);
    send("bringup status");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "ok fail step=gates error=gates_current phase=", 45));
    send("fault");
    TEST_ASSERT_EQUAL_STRING("ok fault 11 commission\r\n", lt.out);
    TEST_ASSERT_FALSE(hal_sim_gates_on(&run.hal));
    send("bringup sense");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "err 9 fault", 11));
    send("fault clear");
    periods(2);
    /* The sense check passes on this board. */
    send("bringup sense");
    periods(1000);
    send("bringup status");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "ok pass step=sense ratio_a=", 27));
    /* Nothing identified yet: an empty fragment. */
    send("ident ini");
    TEST_ASSERT_EQUAL_STRING("ok 0\r\n", lt.out);
    send("ident apply");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "err 8", 5));
}

/* "ident apply" with a flux linkage 25 % above the configured one raises the
 * torque base by 1.25^2 (T_base = 1.5 p psi^2 / Ld, ctrl_params.h): a torque
 * reference keeps its N m in the new base, and one above the limit is
 * clamped to the new limit (the old per-unit clamp would be 1.5625 times
 * it). */
static void test_apply_rebases_the_torque_reference(void)
{
    fw_t *fw = &run.fw;
    const double lim_nm = fw->cfg.speed_out_max_nm;
    char err[256];
    for (int over = 0; over <= 1; over++) {
        if (over != 0) { /* a fresh run: the configured machine again */
            sim_run_free(&run);
            TEST_ASSERT_EQUAL_INT_MESSAGE(
                0, sim_ident_setup(&run, &spm, &spm, ctrl_find("m2ptfc"), 1.0, 1u, err, sizeof err),
                err);
        }
        const double want_nm = over != 0 ? 2.0 * lim_nm : 0.5 * lim_nm;
        fw_set_torque_ref_nm(fw, want_nm);
        const double tb0 = fw->bases.torque_nm;
        fw->cm.res.have = CM_HAVE_FLUX;
        fw->cm.res.bases = fw->bases;
        fw->cm.res.psi = ctrl_q24_from_double(1.25); /* psi_base = the configured psi_pm */
        TEST_ASSERT_EQUAL_INT(FW_OK, fw_commission_apply(fw));
        const double tb = fw->bases.torque_nm;
        TEST_ASSERT_DOUBLE_WITHIN(1e-9 * tb0, 1.5625 * tb0, tb);
        TEST_ASSERT_TRUE(fw->ml.torque_ref_lim <= fw->torque_ref_max);
        const double got_nm = ctrl_q24_to_double(fw->ml.torque_ref_lim) * tb;
        /* one Q24 step of the new base */
        const double want = over != 0 ? lim_nm : want_nm;
        TEST_ASSERT_DOUBLE_WITHIN(2.0 * tb / 16777216.0, want, got_nm);
    }
}

/* "ident apply" while an arm is pending (requested, not yet taken by the
 * interrupt) is refused by that state's name: the interrupt would gate the
 * drive at its next period on a machine half rewritten. Nothing is adopted
 * (fw_t byte for byte as before: not rewritten and restored), the gates
 * stay off until the interrupt takes the arm, and it then arms on the
 * configured machine. */
static void test_apply_refused_while_an_arm_is_pending(void)
{
    fw_t *fw = &run.fw;
    link.write = link_text_capture;
    link.write_ctx = &lt;
    fw->cm.res.have = CM_HAVE_FLUX;
    fw->cm.res.bases = fw->bases;
    fw->cm.res.psi = ctrl_q24_from_double(1.25); /* an apply would raise T_base 1.5625 x */
    const double tb0 = fw->bases.torque_nm;
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(fw));
    send("arm");
    TEST_ASSERT_EQUAL_STRING("ok armed\r\n", lt.out);
    TEST_ASSERT_TRUE(fw_gates_on_or_pending(fw));
    TEST_ASSERT_FALSE(hal_sim_gates_on(&run.hal)); /* the interrupt has not taken it */
    static fw_t before;
    memcpy(&before, fw, sizeof before);
    send("ident apply");
    TEST_ASSERT_EQUAL_STRING("err 8 state arm pending (ready)\r\n", lt.out);
    TEST_ASSERT_EQUAL_INT(FW_EBUSY, fw_commission_apply(fw));
    /* refused before anything the interrupt reads is rewritten: byte for byte */
    TEST_ASSERT_EQUAL_MEMORY(&before, fw, sizeof before);
    TEST_ASSERT_FALSE(hal_sim_gates_on(&run.hal));
    TEST_ASSERT_EQUAL_DOUBLE(tb0, fw->bases.torque_nm);
    periods(2);
    TEST_ASSERT_EQUAL_INT(FW_STATE_RUNNING, fw_state(fw));
    TEST_ASSERT_EQUAL_DOUBLE(tb0, fw->bases.torque_nm);
    send("disarm");
    periods(2);
}

/* A motor with friction and a passive load (the stress file): after a run at
 * 500 r/min and a disarm it stops within milliseconds; "status" then says
 * so, and no torque. */
static void test_status_after_stop(void)
{
    sim_run_free(&run);
    static sim_machine_t m;
    char err[256];
    TEST_ASSERT_EQUAL_INT_MESSAGE(0,
                                  sim_machine_load(PMSM_MACHINES_DIR
                                                   "/nonideal/thesis_spmsm_stress.ini",
                                                   &m, err, sizeof err),
                                  err);
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, sim_ident_setup(&run, &m, &m, ctrl_find("m2ptfc"), 1.0, 1u, err, sizeof err), err);
    fw_link_init(&link, &run.fw, NULL, NULL);
    link.write = link_text_capture;
    link.write_ctx = &lt;
    send("ref speed 500");
    send("arm");
    TEST_ASSERT_EQUAL_STRING("ok armed\r\n", lt.out);
    periods(4000);
    send("status");
    const double running = reply_num("speed_rpm=");
    TEST_ASSERT_DOUBLE_WITHIN(50.0, 500.0, running);
    TEST_ASSERT_TRUE(reply_num("torque_nm=") > 0.5); /* the friction's 0.72 N*m and more */
    send("disarm");
    periods(4000); /* 0.72 N*m of friction and load stop 1.2e-4 kg*m^2 in a few ms */
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 0.0, true_rpm());
    send("status");
    TEST_ASSERT_DOUBLE_WITHIN(2.0, 0.0, reply_num("speed_rpm="));
    TEST_ASSERT_EQUAL_DOUBLE(0.0, reply_num("torque_nm="));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_ident_commands);
    RUN_TEST(test_bringup_fail_and_ini);
    RUN_TEST(test_status_after_stop);
    RUN_TEST(test_apply_rebases_the_torque_reference);
    RUN_TEST(test_apply_refused_while_an_arm_is_pending);
    return UNITY_END();
}
