/*
 * The B-G431B-ESC1's settings store (esc1_app.h, built with
 * PMSM_ESC1_SETTINGS): the record of fw_settings.h in the last two flash
 * pages through the register-level driver (hal/stm32g4/g4_flash.h), applied
 * at start-up, saved and shown by the "config" commands.
 */
#include <string.h>

#include "cmd.h"
#include "controller.h"
#include "esc1_app.h"
#include "fw_params.h"
#include "g4_flash.h"

static int esc1_flash_read(void *ctx, unsigned page, uint32_t off, uint8_t *buf, size_t n)
{
    (void)ctx;
    return g4_flash_read(page, off, buf, n);
}

static int esc1_flash_erase(void *ctx, unsigned page)
{
    (void)ctx;
    return g4_flash_erase(page);
}

static int esc1_flash_program(void *ctx, unsigned page, uint32_t off, const uint8_t dw[8])
{
    (void)ctx;
    uint32_t w[2];
    memcpy(w, dw, sizeof w); /* little-endian target: dw[0] is the low byte */
    return g4_flash_program(page, off, w[0], w[1]);
}

/* The record's machine, encoder and configuration, through the same path as a
 * parameter change (esc1_reconfigure_cfg: previous data kept on a refusal),
 * and its throttle input, checked first so that a refused record changes
 * nothing. The decoder restarts disarmed (the saving and the loading are
 * refused while the gates are on or an arm is pending). */
static int esc1_settings_apply(void *ctx, const settings_t *rec, char *why, size_t cap)
{
    esc1_t *s = (esc1_t *)ctx;
    ctrl_machine_t m;
    fw_config_t c;
    thr_config_t tc;
    if (fw_settings_thr_config(rec, &tc, why, cap) != FW_OK ||
        fw_settings_config(rec, &m, &c, s->ctrl_cfg.bytes, why, cap) != FW_OK) {
        return CMD_E_FAILED;
    }
    const int rc = esc1_reconfigure_cfg(s, &m, rec->enc_cpr, &c);
    if (rc != CMD_OK) {
        (void)fw_explain(&s->fw, why, cap);
    } else {
        thr_init(&s->thr, &tc, s->now_ms);
    }
    return rc;
}

static int esc1_settings_default(void *ctx)
{
    esc1_t *s = (esc1_t *)ctx;
    fw_config_t c;
    esc1_config_default(&c, s->hal.board, &esc1_default_machine, ctrl_find(ESC1_CTRL));
    const int rc = esc1_reconfigure_cfg(s, &esc1_default_machine, ESC1_ENCODER_CPR, &c);
    if (rc == CMD_OK) {
        thr_config_t tc;
        thr_config_default(&tc);
        thr_init(&s->thr, &tc, s->now_ms);
    }
    return rc;
}

/* "config save": the throttle input in force. */
static void esc1_settings_capture(void *ctx, settings_t *rec)
{
    fw_settings_thr_capture(rec, &((esc1_t *)ctx)->thr.cfg);
}

void esc1_settings_start(esc1_t *s)
{
    fw_settings_t *st = &s->settings;
    memset(st, 0, sizeof *st);
    st->flash.page_size = G4_FLASH_PAGE_SIZE;
    st->flash.read = esc1_flash_read;
    st->flash.erase = esc1_flash_erase;
    st->flash.program = esc1_flash_program;
    st->flash.strerror = g4_flash_strerror;
    st->apply = esc1_settings_apply;
    st->apply_default = esc1_settings_default;
    st->capture = esc1_settings_capture;
    st->ctx = s;
    g4_flash_set_clock(s->hal.board->sysclk_hz); /* started only when the clock is up */
    (void)fw_settings_boot(st);
    fw_link_set_settings(&s->link, st);
#if PMSM_LIVE_PARAMS
    /* The configuration beyond the machine data (esc1_params.c lists those
     * with the board's limits) as parameters, written through the apply. */
    fw_params_attach(&s->link, &fw_params_drive);
#endif
    esc1_uart_puts(&s->uart, st->msg);
    esc1_uart_puts(&s->uart, "\r\n");
}
