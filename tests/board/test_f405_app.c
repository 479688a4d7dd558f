/*
 * The STM32F405 board application (firmware/apps/board with the F405 image's
 * parameters, settings sectors and control interrupt: f405_params.c,
 * f405_settings.c, f405_isr.c) on the host, as the VESC 6 image runs it: the
 * clock, the board HAL and the DRV8301 on the register model at RM0090's
 * reset values (f4_model.c, drv8301_model.c), the compiled-in motor of
 * PMSM_F405_MACHINE_INI, the settings record in the model's flash sectors,
 * the command link on a console that keeps every reply line. A power cycle
 * is the model reset with the settings sectors' content kept.
 *
 * What it shows: the machine the identification gave ("ident apply") is the
 * drive's, and stays the drive's through a later "param set" of an unrelated
 * m.* or enc.cpr (a reconfiguration), a "config save" and a power cycle:
 * Rs, Ld, Lq, psi_pm, the encoder's offset and direction, and on an image
 * with the mechanics' identification (CM_MECH, as the F405 images have it)
 * the Coulomb and viscous friction beside the inertia.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "board_app.h"
#include "drv8301_model.h"
#include "f405_app.h"
#include "f405_uart.h"
#include "f4_clock.h"
#include "f4_core.h"
#include "f4_flash.h"
#include "f4_model.h"
#include "unity.h"
#include F405_BOARD_HEADER

const char f405_tag[] = F405_BOARD_TAG ": ";
extern const ctrl_machine_t f405_default_machine;

void setUp(void)
{
}
void tearDown(void)
{
}

static f405_t f405;

/* ---- the console: every reply line kept ---- */

#define MAX_REPLY 64u
static char reply[MAX_REPLY][160];
static size_t n_reply;

static bool console_put(uint8_t c, uint32_t timeout_cycles)
{
    (void)timeout_cycles;
    static char line[160];
    static size_t n;
    if (c == '\n') {
        line[n > 0 && line[n - 1] == '\r' ? n - 1 : n] = '\0';
        if (n_reply < MAX_REPLY) {
            memcpy(reply[n_reply++], line, sizeof line);
        }
        n = 0;
    } else if (n + 1u < sizeof line) {
        line[n++] = (char)c;
    }
    return true;
}

static void console_nothing(void)
{
}

/* A clock that moves with every read: no wait in the application hangs;
 * a test moves it on (test_now += ...) for the time between characters. */
static uint32_t test_now;
static uint32_t test_ticks(void)
{
    return test_now += 10u;
}

static const board_uart_port_t console_port = {console_nothing, console_nothing, console_put,
                                               test_ticks};

/* The board's part of the application as f405_main.c gives it, less what
 * needs the running chip (the throttle's capture, the interrupt watch). */
static void test_control_irq(bool on)
{
    if (on) {
        f4_nvic_enable(F4_IRQ_ADC);
    } else {
        f4_nvic_disable(F4_IRQ_ADC);
    }
}

static double test_dead_time_s(const board_app_t *a)
{
    const f405_t *s = (const f405_t *)a;
    uint8_t dtg = 0;
    TEST_ASSERT_EQUAL_INT(STM32_OK,
                          stm32_dtg_encode(s->clk.tim_apb2_hz, s->board->dead_time_ns, &dtg));
    return (double)stm32_dtg_ticks(dtg) / (double)s->clk.tim_apb2_hz;
}

static bool test_throttle_read(board_app_t *a, uint32_t *width_us, uint32_t *period_us)
{
    (void)a;
    (void)width_us;
    (void)period_us;
    return false;
}

static const board_app_port_t test_port = {
    .tag = f405_tag,
    .machine = &f405_default_machine,
    .ctrl = F405_CTRL,
    .encoder_cpr = F405_ENCODER_CPR,
    .control_irq = test_control_irq,
    .dead_time_s = test_dead_time_s,
    .set_trip = NULL,
    .throttle_read = test_throttle_read,
    .watchdog_refresh = f4_iwdg_refresh,
    .watchdog_long = NULL,
    .gates_on = NULL,
    .isr_stalled = NULL,
    .ticks = test_ticks,
    .ticks_hz = 1000000u,
};

/* Power on, as f405_main.c starts: the clock, the board HAL with its
 * DRV8301, the firmware on the compiled-in motor with the link and its
 * parameters, the settings record applied (or the defaults). The settings
 * sectors keep what they hold (f4_model_reset erases them: put back). */
static void f405_power_on(void)
{
    static uint32_t kept[2u * F4_FLASH_SECTOR_SIZE / 4u];
    memcpy(kept, f4_mem_flash_settings, sizeof kept);
    f4_model_reset();
    memcpy(f4_mem_flash_settings, kept, sizeof kept);
    f4_cycle_counter_init();
    memset(&f405, 0, sizeof f405);
    f405_t *s = &f405;
    s->board = &F405_BOARD;
    const f4_board_t *b = s->board;
    drv8301_model_attach(b->en_gate, b->drv_cs, b->nfault, b->drv_spi);
    TEST_ASSERT_EQUAL_INT(F4_OK, f4_clock_init(b->hse_hz, b->sysclk_hz, &s->clk));
    const f4_hal_cfg_t hc = {F405_FS_HZ, F405_ENCODER_CPR};
    TEST_ASSERT_EQUAL_INT(F4_OK, f4_hal_init(&s->hal, b, &hc, &s->clk));
    board_uart_init(&s->app.uart, &console_port, 1000000u, s->clk.sysclk_hz, b->baud);
    s->app.uart.polled = true; /* every byte straight to console_put */
    n_reply = 0;
    TEST_ASSERT_EQUAL_INT(FW_OK, board_app_start(&s->app, &test_port, &s->hal));
    f405_settings_start(s);
}

/* The phase currents at the board's zero-current code and the DC link at
 * the machine's voltage (through the board's divider): the offsets
 * calibrated, the firmware ready. */
static void f405_calibrate(void)
{
    const f405_t *s = &f405;
    const uint32_t zero = s->hal.info.adc_current_zero;
    const uint32_t vdc = (uint32_t)lround(f405_default_machine.vdc_v * s->board->vbus_ratio /
                                          s->board->vref * 4095.0);
    /* the data registers the HAL reads i_a, i_b, i_c and the DC link from */
    for (unsigned x = 0; x < 3u; x++) {
        TEST_ASSERT_NOT_EQUAL(0u, s->hal.jdr[x]);
        f4_model_put(s->hal.jdr[x], zero);
    }
    f4_model_put(s->hal.jdr[3], vdc);
    for (uint32_t k = 0; k < 4u * f405.app.fc.calib_samples; k++) {
        f405_control_isr(&f405);
        if ((f4_model_get(F4_SCB + F4_SCB_ICSR) & F4_SCB_ICSR_PENDSVSET) != 0u) {
            f4_model_put(F4_SCB + F4_SCB_ICSR, 0u);
            fw_medium(&f405.app.fw); /* PendSV_Handler */
        }
        if (fw_state(&f405.app.fw) == FW_STATE_READY || fw_state(&f405.app.fw) == FW_STATE_FAULT) {
            break;
        }
    }
    TEST_ASSERT_EQUAL_INT(FW_STATE_READY, fw_state(&f405.app.fw));
}

/* Every reply line of a command (the first: "ok ..." or "err ..."). */
static const char *command(const char *text)
{
    n_reply = 0;
    for (const char *c = text; *c != '\0'; c++) {
        fw_link_rx(&f405.app.link, (uint8_t)*c);
    }
    fw_link_rx(&f405.app.link, '\r');
    fw_link_poll(&f405.app.link);
    TEST_ASSERT_TRUE_MESSAGE(n_reply >= 1u, text);
    return reply[0];
}

static void expect_prefix(const char *want, const char *got)
{
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, strncmp(want, got, strlen(want)), got);
}

/* The drive's machine and encoder calibration, and the link's answers. */
static void expect_machine(const ctrl_machine_t *want, double j, uint32_t off, uint32_t neg)
{
    const fw_t *fw = &f405.app.fw;
    const ctrl_machine_t *m = &fw->machine_own;
    TEST_ASSERT_DOUBLE_WITHIN(1e-9 * want->rs_ohm, want->rs_ohm, m->rs_ohm);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9 * want->ld_h, want->ld_h, m->ld_h);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9 * want->lq_h, want->lq_h, m->lq_h);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9 * want->psi_pm_wb, want->psi_pm_wb, m->psi_pm_wb);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9 * j, j, m->inertia_kgm2);
    TEST_ASSERT_EQUAL_HEX32(off, fw->enc_offset);
    TEST_ASSERT_EQUAL_HEX32(neg, fw->enc_neg);
    /* printed to 4 significant digits */
    const char *q[4] = {"param get m.rs_ohm", "param get m.ld_h", "param get m.psi_wb",
                        "param get m.j_kgm2"};
    const double v[4] = {want->rs_ohm, want->ld_h, want->psi_pm_wb, j};
    for (size_t k = 0; k < 4u; k++) {
        const char *a = command(q[k]);
        double got = 0.0;
        TEST_ASSERT_EQUAL_INT_MESSAGE(1, sscanf(a, "ok %*s %lf", &got), a);
        TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(1e-3 * v[k], v[k], got, a);
    }
}

#if CM_MECH
/* The identified friction in force (fw_config_t, what "ident apply"
 * adopted and the settings record keeps). */
static void expect_friction(double coulomb_nm, double viscous_nms)
{
    TEST_ASSERT_DOUBLE_WITHIN(1e-9 * coulomb_nm, coulomb_nm, f405.app.fw.cfg.coulomb_nm);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9 * viscous_nms, viscous_nms, f405.app.fw.cfg.viscous_nms);
}

/* The mechanics step's records (cm_results_t, pu of r->bases) for a shaft
 * with Coulomb friction fc (N*m), viscous friction bv (N*m*s) and inertia j
 * (kg*m^2), as cm_results_si reads them: the four speed windows steady
 * (no speed change) at 100 and 200 rad/s mechanical with the q current
 * that holds the friction there (+i_d and -i_d alike, so no reluctance
 * torque), the two transitions' current sums giving j over the speed step. */
static void identified_mechanics(cm_results_t *r, double fc, double bv, double j)
{
    const fw_t *fw = &f405.app.fw;
    const double pp = (double)fw->params.pole_pairs;
    const double ts = 1.0 / (double)fw->info.pwm_freq_hz;
    const double kt = (double)r->psi / 16777216.0 * r->bases.torque_nm; /* N*m per pu current */
    const double w[4] = {100.0, 200.0, 200.0, 100.0};                   /* rad/s mechanical */
    for (int k = 0; k < 4; k++) {
        r->fw_w[k] = ctrl_q24_from_double(w[k] * pp / r->bases.w_rad_s);
        r->fw_iq[k] = ctrl_q24_from_double((fc + bv * w[k]) / kt);
        r->fw_dw[k] = 0;
        r->fw_n[k] = 1000u;
        r->fw_len[k] = 1000u;
    }
    r->i_fd = 0;
    const uint32_t n = 2000u; /* each transition's periods */
    for (int k = 0; k < 2; k++) {
        /* the torque's integral over it: friction plus j x the speed's change */
        const double dw = k == 0 ? 100.0 : -100.0;
        const double tdt = fc * n * ts + j * dw;
        r->jx_iq[k] = (int64_t)llround(tdt / (kt * ts) * 16777216.0);
        r->jx_th[k] = 0;
        r->jx_n[k] = n;
    }
    r->have |= CM_HAVE_MECH;
}
#endif

/* Identified: twice the file's Rs, 1.5 x its inductances, 1.1 x its flux
 * (pu of the bases they were taken in), the encoder a quarter turn off and
 * counting backwards; adopted by "ident apply". Then param set of the
 * inertia and of the encoder's counts (each a reconfiguration of the
 * firmware), config save, a power cycle (the record applied), param set
 * again: the identified machine and calibration stay in force throughout.
 * Before the board application edited the drive's machine (a3acd36) it
 * answered and rebuilt the compiled-in motor's data (Rs 0.047 ohm for the
 * identified 0.094) with offset 0 and direction +1; before the
 * reconfiguration kept the drive's friction (fw_kept_t) it fell back to none
 * at the first param set after ident apply or after a record's. */
static void test_identified_machine_survives_a_parameter_change(void)
{
    memset(f4_mem_flash_settings, 0xFF, 2u * F4_FLASH_SECTOR_SIZE); /* a new board */
    f405_power_on();
    TEST_ASSERT_EQUAL_STRING("settings: no record in flash, compiled-in defaults",
                             f405.app.settings.msg);
    f405_calibrate();
    const ctrl_machine_t *d = &f405_default_machine;
    cm_results_t *r = &f405.app.fw.cm.res;
    r->have = CM_HAVE_RS | CM_HAVE_LDQ | CM_HAVE_FLUX | CM_HAVE_ENC;
    r->bases = f405.app.fw.bases;
    r->rs = ctrl_q24_from_double(2.0 * d->rs_ohm / r->bases.r_ohm);
    r->ld = ctrl_q24_from_double(1.5 * d->ld_h / r->bases.l_h);
    r->lq = ctrl_q24_from_double(1.5 * d->lq_h / r->bases.l_h);
    r->psi = ctrl_q24_from_double(1.1 * d->psi_pm_wb / r->bases.psi_wb);
    r->enc_dir = -1;
    r->enc_off = 0x40000000u;
#if CM_MECH
    /* and the mechanics: 1.2 x the file's inertia, friction the file has
     * not (5.6 % and 3.6 % of the rated 0.354 N*m at rated speed) */
    const double fc = 0.02, bv = 2e-5;
    identified_mechanics(r, fc, bv, 1.2 * d->inertia_kgm2);
#endif
    expect_prefix("ok ident applied", command("ident apply"));
    const ctrl_machine_t id = f405.app.fw.machine_own;
#if CM_MECH
    TEST_ASSERT_DOUBLE_WITHIN(1e-3 * d->inertia_kgm2, 1.2 * d->inertia_kgm2, id.inertia_kgm2);
    TEST_ASSERT_DOUBLE_WITHIN(1e-3 * fc, fc, f405.app.fw.cfg.coulomb_nm);
    TEST_ASSERT_DOUBLE_WITHIN(1e-3 * bv, bv, f405.app.fw.cfg.viscous_nms);
    const double fc_id = f405.app.fw.cfg.coulomb_nm, bv_id = f405.app.fw.cfg.viscous_nms;
#define EXPECT_FRICTION() expect_friction(fc_id, bv_id)
#else
#define EXPECT_FRICTION() ((void)0)
#endif
    TEST_ASSERT_DOUBLE_WITHIN(1e-3 * d->rs_ohm, 2.0 * d->rs_ohm, id.rs_ohm);
    TEST_ASSERT_DOUBLE_WITHIN(1e-3 * d->ld_h, 1.5 * d->ld_h, id.ld_h);
    TEST_ASSERT_DOUBLE_WITHIN(1e-3 * d->psi_pm_wb, 1.1 * d->psi_pm_wb, id.psi_pm_wb);
    expect_machine(&id, id.inertia_kgm2, 0x40000000u, 0xFFFFFFFFu);
    EXPECT_FRICTION();

    const double j1 = 1.5 * d->inertia_kgm2, j2 = 2.0 * d->inertia_kgm2;
    char set[64];
    (void)snprintf(set, sizeof set, "param set m.j_kgm2 %.9g", j1);
    expect_prefix("ok m.j_kgm2", command(set));
    expect_machine(&id, j1, 0x40000000u, 0xFFFFFFFFu);
    EXPECT_FRICTION();
    TEST_ASSERT_EQUAL_STRING("ok enc.cpr 8192", command("param set enc.cpr 8192"));
    expect_machine(&id, j1, 0x40000000u, 0xFFFFFFFFu);
    EXPECT_FRICTION();

    /* saved, the board powered off and on: the record's data in force, and
     * kept by a change after it */
    expect_prefix("ok saved record 1", command("config save"));
    f405_power_on();
    TEST_ASSERT_EQUAL_STRING("settings: record 1 (page 0) applied", f405.app.settings.msg);
    expect_machine(&id, j1, 0x40000000u, 0xFFFFFFFFu);
    EXPECT_FRICTION();
    f405_calibrate();
    (void)snprintf(set, sizeof set, "param set m.j_kgm2 %.9g", j2);
    expect_prefix("ok m.j_kgm2", command(set));
    expect_machine(&id, j2, 0x40000000u, 0xFFFFFFFFu);
    EXPECT_FRICTION();
    expect_prefix("ok enc.cpr 8192", command("param get enc.cpr"));
}

/* A machine parameter the core refuses leaves everything in force as it
 * was: the machine, the controller, its tunables and the drive's settings
 * changed over the link. Before, the restore put back the defaults (wc 0,
 * est.psi_adapt 1). */
static void test_refused_machine_keeps_what_is_in_force(void)
{
    memset(f4_mem_flash_settings, 0xFF, 2u * F4_FLASH_SECTOR_SIZE);
    f405_power_on();
    f405_calibrate();
    TEST_ASSERT_EQUAL_STRING("ok wc 3000", command("param set wc 3000"));
    expect_prefix("ok est.psi_adapt 0", command("param set est.psi_adapt 0"));
    const ctrl_machine_t before = f405.app.fw.machine_own;
    /* 1 uH: Ts Rs / Ld = 50 us x 0.047 ohm / 1 uH = 2.35 > 1 */
    expect_prefix("err 10 failed Ts Rs / Ld = 2.35 outside [0, 1]",
                  command("param set m.ld_h 1e-6"));
    TEST_ASSERT_EQUAL_MEMORY(&before.ld_h, &f405.app.fw.machine_own.ld_h, sizeof before.ld_h);
    TEST_ASSERT_NOT_NULL(f405.app.fw.ctrl);
    TEST_ASSERT_EQUAL_STRING(F405_CTRL, f405.app.fw.ctrl->name);
    TEST_ASSERT_EQUAL_STRING("ok wc 3000 rad/s", command("param get wc"));
    expect_prefix("ok est.psi_adapt 0", command("param get est.psi_adapt"));
}

/* ---- the console's USART on the register model (f4_model_usart_rx) ---- */

static f4_usart_t usart;

/* The console as f405_main.c starts it (f405_uart_init: the board's USART,
 * VESC 6's USART3, on the model), its output kept by the test's console;
 * the drive calibrated. */
static void serial_on(void)
{
    memset(f4_mem_flash_settings, 0xFF, 2u * F4_FLASH_SECTOR_SIZE);
    f405_power_on();
    f405_calibrate();
    TEST_ASSERT_EQUAL_INT(
        F4_OK, f405_uart_init(&f405.app.uart, &usart, f405.board, &f405.clk, f405.board->baud));
    f405.app.uart.port = &console_port;
    f405.app.uart.polled = true;
    TEST_ASSERT_EQUAL_UINT32(20000u, f405.app.uart.lost_idle_ticks);
    n_reply = 0;
}

/* Characters on the wire; serviced: the USART interrupt runs after each (a
 * core that does not stall), else they wait in the receiver (a core stalled
 * on a flash sector erase: 250 ms is over 2 800 characters at 115 200 Bd,
 * and the F4's USART keeps one, in DR). */
static void wire(const char *text, bool serviced)
{
    for (const char *c = text; *c != '\0'; c++) {
        f4_model_usart_rx(usart.base, (uint8_t)*c, 0u);
        if (serviced) {
            f405_uart_irq(&f405.app.uart, &usart);
        }
    }
}

/* The main loop's passes as f405_main.c runs them (one line each). */
static void main_loop(unsigned passes)
{
    for (unsigned pass = 0; pass < passes; pass++) {
        board_app_console(&f405.app, f405_uart_next);
        fw_link_poll(&f405.app.link);
    }
}

/* The reply lines that answer a line ("ok ...", "err ..."). */
static unsigned answers(void)
{
    unsigned n = 0;
    for (size_t k = 0; k < n_reply; k++) {
        n += strncmp(reply[k], "ok", 2) == 0 || strncmp(reply[k], "err", 3) == 0;
    }
    return n;
}

/* Bytes an overrun lost in the middle of a line (the core stalled while
 * "rs_ohm 15.0" arrived: DR kept the 'r', ORE lost the other 10): the line
 * is discarded up to its end of line and answered "err 13 lost" naming the
 * overrun (what is left of it, "param set m.r9", is not run), and the next
 * command is answered alone. Before: "param set m.r9" ran (err 5 name). */
static void test_overrun_discards_its_line(void)
{
    serial_on();
    char fault_alone[160], rs_before[160];
    strcpy(fault_alone, command("fault"));
    strcpy(rs_before, command("param get m.rs_ohm"));
    n_reply = 0;
    wire("param set m.", true);
    wire("rs_ohm 15.0", false); /* stalled */
    TEST_ASSERT_EQUAL_UINT32(10u, f4_model.usart_lost);
    f405_uart_irq(&f405.app.uart, &usart); /* the core runs again: pended */
    wire("9\r", true);
    wire("fault\r", true);
    main_loop(4u);
    TEST_ASSERT_EQUAL_UINT_MESSAGE(2u, answers(), "one answer per end of line");
    TEST_ASSERT_EQUAL_STRING("err 13 lost overrun (ORE)", reply[0]);
    TEST_ASSERT_EQUAL_STRING(fault_alone, reply[1]);
    TEST_ASSERT_EQUAL_STRING(rs_before, command("param get m.rs_ohm"));
    TEST_ASSERT_EQUAL_UINT32(1u, f405.app.uart.rx_errors);
    TEST_ASSERT_EQUAL_UINT32(0u, f4_model_get(usart.base + F4_USART_SR) &
                                     (F4_USART_SR_ORE | F4_USART_SR_RXNE));
}

/* An overrun that lost the end of line ("ohm\r" sent while the core
 * stalled; DR kept the 'o'): nothing comes after it, so the line is taken
 * as ended once idle BOARD_UART_LOST_IDLE_MS after the loss, answered
 * "err 13 lost" then and not before, and the next line read alone. Before:
 * no answer, and the next line ran as "param get m.rs_ofault". */
static void test_lost_end_of_line_answered_after_the_idle_time(void)
{
    serial_on();
    char fault_alone[160];
    strcpy(fault_alone, command("fault"));
    n_reply = 0;
    wire("param get m.rs_", true);
    wire("ohm\r", false); /* stalled */
    TEST_ASSERT_EQUAL_UINT32(3u, f4_model.usart_lost);
    f405_uart_irq(&f405.app.uart, &usart);
    main_loop(2u);
    test_now += 19000u; /* 19 ms on: the line may still go on */
    main_loop(2u);
    TEST_ASSERT_EQUAL_UINT_MESSAGE(0u, answers(), "not before the idle time");
    test_now += 1000u;
    main_loop(2u);
    TEST_ASSERT_EQUAL_UINT(1u, answers());
    TEST_ASSERT_EQUAL_STRING("err 13 lost overrun (ORE)", reply[0]);
    n_reply = 0;
    wire("fault\r", true);
    main_loop(2u);
    TEST_ASSERT_EQUAL_UINT(1u, answers());
    TEST_ASSERT_EQUAL_STRING(fault_alone, reply[0]);
}

/* "  disarm" whose "dis" an overrun lost (DR held the second space when
 * the core stalled): what arrives within the idle
 * time after the loss ("arm") still belongs to the damaged line, which is
 * discarded: never run as "arm". Before: "  arm" ran. With the idle bound
 * 0 the main loop's pass between ends the line and "arm" runs alone. */
static void test_fragment_of_a_damaged_line_never_runs(void)
{
    serial_on();
    /* "arm" alone is taken: answered, the arm requested of the interrupt */
    const volatile uint32_t *arms = &f405.app.fw.ml.req[FW_REQ_ARM];
    const uint32_t arms0 = *arms;
    wire("arm\r", true);
    main_loop(2u);
    TEST_ASSERT_EQUAL_STRING("ok armed", reply[0]);
    TEST_ASSERT_EQUAL_UINT32(arms0 + 1u, *arms);

    n_reply = 0;
    wire(" ", true);
    wire(" dis", false); /* stalled: DR keeps the second space */
    TEST_ASSERT_EQUAL_UINT32(3u, f4_model.usart_lost);
    f405_uart_irq(&f405.app.uart, &usart);
    main_loop(1u); /* a pass between: the line goes on within a character */
    test_now += 100u;
    wire("arm\r", true);
    main_loop(2u);
    TEST_ASSERT_EQUAL_UINT(1u, answers());
    TEST_ASSERT_EQUAL_STRING("err 13 lost overrun (ORE)", reply[0]);
    TEST_ASSERT_EQUAL_UINT32_MESSAGE(arms0 + 1u, *arms, "the fragment 'arm' ran");
}

/* A character with a framing error after an overrun's loss is one received:
 * the sender is still streaming, so the pending loss waits its idle bound
 * from that character, not from the overrun. */
static void test_framing_error_restarts_the_idle_time(void)
{
    serial_on();
    wire("param get m.rs_", true);
    wire("ohm", false); /* stalled: DR keeps the 'o' */
    f405_uart_irq(&f405.app.uart, &usart);
    main_loop(1u);
    test_now += 15000u;
    f4_model_usart_rx(usart.base, '\r', F4_USART_SR_FE);
    f405_uart_irq(&f405.app.uart, &usart);
    test_now += 15000u; /* 30 ms after the overrun, 15 ms after the FE */
    main_loop(2u);
    TEST_ASSERT_EQUAL_UINT_MESSAGE(0u, answers(), "not 20 ms after the overrun");
    test_now += 5000u;
    main_loop(2u);
    TEST_ASSERT_EQUAL_UINT(1u, answers());
    TEST_ASSERT_EQUAL_STRING("err 13 lost overrun (ORE)", reply[0]);
    TEST_ASSERT_EQUAL_UINT32(2u, f405.app.uart.rx_errors);
    TEST_ASSERT_EQUAL_UINT32(0u, f4_model_get(usart.base + F4_USART_SR) & F4_USART_SR_FE);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_identified_machine_survives_a_parameter_change);
    RUN_TEST(test_refused_machine_keeps_what_is_in_force);
    RUN_TEST(test_overrun_discards_its_line);
    RUN_TEST(test_lost_end_of_line_answered_after_the_idle_time);
    RUN_TEST(test_fragment_of_a_damaged_line_never_runs);
    RUN_TEST(test_framing_error_restarts_the_idle_time);
    return UNITY_END();
}
