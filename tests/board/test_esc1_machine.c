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
 *    board selects any of them with "ctrl select");
 *  - over the serial link (the image's application: board HAL on the register
 *    model of g4_model.c, fw_init, fw_link, the m.* parameters of
 *    esc1_params.c), machine data the core cannot represent are refused with
 *    the quantity, its value and its range, and the previous data stay.
 */
#include <stdio.h>
#include <string.h>

#include "board_esc1.h"
#include "controller.h"
#include "ctrl_params.h"
#include "esc1_app.h"
#include "esc1_report.h"
#include "fw_stack.h"
#include "g4_clock.h"
#include "g4_core.h"
#include "g4_flash.h"
#include "g4_model.h"
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
                        m->psi_ref_wb,
                        m->speed_max_rpm};
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
                        e->psi_ref_wb,
                        e->speed_max_rpm};
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

/* ---- the link on the board's code path ---- */

static esc1_t esc;
#define MAX_REPLY 96u
static char reply[MAX_REPLY][160];
static size_t n_reply;

static void capture(void *ctx, const uint8_t *bytes, size_t len)
{
    (void)ctx;
    static char line[160];
    static size_t n;
    for (size_t k = 0; k < len; k++) {
        if (bytes[k] == '\n') {
            line[n > 0 && line[n - 1] == '\r' ? n - 1 : n] = '\0';
            if (n_reply < MAX_REPLY) {
                memcpy(reply[n_reply++], line, sizeof line);
            }
            n = 0;
        } else if (n + 1u < sizeof line) {
            line[n++] = (char)bytes[k];
        }
    }
}

/* Every reply line of a command (the first: "ok ..." or "err ..."). */
static size_t command_lines(const char *text)
{
    n_reply = 0;
    for (const char *c = text; *c != '\0'; c++) {
        fw_link_rx(&esc.link, (uint8_t)*c);
    }
    fw_link_rx(&esc.link, '\r');
    fw_link_poll(&esc.link);
    return n_reply;
}

static const char *command(const char *text)
{
    TEST_ASSERT_EQUAL_UINT_MESSAGE(1u, command_lines(text), text);
    return reply[0];
}

/* The fault path of g4_startup.c (g4_flash.c's NMI takes it for anything but
 * a settings read's ECC error): counted. */
static unsigned fault_paths;
void g4_fault_handler(void);
void g4_fault_handler(void)
{
    fault_paths++;
}

/* As esc1_main.c: board HAL, fw_init with the compiled-in motor, the link and
 * its application parameters, the throttle, the settings record in flash
 * applied (on the register model, no interrupts). g4_model_reset is a power
 * cycle: the flash's settings pages keep their content. */
static void esc1_start(void)
{
    g4_model_reset();
    g4_cycle_counter_init();
    memset(&esc, 0, sizeof esc);
    const g4_board_t *b = &g4_board_esc1;
    esc.machine = esc1_default_machine;
    esc.encoder_cpr = ESC1_ENCODER_CPR;
    esc.hc.fs_hz = ESC1_FS_HZ;
    esc.hc.encoder_cpr = esc.encoder_cpr;
    esc.hc.trip_current_a = esc1_hw_trip_a(b, &esc.machine);
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_clock_init(b->hse_hz, b->sysclk_hz));
    TEST_ASSERT_EQUAL_INT(G4_OK, g4_hal_init(&esc.hal, b, &esc.hc));
    esc1_config_default(&esc.fc, b, &esc.machine, ctrl_find(ESC1_CTRL));
    TEST_ASSERT_EQUAL_INT(FW_OK, fw_init(&esc.fw, &esc.hal, &esc.fc));
    fw_link_init(&esc.link, &esc.fw, capture, NULL);
    esc1_params_attach(&esc);
    esc1_throttle_init(&esc, b->sysclk_hz);
    esc1_settings_start(&esc);
}

/* The firmware knows the dead time TIM1 inserts: TIMx_BDTR.DTG as the HAL
 * wrote it into the register model, in t_DTS = 1/SYSCLK (CKD = 0). The
 * board's 500 ns at 170 MHz is 85 t_DTS exactly (RM0440, BDTR.DTG range
 * 0xx), so 500 ns within rounding. The same after the machine is
 * configured anew (the m.* parameters, `config default`). */
static void test_config_carries_the_board_dead_time(void)
{
    esc1_start();
    const uint32_t dtg = g4_rd(G4_TIM1 + G4_TIM_BDTR) & G4_TIM_BDTR_DTG_MASK;
    const double dt_s = (double)g4_dtg_ticks((uint8_t)dtg) / (double)g4_board_esc1.sysclk_hz;
    TEST_ASSERT_EQUAL_UINT32(85u, dtg);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, dt_s, esc.fc.dead_time_s);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 500e-9, esc.fc.dead_time_s);
    TEST_ASSERT_EQUAL_INT(CMD_OK, esc1_reconfigure(&esc, &esc1_default_machine, ESC1_ENCODER_CPR));
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, dt_s, esc.fc.dead_time_s);
}

/* A reconfiguration's time with the interrupt held (fw_init, the watchdog
 * not refreshed) is kept for the start-up report, the longest one: the
 * model's cycle counter moves 16 per read, so a hold measured spans at
 * least one step, and a shorter one does not lower the figure. */
static void test_reconfiguration_time_is_kept(void)
{
    esc1_start();
    esc.init_cycles = 0u;
    TEST_ASSERT_EQUAL_INT(CMD_OK, esc1_reconfigure(&esc, &esc1_default_machine, ESC1_ENCODER_CPR));
    TEST_ASSERT_TRUE(esc.init_cycles >= 16u);
    esc.init_cycles = 0xFFFFFFF0u;
    TEST_ASSERT_EQUAL_INT(CMD_OK, esc1_reconfigure(&esc, &esc1_default_machine, ESC1_ENCODER_CPR));
    TEST_ASSERT_EQUAL_UINT32(0xFFFFFFF0u, esc.init_cycles);
}

static void expect_prefix(const char *want, const char *got)
{
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, strncmp(want, got, strlen(want)), got);
}

/* Neighbours of the compiled-in gimbal motor the core cannot represent at
 * 20 kHz (docs/fixed-point.md, "The range the core takes"): each answer names
 * the quantity, its value and the range; the motor's data stay. */
static void test_link_refusal_names_quantity_value_range(void)
{
    esc1_start();
    char want[160];
    /* What is in force before the refusals and must stay after them: a
     * controller tunable and a drive setting changed over the link (a
     * refusal used to put back the defaults: wc 0, psi_adapt 1). */
    TEST_ASSERT_EQUAL_STRING("ok wc 3000", command("param set wc 3000"));
    expect_prefix("ok est.psi_adapt 0", command("param set est.psi_adapt 0"));
    TEST_ASSERT_EQUAL_STRING("ok wc 3000 rad/s", command("param get wc"));
    const char *name = esc.machine.name; /* a setting's apply names the record's */
    /* 15 r/min (inside the link's [10, 100000]): 11 x 15 x 2 pi / 60 x 50 us =
     * 8.64e-4 rad per period < 0.001 */
    TEST_ASSERT_EQUAL_STRING("err 10 failed rated electrical speed x Ts = 0.0008639 rad per period "
                             "outside [0.001, 1]",
                             command("param set m.n_rated_rpm 15"));
    /* 0.3 mH: Ts Rs / Ld = 50 us x 7.545 / 0.3 mH = 1.258 > 1 */
    TEST_ASSERT_EQUAL_STRING(
        "err 10 failed Ts Rs / Ld = 1.258 outside [0, 1] (rs_ohm, ld_h, fs_hz)",
        command("param set m.ld_h 0.0003"));
    /* the previous data are in force */
    snprintf(want, sizeof want, "ok m.n_rated_rpm %g r/min", esc1_default_machine.speed_rated_rpm);
    TEST_ASSERT_EQUAL_STRING(want, command("param get m.n_rated_rpm"));
    TEST_ASSERT_EQUAL_STRING(name, esc.machine.name);
    /* and the firmware runs with them and its controller (the restore used to
     * lose the controller: fw_init had cleared fw_t before it was read) */
    TEST_ASSERT_TRUE(esc.fw.ctrl != NULL);
    TEST_ASSERT_EQUAL_STRING(ESC1_CTRL, esc.fw.ctrl->name);
    TEST_ASSERT_EQUAL_INT(FW_STATE_BOOT, fw_state(&esc.fw));
    /* with its tunables and the drive's settings as they were */
    TEST_ASSERT_EQUAL_STRING("ok wc 3000 rad/s", command("param get wc"));
    expect_prefix("ok est.psi_adapt 0", command("param get est.psi_adapt"));
    /* a value the core takes is taken, and a refusal after it has no stale reason */
    TEST_ASSERT_EQUAL_STRING("ok m.n_rated_rpm 150", command("param set m.n_rated_rpm 150"));
    TEST_ASSERT_EQUAL_STRING("err 4 range [10, 100000]", command("param set m.n_rated_rpm 1"));
}

/* The offset calibration on the board's code path: with the phase-current
 * ADCs at 2553 (2.06 V, the bias network's zero-current level) the firmware
 * calibrates and becomes ready; at 2048 (1.65 V, mid-scale) the offsets are
 * 505 counts off the board's expected code: fault adc_calibration, with the
 * measured offsets kept for the report (fw_link_offsets_text). */
/* One control period as on the board: the ADC interrupt, then PendSV (lower
 * priority, tail-chained) with the medium-rate task when the interrupt pended
 * it (the first period after the arm is completed there). */
static void control_period(void)
{
    esc1_control_isr(&esc);
    if ((g4_model_get(G4_SCB + G4_SCB_ICSR) & G4_SCB_ICSR_PENDSVSET) != 0u) {
        g4_model_put(G4_SCB + G4_SCB_ICSR, 0u);
        fw_medium(&esc.fw);
    }
}

static void calibrate_at(uint32_t code)
{
    esc1_start();
    g4_model_put(G4_ADC1 + G4_ADC_JDR1, code);
    g4_model_put(G4_ADC2 + G4_ADC_JDR1, code);
    g4_model_put(G4_ADC1 + G4_ADC_JDR2, code);
    g4_model_put(G4_ADC2 + G4_ADC_JDR2, 1433u); /* 12 V */
    for (uint32_t k = 0; k < 2u * esc.fc.calib_samples && fw_state(&esc.fw) != FW_STATE_READY &&
                         fw_state(&esc.fw) != FW_STATE_FAULT;
         k++) {
        esc1_control_isr(&esc);
    }
}

/* Phase W's offset is range-checked as U's and V's are (the board has all
 * three; the commissioning steps use W's current): W at mid-scale, 505
 * counts off the board's zero, faults the calibration. */
static void test_calibration_checks_phase_w(void)
{
    esc1_start();
    g4_model_put(G4_ADC1 + G4_ADC_JDR1, 2553u);
    g4_model_put(G4_ADC2 + G4_ADC_JDR1, 2553u);
    g4_model_put(G4_ADC1 + G4_ADC_JDR2, 2048u); /* W */
    g4_model_put(G4_ADC2 + G4_ADC_JDR2, 1433u);
    for (uint32_t k = 0; k < 2u * esc.fc.calib_samples && fw_state(&esc.fw) != FW_STATE_READY &&
                         fw_state(&esc.fw) != FW_STATE_FAULT;
         k++) {
        esc1_control_isr(&esc);
    }
    TEST_ASSERT_EQUAL_INT(FW_STATE_FAULT, fw_state(&esc.fw));
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_CALIB, esc.fw.sm.fault_code);
}

static void test_calibration_takes_the_board_zero(void)
{
    calibrate_at(2553u);
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&esc.fw));
    TEST_ASSERT_EQUAL_INT32(1542 * 256, esc.fw.off_q8[0]);

    calibrate_at(2048u);
    TEST_ASSERT_EQUAL_INT(FW_STATE_FAULT, fw_state(&esc.fw));
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_CALIB, esc.fw.sm.fault_code);
    char line[96];
    TEST_ASSERT_TRUE(fw_link_offsets_text(&esc.fw, line, sizeof line) > 0);
    char want[96];
    snprintf(want, sizeof want, "current offsets 2047 2047 2047 counts, expected 1542 +- %u",
             (unsigned)esc.hal.info.adc_current_zero_tol);
    TEST_ASSERT_EQUAL_STRING(want, line);
    /* Q8 counts rounded to counts */
    esc.fw.off_q8[0] = 1542 * 256 + 127;
    esc.fw.off_q8[1] = 1542 * 256 + 128;
    esc.fw.off_q8[2] = 0;
    TEST_ASSERT_TRUE(fw_link_offsets_text(&esc.fw, line, sizeof line) > 0);
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, strncmp("current offsets 1542 1543 0 counts", line, 34), line);
}

/* Machine data, the controller, its tunables that are not live (FOC's mtpa;
 * its current-loop gains are) and the throttle settings change only with the
 * gates off: while an identification or bring-up step runs (state
 * commission), while running, and while an arm waits for the next period,
 * each is refused naming the state and the parameter, and nothing changes. */
static void expect_config_refused(const char *state, const char *want_select)
{
    const char *names[] = {"m.rs_ohm 5", "mtpa 0", "throttle.low_us 1000", "enc.cpr 2048"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        char line[48];
        char want[120];
        (void)snprintf(line, sizeof line, "param set %s", names[i]);
        (void)snprintf(want, sizeof want, "err 8 state %s: %.*s changes with the gates off only",
                       state, (int)(strchr(names[i], ' ') - names[i]), names[i]);
        TEST_ASSERT_EQUAL_STRING(want, command(line));
    }
    TEST_ASSERT_EQUAL_STRING(want_select, command("ctrl select " ESC1_CTRL));
}

static void test_link_reconfig_refused_while_gates_on(void)
{
    calibrate_at(2553u);
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&esc.fw));
    const double rs = esc.machine.rs_ohm;
    expect_prefix("ok bringup vbus", command("bringup vbus"));
    esc1_control_isr(&esc);
    TEST_ASSERT_EQUAL_INT(FW_STATE_COMMISSION, fw_state(&esc.fw));
    expect_config_refused("in commission", "err 8 state in commission");
    TEST_ASSERT_EQUAL_INT(FW_STATE_COMMISSION, fw_state(&esc.fw));
    TEST_ASSERT_TRUE(esc.machine.rs_ohm == rs);
    expect_prefix("ok", command("stop"));
    esc1_control_isr(&esc);
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&esc.fw));

    expect_prefix("ok", command("arm"));
    expect_config_refused("arm pending (ready)", "err 8 state arm pending (ready)");
    control_period();
    TEST_ASSERT_EQUAL_INT(FW_STATE_RUNNING, fw_state(&esc.fw));
    /* armed: the command layer refuses "ctrl select" itself (PROTOCOL.md) */
    expect_config_refused("in running", "err 8 state disarm first");
    TEST_ASSERT_TRUE(esc.machine.rs_ohm == rs);
    expect_prefix("ok", command("disarm"));
    control_period();
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&esc.fw));
    TEST_ASSERT_EQUAL_STRING("ok m.rs_ohm 5", command("param set m.rs_ohm 5"));
}

/* "bringup sense" says the offsets its currents are measured from when it
 * starts, before it judges anything. */
static void test_bringup_sense_says_the_offsets(void)
{
    calibrate_at(2553u);
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&esc.fw));
    char want[160];
    snprintf(want, sizeof want,
             "ok bringup sense current offsets 1542 1542 1542 counts, expected 1542 +- %u",
             (unsigned)esc.hal.info.adc_current_zero_tol);
    TEST_ASSERT_EQUAL_STRING(want, command("bringup sense"));
}

/* The throttle on the board's code path: TIM2 captures (register model) to
 * the decoder, its decisions to the drive. 50 Hz pulses at the low end for
 * 1 s arm the calibrated drive (state running); with the pulses gone the
 * drive is disarmed (ready, gates off) 100 ms + 100 ms of ramp later, and
 * the loss is counted for the main loop's message. */
static void pulse_at(uint32_t ms, uint32_t width_us)
{
    esc.now_ms = ms;
    if (width_us != 0u && ms % 20u == 0u) {
        g4_model_put(G4_TIM2 + G4_TIM_CCR2, width_us);
        g4_model_put(G4_TIM2 + G4_TIM_CCR1, 20000u);
        g4_model_put(G4_TIM2 + G4_TIM_SR, G4_TIM_SR_CC1IF);
    }
    esc1_throttle_poll(&esc);
    fw_watchdog_kick(&esc.fw);           /* the main loop's service */
    for (unsigned k = 0; k < 20u; k++) { /* 1 ms of control periods at 20 kHz */
        control_period();
    }
}

static void test_throttle_arms_and_disarms_the_drive(void)
{
    calibrate_at(2553u);
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&esc.fw));
    TEST_ASSERT_EQUAL_STRING("ok throttle.mode 1", command("param set throttle.mode 1"));
    uint32_t ms = 0u;
    for (; ms < 990u; ms++) {
        pulse_at(ms, 1000u);
    }
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&esc.fw)); /* not yet 1 s */
    for (; ms < 1100u; ms++) {
        pulse_at(ms, 1000u);
    }
    TEST_ASSERT_EQUAL_INT(FW_STATE_RUNNING, fw_state(&esc.fw));
    const uint32_t t_last = ms - 20u;
    for (; ms < t_last + 195u; ms++) {
        pulse_at(ms, 0u);
    }
    TEST_ASSERT_EQUAL_INT(FW_STATE_RUNNING, fw_state(&esc.fw)); /* ramping */
    for (; ms < t_last + 210u; ms++) {
        pulse_at(ms, 0u);
    }
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&esc.fw));
    TEST_ASSERT_EQUAL_UINT32(1u, esc.thr_losses);
    TEST_ASSERT_EQUAL_UINT8(THR_CAUSE_NO_PULSE, esc.thr.cause);
}

/* A drive that leaves running without the throttle (here a link "disarm"
 * with the stick held high) needs the stick at its low end for 1 s again:
 * neither the held stick nor a later link "arm" lets it drive the torque. */
static void test_throttle_rearms_only_from_its_low_end(void)
{
    calibrate_at(2553u);
    TEST_ASSERT_EQUAL_STRING("ok throttle.mode 1", command("param set throttle.mode 1"));
    uint32_t ms = 0u;
    for (; ms < 1100u; ms++) {
        pulse_at(ms, 1000u);
    }
    TEST_ASSERT_EQUAL_INT(FW_STATE_RUNNING, fw_state(&esc.fw));
    for (; ms < 1200u; ms++) {
        pulse_at(ms, 1800u);
    }
    TEST_ASSERT_TRUE(fw_torque_ref(&esc.fw) > 0);
    expect_prefix("ok", command("disarm"));
    for (; ms < 2500u; ms++) {
        pulse_at(ms, 1800u);
    }
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&esc.fw));
    TEST_ASSERT_EQUAL_UINT8(THR_WAIT_LOW, esc.thr.state);
    expect_prefix("ok", command("ref torque 0"));
    expect_prefix("ok", command("arm"));
    for (; ms < 2600u; ms++) {
        pulse_at(ms, 1800u);
    }
    TEST_ASSERT_EQUAL_INT(FW_STATE_RUNNING, fw_state(&esc.fw));
    TEST_ASSERT_EQUAL_INT32(0, fw_torque_ref(&esc.fw)); /* the link's, not the stick's */
    TEST_ASSERT_EQUAL_UINT8(THR_WAIT_LOW, esc.thr.state);
}

/* Every throttle field set over the link, saved, the board powered off and on
 * (the register model reset, the flash kept): the same input arms the drive
 * at the calibrated low end (1100 us, which the defaults' 1000 + 30 us would
 * not take as low) and maps a pulse with the calibrated end points and dead
 * band; "config show" lists throttle values that thr_config_check accepts. */
static void test_throttle_survives_a_power_cycle(void)
{
    memset(g4_mem_flash_settings, 0xFF, sizeof g4_mem_flash_settings); /* a new board */
    calibrate_at(2553u);
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&esc.fw));
    TEST_ASSERT_EQUAL_STRING("ok throttle.low_us 1100", command("param set throttle.low_us 1100"));
    TEST_ASSERT_EQUAL_STRING("ok throttle.high_us 1900",
                             command("param set throttle.high_us 1900"));
    TEST_ASSERT_EQUAL_STRING("ok throttle.deadband_us 40",
                             command("param set throttle.deadband_us 40"));
    TEST_ASSERT_EQUAL_STRING("ok throttle.mode 1", command("param set throttle.mode 1"));
    TEST_ASSERT_EQUAL_STRING("ok saved record 1", command("config save"));

    calibrate_at(2553u); /* power cycle */
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&esc.fw));
    TEST_ASSERT_EQUAL_STRING("settings: record 1 (page 0) applied", esc.settings.msg);
    TEST_ASSERT_EQUAL_STRING("ok throttle.mode 1 -", command("param get throttle.mode"));
    TEST_ASSERT_EQUAL_STRING("ok throttle.low_us 1100 us", command("param get throttle.low_us"));
    TEST_ASSERT_EQUAL_STRING("ok throttle.high_us 1900 us", command("param get throttle.high_us"));
    TEST_ASSERT_EQUAL_STRING("ok throttle.deadband_us 40 us",
                             command("param get throttle.deadband_us"));
    uint32_t ms = 0u;
    for (; ms < 1100u; ms++) {
        pulse_at(ms, 1100u);
    }
    TEST_ASSERT_EQUAL_INT(FW_STATE_RUNNING, fw_state(&esc.fw));
    for (; ms < 1200u; ms++) {
        pulse_at(ms, 1520u);
    }
    /* (1520 - 1140) / (1900 - 1140) of the torque limit, Q24 */
    const q24_t want = fx_mul((q24_t)((380ll << 24) / 760), esc.fw.torque_ref_max);
    TEST_ASSERT_EQUAL_INT32(want, fw_torque_ref(&esc.fw));
    expect_prefix("ok", command("disarm"));
    control_period();

    /* "config show": the record's throttle values, each one the checks take */
    const size_t n = command_lines("config show");
    TEST_ASSERT_TRUE(n > 2u);
    thr_config_t c;
    thr_config_default(&c);
    unsigned seen = 0u;
    for (size_t k = 1; k < n; k++) {
        unsigned v;
        char key[32];
        if (sscanf(reply[k], " thr.%31[a-z_]=%u", key, &v) != 2) {
            continue;
        }
        seen++;
        if (strcmp(key, "mode") == 0) {
            c.mode = (uint8_t)v;
        } else if (strcmp(key, "low_us") == 0) {
            c.low_us = (uint16_t)v;
        } else if (strcmp(key, "high_us") == 0) {
            c.high_us = (uint16_t)v;
        } else if (strcmp(key, "deadband_us") == 0) {
            c.deadband_us = (uint16_t)v;
        }
    }
    TEST_ASSERT_EQUAL_UINT(4u, seen);
    TEST_ASSERT_EQUAL_INT(0, thr_config_check(&c));
    TEST_ASSERT_EQUAL_UINT16(1100u, c.low_us);
    TEST_ASSERT_EQUAL_UINT16(1900u, c.high_us);
    TEST_ASSERT_EQUAL_UINT16(40u, c.deadband_us);
    TEST_ASSERT_EQUAL_UINT8(1u, c.mode);

    /* "config default": the compiled-in throttle (off) as well */
    expect_prefix("ok", command("config default"));
    TEST_ASSERT_EQUAL_STRING("ok throttle.mode 0 -", command("param get throttle.mode"));

    /* a record whose throttle the checks refuse (written past the link):
     * refused as a whole at start-up, naming the field, its value, its range */
    settings_t rec = esc.settings.rec;
    rec.thr_low_us = 700u;
    TEST_ASSERT_EQUAL_INT(SETTINGS_STORE_OK,
                          settings_store_save(&esc.settings.flash, esc.settings.buf,
                                              sizeof esc.settings.buf, &rec, NULL));
    calibrate_at(2553u);
    TEST_ASSERT_EQUAL_STRING("settings: record 2 refused: throttle.low_us = 700 outside [800, "
                             "1499]; compiled-in defaults",
                             esc.settings.msg);
    TEST_ASSERT_EQUAL_UINT(0u, fault_paths);
    memset(g4_mem_flash_settings, 0xFF, sizeof g4_mem_flash_settings);
}

/* Replies so far whose first word is "ok" or "err" (one per command). */
static unsigned answers(void)
{
    unsigned n = 0;
    for (size_t k = 0; k < n_reply; k++) {
        n += strncmp(reply[k], "ok", 2) == 0 || strncmp(reply[k], "err ", 4) == 0 ? 1u : 0u;
    }
    return n;
}

static unsigned iwdg_refreshes(void)
{
    unsigned n = 0;
    for (uint32_t k = 0; k < g4_model.n_log; k++) {
        n += g4_model.log[k].reg == G4_IWDG + G4_IWDG_KR &&
                     g4_model.log[k].value == G4_IWDG_KR_REFRESH
                 ? 1u
                 : 0u;
    }
    return n;
}

/* Lines that arrive together (a pasted script, a console that does not wait)
 * run one per pass of the main loop, the watchdogs served after each: three
 * "config show" (each a flash read; "config erase" is two page erases of up
 * to 24.5 ms) do not run back to back past the independent watchdog. */
static void test_main_loop_serves_the_watchdog_between_commands(void)
{
    calibrate_at(2553u);
    esc.ms_cycles = 170000u;
    esc.temp_period = 0xFFFFFFFFu;
    esc.t_temp = g4_cycles();
    static const char lines[] = "status\rfault\rstatus\r";
    for (const char *c = lines; *c != '\0'; c++) {
        esc.uart.rx[esc.uart.rx_head & (ESC1_UART_RX_SIZE - 1u)] = (uint8_t)*c;
        esc.uart.rx_head++;
    }
    n_reply = 0;
    g4_model.n_log = 0;
    for (unsigned pass = 1; pass <= 3u; pass++) {
        esc.isr_count++; /* the control interrupt runs */
        esc1_loop_once(&esc);
        TEST_ASSERT_EQUAL_UINT_MESSAGE(pass, answers(), "one command line per pass");
        TEST_ASSERT_EQUAL_UINT_MESSAGE(pass, iwdg_refreshes(), "the watchdog after each");
    }
    TEST_ASSERT_EQUAL_UINT32(esc.uart.rx_head, esc.uart.rx_tail);
    /* in order: status (11 lines), fault, status */
    TEST_ASSERT_EQUAL_STRING("ok 10", reply[0]);
    TEST_ASSERT_NOT_NULL(strstr(reply[11], "none"));
    TEST_ASSERT_EQUAL_STRING("ok 10", reply[12]);
}

/* ---- USART2's receiver on the register model (g4_model_usart_rx) ---- */

/* The board's serial link as esc1_main.c starts it, on a calibrated drive;
 * the main loop's clocks as the test above sets them. */
static void serial_on(void)
{
    calibrate_at(2553u);
    esc.ms_cycles = 170000u;
    esc.temp_period = 0xFFFFFFFFu;
    esc.t_temp = g4_cycles();
    TEST_ASSERT_EQUAL_INT(G4_OK,
                          esc1_uart_init(&esc.uart, g4_board_esc1.sysclk_hz, g4_board_esc1.baud));
}

/* Characters on the wire; serviced: the USART interrupt runs after each (a
 * core that does not stall), else they wait in the receiver (a core stalled
 * on a flash page erase: 2 x 24.5 ms is over 500 characters at 115 200 Bd). */
static void wire(const char *text, bool serviced)
{
    for (const char *c = text; *c != '\0'; c++) {
        g4_model_usart_rx((uint8_t)*c, false);
        if (serviced) {
            esc1_uart_irq(&esc.uart);
        }
    }
}

/* The main loop until the receive ring is empty (one line per pass). */
static void main_loop_drains(void)
{
    esc1_uart_irq(&esc.uart);
    for (unsigned pass = 0; pass < 8u && esc.uart.rx_head != esc.uart.rx_tail; pass++) {
        esc.isr_count++;
        esc1_loop_once(&esc);
    }
    TEST_ASSERT_EQUAL_UINT32(esc.uart.rx_head, esc.uart.rx_tail);
}

static char fault_alone[160];
static char rs_before[160];

static void serial_references(void)
{
    strcpy(fault_alone, command("fault"));
    strcpy(rs_before, command("param get m.rs_ohm"));
}

/* Bytes an overrun lost in the middle of a line (the core stalled while
 * "rs_ohm 15.0" arrived: the RXFIFO kept 8 characters, ORE lost 3): the line
 * is discarded up to its end of line and answered "err 13 lost" naming the
 * overrun (what is left of it, "param set m.rs_ohm 19", is not run), and the
 * next command is answered alone, as it is without the loss. */
static void test_overrun_discards_its_line(void)
{
    serial_on();
    serial_references();
    n_reply = 0;
    wire("param set m.", true);
    wire("rs_ohm 15.0", false); /* stalled */
    TEST_ASSERT_EQUAL_UINT32(3u, g4_model.usart_lost);
    wire("9\r", true);
    wire("fault\r", true);
    main_loop_drains();
    TEST_ASSERT_EQUAL_UINT_MESSAGE(2u, answers(), "one answer per end of line");
    TEST_ASSERT_EQUAL_STRING("err 13 lost overrun (ORE)", reply[0]);
    TEST_ASSERT_EQUAL_STRING(fault_alone, reply[1]);
    TEST_ASSERT_EQUAL_STRING(rs_before, command("param get m.rs_ohm"));
    TEST_ASSERT_EQUAL_UINT32(1u, esc.uart.rx_errors);
    TEST_ASSERT_EQUAL_UINT32(0u, g4_model_get(G4_USART2 + G4_USART_ISR) & G4_USART_ISR_ORE);
}

/* A short line sent while the core stalls (a script that does not wait for
 * "config erase"'s answer) survives in the 8-character RXFIFO, and so does
 * the next command: nothing of one prefixes the other. */
static void test_rx_fifo_keeps_a_short_line_through_a_stall(void)
{
    serial_on();
    serial_references();
    n_reply = 0;
    wire("fault\r", false); /* stalled */
    wire("fault\r", true);
    main_loop_drains();
    TEST_ASSERT_EQUAL_UINT(2u, answers());
    TEST_ASSERT_EQUAL_STRING(fault_alone, reply[0]);
    TEST_ASSERT_EQUAL_STRING(fault_alone, reply[1]);
    TEST_ASSERT_EQUAL_UINT32(0u, g4_model.usart_lost);
    TEST_ASSERT_EQUAL_UINT32(0u, esc.uart.rx_errors);
}

/* A character received with a framing error (FE: RM0440 USART_ISR, the
 * character in RDR) is a lost one: its line is answered "err 13 lost"
 * naming it, the next line alone; the byte itself is not taken. */
static void test_framing_error_discards_its_line(void)
{
    serial_on();
    serial_references();
    n_reply = 0;
    wire("param set m.rs_ohm 1", true);
    g4_model_usart_rx('7', true);
    esc1_uart_irq(&esc.uart);
    wire("5.09\r", true);
    wire("fault\r", true);
    main_loop_drains();
    TEST_ASSERT_EQUAL_UINT(2u, answers());
    TEST_ASSERT_EQUAL_STRING("err 13 lost framing (FE)", reply[0]);
    TEST_ASSERT_EQUAL_STRING(fault_alone, reply[1]);
    TEST_ASSERT_EQUAL_STRING(rs_before, command("param get m.rs_ohm"));
    TEST_ASSERT_EQUAL_UINT32(0u, g4_model_get(G4_USART2 + G4_USART_ISR) & G4_USART_ISR_FE);
}

/* One pass of the main loop `after` core cycles after the USART interrupt
 * noted the loss (the model's cycle counter set there). */
static void loop_after_loss(uint32_t after)
{
    g4_model_put(G4_DWT + G4_DWT_CYCCNT, esc.uart.rx_lost_at + after);
    esc.isr_count++;
    esc1_loop_once(&esc);
}

/* A line whose end an overrun lost (all of "param set m.rs_ohm 19\r" sent
 * while the core stalls: the RXFIFO keeps "param se", the other 14
 * characters, its end of line among them, are lost). Nothing is answered
 * while the line may still go on; idle for ESC1_UART_LOST_IDLE_MS (20 ms at
 * 170 MHz) after the core ran again, it is answered "err 13 lost overrun
 * (ORE)" and not run, and the next line is read alone (before, it was
 * joined to the damaged one and voided with it, the damaged one unanswered
 * until then). */
static void test_overrun_losing_the_end_of_line(void)
{
    serial_on();
    serial_references();
    n_reply = 0;
    wire("param set m.rs_ohm 19\r", false); /* stalled */
    TEST_ASSERT_EQUAL_UINT32(14u, g4_model.usart_lost);
    main_loop_drains(); /* the core runs again: "param se" read, the loss noted */
    const uint32_t idle = esc.uart.lost_idle_cycles;
    TEST_ASSERT_EQUAL_UINT32(170000u * 20u, idle);
    loop_after_loss(idle / 2u);
    loop_after_loss(idle - 64u);
    TEST_ASSERT_EQUAL_UINT_MESSAGE(0u, answers(), "no answer while the line may go on");
    loop_after_loss(idle);
    TEST_ASSERT_EQUAL_UINT(1u, answers());
    TEST_ASSERT_EQUAL_STRING("err 13 lost overrun (ORE)", reply[0]);
    loop_after_loss(2u * idle);
    TEST_ASSERT_EQUAL_UINT_MESSAGE(1u, answers(), "one answer per loss");
    wire("fault\r", true);
    main_loop_drains();
    TEST_ASSERT_EQUAL_UINT(2u, answers());
    TEST_ASSERT_EQUAL_STRING(fault_alone, reply[1]);
    TEST_ASSERT_EQUAL_STRING(rs_before, command("param get m.rs_ohm"));
}

/* A fragment is never run: "  disarm" streamed during a stall loses "dis"
 * (the RXFIFO full of "fault\r  "), and the main loop passes while the
 * sender's line goes on; "arm\r" coming just inside the idle bound belongs
 * to the damaged line, which is answered "err 13 lost" and does not arm
 * (a line ended at the loss itself would have run "arm"). */
static void test_overrun_fragment_is_not_run(void)
{
    serial_on();
    serial_references();
    n_reply = 0;
    wire("fault\r  dis", false); /* stalled */
    TEST_ASSERT_EQUAL_UINT32(3u, g4_model.usart_lost);
    main_loop_drains();
    loop_after_loss(esc.uart.lost_idle_cycles / 4u);
    loop_after_loss(esc.uart.lost_idle_cycles - 64u);
    wire("arm\r", true);
    main_loop_drains();
    TEST_ASSERT_EQUAL_UINT(2u, answers());
    TEST_ASSERT_EQUAL_STRING(fault_alone, reply[0]);
    TEST_ASSERT_EQUAL_STRING("err 13 lost overrun (ORE)", reply[1]);
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&esc.fw));
    TEST_ASSERT_FALSE(fw_gates_on_or_pending(&esc.fw));
}

/* An overrun that loses only the LF of a CRLF ("\r\nfault\r\n" during a
 * stall: the RXFIFO keeps "\r\nfault\r"), as PROTOCOL.md and the board page
 * say: "fault" answered, then, idle 20 ms after the loss, an "err 13 lost"
 * that answers no line; a line within those 20 ms is voided with it. */
static void test_overrun_losing_only_the_lf(void)
{
    serial_on();
    serial_references();
    n_reply = 0;
    wire("\r\nfault\r\n", false); /* stalled */
    TEST_ASSERT_EQUAL_UINT32(1u, g4_model.usart_lost);
    main_loop_drains();
    TEST_ASSERT_EQUAL_UINT(1u, answers());
    TEST_ASSERT_EQUAL_STRING(fault_alone, reply[0]);
    loop_after_loss(esc.uart.lost_idle_cycles / 2u);
    wire("fault\r", true);
    main_loop_drains();
    TEST_ASSERT_EQUAL_UINT(2u, answers());
    TEST_ASSERT_EQUAL_STRING("err 13 lost overrun (ORE)", reply[1]);
}

/* A character damaged (framing, noise) while an overrun's loss is pending
 * is one more received from a sender still streaming: the idle clock starts
 * again there. "fault\r  di" streamed during a stall loses "di", the "s" of
 * "  disarm" comes with a framing error just inside the idle bound, and
 * "arm\r" after the bound counted from the overrun but inside it counted
 * from the "s": all one damaged line, answered "err 13 lost" once, and
 * nothing armed (with the clock left at the overrun the loss was answered
 * before "arm\r" came, which then ran alone and armed). */
static void test_framing_error_restarts_the_idle_clock(void)
{
    serial_on();
    serial_references();
    n_reply = 0;
    wire("fault\r  di", false); /* stalled */
    TEST_ASSERT_EQUAL_UINT32(2u, g4_model.usart_lost);
    main_loop_drains();
    const uint32_t t_ore = esc.uart.rx_lost_at;
    const uint32_t idle = esc.uart.lost_idle_cycles;
    g4_model_put(G4_DWT + G4_DWT_CYCCNT, t_ore + idle - 64u);
    g4_model_usart_rx('s', true);
    esc1_uart_irq(&esc.uart);
    g4_model_put(G4_DWT + G4_DWT_CYCCNT, t_ore + idle + idle / 2u);
    esc.isr_count++;
    esc1_loop_once(&esc);
    TEST_ASSERT_EQUAL_UINT_MESSAGE(1u, answers(), "no answer while the line may go on");
    wire("arm\r", true);
    main_loop_drains();
    TEST_ASSERT_EQUAL_UINT(2u, answers());
    TEST_ASSERT_EQUAL_STRING(fault_alone, reply[0]);
    TEST_ASSERT_EQUAL_STRING("err 13 lost overrun (ORE)", reply[1]);
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&esc.fw));
    TEST_ASSERT_FALSE(fw_gates_on_or_pending(&esc.fw));
    TEST_ASSERT_EQUAL_UINT32(2u, esc.uart.rx_errors);
}

/* "status" gives the main stack's high-water mark once the application has
 * told the link where its painted stack lies. */
static void test_status_gives_the_stack_high_water_mark(void)
{
    calibrate_at(2553u);
    static uint32_t stack[256];
    fw_stack_paint(stack, stack + 256);
    stack[200] = 0u; /* the deepest word written: 56 words below the top */
    fw_link_set_stack(&esc.link, stack, stack + 256);
    const size_t n = command_lines("status");
    TEST_ASSERT_EQUAL_STRING("ok 11", reply[0]);
    TEST_ASSERT_EQUAL_UINT(12u, n);
    TEST_ASSERT_EQUAL_STRING("  stack_used=224 size=1024", reply[11]);
}

/* "ident apply" rewrites what the control interrupt reads (conversion,
 * protections, the encoder's tracking: fw_setup_machine) with the interrupt
 * masked, as the board's own reconfiguration does: fw_t unchanged until the
 * NVIC's ICER masks ADC1_2, and again from the ISER that lets it run. */
static fw_t fw_at_mask, fw_at_unmask;
static int hold_mask = -1, hold_unmask = -1;
static void watch_nvic(uintptr_t reg, uint32_t value)
{
    if ((value & (1u << G4_IRQ_ADC1_2)) == 0u) {
        return;
    }
    if (reg == G4_NVIC + G4_NVIC_ICER(0u) && hold_mask < 0) {
        hold_mask = (int)g4_model.n_log;
        memcpy(&fw_at_mask, &esc.fw, sizeof esc.fw);
    } else if (reg == G4_NVIC + G4_NVIC_ISER(0u) && hold_mask >= 0) {
        hold_unmask = (int)g4_model.n_log;
        memcpy(&fw_at_unmask, &esc.fw, sizeof esc.fw);
    }
}

static void test_ident_apply_holds_the_control_interrupt(void)
{
    calibrate_at(2553u);
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&esc.fw));
    g4_model_put(G4_NVIC + G4_NVIC_ISER(0u), 1u << G4_IRQ_ADC1_2); /* running */
    /* an identified encoder offset to adopt */
    esc.fw.cm.res.have = CM_HAVE_ENC;
    esc.fw.cm.res.enc_dir = 1;
    esc.fw.cm.res.enc_off = 0x40000000u;
    esc.fw.cm.res.bases = esc.fw.bases;
    static fw_t before;
    memcpy(&before, &esc.fw, sizeof esc.fw);
    hold_mask = hold_unmask = -1;
    g4_model.on_write = watch_nvic;
    expect_prefix("ok ident applied", command("ident apply"));
    g4_model.on_write = NULL;
    TEST_ASSERT_TRUE_MESSAGE(hold_mask >= 0, "ADC1_2 masked during ident apply");
    TEST_ASSERT_TRUE_MESSAGE(hold_unmask > hold_mask, "and enabled again after it");
    TEST_ASSERT_EQUAL_MEMORY_MESSAGE(&before, &fw_at_mask, sizeof before,
                                     "nothing rewritten before the mask");
    TEST_ASSERT_EQUAL_MEMORY_MESSAGE(&fw_at_unmask, &esc.fw, sizeof before,
                                     "nothing rewritten after the interrupt runs again");
    TEST_ASSERT_EQUAL_UINT32(0x40000000u, esc.fw.enc_offset); /* and it was adopted */
}

/* The machine in force after "ident apply" is the drive's (fw_t.machine_own,
 * the encoder's offset and direction): "param get" reads it, and a later
 * change of an unrelated m.* parameter or enc.cpr (a reconfiguration) keeps
 * the identified Rs, Ld, Lq, psi_pm, the inertia set after it and the
 * encoder calibration; the same after a settings record carrying them is
 * loaded at power-up. Before, the board's own copy answered the pre-
 * identification values and a reconfiguration restored them, offset 0 and
 * direction +1 with them. */
static void expect_machine(const ctrl_machine_t *want, double j, uint32_t off, uint32_t neg)
{
    const ctrl_machine_t *m = &esc.fw.machine_own;
    TEST_ASSERT_DOUBLE_WITHIN(1e-9 * want->rs_ohm, want->rs_ohm, m->rs_ohm);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9 * want->ld_h, want->ld_h, m->ld_h);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9 * want->lq_h, want->lq_h, m->lq_h);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9 * want->psi_pm_wb, want->psi_pm_wb, m->psi_pm_wb);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9 * j, j, m->inertia_kgm2);
    TEST_ASSERT_EQUAL_HEX32(off, esc.fw.enc_offset);
    TEST_ASSERT_EQUAL_HEX32(neg, esc.fw.enc_neg);
    /* the link's answers: the same values (printed to 4 significant digits) */
    const char *q[3] = {"param get m.rs_ohm", "param get m.psi_wb", "param get m.j_kgm2"};
    const double v[3] = {want->rs_ohm, want->psi_pm_wb, j};
    for (size_t k = 0; k < 3u; k++) {
        const char *a = command(q[k]);
        double got = 0.0;
        TEST_ASSERT_EQUAL_INT_MESSAGE(1, sscanf(a, "ok %*s %lf", &got), a);
        TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(1e-3 * v[k], v[k], got, a);
    }
}

static void test_identified_machine_survives_a_parameter_change(void)
{
    memset(g4_mem_flash_settings, 0xFF, sizeof g4_mem_flash_settings); /* a new board */
    calibrate_at(2553u);
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&esc.fw));
    const ctrl_machine_t *d = &esc1_default_machine;
    /* identified: twice the file's Rs, 1.5 x its inductances, 1.1 x its
     * flux (pu of the bases they were taken in), the encoder a quarter turn
     * off and counting backwards */
    cm_results_t *r = &esc.fw.cm.res;
    r->have = CM_HAVE_RS | CM_HAVE_LDQ | CM_HAVE_FLUX | CM_HAVE_ENC;
    r->bases = esc.fw.bases;
    r->rs = ctrl_q24_from_double(2.0 * d->rs_ohm / r->bases.r_ohm);
    r->ld = ctrl_q24_from_double(1.5 * d->ld_h / r->bases.l_h);
    r->lq = ctrl_q24_from_double(1.5 * d->lq_h / r->bases.l_h);
    r->psi = ctrl_q24_from_double(1.1 * d->psi_pm_wb / r->bases.psi_wb);
    r->enc_dir = -1;
    r->enc_off = 0x40000000u;
    expect_prefix("ok ident applied", command("ident apply"));
    const ctrl_machine_t id = esc.fw.machine_own;
    TEST_ASSERT_DOUBLE_WITHIN(1e-3 * d->rs_ohm, 2.0 * d->rs_ohm, id.rs_ohm);
    TEST_ASSERT_DOUBLE_WITHIN(1e-3 * d->psi_pm_wb, 1.1 * d->psi_pm_wb, id.psi_pm_wb);
    expect_machine(&id, d->inertia_kgm2, 0x40000000u, 0xFFFFFFFFu);

    expect_prefix("ok m.j_kgm2", command("param set m.j_kgm2 6e-5"));
    expect_machine(&id, 6e-5, 0x40000000u, 0xFFFFFFFFu);
    TEST_ASSERT_EQUAL_STRING("ok enc.cpr 2048", command("param set enc.cpr 2048"));
    expect_machine(&id, 6e-5, 0x40000000u, 0xFFFFFFFFu);

    /* saved, the board powered off and on: the record's data in force, and
     * kept by a change after it */
    expect_prefix("ok saved record 1", command("config save"));
    calibrate_at(2553u); /* power cycle */
    TEST_ASSERT_EQUAL_STRING("settings: record 1 (page 0) applied", esc.settings.msg);
    expect_machine(&id, 6e-5, 0x40000000u, 0xFFFFFFFFu);
    expect_prefix("ok m.j_kgm2", command("param set m.j_kgm2 7e-5"));
    expect_machine(&id, 7e-5, 0x40000000u, 0xFFFFFFFFu);
    TEST_ASSERT_EQUAL_STRING("ok enc.cpr 2048 -", command("param get enc.cpr"));
    memset(g4_mem_flash_settings, 0xFF, sizeof g4_mem_flash_settings);
}

/* The speed reference's limit is the drive's (fw_speed_info_t.speed_ref_max_rpm,
 * which fw_set_speed_ref_rpm clamps to), at power-up and after every
 * reconfiguration: a reference just inside it is taken, one just beyond it
 * refused with the range, never taken and clamped silently. Before, a
 * reconfiguration set the link's limit to 1.2 x rated speed. */
static void expect_speed_limit(void)
{
    const double lim = esc.fw.speed_info.speed_ref_max_rpm;
    char line[64];
    (void)snprintf(line, sizeof line, "ref speed %.6g", 0.99 * lim);
    expect_prefix("ok ref speed", command(line));
    (void)snprintf(line, sizeof line, "ref speed %.6g", 1.01 * lim);
    expect_prefix("err 4 range [-", command(line));
}

static void test_speed_reference_limit_is_the_drives(void)
{
    calibrate_at(2553u);
    expect_speed_limit();
    expect_prefix("ok m.j_kgm2", command("param set m.j_kgm2 6e-5"));
    expect_speed_limit();
    expect_prefix("ok m.n_rated_rpm", command("param set m.n_rated_rpm 290"));
    expect_speed_limit();
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_default_machine_is_the_file);
    RUN_TEST(test_default_machine_within_the_board);
    RUN_TEST(test_core_and_every_controller_take_it);
    RUN_TEST(test_config_carries_the_board_dead_time);
    RUN_TEST(test_reconfiguration_time_is_kept);
    RUN_TEST(test_link_refusal_names_quantity_value_range);
    RUN_TEST(test_calibration_takes_the_board_zero);
    RUN_TEST(test_calibration_checks_phase_w);
    RUN_TEST(test_throttle_arms_and_disarms_the_drive);
    RUN_TEST(test_throttle_rearms_only_from_its_low_end);
    RUN_TEST(test_link_reconfig_refused_while_gates_on);
    RUN_TEST(test_bringup_sense_says_the_offsets);
    RUN_TEST(test_throttle_survives_a_power_cycle);
    RUN_TEST(test_main_loop_serves_the_watchdog_between_commands);
    RUN_TEST(test_status_gives_the_stack_high_water_mark);
    RUN_TEST(test_overrun_discards_its_line);
    RUN_TEST(test_rx_fifo_keeps_a_short_line_through_a_stall);
    RUN_TEST(test_framing_error_discards_its_line);
    RUN_TEST(test_overrun_losing_the_end_of_line);
    RUN_TEST(test_overrun_fragment_is_not_run);
    RUN_TEST(test_framing_error_restarts_the_idle_clock);
    RUN_TEST(test_overrun_losing_only_the_lf);
    RUN_TEST(test_ident_apply_holds_the_control_interrupt);
    RUN_TEST(test_identified_machine_survives_a_parameter_change);
    RUN_TEST(test_speed_reference_limit_is_the_drives);
    return UNITY_END();
}
