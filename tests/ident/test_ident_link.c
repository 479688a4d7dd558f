/*
 * Commissioning through the serial link (PROTOCOL.md "Commissioning"): the
 * command lines reach the firmware's steps on the host closed loop, refusals
 * say why, progress shows in "ident status" and in the telemetry signals
 * cm_step / cm_progress, "stop" ends a step with the gates off, a failed
 * bring-up check answers "fail" with its reason, and the results read back
 * as values and as a machine-file fragment.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_ident_commands);
    RUN_TEST(test_bringup_fail_and_ini);
    return UNITY_END();
}
