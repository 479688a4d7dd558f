/*
 * The settings record in flash: two pages used alternately (the last two of
 * the device), so that a power cut at any instant of a save leaves either the
 * previous record or the new one readable, never a mixture:
 *
 *   save:  the page NOT holding the newest valid record is erased, the new
 *          record (sequence number + 1) programmed double word by double
 *          word and read back; the other page, untouched, still holds the
 *          previous record until the new one is complete (its CRC-32 covers
 *          every byte, so a torn record never passes).
 *   load:  both pages read and checked (settings_decode); the valid record
 *          with the larger sequence number wins.
 *   erase: the page of the older record first, then the newest one, so a cut
 *          in between leaves the newest record (never an older one).
 *
 * The flash is reached through settings_flash_t (hal/stm32g4/g4_flash.h on
 * the board, settings_flash_model.h on the host and in QEMU). Hardware-free.
 */
#ifndef FIRMWARE_SETTINGS_SETTINGS_STORE_H
#define FIRMWARE_SETTINGS_SETTINGS_STORE_H

#include <stddef.h>
#include <stdint.h>

#include "settings.h"

/* A flash device with two pages of page_size bytes (numbered 0 and 1 here):
 * the settings record at offset 0, the anti-cogging table's record at
 * SETTINGS_TAB_OFFSET where the page holds it (settings_table.h: the F405's
 * 16 KiB sectors, not the G4's 2 KiB pages). */
typedef struct {
    void *ctx;
    uint32_t page_size; /* bytes, a multiple of 8 and >= SETTINGS_REC_MAX */
    /* n bytes from offset off of the page into buf: 0, or a negative device
     * code (an uncorrectable ECC error in a torn double word) */
    int (*read)(void *ctx, unsigned page, uint32_t off, uint8_t *buf, size_t n);
    /* whole page to 0xFF: 0 or a negative device code */
    int (*erase)(void *ctx, unsigned page);
    /* one 64-bit double word (little-endian bytes dw[0..7]) at off (a multiple
     * of 8) of an erased double word: 0 or a negative device code */
    int (*program)(void *ctx, unsigned page, uint32_t off, const uint8_t dw[8]);
    /* name of a device code, e.g. "PROGERR" */
    const char *(*strerror)(int code);
} settings_flash_t;

/* What a scan of both pages found. */
typedef struct {
    settings_status_t status[2]; /* per page */
    uint16_t format[2];          /* format version read (0: none) */
    uint32_t seq[2];             /* sequence numbers of valid records */
    int read_rc[2];              /* device code of a failed read (0: none) */
    int page;                    /* page of the newest valid record, -1: none */
} settings_scan_t;

/* Store codes (negative device codes pass through). */
#define SETTINGS_STORE_OK 0
#define SETTINGS_STORE_E_ARGS 1   /* NULL, a page smaller than a record */
#define SETTINGS_STORE_E_ENCODE 2 /* a double is not finite (settings_encode) */
#define SETTINGS_STORE_E_VERIFY 3 /* the record read back differs */

/* Scan both pages; *s (may be NULL) receives the newest valid record.
 * Returns SETTINGS_OK when one was found, else why none was: SETTINGS_E_EMPTY
 * when both pages are erased, otherwise the first page's reason (an older or
 * newer format takes precedence, so that the message names it). */
settings_status_t settings_store_load(const settings_flash_t *f, uint8_t *buf, size_t cap,
                                      settings_t *s, settings_scan_t *scan);

/* Save s as the newest record (buf: a work area of cap >= settings_record_size()
 * bytes). *seq_out (may be NULL) receives its sequence number. Returns
 * SETTINGS_STORE_OK, a SETTINGS_STORE_E_* code or a negative device code. */
int settings_store_save(const settings_flash_t *f, uint8_t *buf, size_t cap, const settings_t *s,
                        uint32_t *seq_out);

/* The same with another record in the page (the anti-cogging table,
 * settings_table.h): write(wctx, f, page, seq, buf, cap) programs it into
 * the freshly erased page before the settings record, so that the page only
 * counts (its settings record complete) once both are; its code, when not
 * 0, ends the save (the previous page still the newest). write NULL: none. */
typedef int (*settings_store_writer_t)(const void *wctx, const settings_flash_t *f, unsigned page,
                                       uint32_t seq, uint8_t *buf, size_t cap);
int settings_store_save_with(const settings_flash_t *f, uint8_t *buf, size_t cap,
                             const settings_t *s, settings_store_writer_t write, const void *wctx,
                             uint32_t *seq_out);

/* Erase both pages (older record first). */
int settings_store_erase(const settings_flash_t *f, uint8_t *buf, size_t cap);

/* One line about a load: "settings: record 12 (page 1) applied" /
 * "settings: no record in flash, compiled-in defaults" / "settings: page 0:
 * record format 3 (this firmware reads 1 to 2), refused; compiled-in
 * defaults"; a format-1 record's line says that it holds no throttle input. */
size_t settings_load_message(const settings_scan_t *scan, char *out, size_t cap);

/* One line about a save/erase code: "ok", "page 1: PROGERR", ... */
const char *settings_store_strerror(const settings_flash_t *f, int rc);

#endif /* FIRMWARE_SETTINGS_SETTINGS_STORE_H */
