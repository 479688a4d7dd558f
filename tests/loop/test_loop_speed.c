/*
 * Speed loop sized from the machine (firmware/isr/speed_loop.h) and the
 * overspeed protection (protect.h), closed loop on the host.
 *
 *  - The sizing's own frequency response: at the returned crossover the open
 *    loop Kp (1 + wz/s) e^{-s Td} / (J s) has |L| = 1 and the requested phase
 *    margin, computed here from the gains; the gains scale with J.
 *  - Thesis 80 kW IPMSM (J = 0.165 kg m^2), m2ptfc, free mechanics, no load,
 *    speed step 0 -> 1000 r/min: overshoot <= 10 % and within 2 % from 2 s on
 *    (the SPMSM's fixed gains gave 1900 r/min and a 0.95 s limit
 *    cycle on this machine).
 *  - Thesis SPMSM declared for at most 3000 r/min, in torque mode, free and
 *    unloaded, 1.8 N*m: the rotor accelerates until the back-EMF meets the DC
 *    link (~3250 r/min); the overspeed protection (1.05 x the maximum speed)
 *    trips before that.
 */
#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "loop_util.h"
#include "speed_loop.h"
#include "unity.h"

#define PI_D 3.14159265358979323846

static sim_run_t run;

void setUp(void)
{
}

void tearDown(void)
{
    sim_run_free(&run);
}

static void test_design_meets_its_crossover_and_margin(void)
{
    ctrl_machine_t m;
    sim_ctrl_machine_from(loop_spmsm(), &m);
    const double pms[] = {45.0, 60.0, 70.0};
    for (size_t k = 0; k < 3; k++) {
        fw_speed_design_t d = {0.0, pms[k], 0, 0, 0, 0};
        TEST_ASSERT_EQUAL_INT(CTRL_OK, fw_speed_loop_design(&d, &m, 1000.0, 500.0, NULL, 0u));
        const double wc = 2.0 * PI_D * d.bandwidth_hz;
        const double complex s = I * wc;
        const double complex l =
            (d.kp_nm_s_rad + d.ki_nm_rad / s) * cexp(-s * d.dead_time_s) / (m.inertia_kgm2 * s);
        const double pm = 180.0 + carg(l) * 180.0 / PI_D;
        printf("  PM %.0f deg: crossover %.2f Hz, zero %.2f Hz, Td %.3f ms, Kp %.4g, Ki %.4g; "
               "|L(wc)| = %.6f, phase margin %.3f deg\n",
               pms[k], d.bandwidth_hz, d.zero_hz, d.dead_time_s * 1e3, d.kp_nm_s_rad, d.ki_nm_rad,
               cabs(l), pm);
        TEST_ASSERT_DOUBLE_WITHIN(1e-9, 1.0, cabs(l));
        TEST_ASSERT_DOUBLE_WITHIN(1e-6, pms[k], pm);
        /* Gains proportional to the inertia, bandwidth independent of it. */
        ctrl_machine_t m10 = m;
        m10.inertia_kgm2 *= 10.0;
        fw_speed_design_t d10 = {0.0, pms[k], 0, 0, 0, 0};
        TEST_ASSERT_EQUAL_INT(CTRL_OK, fw_speed_loop_design(&d10, &m10, 1000.0, 500.0, NULL, 0u));
        TEST_ASSERT_DOUBLE_WITHIN(1e-12, d.bandwidth_hz, d10.bandwidth_hz);
        TEST_ASSERT_DOUBLE_WITHIN(1e-9 * d10.kp_nm_s_rad, 10.0 * d.kp_nm_s_rad, d10.kp_nm_s_rad);
    }
    /* A bandwidth the dead time cannot carry: refused, with the allowed range. */
    char why[200] = "";
    fw_speed_design_t bad = {200.0, 60.0, 0, 0, 0, 0};
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, fw_speed_loop_design(&bad, &m, 1000.0, 500.0, why, 200));
    TEST_MESSAGE(why);
    TEST_ASSERT_NOT_NULL(strstr(why, "bandwidth 200 Hz is out of range (0, "));
}

static void test_ipmsm80_speed_step(void)
{
    const ctrl_desc_t *d = ctrl_find("m2ptfc");
    sim_run_cfg_t c;
    sim_run_config_default(&c, loop_ipmsm80(), d);
    c.fs_hz = d->fs_default_hz;
    c.free_mech = true;
    c.speed_mode = true;
    c.speed_ref_rpm = 1000.0;
    c.duration_s = 3.0;
    c.win_start_s = 2.999; /* the Ts/10 observer only at the very end */
    c.win_end_s = 3.0;
    c.calib_samples = 32u;
    loop_start(&run, &c);
    double max_rpm = -1e9;
    double lo_after = 1e9;
    double hi_after = -1e9;
    while (sim_run_time(&run) < c.duration_s) {
        TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run));
        const double rpm = sim_run_speed_rpm(&run);
        max_rpm = fmax(max_rpm, rpm);
        if (sim_run_time(&run) >= 2.0) {
            lo_after = fmin(lo_after, rpm);
            hi_after = fmax(hi_after, rpm);
        }
    }
    const fw_speed_info_t *si = &run.fw.speed_info;
    printf("  80 kW, m2ptfc, 0 -> 1000 r/min: Kp %.4g N*m s/rad, Ki %.4g N*m/rad (bandwidth %.1f "
           "Hz, PM %.0f deg), torque limit %.1f N*m; max %.1f r/min (overshoot %.2f %%), "
           "from 2 s on [%.1f, %.1f] r/min\n",
           si->kp_nm_s_rad, si->ki_nm_rad, si->bandwidth_hz, si->phase_margin_deg,
           run.torque_limit_nm, max_rpm, (max_rpm / 1000.0 - 1.0) * 100.0, lo_after, hi_after);
    TEST_ASSERT_EQUAL_INT(FW_STATE_RUNNING, fw_state(&run.fw));
    TEST_ASSERT_TRUE_MESSAGE(max_rpm >= 1000.0, "never reached the reference");
    TEST_ASSERT_TRUE_MESSAGE(max_rpm <= 1100.0, "overshoot above 10 %");
    TEST_ASSERT_TRUE_MESSAGE(lo_after >= 980.0 && hi_after <= 1020.0, "not within 2 % after 2 s");
}

static void test_spmsm_runaway_trips_overspeed(void)
{
    sim_run_cfg_t c;
    loop_cfg(&c, "bst", 0.0, 1.8, 0.1, 0.09);
    c.free_mech = true;
    c.ctrl_machine.speed_max_rpm = 3000.0; /* the file declares 3750 r/min */
    loop_start(&run, &c);
    double max_rpm = 0.0;
    while (sim_run_time(&run) < c.duration_s && fw_state(&run.fw) != FW_STATE_FAULT) {
        TEST_ASSERT_EQUAL_INT(0, sim_run_period(&run));
        max_rpm = fmax(max_rpm, sim_run_speed_rpm(&run));
    }
    const double level = run.fw.speed_info.overspeed_rpm;
    printf("  SPMSM, bst, 1.8 N*m unloaded: fault %s at t = %.4f s, %.1f r/min (level %.0f)\n",
           fw_fault_name(fw_fault(&run.fw)), run.fault_time_s, max_rpm, level);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 1.05 * 3000.0, level);
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_OVERSPEED, fw_fault(&run.fw));
    TEST_ASSERT_EQUAL_UINT8(0u, fw_telemetry(&run.fw)->gates);
    /* Tripped on the way up: above the level, below the back-EMF limit. */
    TEST_ASSERT_TRUE(max_rpm > level && max_rpm < 3250.0);
}

/* The maximum speed behind the overspeed level: declared, or where the
 * magnets' line-to-line back-EMF meets the DC link (sqrt(3) w_e psi_pm = Vdc),
 * at least the rated speed; a declared value below the rated speed is refused. */
static void test_speed_max_default(void)
{
    ctrl_machine_t m;
    sim_ctrl_machine_from(loop_spmsm(), &m);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 3750.0, fw_speed_max_rpm(&m)); /* the file's */
    m.speed_max_rpm = 0.0;
    const double n_emf = 220.0 / (sqrt(3.0) * 0.09427) / 4.0 * 60.0 / (2.0 * PI_D);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, n_emf, fw_speed_max_rpm(&m));
    TEST_ASSERT_TRUE(n_emf > 3000.0 && n_emf < 3250.0); /* 3217 r/min */
    m.vdc_v = 100.0; /* a link below the rated back-EMF: the rated speed */
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 3000.0, fw_speed_max_rpm(&m));
    m.speed_max_rpm = 2000.0; /* below the rated speed */
    TEST_ASSERT_EQUAL_DOUBLE(0.0, fw_speed_max_rpm(&m));
    sim_run_cfg_t c;
    loop_cfg(&c, "bst", 0.0, 0.0, 0.01, 0.0);
    c.ctrl_machine.speed_max_rpm = 2000.0;
    char err[256];
    TEST_ASSERT_NOT_EQUAL(0, sim_run_init(&run, &c, err, sizeof err));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_design_meets_its_crossover_and_margin);
    RUN_TEST(test_ipmsm80_speed_step);
    RUN_TEST(test_spmsm_runaway_trips_overspeed);
    RUN_TEST(test_speed_max_default);
    return UNITY_END();
}
