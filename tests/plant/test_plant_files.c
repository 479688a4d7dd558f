/*
 * File inputs of the plant: machine INI files (shipped ones and bad input),
 * the open-loop replay engine (round trip and malformed rows), flux maps
 * (shipped synthetic map, inverse, malformed files, saturated simulation).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ini_machines.h"
#include "plant.h"
#include "sim_machine.h"
#include "sim_replay.h"
#include "unity.h"

#ifndef PLANT_MACHINES_DIR
#error "PLANT_MACHINES_DIR must point at sim_host/machines"
#endif

void setUp(void)
{
}
void tearDown(void)
{
}

/* Scratch files in the working directory (ctest runs each build's tests in
 * that build's folder, so parallel builds do not collide). */
static char g_tmp[4][256];
static int g_tmp_i;

static const char *tmp_path(const char *name)
{
    char *b = g_tmp[g_tmp_i++ & 3];
    snprintf(b, sizeof g_tmp[0], "plant_test_%s", name);
    return b;
}

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    TEST_ASSERT_NOT_NULL(f);
    fputs(text, f);
    fclose(f);
}

/* ------------------------------------------------------------- INI files */

static void test_ini_shipped_machines(void)
{
    sim_machine_t m;
    char err[256];
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, sim_machine_load(PLANT_MACHINES_DIR "/thesis_spmsm.ini", &m, err, sizeof err), err);
    TEST_ASSERT_EQUAL_STRING("thesis_spmsm", m.name);
    TEST_ASSERT_EQUAL_INT(4, m.pole_pairs);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 0.901, m.rs_ohm);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 6.552e-3, m.ld_h);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 6.552e-3, m.lq_h);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 0.09427, m.psi_pm_wb);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 220.0, m.vdc_v);
    TEST_ASSERT_DOUBLE_WITHIN(1e-18, 1.2e-4, m.inertia_kgm2);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 2.4, m.torque_rated_nm);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 20000.0, m.fs_hz);
    TEST_ASSERT_TRUE(m.current_max_a > m.current_rated_a);
    TEST_ASSERT_EQUAL_STRING("", m.fluxmap_path);

    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, sim_machine_load(PLANT_MACHINES_DIR "/thesis_ipmsm_80kw.ini", &m, err, sizeof err), err);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 0.6e-3, m.ld_h);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 1.33e-3, m.lq_h);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 0.0075, m.rs_ohm);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.1837, m.psi_ref_wb);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 540.0, m.vdc_v);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 400.0, m.current_rated_a);

    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, sim_machine_load(PLANT_MACHINES_DIR "/chapter_ipmsm.ini", &m, err, sizeof err), err);
    TEST_ASSERT_EQUAL_INT(2, m.pole_pairs);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 44.8e-3,
                              m.ld_h); /* Ld < Lq: S1 prints the two labels crossed */
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 102.7e-3, m.lq_h);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.533, m.psi_pm_wb);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 10000.0, m.fs_hz);

    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, sim_machine_load(PLANT_MACHINES_DIR "/thesis_ipmsm_80kw_sat.ini", &m, err, sizeof err),
        err);
    TEST_ASSERT_NOT_NULL(strstr(m.fluxmap_path, "ipmsm_80kw_fluxmap_synthetic.csv"));

    plant_config_t pc;
    sim_machine_to_plant(&m, &pc);
    plant_t p;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &pc));
}

static const char *k_good_ini = "[machine]\nname = t\npole_pairs = 4\nrs_ohm = 0.9\n"
                                "ld_mh = 6.5\nlq_mh = 6.5\npsi_pm_wb = 0.09\n"
                                "[rated]\ntorque_nm = 2.4\nspeed_rpm = 3000\ncurrent_a = 4.2\n"
                                "current_max_a = 10\n"
                                "[inverter]\nvdc_v = 220\nfs_hz = 20000\n"
                                "[mechanics]\ninertia_kgm2 = 1e-4\n";

/* Load text after replacing `from` by `to`; return the error message. */
static int load_variant(const char *from, const char *to, char *err, size_t errlen)
{
    char text[1024];
    const char *at = strstr(k_good_ini, from);
    TEST_ASSERT_NOT_NULL(at);
    snprintf(text, sizeof text, "%.*s%s%s", (int)(at - k_good_ini), k_good_ini, to,
             at + strlen(from));
    const char *path = tmp_path("m.ini");
    write_file(path, text);
    sim_machine_t m;
    const int rc = sim_machine_load(path, &m, err, errlen);
    remove(path);
    return rc;
}

static void expect_ini_error(const char *from, const char *to, const char *must_contain)
{
    char err[256] = "";
    TEST_ASSERT_EQUAL_INT(-1, load_variant(from, to, err, sizeof err));
    TEST_MESSAGE(err);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err, must_contain), err);
}

/* tests/plant/ini_machines.h (the machines the controller unit tests use
 * without the INI loader) transcribes the shipped INI files: every field
 * equal, up to the rounding of the mH -> H conversion (relative 1e-12). */
static void check_mirror(const char *file, const ctrl_machine_t *c)
{
    char path[512];
    char err[256];
    snprintf(path, sizeof path, "%s/%s", PLANT_MACHINES_DIR, file);
    sim_machine_t m;
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, sim_machine_load(path, &m, err, sizeof err), err);
    TEST_ASSERT_EQUAL_STRING(m.name, c->name);
    TEST_ASSERT_EQUAL_INT(m.pole_pairs, c->pole_pairs);
    const double ini[] = {m.rs_ohm,
                          m.ld_h,
                          m.lq_h,
                          m.psi_pm_wb,
                          m.vdc_v,
                          m.inertia_kgm2,
                          m.torque_rated_nm,
                          m.speed_rated_rpm,
                          m.speed_max_rpm,
                          m.current_rated_a,
                          m.current_max_a,
                          m.psi_ref_wb};
    const double mir[] = {c->rs_ohm,
                          c->ld_h,
                          c->lq_h,
                          c->psi_pm_wb,
                          c->vdc_v,
                          c->inertia_kgm2,
                          c->torque_rated_nm,
                          c->speed_rated_rpm,
                          c->speed_max_rpm,
                          c->current_rated_a,
                          c->current_max_a,
                          c->psi_ref_wb};
    for (size_t i = 0; i < sizeof ini / sizeof ini[0]; i++) {
        char msg[96];
        snprintf(msg, sizeof msg, "%s field %zu", file, i);
        TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(1e-12 * fabs(ini[i]), ini[i], mir[i], msg);
    }
}

static void test_ini_mirror_header(void)
{
    check_mirror("thesis_spmsm.ini", &ini_thesis_spmsm);
    check_mirror("thesis_ipmsm_80kw.ini", &ini_thesis_ipmsm80);
    check_mirror("chapter_ipmsm.ini", &ini_chapter_ipmsm);
    check_mirror("mj5208_drone.ini", &ini_mj5208_drone);
    check_mirror("gbm5208_gimbal.ini", &ini_gbm5208_gimbal);
    check_mirror("outrunner_24v.ini", &ini_outrunner_24v);
}

static void test_ini_bad_input(void)
{
    char err[256];
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, load_variant("name = t", "name = t", err, sizeof err), err);
    /* missing key: named with its section */
    expect_ini_error("rs_ohm = 0.9\n", "", "missing key rs_ohm in [machine]");
    /* non-numeric: key and line (line 4) */
    expect_ini_error("rs_ohm = 0.9", "rs_ohm = 0.9x", ":4: [machine] rs_ohm");
    /* negative inductance */
    expect_ini_error("ld_mh = 6.5", "ld_mh = -6.5", ":5: [machine] ld_mh = -6.5 out of range");
    /* zero inductance (open lower bound) */
    expect_ini_error("lq_mh = 6.5", "lq_mh = 0", "lq_mh = 0 out of range");
    /* non-integer pole pairs */
    expect_ini_error("pole_pairs = 4", "pole_pairs = 4.5", "pole_pairs = 4.5 is not an integer");
    /* unknown section: rejected on its header's line (16), not its first key's */
    expect_ini_error("[mechanics]", "[mechanic]", ":16: unknown section [mechanic] (known: ");
    /* an unknown section without keys (libinih calls no handler for it) */
    expect_ini_error("[inverter]", "[inverterr]\n[inverter]", ":13: unknown section [inverterr]");
    /* unknown key: rejected */
    expect_ini_error("fs_hz = 20000", "fs_khz = 20", "unknown key fs_khz in [inverter]");
    /* duplicate key */
    expect_ini_error("vdc_v = 220", "vdc_v = 220\nvdc_v = 230", "vdc_v given twice");
    /* cross-field rule */
    expect_ini_error("current_max_a = 10", "current_max_a = 4", "current_max_a must exceed");
    /* A header libinih would skip, filing the keys under no section. */
    expect_ini_error("[rated]", "[rated", ":8: malformed section header '[rated'");
    /* empty value */
    expect_ini_error("vdc_v = 220", "vdc_v =", "vdc_v = '' is not a number");
    /* missing file */
    sim_machine_t m;
    TEST_ASSERT_EQUAL_INT(-1, sim_machine_load("/nonexistent/x.ini", &m, err, sizeof err));
    TEST_ASSERT_NOT_NULL(strstr(err, "cannot open"));
    TEST_ASSERT_EQUAL_INT(-1, sim_machine_load(NULL, &m, err, sizeof err));
}

/* [mechanics]' non-ideal terms: every key read into the machine and the
 * plant's configuration; bad values named with the file, the line, the key,
 * the value and the allowed range (line 17 is the first after inertia_kgm2). */
static void test_ini_mechanics(void)
{
    char err[256];
    const char *all = "inertia_kgm2 = 1e-4\ncoulomb_nm = 0.02\nstiction_nm = 0.03\nslots = 12\n"
                      "cogging_nm = 0.01\ncogging_phase_deg = 90\n"
                      "cogging_harmonics_nm = 0.004, 0.002\ncogging_harmonics_deg = 10 -20\n"
                      "load_kind = speed\nload_profile = -3000:-0.4 0:0, 3000:0.4\n";
    char text[1400];
    const char *at = strstr(k_good_ini, "inertia_kgm2 = 1e-4\n");
    snprintf(text, sizeof text, "%.*s%s", (int)(at - k_good_ini), k_good_ini, all);
    const char *path = tmp_path("mech.ini");
    write_file(path, text);
    sim_machine_t m;
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, sim_machine_load(path, &m, err, sizeof err), err);
    remove(path);
    TEST_ASSERT_EQUAL_INT(24, sim_machine_cog_per_rev(&m)); /* lcm(12, 8) */
    TEST_ASSERT_EQUAL_INT(2, m.cog_harm_n);
    TEST_ASSERT_EQUAL_INT(SIM_LOAD_SPEED, m.load_kind);
    plant_config_t pc;
    sim_machine_to_plant(&m, &pc);
    TEST_ASSERT_EQUAL_DOUBLE(0.02, pc.coulomb_nm);
    TEST_ASSERT_EQUAL_DOUBLE(0.03, pc.stiction_nm);
    TEST_ASSERT_EQUAL_INT(24, pc.cog_per_rev);
    TEST_ASSERT_EQUAL_INT(3, pc.cog_n);
    TEST_ASSERT_EQUAL_DOUBLE(0.01, pc.cog_amp_nm[0]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 0.5 * PLANT_PI, pc.cog_phase_rad[0]);
    TEST_ASSERT_EQUAL_DOUBLE(0.002, pc.cog_amp_nm[2]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, -20.0 * PLANT_PI / 180.0, pc.cog_phase_rad[2]);
    TEST_ASSERT_EQUAL_INT(PLANT_PROFILE_SPEED, pc.load_profile.kind);
    TEST_ASSERT_EQUAL_INT(3, pc.load_profile.n);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, -100.0 * PLANT_PI, pc.load_profile.x[0]); /* r/min -> rad/s */
    pc.mech = PLANT_MECH_FREE;
    plant_t p;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &pc));

    /* defaults: stiction = coulomb; a passive and a constant load */
    const char *base = "inertia_kgm2 = 1e-4\n";
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, load_variant(base, "inertia_kgm2 = 1e-4\ncoulomb_nm = 0.02\n", err, sizeof err), err);

    expect_ini_error(base, "inertia_kgm2 = 1e-4\ncoulomb_nm = 0.02\nstiction_nm = 0.01\n",
                     ":19: [mechanics] stiction_nm = 0.01 below coulomb_nm = 0.02: allowed range "
                     "[0.02, 1e5]");
    expect_ini_error(base, "inertia_kgm2 = 1e-4\ncoulomb_nm = -1\n",
                     ":18: [mechanics] coulomb_nm = -1 out of range [0, 100000]");
    expect_ini_error(base, "inertia_kgm2 = 1e-4\ncogging_nm = 0.01\n",
                     ":18: [mechanics] cogging_nm needs slots");
    expect_ini_error(base, "inertia_kgm2 = 1e-4\nslots = 0\n",
                     ":18: [mechanics] slots = 0 out of range [1, 1000]");
    expect_ini_error(base, "inertia_kgm2 = 1e-4\nslots = 9.5\n", "slots = 9.5 is not an integer");
    expect_ini_error(
        base, "inertia_kgm2 = 1e-4\nslots = 12\ncogging_harmonics_nm = 0.1 -0.2\n",
        ":19: [mechanics] cogging_harmonics_nm value 2 = -0.2 out of range [0, 100000]");
    expect_ini_error(base, "inertia_kgm2 = 1e-4\nslots = 12\ncogging_harmonics_nm = 0.1 x\n",
                     ":19: [mechanics] cogging_harmonics_nm value 2 'x' is not a number");
    expect_ini_error(base,
                     "inertia_kgm2 = 1e-4\nslots = 12\ncogging_harmonics_nm = 1 1 1 1 1 1 1 1\n",
                     "cogging_harmonics_nm has more than 7 values");
    expect_ini_error(base,
                     "inertia_kgm2 = 1e-4\nslots = 12\ncogging_harmonics_nm = 0.1\n"
                     "cogging_harmonics_deg = 1 2\n",
                     ":20: [mechanics] cogging_harmonics_deg has 2 values, cogging_harmonics_nm 1");
    expect_ini_error(base, "inertia_kgm2 = 1e-4\nload_kind = heavy\n",
                     ":18: [mechanics] load_kind = 'heavy': expected none, constant, passive");
    expect_ini_error(
        base, "inertia_kgm2 = 1e-4\nload_kind = passive\nload_nm = -0.3\n",
        ":19: [mechanics] load_nm = -0.3 out of range [0, 1e5] for load_kind = passive");
    expect_ini_error(base, "inertia_kgm2 = 1e-4\nload_kind = passive\n",
                     ":18: [mechanics] load_kind = passive needs load_nm");
    expect_ini_error(base, "inertia_kgm2 = 1e-4\nload_nm = 0.3\n",
                     ":18: [mechanics] load_nm belongs to load_kind = constant or passive");
    expect_ini_error(base, "inertia_kgm2 = 1e-4\nload_kind = time\nload_profile = 0:0 1:1 1:2\n",
                     ":19: [mechanics] load_profile point 3: x = 1 not after the previous");
    expect_ini_error(base, "inertia_kgm2 = 1e-4\nload_kind = time\nload_profile = 0:0 1\n",
                     ":19: [mechanics] load_profile point 2 '1' is not x:T");
    expect_ini_error(base, "inertia_kgm2 = 1e-4\nload_kind = time\nload_profile = 0:0\n",
                     "load_profile needs at least 2 points");
    expect_ini_error(base, "inertia_kgm2 = 1e-4\nload_kind = time\nload_profile = -1:0 1:1\n",
                     ":19: [mechanics] load_profile point 1 at t = -1 s: allowed range [0, 1e6]");
    expect_ini_error(base, "inertia_kgm2 = 1e-4\nload_kind = speed\n",
                     ":18: [mechanics] load_kind = speed needs load_profile");
    expect_ini_error(base, "inertia_kgm2 = 1e-4\nfriction_nms = -1e-5\n",
                     ":18: [mechanics] friction_nms = -1e-05 out of range [0, 1e+06]");
    expect_ini_error(base, "inertia_kgm2 = 1e-4\nstiction = 0.1\n",
                     "unknown key stiction in [mechanics]");
}

/* The identification's stress cases (sim_host/machines/nonideal/*_stress.ini,
 * made by gen_nonideal.py): stiction 15 %, Coulomb friction 10 %, viscous
 * friction 5 % at rated speed, cogging 10 % peak (one harmonic), passive load
 * 20 % of each file's rated torque; they load and the plant takes them. */
static void test_ini_nonideal_stress(void)
{
    static const char *const files[] = {"thesis_spmsm", "mj5208_drone", "gbm5208_gimbal",
                                        "outrunner_24v"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; ++i) {
        char path[512], err[256];
        snprintf(path, sizeof path, "%s/nonideal/%s_stress.ini", PLANT_MACHINES_DIR, files[i]);
        sim_machine_t m;
        TEST_ASSERT_EQUAL_INT_MESSAGE(0, sim_machine_load(path, &m, err, sizeof err), err);
        const double t = m.torque_rated_nm, w = m.speed_rated_rpm * 2.0 * PLANT_PI / 60.0;
        TEST_MESSAGE(path);
        TEST_ASSERT_DOUBLE_WITHIN(1e-5, 0.15, m.stiction_nm / t);
        TEST_ASSERT_DOUBLE_WITHIN(1e-5, 0.10, m.coulomb_nm / t);
        TEST_ASSERT_DOUBLE_WITHIN(1e-5, 0.05, m.friction_nms * w / t);
        TEST_ASSERT_DOUBLE_WITHIN(1e-5, 0.10, m.cogging_nm / t);
        TEST_ASSERT_EQUAL_INT(0, m.cog_harm_n);
        TEST_ASSERT_TRUE(sim_machine_cog_per_rev(&m) > 0);
        TEST_ASSERT_EQUAL_INT(SIM_LOAD_PASSIVE, m.load_kind);
        TEST_ASSERT_DOUBLE_WITHIN(1e-5, 0.20, m.load_nm / t);
        plant_config_t pc;
        sim_machine_to_plant(&m, &pc);
        pc.mech = PLANT_MECH_FREE;
        plant_t p;
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &pc));
        TEST_ASSERT_TRUE(plant_stuck(&p));
    }
}

/* --------------------------------------------------------------- replay */

static plant_config_t spmsm_cfg(void)
{
    sim_machine_t m;
    char err[256];
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, sim_machine_load(PLANT_MACHINES_DIR "/thesis_spmsm.ini", &m, err, sizeof err), err);
    plant_config_t c;
    sim_machine_to_plant(&m, &c);
    return c;
}

static void test_replay_round_trip(void)
{
    const char *in = "t_start_s,duration_s,S1,S2,S3\n"
                     "0,0.000012345,1,0,0\n"
                     "0.000012345,0.000000001,1,1,0\n"
                     "# a comment\n"
                     "0.000012346,0.000037654,0,1,1\n"
                     "0.00005,0.0001,1,1,1\n";
    const char *ip = tmp_path("r_in.csv");
    write_file(ip, in);
    const char *op = tmp_path("r_out.csv");
    const plant_config_t base = spmsm_cfg();
    const sim_replay_opts_t o = {1500.0, 0.7, -0.5, 1.5};
    char err[256] = "";
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, sim_replay_files(&base, &o, ip, op, err, sizeof err), err);
    /* the same by hand */
    plant_config_t c = base;
    c.speed0_rpm = 1500.0;
    c.theta0_e_rad = 0.7;
    c.id0_a = -0.5;
    c.iq0_a = 1.5;
    plant_t p;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
    const double dur[4] = {12345e-9, 1e-9, 37654e-9, 100000e-9};
    const uint8_t sw[4][3] = {{1, 0, 0}, {1, 1, 0}, {0, 1, 1}, {1, 1, 1}};
    FILE *f = fopen(op, "r");
    TEST_ASSERT_NOT_NULL(f);
    char line[512];
    TEST_ASSERT_NOT_NULL(fgets(line, sizeof line, f));
    TEST_ASSERT_EQUAL_STRING("t,i_a,i_b,i_c,i_d,i_q,psi_alpha,psi_beta,torque\n", line);
    double t_acc = 0.0;
    for (int k = 0; k < 4; ++k) {
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance(&p, dur[k], sw[k]));
        t_acc += dur[k];
        TEST_ASSERT_NOT_NULL(fgets(line, sizeof line, f));
        double v[9];
        TEST_ASSERT_EQUAL_INT(9, sscanf(line, "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &v[0], &v[1],
                                        &v[2], &v[3], &v[4], &v[5], &v[6], &v[7], &v[8]));
        double iabc[3], id, iq, pa, pb;
        plant_i_abc(&p, iabc);
        plant_i_dq(&p, &id, &iq);
        plant_psi_ab(&p, &pa, &pb);
        const double ref[9] = {t_acc, iabc[0], iabc[1], iabc[2], id, iq, pa, pb, plant_torque(&p)};
        for (int j = 0; j < 9; ++j) {
            /* %.12g printing: 1e-11 relative */
            TEST_ASSERT_DOUBLE_WITHIN(1e-11 * (1.0 + fabs(ref[j])), ref[j], v[j]);
        }
    }
    TEST_ASSERT_NULL(fgets(line, sizeof line, f));
    fclose(f);
    remove(ip);
    remove(op);
}

static void expect_replay_error(const char *text, const char *must_contain)
{
    const plant_config_t base = spmsm_cfg();
    const sim_replay_opts_t o = {0.0, 0.0, 0.0, 0.0};
    const char *ip = tmp_path("bad.csv");
    write_file(ip, text);
    FILE *in = fopen(ip, "r");
    FILE *out = tmpfile();
    TEST_ASSERT_NOT_NULL(in);
    TEST_ASSERT_NOT_NULL(out);
    char err[256] = "";
    /* a malformed file is the input's fault (the simulator exits 2 on it) */
    TEST_ASSERT_EQUAL_INT(SIM_REPLAY_EINPUT,
                          sim_replay_run(&base, &o, in, "bad.csv", out, err, sizeof err));
    fclose(in);
    fclose(out);
    remove(ip);
    TEST_MESSAGE(err);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err, must_contain), err);
}

/* The replay header, then rows: the replay must fail with must_contain. */
static void expect_replay_rows_error(const char *rows, const char *must_contain)
{
    char buf[512];
    snprintf(buf, sizeof buf, "t_start_s,duration_s,S1,S2,S3\n%s", rows);
    expect_replay_error(buf, must_contain);
}

static void test_replay_malformed_rows(void)
{
    expect_replay_error("t,d,S1,S2,S3\n0,1e-6,1,0,0\n", "bad.csv:1: expected header");
    expect_replay_error("", "empty file");
    expect_replay_rows_error("0,1e-6,1,0,0\n1e-6,abc,1,0,0\n",
                             "bad.csv:3: expected 5 numeric fields");
    expect_replay_rows_error("0,1e-6,1,0\n", "bad.csv:2: expected 5 numeric fields");
    expect_replay_rows_error("0,1e-6,1,0,0,7\n", "bad.csv:2: expected 5 numeric fields");
    expect_replay_rows_error("0,1e-6,1,2,0\n", "bad.csv:2: S2 = 2 must be 0 or 1");
    expect_replay_rows_error("0,-1e-6,1,0,0\n", "bad.csv:2: duration_s = -1e-06 must be in");
    expect_replay_rows_error("0,1.5e-9,1,0,0\n",
                             "bad.csv:2: duration_s = 1.5e-09 is not a whole number of ns");
    expect_replay_rows_error("0,1e-6,1,0,0\n2e-6,1e-6,1,0,0\n",
                             "bad.csv:3: t_start_s = 2e-06, expected 1e-06");
    expect_replay_rows_error("0,nan,1,0,0\n", "bad.csv:2:");
}

/* ------------------------------------------------------------ flux maps */

/* The shipped synthetic flux map of the 80 kW IPMSM (gen_fluxmap_ipmsm80.py). */
static void load_fluxmap_ipmsm80(plant_fluxmap_t *m)
{
    char err[256] = "";
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        PLANT_OK,
        plant_fluxmap_load(m, PLANT_MACHINES_DIR "/ipmsm_80kw_fluxmap_synthetic.csv", err,
                           sizeof err),
        err);
}

/* The plant of the shipped saturated 80 kW IPMSM file (its linear data; the
 * caller binds the flux map). */
static void load_plant_ipmsm80_sat(plant_config_t *c)
{
    char err[256] = "";
    sim_machine_t mm;
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, sim_machine_load(PLANT_MACHINES_DIR "/thesis_ipmsm_80kw_sat.ini", &mm, err, sizeof err),
        err);
    sim_machine_to_plant(&mm, c);
}

static void test_fluxmap_shipped_and_inverse(void)
{
    plant_fluxmap_t m;
    load_fluxmap_ipmsm80(&m);
    TEST_ASSERT_EQUAL_UINT32(31u, (uint32_t)m.n_d);
    TEST_ASSERT_EQUAL_UINT32(31u, (uint32_t)m.n_q);
    /* the generating law at grid points (gen_fluxmap_ipmsm80.py) */
    for (int a = -600; a <= 600; a += 200) {
        for (int b = -600; b <= 600; b += 120) {
            double pd, pq;
            plant_fluxmap_psi(&m, a, b, &pd, &pq);
            const double ed = 0.1875 + 0.6e-3 * a / sqrt(1.0 + pow(a / 1000.0, 2));
            const double eq = 1.33e-3 * b / sqrt(1.0 + pow(b / 600.0, 2));
            TEST_ASSERT_DOUBLE_WITHIN(1e-11, ed, pd);
            TEST_ASSERT_DOUBLE_WITHIN(1e-11, eq, pq);
        }
    }
    /* inverse: psi -> i -> psi round trip, random points */
    unsigned s = 5u;
    double worst = 0.0;
    for (int k = 0; k < 500; ++k) {
        s = s * 1664525u + 1013904223u;
        const double id = ((double)(s >> 8) / 16777216.0 - 0.5) * 1100.0;
        s = s * 1664525u + 1013904223u;
        const double iq = ((double)(s >> 8) / 16777216.0 - 0.5) * 1100.0;
        double pd, pq;
        plant_fluxmap_psi(&m, id, iq, &pd, &pq);
        double rid = NAN, riq = NAN;
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_fluxmap_current(&m, pd, pq, &rid, &riq));
        worst = fmax(worst, fmax(fabs(rid - id), fabs(riq - iq)));
    }
    char msg[80];
    snprintf(msg, sizeof msg, "flux map inverse: max current error %.3g A", worst);
    TEST_MESSAGE(msg);
    /* 1e-12 Wb over a differential inductance >= 0.3 mH: < 1e-8 A */
    TEST_ASSERT_TRUE_MESSAGE(worst < 1e-8, msg);

    /* Saturated 80 kW IPMSM at 1500 r/min: the simulation runs; at small
     * current its torque matches the linear model (the map is linear at 0). */
    plant_config_t c;
    load_plant_ipmsm80_sat(&c);
    c.speed0_rpm = 1500.0;
    c.id0_a = -2.0;
    c.iq0_a = 3.0;
    plant_t lin, sat;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&lin, &c));
    c.fluxmap = &m;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&sat, &c));
    TEST_ASSERT_DOUBLE_WITHIN(1e-3 * fabs(plant_torque(&lin)), plant_torque(&lin),
                              plant_torque(&sat));
    /* drive it: synchronous-ish modulation at 10 kHz, 20 ms */
    for (int k = 0; k < 200; ++k) {
        const double th = plant_theta_e(&sat) + 2.0;
        double d[3];
        for (int x = 0; x < 3; ++x) {
            d[x] = 0.5 + 0.45 * cos(th - 2.0 * PLANT_PI / 3.0 * x);
        }
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance_period(&sat, 100e-6, d));
    }
    double id, iq;
    plant_i_dq(&sat, &id, &iq);
    TEST_ASSERT_TRUE(isfinite(id) && isfinite(iq));
    snprintf(msg, sizeof msg, "saturated IPMSM after 20 ms: id %.4g iq %.4g A, Te %.4g N m", id, iq,
             plant_torque(&sat));
    TEST_MESSAGE(msg);
    plant_fluxmap_free(&m);
}

/* Accuracy of the RK4 flux-coordinate path on the nonlinear (saturated) map:
 * Richardson estimate from the default step (0.5 us) and half of it; RK4 is
 * fourth order, so err(h) ~ 16/15 |x_h - x_{h/2}|. */
static void test_fluxmap_rk4_accuracy(void)
{
    plant_fluxmap_t m;
    load_fluxmap_ipmsm80(&m);
    plant_config_t c;
    load_plant_ipmsm80_sat(&c);
    c.fluxmap = &m;
    c.speed0_rpm = 2000.0;
    c.id0_a = -150.0;
    c.iq0_a = 250.0;
    plant_t a, b;
    c.rk4_step_s = 0.5e-6;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&a, &c));
    c.rk4_step_s = 0.25e-6;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&b, &c));
    double worst = 0.0, imax = 0.0;
    for (int k = 0; k < 100; ++k) {
        const double th = plant_theta_e(&a) + 2.0;
        double d[3];
        for (int x = 0; x < 3; ++x) {
            d[x] = 0.5 + 0.4 * cos(th - 2.0 * PLANT_PI / 3.0 * x);
        }
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance_period(&a, 50e-6, d));
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance_period(&b, 50e-6, d));
        double ia, qa, ib, qb;
        plant_i_dq(&a, &ia, &qa);
        plant_i_dq(&b, &ib, &qb);
        imax = fmax(imax, hypot(ia, qa));
        worst = fmax(worst, 16.0 / 15.0 * hypot(ia - ib, qa - qb));
    }
    char msg[128];
    snprintf(msg, sizeof msg,
             "saturated RK4 (0.5 us): estimated max error %.3g A of %.4g A (rel %.3g)", worst, imax,
             worst / imax);
    TEST_MESSAGE(msg);
    /* The bilinear map has kinks at cell edges (40 A): RK4 drops to low order
     * at the steps that cross one, so the bound is looser than the linear
     * path's 1e-9 (measured ~1e-11). */
    TEST_ASSERT_TRUE_MESSAGE(worst < 1e-8 * imax, msg);
    plant_fluxmap_free(&m);
}

static void expect_fluxmap_error(const char *text, const char *must_contain)
{
    const char *path = tmp_path("fm.csv");
    write_file(path, text);
    plant_fluxmap_t m;
    char err[256] = "";
    TEST_ASSERT_EQUAL_INT(PLANT_EINVAL, plant_fluxmap_load(&m, path, err, sizeof err));
    remove(path);
    TEST_MESSAGE(err);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err, must_contain), err);
    TEST_ASSERT_NULL(m.psi_d);
}

static void test_fluxmap_malformed(void)
{
    const char *h = "id_a,iq_a,psi_d_wb,psi_q_wb\n";
    char buf[512];
    expect_fluxmap_error("id,iq,pd,pq\n0,0,0,0\n", ":1: expected header");
    /* the header exactly (sim_csv.h): a fifth column is not silently ignored */
    expect_fluxmap_error("# map\nid_a,iq_a,psi_d_wb,psi_q_wb,extra\n0,0,0.1,0\n",
                         ":2: expected header");
    snprintf(buf, sizeof buf, "%s0,0,0.1,0\n0,1,0.1,x\n", h);
    expect_fluxmap_error(buf, ":3: expected 4 numbers");
    snprintf(buf, sizeof buf, "%s0,0,0.1,0\n0,1,0.1,0.1\n1,0,0.2,0\n", h);
    expect_fluxmap_error(buf, "need at least a 2x2 grid");
    snprintf(buf, sizeof buf, "%s0,0,0.1,0\n0,1,0.1,0.1\n1,0,0.2,0\n1,1,0.2,0.1\n2,0,0.3,0\n", h);
    expect_fluxmap_error(buf, "full grid");
    snprintf(buf, sizeof buf, "%s0,0,0.1,0\n0,1,0.1,0.1\n1,0,0.2,0\n1,0,0.2,0\n", h);
    expect_fluxmap_error(buf, "duplicate grid point");
    snprintf(buf, sizeof buf,
             "%s0,0,0.1,0\n0,1,0.1,0.1\n0,3,0.1,0.3\n1,0,0.2,0\n1,1,0.2,0.1\n1,3,0.2,0.3\n", h);
    expect_fluxmap_error(buf, "not evenly spaced");
    plant_fluxmap_t m;
    char err[128];
    TEST_ASSERT_EQUAL_INT(PLANT_EINVAL,
                          plant_fluxmap_load(&m, "/nonexistent.csv", err, sizeof err));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_ini_shipped_machines);
    RUN_TEST(test_ini_mirror_header);
    RUN_TEST(test_ini_bad_input);
    RUN_TEST(test_ini_mechanics);
    RUN_TEST(test_ini_nonideal_stress);
    RUN_TEST(test_replay_round_trip);
    RUN_TEST(test_replay_malformed_rows);
    RUN_TEST(test_fluxmap_shipped_and_inverse);
    RUN_TEST(test_fluxmap_rk4_accuracy);
    RUN_TEST(test_fluxmap_malformed);
    return UNITY_END();
}
