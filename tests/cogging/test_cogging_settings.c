/*
 * The anti-cogging table and the friction kept with the settings
 * (firmware/link/fw_settings.c, firmware/settings/settings_table.h), on the
 * host closed loop with the RAM model of the F405's 16 KiB settings sectors:
 *   - "config save" with a table and the feed-forward on, a modelled power
 *     cycle (a new run from the compiled-in data, the same flash): the table
 *     bit for bit, the friction, and the feed-forward in the torque
 *     reference of the running drive;
 *   - a save cut by a power loss in the middle of the table's record: the
 *     next boot has the previous record and its table, whole;
 *   - a table measured on another machine or encoder setting (counts,
 *     direction, offset, pole pairs, rated torque, entries): refused, the
 *     reason named, no feed-forward;
 *   - the G4's 2 KiB page: the record saved, the table not, and said so.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cmd.h"
#include "cog_util.h"
#include "fw_link.h"
#include "link_text.h"
#include "loop_util.h"
#include "settings_flash_model.h"
#include "settings_table.h"
#include "sim_ident.h"
#include "unity.h"

static sim_machine_t mach;
static sim_run_t run;
static fw_link_t link;
static fw_settings_t st;
static sfm_t flash;
static link_text_t lt;
static ctrl_machine_t conf_machine;
static int16_t truth[CTRL_COG_N], other[CTRL_COG_N];

#define REPLY(text) TEST_ASSERT_EQUAL_STRING(text "\r\n", lt.out)

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
    fw_config_default(&c, &conf_machine, ctrl_find("foc"));
    c.enc_cpr = run.fw.cfg.enc_cpr;
    return fw_init(&run.fw, &run.hal, &c) == FW_OK ? CMD_OK : CMD_E_FAILED;
}

/* A boot: the run from the compiled-in data, the flash as it is. */
static void boot(void)
{
    char err[256];
    sim_run_free(&run);
    sfm_power_on(&flash);
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, sim_ident_setup(&run, &mach, &mach, ctrl_find("foc"), 0.3, 1u, err, sizeof err), err);
    conf_machine = run.fw.machine_own;
    memset(&st, 0, sizeof st);
    sfm_flash(&flash, &st.flash);
    st.apply = app_apply;
    st.apply_default = app_default;
    st.fw = &run.fw;
    (void)fw_settings_boot(&st);
    fw_link_init(&link, &run.fw, link_text_capture, &lt);
    fw_link_set_settings(&link, &st);
    link_text_periods(&run, &link, 300); /* calibration after the re-initialisation */
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&run.fw));
}

void setUp(void)
{
    mach = loop_machine_file("nonideal/thesis_spmsm_stress.ini");
    cog_table_truth(&mach, truth);
    for (uint32_t i = 0; i < CTRL_COG_N; i++) {
        other[i] = (int16_t)(truth[i] / 2 + 1);
    }
    sfm_init_size(&flash, 1u, SFM_PAGE_MAX);
}

void tearDown(void)
{
    sim_run_free(&run);
}

static bool same_double(double a, double b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

/* A table and friction as "ident cogging" and "ident apply" leave them. */
static void calibrated(const int16_t *table, bool on, double coulomb, double viscous)
{
    TEST_ASSERT_EQUAL_INT(FW_OK, fw_cogging_load(&run.fw, table, CTRL_COG_N));
    TEST_ASSERT_EQUAL_INT(FW_OK, fw_cogging_enable(&run.fw, on));
    run.fw.cfg.coulomb_nm = coulomb;
    run.fw.cfg.viscous_nms = viscous;
}

static void test_save_power_cycle_restores(void)
{
    boot();
    TEST_ASSERT_EQUAL_STRING("", st.tab_msg);
    TEST_ASSERT_NULL(fw_cogging_table(&run.fw, NULL));
    const double coulomb = 0.0123456789, viscous = 2.5e-5;
    calibrated(truth, true, coulomb, viscous);
    link_text_send(&lt, &link, "config save");
    REPLY("ok saved record 1 with the cogging table");
    link_text_send(&lt, &link, "config show");
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(lt.out, "  m.coulomb_nm=0.01234568\r\n"), lt.out);

    /* power cycle */
    boot();
    TEST_ASSERT_NOT_NULL(strstr(st.msg, "settings: record 1 (page 0) applied"));
    TEST_ASSERT_EQUAL_STRING("cogging table (2048 entries) applied, feed-forward on", st.tab_msg);
    uint32_t n = 0;
    const int16_t *t = fw_cogging_table(&run.fw, &n);
    TEST_ASSERT_NOT_NULL(t);
    TEST_ASSERT_EQUAL_UINT32(CTRL_COG_N, n);
    TEST_ASSERT_EQUAL_MEMORY(truth, t, sizeof truth);
    TEST_ASSERT_EQUAL_UINT8(1u, run.fw.cog_on);
    TEST_ASSERT_TRUE(same_double(coulomb, run.fw.cfg.coulomb_nm));
    TEST_ASSERT_TRUE(same_double(viscous, run.fw.cfg.viscous_nms));
    link_text_send(&lt, &link, "cogging status");
    REPLY("ok cogging on");

    /* the feed-forward in the running drive's torque reference: the torque
     * reference less the requested torque is the table at the rotor's
     * position (no field weakening at rest: no trim) */
    link_text_send(&lt, &link, "ref torque 0.05");
    link_text_send(&lt, &link, "arm");
    link_text_periods(&run, &link, 3);
    TEST_ASSERT_EQUAL_INT(FW_STATE_RUNNING, fw_state(&run.fw));
    int32_t ff_max = 0;
    for (int k = 0; k < 2000; k++) {
        link_text_periods(&run, &link, 1);
        const q24_t ff = ctrl_cogging_ff(&run.fw.cog.map, run.fw.enc_pos);
        TEST_ASSERT_EQUAL_INT32(0, run.fw.trim);
        TEST_ASSERT_EQUAL_INT32(fx_add(run.fw.torque_ref_now, ff), run.fw.refs.torque);
        ff_max = abs(ff) > ff_max ? abs(ff) : ff_max;
    }
    /* a table of a 10 %-of-rated cogging: entries of that size act */
    TEST_ASSERT_TRUE(ff_max > run.fw.cog.map.torque_rated / 50);
    link_text_send(&lt, &link, "disarm");
    link_text_periods(&run, &link, 3);

    /* the feed-forward off when saved: off after the power cycle, table kept */
    TEST_ASSERT_EQUAL_INT(FW_OK, fw_cogging_enable(&run.fw, false));
    link_text_send(&lt, &link, "config save");
    REPLY("ok saved record 2 with the cogging table");
    boot();
    TEST_ASSERT_EQUAL_STRING("cogging table (2048 entries) applied, feed-forward off", st.tab_msg);
    TEST_ASSERT_EQUAL_UINT8(0u, run.fw.cog_on);
    TEST_ASSERT_NOT_NULL(fw_cogging_table(&run.fw, NULL));
}

static void test_cut_save_keeps_previous_table(void)
{
    boot();
    calibrated(truth, true, 0.01, 0.0);
    link_text_send(&lt, &link, "config save");
    REPLY("ok saved record 1 with the cogging table");
    /* a new table, the power lost in the middle of its record */
    calibrated(other, false, 0.02, 0.0);
    sfm_cut(&flash, 1u + 260u, SFM_CUT_TORN); /* the erase, then half of ~520 double words */
    link_text_send(&lt, &link, "config save");
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, strncmp(lt.out, "err 10 failed flash: power off", 30), lt.out);
    boot();
    TEST_ASSERT_NOT_NULL(strstr(st.msg, "settings: record 1 (page 0) applied"));
    TEST_ASSERT_EQUAL_STRING("cogging table (2048 entries) applied, feed-forward on", st.tab_msg);
    TEST_ASSERT_EQUAL_MEMORY(truth, fw_cogging_table(&run.fw, NULL), sizeof truth);
    TEST_ASSERT_TRUE(run.fw.cfg.coulomb_nm == 0.01);
}

/* The record as saved with a table whose header edit() changes. */
static void save_foreign(void (*edit)(settings_tab_hdr_t *h), const char *want)
{
    boot();
    settings_t s;
    fw_settings_capture(&run.fw, &s);
    settings_tab_t t;
    memset(&t, 0, sizeof t);
    t.hdr.enc_cpr = run.fw.enc_cpr;
    t.hdr.enc_offset = run.fw.enc_offset;
    t.hdr.enc_dir = run.fw.enc_neg != 0u ? -1 : 1;
    t.hdr.n_log2 = (uint8_t)CTRL_COG_N_LOG2;
    t.hdr.ff_on = 1u;
    t.hdr.pole_pairs = run.fw.machine_own.pole_pairs;
    t.hdr.torque_rated_nm = run.fw.machine_own.torque_rated_nm;
    t.entries = truth;
    edit(&t.hdr);
    TEST_ASSERT_EQUAL_INT(0, settings_store_save_with(&st.flash, st.buf, sizeof st.buf, &s,
                                                      settings_tab_program, &t, NULL));
    boot();
    printf("%s\n", st.tab_msg);
    TEST_ASSERT_EQUAL_STRING_MESSAGE(want, st.tab_msg, st.msg);
    const bool refused = strstr(want, "refused") != NULL;
    TEST_ASSERT_EQUAL_INT(refused, fw_cogging_table(&run.fw, NULL) == NULL);
    TEST_ASSERT_EQUAL_UINT8(refused ? 0u : 1u, run.fw.cog_on);
}

static void edit_none(settings_tab_hdr_t *h)
{
    (void)h;
}
static void edit_cpr(settings_tab_hdr_t *h)
{
    h->enc_cpr /= 2u;
}
static void edit_dir(settings_tab_hdr_t *h)
{
    h->enc_dir = (int8_t)-h->enc_dir;
}
static void edit_pp(settings_tab_hdr_t *h)
{
    h->pole_pairs += 3;
}
static void edit_torque(settings_tab_hdr_t *h)
{
    h->torque_rated_nm *= 1.25;
}
static void edit_offset(settings_tab_hdr_t *h)
{
    h->enc_offset += 35791394u; /* 3 degrees electrical */
}
static void edit_offset_ok(settings_tab_hdr_t *h)
{
    h->enc_offset -= 11930465u; /* 1 degree: the identification's scatter */
}
static void edit_entries(settings_tab_hdr_t *h)
{
    h->n_log2 = (uint8_t)(CTRL_COG_N_LOG2 - 1u);
}

static void test_foreign_table_refused(void)
{
    save_foreign(edit_none, "cogging table (2048 entries) applied, feed-forward on");
    save_foreign(edit_offset_ok, "cogging table (2048 entries) applied, feed-forward on");
    char want[112];
    (void)snprintf(want, sizeof want,
                   "cogging table refused: encoder %lu counts per revolution, the table's %lu; "
                   "feed-forward off",
                   (unsigned long)run.fw.enc_cpr, (unsigned long)(run.fw.enc_cpr / 2u));
    save_foreign(edit_cpr, want);
    const int dir = run.fw.enc_neg != 0u ? -1 : 1;
    (void)snprintf(want, sizeof want,
                   "cogging table refused: encoder direction %d, the table's %d; feed-forward off",
                   dir, -dir);
    save_foreign(edit_dir, want);
    const int pp = run.fw.machine_own.pole_pairs;
    (void)snprintf(want, sizeof want,
                   "cogging table refused: pole pairs %d, the table's %d; feed-forward off", pp,
                   pp + 3);
    save_foreign(edit_pp, want);
    const double tr = run.fw.machine_own.torque_rated_nm;
    (void)snprintf(want, sizeof want,
                   "cogging table refused: rated torque %.6g N*m, the table's %.6g; "
                   "feed-forward off",
                   tr, 1.25 * tr);
    save_foreign(edit_torque, want);
    save_foreign(edit_offset, "cogging table refused: encoder offset 3 deg electrical from the "
                              "table's (> 2); feed-forward off");
    save_foreign(edit_entries, "cogging table refused: 1024 entries, this image's table 2048; "
                               "feed-forward off");
}

static void test_g4_page_keeps_record_not_table(void)
{
    sfm_init(&flash, 2u); /* 2 KiB pages */
    boot();
    calibrated(truth, true, 0.01, 0.0);
    link_text_send(&lt, &link, "config save");
    REPLY("ok saved record 1; the cogging table not kept: the flash page is too small");
    boot();
    TEST_ASSERT_NOT_NULL(strstr(st.msg, "settings: record 1 (page 0) applied"));
    TEST_ASSERT_EQUAL_STRING("", st.tab_msg);
    TEST_ASSERT_NULL(fw_cogging_table(&run.fw, NULL));
    TEST_ASSERT_TRUE(run.fw.cfg.coulomb_nm == 0.01);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_save_power_cycle_restores);
    RUN_TEST(test_cut_save_keeps_previous_table);
    RUN_TEST(test_foreign_table_refused);
    RUN_TEST(test_g4_page_keeps_record_not_table);
    return UNITY_END();
}
