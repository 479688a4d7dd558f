/*
 * The anti-cogging table's record (settings_table.h).
 */
#include "settings_table.h"

#include <string.h>

size_t settings_tab_size(unsigned n_log2)
{
    /* header, entries, CRC, rounded up to whole double words */
    return (SETTINGS_TAB_HDR_SIZE + ((size_t)2u << n_log2) + 4u + 7u) & ~(size_t)7u;
}

bool settings_tab_fits(const settings_flash_t *f, unsigned n_log2)
{
    return f != NULL && n_log2 >= SETTINGS_TAB_LOG2_MIN && n_log2 <= SETTINGS_TAB_LOG2_MAX &&
           f->page_size >= SETTINGS_TAB_OFFSET + settings_tab_size(n_log2);
}

static void settings_tab_header(const settings_tab_hdr_t *h, uint32_t seq, uint8_t out[48])
{
    memset(out, 0, SETTINGS_TAB_HDR_SIZE);
    settings_put(out, SETTINGS_TAB_MAGIC, 4u);
    settings_put(out + 4, SETTINGS_TAB_FORMAT, 2u);
    settings_put(out + 6, SETTINGS_TAB_HDR_SIZE, 2u);
    settings_put(out + 8, settings_tab_size(h->n_log2), 4u);
    settings_put(out + 12, seq, 4u);
    settings_put(out + 16, h->enc_cpr, 4u);
    settings_put(out + 20, h->enc_offset, 4u);
    out[24] = (uint8_t)h->enc_dir;
    out[25] = h->n_log2;
    out[26] = h->ff_on;
    settings_put(out + 28, (uint32_t)h->pole_pairs, 4u);
    uint64_t bits;
    memcpy(&bits, &h->torque_rated_nm, sizeof bits);
    settings_put(out + 32, bits, 8u);
    settings_put(out + 40, (uint32_t)1u << h->n_log2, 4u);
}

/* A header's values (the entries' count and the record's length agree with
 * n_log2 where they are read). */
static bool settings_tab_hdr_ok(const settings_tab_hdr_t *h)
{
    uint64_t bits;
    memcpy(&bits, &h->torque_rated_nm, sizeof bits);
    return (h->enc_dir == 1 || h->enc_dir == -1) && h->n_log2 >= SETTINGS_TAB_LOG2_MIN &&
           h->n_log2 <= SETTINGS_TAB_LOG2_MAX && h->ff_on <= 1u && h->pole_pairs >= 1 &&
           h->enc_cpr >= 2u && ((bits >> 52) & 0x7FFu) != 0x7FFu && h->torque_rated_nm > 0.0;
}

int settings_tab_program(const void *tab, const settings_flash_t *f, unsigned page, uint32_t seq,
                         uint8_t *buf, size_t cap)
{
    /* a double word at a time from the header and the entries; buf only for
     * the read-back */
    const settings_tab_t *t = tab;
    if (t == NULL || t->entries == NULL || !settings_tab_fits(f, t->hdr.n_log2)) {
        return SETTINGS_STORE_E_ARGS;
    }
    if (!settings_tab_hdr_ok(&t->hdr)) {
        return SETTINGS_STORE_E_ENCODE;
    }
    uint8_t hdr[SETTINGS_TAB_HDR_SIZE];
    settings_tab_header(&t->hdr, seq, hdr);
    const size_t len = settings_tab_size(t->hdr.n_log2);
    const size_t end = SETTINGS_TAB_HDR_SIZE + ((size_t)2u << t->hdr.n_log2);
    uint32_t crc = SETTINGS_CRC_INIT;
    int rc = 0;
    for (size_t off = 0; rc == 0 && off < len; off += 8u) {
        uint8_t dw[8];
        for (unsigned b = 0; b < 8u; b++) {
            const size_t i = off + b;
            if (i < SETTINGS_TAB_HDR_SIZE) {
                dw[b] = hdr[i];
            } else if (i < end) {
                const size_t k = (i - SETTINGS_TAB_HDR_SIZE) / 2u;
                const uint16_t e = (uint16_t)t->entries[k]; /* two's complement bits */
                dw[b] = (uint8_t)((i & 1u) == 0u ? e : e >> 8);
            } else {
                dw[b] = 0xFFu;
            }
        }
        if (off + 8u == len) {
            crc = settings_crc32_update(crc, dw, 4u);
            settings_put(dw + 4, ~crc, 4u);
        } else {
            crc = settings_crc32_update(crc, dw, 8u);
        }
        rc = f->program(f->ctx, page, (uint32_t)(SETTINGS_TAB_OFFSET + off), dw);
    }
    if (rc != 0) {
        return rc;
    }
    /* read back through the checks the next boot applies (the entries' CRC) */
    settings_tab_hdr_t back;
    return settings_tab_load(f, page, seq, buf, cap, &back, NULL, 0u, NULL) == SETTINGS_OK
               ? 0
               : SETTINGS_STORE_E_VERIFY;
}

/* An entry from its two bytes, without implementation-defined conversion. */
static int16_t settings_tab_entry(const uint8_t *p)
{
    const int32_t u = (int32_t)p[0] | ((int32_t)p[1] << 8);
    return (int16_t)(u >= 0x8000 ? u - 0x10000 : u);
}

settings_status_t settings_tab_load(const settings_flash_t *f, unsigned page, uint32_t seq,
                                    uint8_t *buf, size_t cap, settings_tab_hdr_t *hdr,
                                    int16_t *entries, size_t n_max, uint16_t *format)
{
    if (format != NULL) {
        *format = 0;
    }
    if (f == NULL || f->read == NULL || buf == NULL || cap < 64u || hdr == NULL ||
        f->page_size < SETTINGS_TAB_OFFSET + SETTINGS_TAB_HDR_SIZE) {
        return SETTINGS_E_READ;
    }
    if (f->read(f->ctx, page, SETTINGS_TAB_OFFSET, buf, SETTINGS_TAB_HDR_SIZE) != 0) {
        return SETTINGS_E_READ;
    }
    if (settings_get(buf, 4u) != SETTINGS_TAB_MAGIC) {
        for (size_t i = 0; i < SETTINGS_TAB_HDR_SIZE; i++) {
            if (buf[i] != 0xFFu) {
                return SETTINGS_E_MAGIC;
            }
        }
        return SETTINGS_E_EMPTY;
    }
    const uint16_t fmt = (uint16_t)settings_get(buf + 4, 2u);
    if (format != NULL) {
        *format = fmt;
    }
    const size_t len = (size_t)settings_get(buf + 8, 4u);
    if (len < SETTINGS_TAB_HDR_SIZE + 4u || (len & 7u) != 0u ||
        len > f->page_size - SETTINGS_TAB_OFFSET) {
        return SETTINGS_E_LENGTH;
    }
    /* the CRC first: a version or a length is only believed when intact */
    uint32_t crc = SETTINGS_CRC_INIT;
    for (size_t off = 0; off < len - 4u;) {
        const size_t n = (len - 4u - off) < cap ? (len - 4u - off) : cap;
        if (f->read(f->ctx, page, (uint32_t)(SETTINGS_TAB_OFFSET + off), buf, n) != 0) {
            return SETTINGS_E_READ;
        }
        crc = settings_crc32_update(crc, buf, n);
        off += n;
    }
    if (f->read(f->ctx, page, (uint32_t)(SETTINGS_TAB_OFFSET + len - 4u), buf, 4u) != 0) {
        return SETTINGS_E_READ;
    }
    if (settings_get(buf, 4u) != ~crc) {
        return SETTINGS_E_CRC;
    }
    if (fmt < SETTINGS_TAB_FORMAT) {
        return SETTINGS_E_OLD;
    }
    if (fmt > SETTINGS_TAB_FORMAT) {
        return SETTINGS_E_NEW;
    }
    if (f->read(f->ctx, page, SETTINGS_TAB_OFFSET, buf, SETTINGS_TAB_HDR_SIZE) != 0) {
        return SETTINGS_E_READ;
    }
    settings_tab_hdr_t h;
    h.seq = (uint32_t)settings_get(buf + 12, 4u);
    h.enc_cpr = (uint32_t)settings_get(buf + 16, 4u);
    h.enc_offset = (uint32_t)settings_get(buf + 20, 4u);
    h.enc_dir = buf[24] == 1u ? 1 : (buf[24] == 0xFFu ? -1 : 0);
    h.n_log2 = buf[25];
    h.ff_on = buf[26];
    const uint32_t pp = (uint32_t)settings_get(buf + 28, 4u);
    h.pole_pairs = pp <= 0x7FFFFFFFu ? (int32_t)pp : -1;
    const uint64_t bits = settings_get(buf + 32, 8u);
    memcpy(&h.torque_rated_nm, &bits, sizeof bits);
    if (settings_get(buf + 6, 2u) != SETTINGS_TAB_HDR_SIZE || buf[27] != 0u ||
        settings_get(buf + 44, 4u) != 0u || !settings_tab_hdr_ok(&h)) {
        return SETTINGS_E_VALUE;
    }
    const size_t n = (size_t)1u << h.n_log2;
    if (len != settings_tab_size(h.n_log2) || settings_get(buf + 40, 4u) != n ||
        (entries != NULL && n > n_max)) {
        return SETTINGS_E_LENGTH;
    }
    if (h.seq != seq) {
        return SETTINGS_E_VALUE; /* another record's table */
    }
    /* the entries, a work area at a time (an even number of bytes) */
    const size_t step = cap & ~(size_t)1u;
    for (size_t off = 0; entries != NULL && off < 2u * n; off += step) {
        const size_t m = (2u * n - off) < step ? (2u * n - off) : step;
        if (f->read(f->ctx, page, (uint32_t)(SETTINGS_TAB_OFFSET + SETTINGS_TAB_HDR_SIZE + off),
                    buf, m) != 0) {
            return SETTINGS_E_READ; /* entries before it written: the caller drops them */
        }
        for (size_t i = 0; i < m; i += 2u) {
            entries[(off + i) / 2u] = settings_tab_entry(buf + i);
        }
    }
    *hdr = h;
    return SETTINGS_OK;
}
