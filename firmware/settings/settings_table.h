/*
 * The anti-cogging table's record (control/regulators/cogging_ff.h): a
 * record of its own beside the settings record, in the same flash page
 * (settings_store.h), with the machine and encoder it was measured on, so
 * that a table from another motor or encoder setting is refused by name.
 * Hardware-free, no firmware types, no floating-point arithmetic.
 *
 * Layout of format SETTINGS_TAB_FORMAT (little-endian, a whole number of
 * 64-bit double words), at SETTINGS_TAB_OFFSET of the settings page:
 *   0  u32 magic SETTINGS_TAB_MAGIC ("PMSC")
 *   4  u16 format version
 *   6  u16 header length (SETTINGS_TAB_HDR_SIZE)
 *   8  u32 record length in bytes (header, entries, padding and CRC)
 *  12  u32 sequence number: the settings record's it was written with
 *  16  u32 encoder counts per revolution it was measured with
 *  20  u32 encoder offset then (electrical angle at count 0, 2^-32 turn)
 *  24  i8  encoder direction (+1 / -1), u8 log2 of the entries,
 *      u8  feed-forward on (0/1) when saved, u8 0
 *  28  i32 pole pairs
 *  32  f64 rated torque, N*m (IEEE 754 binary64 bits): the entries' scale
 *  40  u32 entries n (= 2^log2), u32 0
 *  48  n x i16 entries, Q15 of the rated torque (cogging_ff.h)
 *      0xFF padding up to length - 4
 *  len-4 u32 CRC-32 (settings_crc32) of every byte before it
 *
 * The store programs this record before the settings record of the same
 * save and reads it only from the page whose settings record is the newest
 * valid one (settings_store.h): a save cut by a power loss leaves the
 * previous page, its record and its table (or none), never a half table.
 */
#ifndef FIRMWARE_SETTINGS_SETTINGS_TABLE_H
#define FIRMWARE_SETTINGS_SETTINGS_TABLE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "settings.h"
#include "settings_store.h"

#define SETTINGS_TAB_MAGIC 0x43534D50u /* "PMSC" in memory order */
#define SETTINGS_TAB_FORMAT 1u
#define SETTINGS_TAB_HDR_SIZE 48u
#define SETTINGS_TAB_OFFSET SETTINGS_REC_MAX /* in the page, after the settings record */
#define SETTINGS_TAB_LOG2_MIN 3u
#define SETTINGS_TAB_LOG2_MAX 12u

/* What the table was measured on, and whether its feed-forward was on. */
typedef struct {
    uint32_t seq;        /* the settings record's sequence number (the store sets it) */
    uint32_t enc_cpr;    /* counts per revolution */
    uint32_t enc_offset; /* electrical angle at count 0, 2^-32 turn */
    int8_t enc_dir;      /* +1 / -1 */
    uint8_t n_log2;      /* entries = 2^n_log2 */
    uint8_t ff_on;       /* 0/1 */
    int32_t pole_pairs;
    double torque_rated_nm; /* the entries' scale (Q15 of it) */
} settings_tab_hdr_t;

/* A table to save: its header and its 2^hdr.n_log2 entries. */
typedef struct {
    settings_tab_hdr_t hdr;
    const int16_t *entries;
} settings_tab_t;

/* Record length in bytes for 2^n_log2 entries (a multiple of 8). */
size_t settings_tab_size(unsigned n_log2);

/* The store's writer (settings_store_save_with): programs tab's record with
 * sequence number seq at SETTINGS_TAB_OFFSET of page (erased), double word by
 * double word, and reads it back through settings_tab_load's checks (buf:
 * their work area, cap >= 64). 0, SETTINGS_STORE_E_ARGS (the page too
 * small: settings_tab_fits), SETTINGS_STORE_E_ENCODE (a header value outside
 * its range), SETTINGS_STORE_E_VERIFY or a negative device code. */
int settings_tab_program(const void *tab, const settings_flash_t *f, unsigned page, uint32_t seq,
                         uint8_t *buf, size_t cap);

/* True when f's pages hold a table of 2^n_log2 entries beside the record. */
bool settings_tab_fits(const settings_flash_t *f, unsigned n_log2);

/* Read and check the table record of page (that of the newest valid settings
 * record, whose sequence number is seq). buf: a work area (cap >= 64 bytes).
 * entries NULL: the checks alone.
 * On SETTINGS_OK, *hdr and the entries (n_max >= 2^hdr->n_log2, else
 * SETTINGS_E_LENGTH) hold it; otherwise why none is there (entries are
 * untouched, but for a read error after the CRC's check: then they may hold
 * part of it, to be dropped): SETTINGS_E_EMPTY (no table saved), _MAGIC, _OLD / _NEW (*format
 * names it), _LENGTH, _CRC (bit flips), _VALUE (a field outside its values,
 * or a table another record's), _READ (ECC). */
settings_status_t settings_tab_load(const settings_flash_t *f, unsigned page, uint32_t seq,
                                    uint8_t *buf, size_t cap, settings_tab_hdr_t *hdr,
                                    int16_t *entries, size_t n_max, uint16_t *format);

#endif /* FIRMWARE_SETTINGS_SETTINGS_TABLE_H */
