/*
 * The B-G431B-ESC1's main loop (esc1_app.h): one command line at a time from
 * the serial link, the watchdogs served after each, telemetry out, the
 * throttle, the break interrupt's re-arm, the board temperature and the LED.
 */
#include <math.h>

#include "board_esc1.h"
#include "esc1_app.h"
#include "g4_core.h"
#include "g4_periph.h"

/* The main loop's liveness: the firmware watchdog's kick, the independent
 * watchdog refreshed only while the control interrupt keeps running, the
 * millisecond clock and the throttle. Also called while the serial writer
 * waits for space, so that neither a watchdog nor the throttle's 100 ms
 * loss time-out sees a long reply as a hang. */
void esc1_service(void *ctx)
{
    esc1_t *s = ctx;
    fw_watchdog_kick(&s->fw);
    const uint32_t n = s->isr_count;
    if (n != s->last_isr) {
        s->last_isr = n;
        g4_iwdg_refresh();
    }
    while (g4_cycles() - s->ms_cycle >= s->ms_cycles) {
        s->ms_cycle += s->ms_cycles;
        s->now_ms++;
    }
    esc1_throttle_poll(s);
}

/* Board temperature every 100 ms; over-temperature or a broken sensor latch
 * the board trip (gates off; the firmware latches hw_trip). */
static void esc1_temperature(esc1_t *s)
{
    const int32_t counts = g4_hal_temp_counts(&s->hal);
    s->temp_c = g4_hal_temp_c(s->hal.board, counts);
    if (!s->temp_check) {
        g4_hal_trip_board(&s->hal, false);
        return;
    }
    if (isnan(s->temp_c) || s->temp_c > s->hal.board->temp_trip_c) {
        g4_hal_trip_board(&s->hal, true);
    } else if (s->temp_c < s->hal.board->temp_trip_c - 10.0) {
        g4_hal_trip_board(&s->hal, false); /* 10 C hysteresis */
    }
}

void esc1_loop_once(esc1_t *s)
{
    /* The received bytes up to the end of one command line: a queue of
     * lines (each up to a flash erase long: config erase 2 x 24.5 ms) runs
     * one per pass, with the watchdogs served in between. */
    for (;;) {
        int c = esc1_uart_getc(&s->uart);
        if (c < 0) { /* all read: a line that ended inside a loss ends now */
            c = esc1_uart_lost_idle(&s->uart);
            if (c < 0) {
                break;
            }
        }
        if (c > 0xFF) { /* bytes lost before this one: their line is void */
            cmd_line_lost(&s->link.cmd, esc1_uart_lost_why(c));
        }
        if (fw_link_rx(&s->link, (uint8_t)c)) {
            break;
        }
    }
    fw_link_poll(&s->link);
    esc1_service(s);
    /* The break interrupt, masked by a long break, back on once the
     * comparators are low (the trip stays latched until a clear). */
    (void)g4_hal_break_rearm(&s->hal);
    if (s->thr_losses != s->thr_losses_told) {
        s->thr_losses_told = s->thr_losses;
        esc1_uart_puts(&s->uart, s->thr.cause == THR_CAUSE_NO_PULSE
                                     ? "esc1: throttle: no pulse"
                                     : "esc1: throttle: no valid pulse");
        esc1_uart_puts(&s->uart, " for 100 ms; torque to zero, gates off\r\n");
    }
    /* Once the offset calibration has ended (ready, or its fault): the
     * measured offsets, which the fault alone would not show. */
    const fw_state_id_t st_now = fw_state(&s->fw);
    if (!s->offsets_told && st_now != FW_STATE_BOOT && st_now != FW_STATE_CALIB) {
        char line[80];
        s->offsets_told = true;
        if (fw_link_offsets_text(&s->fw, line, sizeof line) > 0) {
            esc1_uart_puts(&s->uart, "esc1: ");
            esc1_uart_puts(&s->uart, line);
            esc1_uart_puts(&s->uart, "\r\n");
        }
    }
    if (g4_cycles() - s->t_temp >= s->temp_period) {
        s->t_temp += s->temp_period;
        esc1_temperature(s);
        /* LED: on while running, blinking (5 Hz) on a fault. */
        s->blink = !s->blink;
        g4_gpio_write(s->hal.board->led,
                      st_now == FW_STATE_RUNNING || (st_now == FW_STATE_FAULT && s->blink));
    }
}
