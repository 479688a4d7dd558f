/* What every board image shares above its chip's HAL (board_app.h). */
#include "board_app.h"

#include <math.h>
#include <string.h>

#include "board_app_cfg.h" /* the image's back-end of hal.h: its struct hal */
#include "cmd.h"
#include "fw_params.h"

void board_app_config_default(const board_app_t *a, fw_config_t *c, const ctrl_machine_t *m,
                              const ctrl_desc_t *ctrl)
{
    fw_config_default(c, m, ctrl);
    c->dead_time_s = a->port->dead_time_s(a);
}

static void board_app_write(void *ctx, const uint8_t *bytes, size_t len)
{
    board_uart_write((board_uart_t *)ctx, bytes, len);
}

int board_app_start(board_app_t *a, const board_app_port_t *port, hal_t *hal)
{
    a->port = port;
    a->hal = hal;
    a->machine = *port->machine;
    a->encoder_cpr = port->encoder_cpr;
    a->temp_check = true;
    a->temp_c = NAN;
    a->ms_ticks = port->ticks_hz / 1000u;
    a->ms_tick = port->ticks();
    a->isr_watch_ticks = (uint32_t)((uint64_t)BOARD_ISR_WATCH_US * port->ticks_hz / 1000000u);
    board_app_config_default(a, &a->fc, &a->machine, ctrl_find(port->ctrl));
    const int rc = fw_init(&a->fw, hal, &a->fc);
    fw_link_init(&a->link, &a->fw, board_app_write, &a->uart);
    board_app_params_attach(a);
    thr_config_t c;
    thr_config_default(&c);
    thr_init(&a->thr, &c, a->now_ms);
    return rc;
}

/* The default configuration for the machine staged in a->machine, with what
 * the drive held beyond its machine data (identified, or a settings
 * record's: the encoder's offset and direction, the friction; fw_kept_t),
 * so that a machine parameter changed after it does not put back the
 * uncalibrated encoder (0, +1) or no friction. */
static void board_app_config_kept(board_app_t *a, const ctrl_desc_t *ctrl, const fw_kept_t *kept)
{
    board_app_config_default(a, &a->fc, &a->machine, ctrl);
    fw_kept_config(kept, &a->fc);
}

/* What a refusal puts back (fw_in_force_t; static: the stack of the
 * deepest command path does not grow by it). */
static fw_in_force_t board_app_in_force;

int board_app_reconfigure(board_app_t *a, const ctrl_machine_t *m, uint32_t encoder_cpr,
                          const fw_config_t *cfg)
{
    /* fw_init starts the firmware anew: not while the gates are on (running,
     * or an identification driving the legs) or about to go on */
    if (fw_gates_on_or_pending(&a->fw)) {
        return CMD_E_STATE;
    }
    if (encoder_cpr < 4u || encoder_cpr > 0xFFFFu) {
        return CMD_E_RANGE;
    }
    const ctrl_machine_t old = a->fw.machine_own; /* in force ("ident apply" rewrites it) */
    const uint32_t old_cpr = a->encoder_cpr;
    fw_kept_t kept; /* fw_init clears fw_t: read here */
    fw_kept_read(&a->fw, &kept);
    /* fw_init clears fw_t: the controller in use and its settings kept for the restore */
    const ctrl_desc_t *ctrl = a->fw.ctrl;
    fw_in_force_read(&a->fw, &board_app_in_force);
    a->port->control_irq(false);
    /* fw_init blocks the main loop for longer than the run window (the
     * board's documentation gives its count), the interrupt masked. */
    if (a->port->watchdog_long != NULL) {
        a->port->watchdog_long(a, true);
    }
    a->machine = *m;
    a->encoder_cpr = encoder_cpr;
    /* every board back-end keeps the hal.h description it reports in its
     * struct hal as `info` (hal_info_get) */
    a->hal->info.encoder_counts_per_rev = encoder_cpr;
    if (cfg != NULL) {
        a->fc = *cfg;
        a->fc.machine = &a->machine;
    } else {
        board_app_config_kept(a, ctrl, &kept);
    }
    int rc = fw_init(&a->fw, a->hal, &a->fc);
    if (rc == FW_OK && a->port->set_trip != NULL && a->port->set_trip(a, &a->machine) != 0) {
        rc = FW_ERANGE;
    }
    if (rc != FW_OK) {
        /* The core's reason for "err 10 failed", before the restore clears it. */
        fw_link_set_why(&a->link, &a->fw.why);
        a->machine = old;
        a->encoder_cpr = old_cpr;
        a->hal->info.encoder_counts_per_rev = old_cpr;
        /* as it was, tunables included; nothing installed before: the defaults */
        if (!fw_in_force_config(&board_app_in_force, &a->machine, &kept, &a->fc)) {
            board_app_config_kept(a, ctrl, &kept);
        }
        (void)fw_init(&a->fw, a->hal, &a->fc);
        if (a->port->set_trip != NULL) {
            (void)a->port->set_trip(a, &a->machine);
        }
    }
    /* the drive's speed reference limit, which it clamps to (as at power-up,
     * fw_link_init): the link refuses a reference beyond it */
    a->link.speed_max_rpm = a->fw.speed_info.speed_ref_max_rpm;
    if (a->port->watchdog_long != NULL) {
        a->port->watchdog_long(a, false);
    }
    a->port->control_irq(true);
    return rc == FW_OK ? CMD_OK : CMD_E_FAILED;
}

void board_app_service(void *ctx)
{
    board_app_t *a = ctx;
    fw_watchdog_kick(&a->fw);
    const uint32_t n = a->isr_count;
    if (n != a->last_isr || a->link.hold != NULL) {
        a->last_isr = n;
        a->port->watchdog_refresh();
    }
    if (a->port->isr_stalled != NULL &&
        board_isr_watch_check(&a->isr_watch, n, a->port->ticks(), a->port->gates_on(),
                              a->isr_watch_ticks)) {
        a->port->isr_stalled(a);
    }
    while (a->port->ticks() - a->ms_tick >= a->ms_ticks) {
        a->ms_tick += a->ms_ticks;
        a->now_ms++;
    }
    board_app_throttle_poll(a);
}

void board_app_throttle_poll(board_app_t *a)
{
    thr_t *t = &a->thr;
    if (t->cfg.mode == THR_MODE_OFF) {
        return;
    }
    uint32_t width, period;
    if (a->port->throttle_read(a, &width, &period)) {
        thr_pulse(t, width, period, a->now_ms);
    }
    fw_t *fw = &a->fw;
    if (t->state == THR_ARMED && !fw_gates_on_or_pending(fw)) {
        /* The drive left running without the throttle (a fault, a link
         * disarm or stop, a refused arm): the stick must come back to its low
         * end for 1 s before it drives again, as at power-up. */
        thr_init(t, &t->cfg, a->now_ms);
    }
    const uint8_t before = t->state;
    const thr_out_t o = thr_update(t, a->now_ms);
    const bool speed = t->cfg.mode == THR_MODE_SPEED;
    if (o.event == THR_EV_ARM) {
        fw_set_torque_ref(fw, 0);
        fw_cmd_arm(fw);
    }
    if (t->state == THR_ARMED) {
        if (speed) {
            fw_set_speed_ref_rpm(fw, (double)o.ref / FX_ONE * fw->speed_info.speed_ref_max_rpm);
            a->thr_tref = fw_speed_loop_torque(fw); /* the medium task's last */
        } else {
            fw_set_torque_ref(fw, fx_mul(o.ref, fw->torque_ref_max));
        }
    } else if (t->state == THR_RAMP_DOWN) {
        /* Torque to zero along the ramp: the throttle's torque, or in speed
         * mode the speed loop's last torque. */
        fw_set_torque_ref(fw,
                          speed ? fx_mul(a->thr_tref, o.ramp) : fx_mul(o.ref, fw->torque_ref_max));
        if (before == THR_ARMED) {
            a->thr_losses++; /* the main loop says so (not from inside a write) */
        }
    }
    if (o.event == THR_EV_DISARM) {
        fw_set_torque_ref(fw, 0);
        fw_cmd_disarm(fw);
    }
}

bool board_app_temperature(board_app_t *a, double temp_c, double trip_c)
{
    a->temp_c = temp_c;
    if (!a->temp_check) {
        a->temp_trip = false;
    } else if (isnan(temp_c) || temp_c > trip_c) {
        a->temp_trip = true;
    } else if (temp_c < trip_c - 10.0) {
        a->temp_trip = false; /* 10 C hysteresis */
    }
    return a->temp_trip;
}

void board_app_console(board_app_t *a, int (*next)(board_uart_t *u))
{
    int c;
    while ((c = next(&a->uart)) >= 0) {
        if (c > 0xFF) { /* bytes lost before this one: their line is void */
            cmd_line_lost(&a->link.cmd, board_uart_lost_why(c));
        }
        if (fw_link_rx(&a->link, (uint8_t)c)) {
            break; /* one command line per pass: the watchdogs after each */
        }
    }
}

void board_app_messages(board_app_t *a)
{
    if (a->thr_losses != a->thr_losses_told) {
        a->thr_losses_told = a->thr_losses;
        board_uart_puts(&a->uart, a->port->tag);
        board_uart_puts(&a->uart,
                        a->thr.cause == THR_CAUSE_NO_PULSE
                            ? "throttle: no pulse for 100 ms; torque to zero, gates off\r\n"
                            : "throttle: no valid pulse for 100 ms; torque to zero, "
                              "gates off\r\n");
    }
    /* Once the offset calibration has ended (ready, or its fault): the
     * measured offsets, which the fault alone would not show. */
    const fw_state_id_t st = fw_state(&a->fw);
    if (!a->offsets_told && st != FW_STATE_BOOT && st != FW_STATE_CALIB) {
        char line[80];
        a->offsets_told = true;
        if (fw_link_offsets_text(&a->fw, line, sizeof line) > 0) {
            board_uart_puts(&a->uart, a->port->tag);
            board_uart_puts(&a->uart, line);
            board_uart_puts(&a->uart, "\r\n");
        }
    }
}

/* ---- settings ---- */

/* The record's machine, encoder and configuration, through the same path as
 * a parameter change (previous data kept on a refusal), and its throttle
 * input, checked first so that a refused record changes nothing. */
static int board_app_settings_apply(void *ctx, const settings_t *rec, char *why, size_t cap)
{
    board_app_t *a = ctx;
    ctrl_machine_t m;
    fw_config_t c;
    thr_config_t tc;
    if (fw_settings_thr_config(rec, &tc, why, cap) != FW_OK ||
        fw_settings_config(rec, &m, &c, a->ctrl_cfg.bytes, why, cap) != FW_OK) {
        return CMD_E_FAILED;
    }
    const int rc = board_app_reconfigure(a, &m, rec->enc_cpr, &c);
    if (rc != CMD_OK) {
        (void)fw_explain(&a->fw, why, cap);
    } else {
        thr_init(&a->thr, &tc, a->now_ms);
    }
    return rc;
}

static int board_app_settings_default(void *ctx)
{
    board_app_t *a = ctx;
    fw_config_t c;
    board_app_config_default(a, &c, a->port->machine, ctrl_find(a->port->ctrl));
    const int rc = board_app_reconfigure(a, a->port->machine, a->port->encoder_cpr, &c);
    if (rc == CMD_OK) {
        thr_config_t tc;
        thr_config_default(&tc);
        thr_init(&a->thr, &tc, a->now_ms);
    }
    return rc;
}

/* "config save": the throttle input in force. */
static void board_app_settings_capture(void *ctx, settings_t *rec)
{
    fw_settings_thr_capture(rec, &((board_app_t *)ctx)->thr.cfg);
}

void board_app_settings_start(board_app_t *a, const settings_flash_t *flash)
{
    fw_settings_t *st = &a->settings;
    memset(st, 0, sizeof *st);
    st->flash = *flash;
    st->apply = board_app_settings_apply;
    st->apply_default = board_app_settings_default;
    st->capture = board_app_settings_capture;
    st->ctx = a;
    st->fw = &a->fw; /* the anti-cogging table beside the record (F405 sectors) */
    (void)fw_settings_boot(st);
    fw_link_set_settings(&a->link, st);
#if PMSM_LIVE_PARAMS
    fw_params_attach(&a->link, &fw_params_drive);
#endif
    board_uart_puts(&a->uart, a->port->tag);
    board_uart_puts(&a->uart, st->msg);
    board_uart_puts(&a->uart, "\r\n");
#if CTRL_COGGING
    if (st->tab_msg[0] != '\0') {
        board_uart_puts(&a->uart, a->port->tag);
        board_uart_puts(&a->uart, st->tab_msg);
        board_uart_puts(&a->uart, "\r\n");
    }
#endif
}
