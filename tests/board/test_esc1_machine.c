/*
 * The B-G431B-ESC1 image's default motor (esc1_default_machine, generated from
 * the machine file PMSM_ESC1_MACHINE_INI by tools/board/machine_c.py; this
 * test compiles the same generated file on the host):
 *  - it equals what the simulator reads from that file, field by field
 *    (sim_machine_load, the fields sim_ctrl_machine_from copies): one home
 *    for the data;
 *  - it is inside the board's ratings (board_esc1.c: vbus_max_v 25.2 V,
 *    current_peak_a 40 A) and the link's m.vdc_v range (>= 8 V);
 *  - the core takes it at the image's PWM frequency (ESC1_FS_HZ) and every
 *    registered controller accepts its default configuration for it (the
 *    board selects any of them with "ctrl select").
 */
#include <string.h>

#include "board_esc1.h"
#include "controller.h"
#include "ctrl_params.h"
#include "esc1_app.h"
#include "sim_machine.h"
#include "unity.h"

void setUp(void)
{
}
void tearDown(void)
{
}

static void test_default_machine_is_the_file(void)
{
    sim_machine_t sm;
    char err[256];
    if (sim_machine_load(PMSM_ESC1_MACHINE_INI, &sm, err, sizeof err) != 0) {
        TEST_FAIL_MESSAGE(err);
    }
    const sim_machine_t *m = &sm;
    const ctrl_machine_t *e = &esc1_default_machine;
    TEST_ASSERT_EQUAL_STRING(m->name, e->name);
    TEST_ASSERT_EQUAL_INT(m->pole_pairs, e->pole_pairs);
    /* bit for bit: the generator converts as sim_machine_load does */
    const double a[] = {m->rs_ohm,
                        m->ld_h,
                        m->lq_h,
                        m->psi_pm_wb,
                        m->vdc_v,
                        m->inertia_kgm2,
                        m->torque_rated_nm,
                        m->speed_rated_rpm,
                        m->current_rated_a,
                        m->current_max_a,
                        m->psi_ref_wb};
    const double b[] = {e->rs_ohm,
                        e->ld_h,
                        e->lq_h,
                        e->psi_pm_wb,
                        e->vdc_v,
                        e->inertia_kgm2,
                        e->torque_rated_nm,
                        e->speed_rated_rpm,
                        e->current_rated_a,
                        e->current_max_a,
                        e->psi_ref_wb};
    for (size_t k = 0; k < sizeof a / sizeof a[0]; k++) {
        TEST_ASSERT_EQUAL_MEMORY(&a[k], &b[k], sizeof a[k]);
    }
}

static void test_default_machine_within_the_board(void)
{
    const ctrl_machine_t *e = &esc1_default_machine;
    const g4_board_t *b = &g4_board_esc1;
    TEST_ASSERT_TRUE_MESSAGE(e->vdc_v >= 8.0 && e->vdc_v <= b->vbus_max_v,
                             "DC link outside the board's [8, 25.2] V");
    TEST_ASSERT_TRUE_MESSAGE(e->current_max_a <= b->current_peak_a,
                             "trip current above the board's 40 A peak");
    TEST_ASSERT_TRUE(e->current_rated_a < e->current_max_a);
    /* the hardware trip the image derives from it stays within the board */
    TEST_ASSERT_TRUE(esc1_hw_trip_a(b, e) <= b->current_peak_a);
}

static void test_core_and_every_controller_take_it(void)
{
    ctrl_params_t p;
    ctrl_bases_t bases;
    ctrl_diag_t why;
    char msg[200];
    const int rc = ctrl_params_init_diag(&p, &bases, &esc1_default_machine, ESC1_FS_HZ, &why);
    (void)ctrl_diag_format(&why, msg, sizeof msg);
    TEST_ASSERT_EQUAL_INT_MESSAGE(CTRL_OK, rc, msg);
    const ctrl_setup_t su = {&esc1_default_machine, &bases, &p};
    for (size_t k = 0; k < ctrl_count(); k++) {
        const ctrl_desc_t *d = ctrl_at(k);
        _Alignas(16) unsigned char cfg[CTRL_CFG_MAX];
        _Alignas(16) unsigned char st[CTRL_STATE_MAX];
        d->cfg_default(cfg, &esc1_default_machine);
        TEST_ASSERT_EQUAL_INT_MESSAGE(CTRL_OK, ctrl_init(d, st, cfg, &su), d->name);
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_default_machine_is_the_file);
    RUN_TEST(test_default_machine_within_the_board);
    RUN_TEST(test_core_and_every_controller_take_it);
    return UNITY_END();
}
