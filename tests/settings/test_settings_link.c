/*
 * The "config" commands on the host closed loop (fw_link.c, fw_settings.c)
 * with the RAM model of the G4 flash: the drive identifies a motor it was
 * configured for wrongly, "config save" keeps the identified machine, and the
 * next boot (a new run from the same wrong compiled-in data, the same flash)
 * applies it bit for bit: machine, encoder offset and direction, controller
 * and tunables. Saving with the gates on is refused; "config show" lists the
 * stored record; "config default" and "config erase" do what they say.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cmd.h"
#include "fw_link.h"
#include "link_text.h"
#include "settings_flash_model.h"
#include "sim_ident.h"
#include "unity.h"

static sim_machine_t spm, plant, conf;
static sim_run_t run;
static fw_link_t link;
static fw_settings_t st;
static sfm_t flash;
static link_text_t lt;
static ctrl_machine_t conf_machine;

static void send(const char *line)
{
    link_text_send(&lt, &link, line);
}

static void periods(int n)
{
    link_text_periods(&run, &link, n);
}

/* The application's side on the simulator: fw_init with the record's data. */
static int app_apply(void *ctx, const settings_t *s, char *why, size_t cap)
{
    (void)ctx;
    ctrl_machine_t m;
    fw_config_t c;
    if (fw_settings_config(s, &m, &c, run.ctrl_cfg_buf, why, cap) != FW_OK) {
        return CMD_E_FAILED;
    }
    if (fw_init(&run.fw, &run.hal, &c) != FW_OK) {
        (void)fw_explain(&run.fw, why, cap);
        return CMD_E_FAILED;
    }
    return CMD_OK;
}

static int app_default(void *ctx)
{
    (void)ctx;
    fw_config_t c;
    fw_config_default(&c, &conf_machine, ctrl_find("m2ptfc"));
    c.enc_cpr = run.fw.cfg.enc_cpr;
    return fw_init(&run.fw, &run.hal, &c) == FW_OK ? CMD_OK : CMD_E_FAILED;
}

/* A boot: the run from the wrong compiled-in data, the flash as it is. */
static void boot(void)
{
    char err[256];
    sim_run_free(&run);
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, sim_ident_setup(&run, &plant, &conf, ctrl_find("m2ptfc"), 2.0, 1u, err, sizeof err),
        err);
    conf_machine = run.fw.machine_own;
    memset(&st, 0, sizeof st);
    sfm_flash(&flash, &st.flash);
    st.apply = app_apply;
    st.apply_default = app_default;
    (void)fw_settings_boot(&st);
    fw_link_init(&link, &run.fw, link_text_capture, &lt);
    fw_link_set_settings(&link, &st);
    periods(300); /* calibration after the re-initialisation */
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&run.fw));
}

void setUp(void)
{
    char err[256];
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, sim_machine_load(PMSM_MACHINES_DIR "/thesis_spmsm.ini", &spm, err, sizeof err), err);
    sim_ident_case(&spm, &plant, &conf);
    sfm_init(&flash, 1u);
}

void tearDown(void)
{
    sim_run_free(&run);
}

static bool same_double(double a, double b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

static void test_ident_save_boot(void)
{
    boot();
    TEST_ASSERT_NOT_NULL(strstr(st.msg, "no record in flash, compiled-in defaults"));
    send("config show");
    TEST_ASSERT_EQUAL_STRING("err 8 state settings: no record in flash, compiled-in defaults\r\n",
                             lt.out);

    /* identify: the drive adopts the results (fw_commission_poll) */
    sim_ident_t id;
    char err[256];
    TEST_ASSERT_EQUAL_INT_MESSAGE(0,
                                  sim_ident_run(&run, sim_ident_plan, sim_ident_plan_n, 10.0,
                                                SIM_BAD_NONE, &id, err, sizeof err),
                                  err);
    TEST_ASSERT_TRUE(id.applied);
    const ctrl_machine_t ident = run.fw.machine_own;
    const fx_angle_t enc_off = run.fw.enc_offset;
    const uint32_t enc_neg = run.fw.enc_neg;
    TEST_ASSERT_TRUE(fabs(ident.rs_ohm - spm.rs_ohm) <= 0.03 * spm.rs_ohm);
    TEST_ASSERT_TRUE(fabs(ident.rs_ohm - conf.rs_ohm) > 0.2 * spm.rs_ohm);
    TEST_ASSERT_EQUAL_HEX32(0xFFFFFFFFu, enc_neg); /* backwards, as the plant's encoder */

    /* a controller and a tunable of the user's */
    send("ctrl select fst");
    TEST_ASSERT_EQUAL_STRING("ok ctrl fst\r\n", lt.out);
    const char *tun = run.fw.ctrl->tunables[0].name;
    double lo = run.fw.ctrl->tunables[0].min, hi = run.fw.ctrl->tunables[0].max;
    double want = lo + 0.37 * (hi - lo);
    char line[96];
    (void)snprintf(line, sizeof line, "param set %s %.17g", tun, want);
    send(line);
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "ok", 2));
    double tv = 0.0;
    TEST_ASSERT_EQUAL_INT(FW_OK, fw_tunable_get(&run.fw, tun, &tv));

    /* saving with the gates on, or with an arm the interrupt has not taken
     * yet (the erase would run with the gates on): refused, nothing written */
    send("ref torque 0.1");
    send("arm");
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&run.fw));
    const uint32_t ops = flash.ops;
    send("config save");
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, strncmp("err 8 state arm pending (ready): disarm first", lt.out, 45), lt.out);
    TEST_ASSERT_EQUAL_UINT32(ops, flash.ops);
    periods(3);
    TEST_ASSERT_EQUAL_INT(FW_STATE_RUNNING, fw_state(&run.fw));
    send("config save");
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, strncmp("err 8 state gates on (running): disarm first", lt.out, 44), lt.out);
    TEST_ASSERT_EQUAL_UINT32(ops, flash.ops);
    /* a read too: an ECC error in it would turn the gates off (the NMI) */
    send("config show");
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, strncmp("err 8 state gates on (running)", lt.out, 30), lt.out);
    TEST_ASSERT_EQUAL_UINT32(ops, flash.ops);
    send("disarm");
    periods(3);

    send("config save");
    TEST_ASSERT_EQUAL_STRING("ok saved record 1\r\n", lt.out);
    send("config show");
    TEST_ASSERT_EQUAL_INT(0, strncmp(lt.out, "ok ", 3));
    TEST_ASSERT_NOT_NULL(strstr(lt.out, "  record=1\r\n"));
    TEST_ASSERT_NOT_NULL(strstr(lt.out, "  ctrl=fst\r\n"));
    TEST_ASSERT_NOT_NULL(strstr(lt.out, "  enc.dir=-1\r\n"));
    TEST_ASSERT_NOT_NULL(strstr(lt.out, "  m.rs_ohm="));

    /* power cycle: the identified motor, the controller and its tunable */
    boot();
    TEST_ASSERT_NOT_NULL(strstr(st.msg, "settings: record 1 (page 0) applied"));
    const ctrl_machine_t *m = &run.fw.machine_own;
    TEST_ASSERT_TRUE(same_double(ident.rs_ohm, m->rs_ohm));
    TEST_ASSERT_TRUE(same_double(ident.ld_h, m->ld_h));
    TEST_ASSERT_TRUE(same_double(ident.lq_h, m->lq_h));
    TEST_ASSERT_TRUE(same_double(ident.psi_pm_wb, m->psi_pm_wb));
    TEST_ASSERT_TRUE(same_double(ident.inertia_kgm2, m->inertia_kgm2));
    TEST_ASSERT_EQUAL_HEX32(enc_off, run.fw.enc_offset);
    TEST_ASSERT_EQUAL_HEX32(enc_neg, run.fw.enc_neg);
    TEST_ASSERT_EQUAL_STRING("fst", run.fw.ctrl->name);
    double got = 0.0;
    TEST_ASSERT_EQUAL_INT(FW_OK, fw_tunable_get(&run.fw, tun, &got));
    TEST_ASSERT_TRUE(same_double(tv, got));

    /* config default: the compiled-in data now, the flash unchanged */
    send("config default");
    TEST_ASSERT_EQUAL_STRING("ok compiled-in defaults applied (flash unchanged)\r\n", lt.out);
    TEST_ASSERT_TRUE(same_double(conf_machine.rs_ohm, run.fw.machine_own.rs_ohm));
    send("config show");
    TEST_ASSERT_NOT_NULL(strstr(lt.out, "  record=1\r\n"));

    /* config erase: nothing left; the next boot says so */
    send("config erase");
    TEST_ASSERT_EQUAL_STRING("ok erased: compiled-in defaults from the next start\r\n", lt.out);
    boot();
    TEST_ASSERT_NOT_NULL(strstr(st.msg, "no record in flash, compiled-in defaults"));
    TEST_ASSERT_TRUE(same_double(conf_machine.rs_ohm, run.fw.machine_own.rs_ohm));
}

static void test_refused_record_keeps_defaults(void)
{
    boot();
    /* a record whose controller this build does not have */
    settings_t s;
    fw_settings_capture(&run.fw, &s);
    strcpy(s.ctrl, "nosuch");
    TEST_ASSERT_EQUAL_INT(0, settings_store_save(&st.flash, st.buf, sizeof st.buf, &s, NULL));
    boot();
    TEST_ASSERT_NOT_NULL(
        strstr(st.msg, "record 1 refused: controller nosuch is not in this image; compiled-in"));
    TEST_ASSERT_EQUAL_STRING("m2ptfc", run.fw.ctrl->name);
    /* a record the core refuses (Ld below the core's range) */
    fw_settings_capture(&run.fw, &s);
    s.ld_h = 1e-12;
    TEST_ASSERT_EQUAL_INT(0, settings_store_save(&st.flash, st.buf, sizeof st.buf, &s, NULL));
    boot();
    TEST_ASSERT_NOT_NULL(strstr(st.msg, "record 2 refused: "));
    TEST_ASSERT_TRUE(same_double(conf_machine.ld_h, run.fw.machine_own.ld_h));
    /* no settings store attached: the commands say so */
    fw_link_set_settings(&link, NULL);
    send("config save");
    TEST_ASSERT_EQUAL_STRING("err 12 unsupported\r\n", lt.out);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_ident_save_boot);
    RUN_TEST(test_refused_record_keeps_defaults);
    return UNITY_END();
}
