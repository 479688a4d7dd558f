/*
 * Anti-cogging (docs/anticogging.md): the feed-forward's interpolation
 * against a double reference; the calibration (step "cogging") against the
 * plant's cogging on a shipped machine file and on one it has not seen; the
 * ripple the measured table removes.
 *
 * Ripple: speed mode at 30 r/min on the free rotor (the speed's amplitude at
 * the cogging harmonics of the mechanical angle, and its sd), and torque mode
 * at 5 % of the rated torque on the dynamometer at 30 r/min (sd of the shaft
 * torque Te + T_cog sampled once a period, and its amplitude at the cogging
 * harmonics). The target: each reduced by at least 80 % by the table.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cog_util.h"
#include "link_text.h"
#include "loop_util.h"
#include "sim_ident.h"
#include "unity.h"

void setUp(void)
{
}
void tearDown(void)
{
}

static int16_t truth[CTRL_COG_N];

/* Feed-forward: linear interpolation of the table at pos / cpr of a turn,
 * within the rounding of its formats (below 2 LSB of Q24 for the product,
 * plus the angle's error: under 1/2^17 of a count times the steepest slope). */
static void test_ff_interpolation(void)
{
    static const uint32_t cprs[] = {16384u, 10000u, 4096u, 1000003u};
    static int16_t t[CTRL_COG_N];
    uint32_t seed = 12345u;
    for (uint32_t i = 0; i < CTRL_COG_N; i++) {
        seed = seed * 1664525u + 1013904223u;
        t[i] = (int16_t)(int32_t)((seed >> 16) - 32768u);
    }
    t[0] = INT16_MIN + 1; /* the extremes */
    t[1] = INT16_MAX;
    const q24_t tr = 22369621; /* 1.333 pu */
    for (size_t c = 0; c < sizeof cprs / sizeof cprs[0]; c++) {
        ctrl_cogging_t cg;
        TEST_ASSERT_EQUAL_INT(0, ctrl_cogging_init(&cg, t, CTRL_COG_N_LOG2, cprs[c], tr));
        double worst = 0.0;
        for (uint32_t k = 0; k < 20000u; k++) {
            seed = seed * 1664525u + 1013904223u;
            const uint32_t pos = k < 3u ? (k == 2u ? cprs[c] - 1u : k) : seed % cprs[c];
            const double x = (double)pos / (double)cprs[c] * CTRL_COG_N;
            const uint32_t i = (uint32_t)floor(x);
            const double f = x - (double)i;
            const double a = t[i], b = t[(i + 1u) % CTRL_COG_N];
            const double ref = (a + (b - a) * f) / 32768.0 * tr; /* Q24 */
            const double err = fabs((double)ctrl_cogging_ff(&cg, pos) - ref);
            worst = fmax(worst, err);
        }
        /* 15-bit weight, truncated: below |b - a| 2^-15 entries (|b - a| <= 65535),
         * an entry is tr / 2^15; the product's rounding and the angle: 2 LSB */
        const double bound = 65535.0 / 32768.0 * tr / 32768.0 + 2.0;
        printf("cpr %u: worst %.2f LSB (bound %.2f)\n", (unsigned)cprs[c], worst, bound);
        TEST_ASSERT_TRUE(worst <= bound);
    }
    ctrl_cogging_t cg;
    TEST_ASSERT_EQUAL_INT(-1, ctrl_cogging_init(&cg, t, CTRL_COG_N_LOG2_MAX + 1u, 16384u, tr));
    TEST_ASSERT_EQUAL_INT(-1, ctrl_cogging_init(&cg, t, CTRL_COG_N_LOG2, 1u, tr));
    TEST_ASSERT_EQUAL_INT(-1, ctrl_cogging_init(&cg, t, CTRL_COG_N_LOG2, 16384u, 0));
    TEST_ASSERT_EQUAL_INT(-1, ctrl_cogging_init(&cg, NULL, CTRL_COG_N_LOG2, 16384u, tr));
}

static void test_shipped_thesis_stress(void)
{
    const sim_machine_t m = loop_machine_file("nonideal/thesis_spmsm_stress.ini");
    cog_case("thesis_spmsm_stress", &m, 40.0, 80.0);
}

/* A machine the code has not seen: 3 pole pairs, 9 slots (18 cogging periods
 * per revolution), cogging 8 % of rated with a 2nd and 3rd harmonic at their
 * own phases, stiction 12 %, Coulomb 7 %, a passive load of 10 %. */
static void test_unseen(void)
{
    sim_machine_t m = loop_machine_file("nonideal/thesis_spmsm_stress.ini");
    const double tr = m.torque_rated_nm;
    m.pole_pairs = 3;
    m.psi_pm_wb *= 4.0 / 3.0; /* the same torque per ampere */
    m.slots = 9;
    m.cogging_nm = 0.08 * tr;
    m.cogging_phase_deg = 25.0;
    m.cog_harm_n = m.cog_harm_deg_n = 2;
    m.cog_harm_nm[0] = 0.03 * tr;
    m.cog_harm_deg[0] = 70.0;
    m.cog_harm_nm[1] = 0.012 * tr;
    m.cog_harm_deg[1] = -40.0;
    m.stiction_nm = 0.12 * tr;
    m.coulomb_nm = 0.07 * tr;
    m.load_nm = 0.10 * tr;
    cog_case("unseen p3 9 slots", &m, 50.0, 80.0);
}

/* The reply line (the link ends it with CR LF). */
#define COG_REPLY(text) TEST_ASSERT_EQUAL_STRING(text "\r\n", out.out)

/* The link: "cogging status | on | off", "ident cogging", refusals named. */
static void test_link(void)
{
    static sim_run_t r;
    static fw_link_t link;
    static link_text_t out;
    char err[256];
    const sim_machine_t m = loop_machine_file("nonideal/thesis_spmsm_stress.ini");
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, sim_ident_setup(&r, &m, &m, ctrl_find("foc"), 0.3, 1u, err, sizeof err), err);
    fw_link_init(&link, &r.fw, link_text_capture, &out);
    link_text_send(&out, &link, "cogging status");
    COG_REPLY("ok cogging none");
    link_text_send(&out, &link, "cogging on");
    COG_REPLY("err 8 state no table for this encoder: ident cogging");
    link_text_send(&out, &link, "cogging maybe");
    COG_REPLY("err 2 args cogging on|off|status");
    cog_table_truth(&m, truth);
    TEST_ASSERT_EQUAL_INT(FW_OK, fw_cogging_load(&r.fw, truth, CTRL_COG_N));
    TEST_ASSERT_EQUAL_INT(FW_ERANGE, fw_cogging_load(&r.fw, truth, CTRL_COG_N / 2u));
    link_text_send(&out, &link, "cogging status");
    COG_REPLY("ok cogging off");
    link_text_send(&out, &link, "cogging on");
    COG_REPLY("ok cogging on");
    link_text_send(&out, &link, "cogging off");
    COG_REPLY("ok cogging off");
    /* the calibration starts (state commission), stop ends it */
    link_text_send(&out, &link, "ident cogging");
    printf("ident cogging: %s", out.out);
    COG_REPLY("ok ident cogging");
    link_text_periods(&r, &link, 200);
    TEST_ASSERT_EQUAL_INT(FW_STATE_COMMISSION, fw_state(&r.fw));
    TEST_ASSERT_EQUAL_UINT8(CM_STEP_COGGING, fw_telemetry(&r.fw)->cm_step);
    link_text_send(&out, &link, "stop");
    link_text_periods(&r, &link, 2);
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&r.fw));
    sim_run_free(&r);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_ff_interpolation);
    RUN_TEST(test_link);
    RUN_TEST(test_shipped_thesis_stress);
    RUN_TEST(test_unseen);
    return UNITY_END();
}
