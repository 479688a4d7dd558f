/*
 * Two-page settings store (settings_store.h).
 */
#include "settings_store.h"

#include <stdio.h>
#include <string.h>

static bool settings_store_args(const settings_flash_t *f, const uint8_t *buf, size_t cap)
{
    const size_t len = settings_record_size();
    return f != NULL && buf != NULL && cap >= len && f->page_size >= len &&
           (f->page_size & 7u) == 0u && f->read != NULL && f->erase != NULL && f->program != NULL;
}

/* Read and check one page's record. */
static void settings_store_scan_page(const settings_flash_t *f, unsigned page, uint8_t *buf,
                                     size_t len, settings_t *s, settings_scan_t *scan)
{
    const int rc = f->read(f->ctx, page, 0u, buf, len);
    scan->read_rc[page] = rc;
    scan->seq[page] = 0;
    scan->format[page] = 0;
    if (rc != 0) {
        scan->status[page] = SETTINGS_E_READ;
        return;
    }
    scan->status[page] = settings_decode(buf, len, s, &scan->seq[page], &scan->format[page]);
}

settings_status_t settings_store_load(const settings_flash_t *f, uint8_t *buf, size_t cap,
                                      settings_t *s, settings_scan_t *scan)
{
    settings_scan_t local;
    if (scan == NULL) {
        scan = &local;
    }
    memset(scan, 0, sizeof *scan);
    scan->page = -1;
    if (!settings_store_args(f, buf, cap)) {
        scan->status[0] = scan->status[1] = SETTINGS_E_READ;
        return SETTINGS_E_READ;
    }
    const size_t len = settings_record_size();
    settings_t rec[2];
    for (unsigned p = 0; p < 2u; p++) {
        settings_store_scan_page(f, p, buf, len, &rec[p], scan);
    }
    const bool ok0 = scan->status[0] == SETTINGS_OK;
    const bool ok1 = scan->status[1] == SETTINGS_OK;
    if (ok0 || ok1) {
        scan->page = (ok1 && (!ok0 || scan->seq[1] > scan->seq[0])) ? 1 : 0;
        if (s != NULL) {
            *s = rec[scan->page];
        }
        return SETTINGS_OK;
    }
    for (unsigned p = 0; p < 2u; p++) {
        if (scan->status[p] == SETTINGS_E_OLD || scan->status[p] == SETTINGS_E_NEW) {
            return scan->status[p];
        }
    }
    if (scan->status[0] == SETTINGS_E_EMPTY && scan->status[1] == SETTINGS_E_EMPTY) {
        return SETTINGS_E_EMPTY;
    }
    return scan->status[0] != SETTINGS_E_EMPTY ? scan->status[0] : scan->status[1];
}

int settings_store_save(const settings_flash_t *f, uint8_t *buf, size_t cap, const settings_t *s,
                        uint32_t *seq_out)
{
    return settings_store_save_with(f, buf, cap, s, NULL, NULL, seq_out);
}

int settings_store_save_with(const settings_flash_t *f, uint8_t *buf, size_t cap,
                             const settings_t *s, settings_store_writer_t write, const void *wctx,
                             uint32_t *seq_out)
{
    if (s == NULL || !settings_store_args(f, buf, cap)) {
        return SETTINGS_STORE_E_ARGS;
    }
    settings_scan_t scan;
    (void)settings_store_load(f, buf, cap, NULL, &scan);
    /* the other page than the newest valid record; page 0 when there is none */
    const unsigned page = scan.page == 0 ? 1u : 0u;
    const uint32_t seq = scan.page >= 0 ? scan.seq[scan.page] + 1u : 1u;
    const size_t len = settings_encode(s, seq, buf, cap);
    if (len == 0u) {
        return SETTINGS_STORE_E_ENCODE;
    }
    int rc = f->erase(f->ctx, page);
    if (rc == 0 && write != NULL) {
        rc = write(wctx, f, page, seq, buf + len, cap - len); /* buf: the record so far */
    }
    for (size_t off = 0; rc == 0 && off < len; off += 8u) {
        rc = f->program(f->ctx, page, (uint32_t)off, buf + off);
    }
    if (rc != 0) {
        return rc;
    }
    /* read back through the same checks the next boot applies (the record
     * itself not kept: no second settings_t on the stack) */
    uint32_t seq_back = 0;
    rc = f->read(f->ctx, page, 0u, buf, len);
    if (rc != 0) {
        return rc;
    }
    if (settings_decode(buf, len, NULL, &seq_back, NULL) != SETTINGS_OK || seq_back != seq) {
        return SETTINGS_STORE_E_VERIFY;
    }
    if (seq_out != NULL) {
        *seq_out = seq;
    }
    return SETTINGS_STORE_OK;
}

int settings_store_erase(const settings_flash_t *f, uint8_t *buf, size_t cap)
{
    if (!settings_store_args(f, buf, cap)) {
        return SETTINGS_STORE_E_ARGS;
    }
    settings_scan_t scan;
    (void)settings_store_load(f, buf, cap, NULL, &scan);
    /* the newest record last: a cut in between leaves it, not an older one */
    const unsigned first = scan.page == 0 ? 1u : 0u;
    int rc = f->erase(f->ctx, first);
    if (rc == 0) {
        rc = f->erase(f->ctx, 1u - first);
    }
    return rc;
}

size_t settings_load_message(const settings_scan_t *scan, char *out, size_t cap)
{
    if (out == NULL || cap == 0u) {
        return 0;
    }
    int n;
    if (scan->page >= 0) {
        /* a format-1 record has no throttle input (settings.h): said, as the
         * throttle then runs on its defaults */
        n = snprintf(out, cap, "settings: record %lu (page %d%s) applied",
                     (unsigned long)scan->seq[scan->page], scan->page,
                     scan->format[scan->page] < 2u ? ", format 1: throttle input not stored" : "");
    } else {
        unsigned p = 0;
        while (p < 2u && scan->status[p] == SETTINGS_E_EMPTY) {
            p++;
        }
        if (p == 2u) {
            n = snprintf(out, cap, "settings: no record in flash,");
        } else {
            /* an older or newer format is named first */
            for (unsigned q = 0; q < 2u; q++) {
                if (scan->status[q] == SETTINGS_E_OLD || scan->status[q] == SETTINGS_E_NEW) {
                    p = q;
                }
            }
            if (scan->status[p] == SETTINGS_E_OLD || scan->status[p] == SETTINGS_E_NEW) {
                n = snprintf(out, cap,
                             "settings: page %u: record format %u (this firmware reads %u to "
                             "%u), refused;",
                             p, (unsigned)scan->format[p], SETTINGS_FORMAT_MIN, SETTINGS_FORMAT);
            } else {
                n = snprintf(out, cap, "settings: page %u: %s, no valid record;", p,
                             settings_status_name(scan->status[p]));
            }
        }
        /* what runs instead, once for the three cases (flash) */
        if (n >= 0 && (size_t)n < cap) {
            const int m = snprintf(out + n, cap - (size_t)n, " compiled-in defaults");
            n = m < 0 ? m : n + m;
        }
    }
    return n < 0 ? 0u : ((size_t)n < cap ? (size_t)n : cap - 1u);
}

const char *settings_store_strerror(const settings_flash_t *f, int rc)
{
    switch (rc) {
    case SETTINGS_STORE_OK:
        return "ok";
    case SETTINGS_STORE_E_ARGS:
        return "no flash for settings";
    case SETTINGS_STORE_E_ENCODE:
        return "a value is not finite";
    case SETTINGS_STORE_E_VERIFY:
        return "record read back differs";
    default:
        return (f != NULL && f->strerror != NULL) ? f->strerror(rc) : "flash error";
    }
}
