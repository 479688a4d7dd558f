/*
 * The machine files' [sensors] section (sim_host/sim_machine.h): defaults
 * (today's aligned 2500-line encoder), values read, bad values refused with
 * the key named; and the plant's encoder model following it (hal/sim): the
 * encoder reads 0 where the d axis is at encoder_offset_deg and counts the
 * other way with encoder_direction = -1.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "ctrl_units.h"
#include "hal_sim.h"
#include "sim_machine.h"
#include "unity.h"

static char path[256];

void setUp(void)
{
    (void)snprintf(path, sizeof path, "ident_sensors_%d.ini", 1);
}

void tearDown(void)
{
    (void)remove(path);
}

/* The shipped SPMSM with `extra` appended. */
static int load_with(const char *extra, sim_machine_t *m, char *err, size_t len)
{
    char src[512];
    (void)snprintf(src, sizeof src, "%s/thesis_spmsm.ini", PMSM_MACHINES_DIR);
    FILE *in = fopen(src, "r");
    FILE *out = fopen(path, "w");
    TEST_ASSERT_NOT_NULL(in);
    TEST_ASSERT_NOT_NULL(out);
    int ch;
    while ((ch = fgetc(in)) != EOF) {
        fputc(ch, out);
    }
    fputs(extra, out);
    fclose(in);
    fclose(out);
    return sim_machine_load(path, m, err, len);
}

static void test_defaults(void)
{
    sim_machine_t m;
    char err[256];
    TEST_ASSERT_EQUAL_INT(0, load_with("", &m, err, sizeof err));
    TEST_ASSERT_EQUAL_INT(2500, m.encoder_lines);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, m.encoder_offset_deg);
    TEST_ASSERT_EQUAL_INT(1, m.encoder_direction);
}

static void test_values_and_refusals(void)
{
    sim_machine_t m;
    char err[256];
    TEST_ASSERT_EQUAL_INT(0, load_with("\n[sensors]\nencoder_lines = 1024\nencoder_offset_deg = "
                                       "-37.5\nencoder_direction = -1\n",
                                       &m, err, sizeof err));
    TEST_ASSERT_EQUAL_INT(1024, m.encoder_lines);
    TEST_ASSERT_EQUAL_DOUBLE(-37.5, m.encoder_offset_deg);
    TEST_ASSERT_EQUAL_INT(-1, m.encoder_direction);
    TEST_ASSERT_EQUAL_INT(-1,
                          load_with("\n[sensors]\nencoder_direction = 0\n", &m, err, sizeof err));
    TEST_ASSERT_NOT_NULL(strstr(err, "encoder_direction"));
    TEST_ASSERT_EQUAL_INT(-1,
                          load_with("\n[sensors]\nencoder_direction = 2\n", &m, err, sizeof err));
    TEST_ASSERT_NOT_NULL(strstr(err, "encoder_direction"));
    TEST_ASSERT_EQUAL_INT(
        -1, load_with("\n[sensors]\nencoder_offset_deg = 400\n", &m, err, sizeof err));
    TEST_ASSERT_NOT_NULL(strstr(err, "encoder_offset_deg"));
    TEST_ASSERT_EQUAL_INT(-1, load_with("\n[sensors]\nencoder_gain = 1\n", &m, err, sizeof err));
    TEST_ASSERT_NOT_NULL(strstr(err, "encoder_gain"));
}

/* hal/sim's encoder: count 0 where theta_e = offset; direction -1 counts down. */
static void test_plant_encoder(void)
{
    static plant_t plant;
    static hal_t hal;
    plant_config_t pc;
    memset(&pc, 0, sizeof pc);
    pc.pole_pairs = 4;
    pc.rs_ohm = 1.0;
    pc.ld_h = pc.lq_h = 0.01;
    pc.psi_pm_wb = 0.1;
    pc.vdc_v = 100.0;
    pc.mech = PLANT_MECH_IMPOSED;
    const double off_e = 100.0 * CTRL_PI / 180.0;
    for (int dir = -1; dir <= 1; dir += 2) {
        /* Rotor d axis 0.5 mechanical degrees past the encoder's zero. */
        pc.theta0_e_rad = off_e + 4.0 * 0.5 * CTRL_PI / 180.0;
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&plant, &pc));
        hal_sim_config_t hc;
        hal_sim_config_default(&hc, 10000u, 10.0, 100.0);
        hc.adc_noise_counts = 0.0;
        hc.enc_zero_rad = off_e / 4.0;
        hc.enc_dir = (int8_t)dir;
        TEST_ASSERT_EQUAL_INT(HAL_SIM_OK, hal_sim_init(&hal, &hc, &plant));
        hal_sim_period_begin(&hal);
        hal_encoder_raw_t e;
        hal_encoder_read(&hal, &e);
        /* 0.5 deg of 10000 counts/rev = 13.9 counts: 13 forwards, -14 backwards */
        TEST_ASSERT_EQUAL_INT32(dir > 0 ? 13 : -14, (int32_t)e.count);
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_defaults);
    RUN_TEST(test_values_and_refusals);
    RUN_TEST(test_plant_encoder);
    return UNITY_END();
}
