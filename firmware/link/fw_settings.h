/*
 * The settings record (settings.h) on the firmware: what a save captures
 * from the running firmware, the configuration a record gives back, and the
 * "config" commands' side of the link (PROTOCOL.md "Settings").
 *
 * An application that keeps settings owns one fw_settings_t: the flash
 * device (settings_store.h), a work area, and how to reconfigure itself from
 * a record (its HAL may need more than fw_init: the ESC1's over-current
 * threshold, for instance). fw_link_set_settings (fw_link.h) attaches it to
 * the command link; fw_settings_boot applies the newest record at start-up.
 */
#ifndef FIRMWARE_FW_SETTINGS_H
#define FIRMWARE_FW_SETTINGS_H

#include <stddef.h>
#include <stdint.h>

#include "pipeline.h"
#include "settings.h"
#include "settings_store.h"
#include "throttle.h"

#define FW_SETTINGS_MSG_MAX 112u
/* A saved anti-cogging table is refused when the encoder's offset moved by
 * more than 2 degrees electrical (2^-32 turn): the identification's bound. */
#define FW_SETTINGS_TAB_OFFSET_MAX 23860929u

typedef struct {
    settings_flash_t flash;
    /* The drive whose anti-cogging table (pipeline.h) is kept with the
     * record, in its own record (settings_table.h) where the flash's pages
     * hold it; NULL: none (the record alone). */
    fw_t *fw;
    uint8_t buf[SETTINGS_REC_MAX]; /* work area of the store */
    settings_t rec;                /* the record last read ("config show") */
    settings_scan_t scan;          /* what the last read found */
    /* Reconfigure the drive from s (not running): CMD_OK, or a cmd_err_t code
     * with the reason in why (the previous configuration then stays). */
    int (*apply)(void *ctx, const settings_t *s, char *why, size_t cap);
    /* The compiled-in defaults (not running): CMD_OK or a cmd_err_t code. */
    int (*apply_default)(void *ctx);
    /* Optional: the application's own fields of the record, after
     * fw_settings_capture (an application with a throttle input stores it
     * with fw_settings_thr_capture; without one the record says "off"). */
    void (*capture)(void *ctx, settings_t *s);
    void *ctx;
    char msg[FW_SETTINGS_MSG_MAX]; /* the last operation's message */
#if CTRL_COGGING
    /* The table's part of the last start-up: "" (none saved), "cogging
     * table (2048 entries) applied, feed-forward on", or why it was refused
     * ("cogging table refused: encoder 4096 counts per revolution, the
     * table's 16384; feed-forward off"). */
    char tab_msg[FW_SETTINGS_MSG_MAX];
#endif
} fw_settings_t;

/* The firmware's configuration as a record: machine, encoder, inverter,
 * controller and its tunables, speed loop and limits, identification
 * results; the throttle input as fw_settings_thr_capture(s, NULL) gives it
 * (off), which the application's capture replaces with its own. */
void fw_settings_capture(const fw_t *fw, settings_t *s);

/* The throttle input into the record (c NULL: an image without one: the
 * defaults, mode off); thr_stored = 1. */
void fw_settings_thr_capture(settings_t *s, const thr_config_t *c);
/* The throttle input a record gives: its fields (thr_stored), or the
 * defaults for a record that holds none (format 1). FW_OK, or FW_EINVAL when
 * thr_config_check refuses them, with the field, its value and its range in
 * why ("throttle.low_us = 0 outside [800, 1499]"). */
int fw_settings_thr_config(const settings_t *s, thr_config_t *c, char *why, size_t cap);

/* The machine and configuration a record gives: *m from s, *c =
 * fw_config_default(m, the controller of s) with s's values, the controller's
 * SI configuration in cfg_buf (CTRL_CFG_MAX bytes, max_align_t aligned; its
 * defaults for m with s's tunables) and c->ctrl_cfg = cfg_buf. Returns FW_OK,
 * or FW_ENOENT (controller not in this build) / FW_EINVAL (a tunable refused)
 * with the reason in why. */
int fw_settings_config(const settings_t *s, ctrl_machine_t *m, fw_config_t *c, void *cfg_buf,
                       char *why, size_t cap);

/* A record's configuration installed on a drive that nothing else holds
 * (the interactive images, whose commands run between periods): fw_settings_config,
 * then fw_init. Returns CMD_OK, or CMD_E_FAILED with the reason in why (the
 * record's refusal, or fw_explain's). */
int fw_settings_init(fw_t *fw, hal_t *hal, const settings_t *s, void *cfg_buf, char *why,
                     size_t cap);

/* Start-up: the newest valid record applied through st->apply, else the
 * defaults (st->apply_default when a record was refused). st->msg says which
 * ("settings: record 3 (page 1) applied", "settings: no record in flash,
 * compiled-in defaults", ...). Returns true when a record was applied.
 * Then, in an image with anti-cogging and st->fw set, the table saved with
 * that record: loaded when it was measured on what the record configured
 * (the table's entries, the encoder's counts, direction and offset within
 * 2 degrees electrical, the pole pairs and the rated torque that scales it),
 * its feed-forward on if it was on when saved; else refused, the reason in
 * st->tab_msg, and the drive runs without it. */
bool fw_settings_boot(fw_settings_t *st);

#endif /* FIRMWARE_FW_SETTINGS_H */
