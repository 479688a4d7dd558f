#include "loop_util.h"

#include <string.h>

#include "unity.h"

const sim_machine_t *loop_spmsm(void)
{
    static sim_machine_t m;
    static int loaded;
    if (!loaded) {
        char err[256];
        if (sim_machine_load(PMSM_MACHINES_DIR "/thesis_spmsm.ini", &m, err, sizeof err) != 0) {
            TEST_FAIL_MESSAGE(err);
        }
        loaded = 1;
    }
    return &m;
}

void loop_cfg(sim_run_cfg_t *c, const char *name, double speed_rpm, double torque_nm,
              double duration_s, double win_start_s)
{
    const ctrl_desc_t *d = ctrl_find(name);
    TEST_ASSERT_NOT_NULL_MESSAGE(d, name);
    sim_run_config_default(c, loop_spmsm(), d);
    c->fs_hz = d->fs_default_hz;
    c->hal.pwm_freq_hz = c->fs_hz;
    c->speed_rpm = speed_rpm;
    c->torque_ref_nm = torque_nm;
    c->duration_s = duration_s;
    c->win_start_s = win_start_s;
    c->win_end_s = duration_s;
    c->calib_samples = 64u;
}

void loop_start(sim_run_t *r, const sim_run_cfg_t *c)
{
    char err[256];
    if (sim_run_init(r, c, err, sizeof err) != 0) {
        TEST_FAIL_MESSAGE(err);
    }
}
