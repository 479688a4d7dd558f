/*
 * The settings record: what a drive keeps across a reset or a power cut
 * (machine and sensor data, inverter data, the controller and its tunables,
 * the speed loop and its limits, the throttle input, the identification's
 * results), its byte layout in flash and its checks. Hardware-free: no
 * firmware types, no floating-point arithmetic (a double is kept as its
 * IEEE 754 binary64 bits), no globals; the flash itself is settings_store.h.
 *
 * Layout of format SETTINGS_FORMAT (little-endian, packed, a whole number of
 * 64-bit double words because the flash programs double words):
 *   0  u32 magic SETTINGS_MAGIC ("PMSS")
 *   4  u16 format version
 *   6  u16 record length in bytes (header, body, padding and CRC)
 *   8  u32 sequence number (a save writes the previous one + 1)
 *  12  u32 body length in bytes (the fields of settings_fields[] in order)
 *  16  body
 *      0xFF padding up to length - 4
 *  len-4 u32 CRC-32 (IEEE 802.3: reflected 0xEDB88320, init and xorout
 *      0xFFFFFFFF) of every byte before it
 * A record of another format version is refused with its version named
 * (settings_decode: SETTINGS_E_OLD / SETTINGS_E_NEW). This firmware writes
 * format 3 and reads formats 1 to 3. A format appends its fields at the end
 * of the body (settings.c: the fields each format has), and a record of an
 * earlier format is read with the fields it lacks zero:
 *   format 1: the layout of format 2, but its writers never stored the
 *             throttle input (its four fields hold zeroes, which no throttle
 *             check accepts): read with thr_stored = 0 and its throttle
 *             fields cleared; the firmware keeps the throttle's defaults
 *             (fw_settings_thr_config);
 *   format 2: no friction (m.coulomb_nm, m.viscous_nms, id.coulomb_nm,
 *             id.viscous_nms read as 0: none known).
 * A later format appends its fields and its entry in settings.c's table.
 *
 * The anti-cogging table is a record of its own in the same flash page
 * (settings_table.h): 4 KiB does not fit this record's page on every board.
 */
#ifndef FIRMWARE_SETTINGS_SETTINGS_H
#define FIRMWARE_SETTINGS_SETTINGS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define SETTINGS_MAGIC 0x53534D50u /* "PMSS" in memory order */
#define SETTINGS_FORMAT 3u         /* written; read: SETTINGS_FORMAT_MIN .. SETTINGS_FORMAT */
#define SETTINGS_FORMAT_MIN 1u     /* format 1: no throttle input stored (thr_stored = 0) */
#define SETTINGS_HDR_SIZE 16u
#define SETTINGS_NAME_MAX 16u     /* controller and tunable names, NUL included */
#define SETTINGS_TUNABLES_MAX 12u /* tunables kept per record (by name) */
#define SETTINGS_REC_MAX 1024u    /* largest record (bytes), below one flash page */

/* Throttle input (servo pulse): what the pulse commands. */
typedef enum {
    SETTINGS_THR_OFF = 0,
    SETTINGS_THR_TORQUE = 1,
    SETTINGS_THR_SPEED = 2
} settings_thr_mode_t;

/* The record's content. SI values as doubles (the configuration's own type);
 * enc_offset in turns, 2^32 = one electrical turn (fx_angle_t). */
typedef struct {
    /* machine (ctrl_machine_t) */
    int32_t pole_pairs;
    double rs_ohm, ld_h, lq_h, psi_pm_wb, vdc_v, inertia_kgm2;
    double torque_rated_nm, speed_rated_rpm, current_rated_a, current_max_a;
    double psi_ref_wb, speed_max_rpm;
    /* position sensor */
    uint32_t enc_cpr;     /* counts per revolution */
    int8_t enc_direction; /* +1 / -1 */
    uint32_t enc_offset;  /* electrical angle at count 0, 2^-32 turn */
    uint8_t sensorless;   /* 0/1: angle from the flux observer; 2: with the injection at and
                           * near standstill (its settings among the tunables, "hfi.*") */
    /* inverter */
    double dead_time_s, v_fwd_v;
    uint8_t psi_adapt; /* 0/1: PM flux tracked from the voltage model */
    /* controller and its tunables (by name: indices differ between builds) */
    char ctrl[SETTINGS_NAME_MAX];
    uint8_t n_tunables;
    char tunable_name[SETTINGS_TUNABLES_MAX][SETTINGS_NAME_MAX];
    double tunable_value[SETTINGS_TUNABLES_MAX];
    /* speed loop and limits (fw_config_t) */
    double speed_bw_hz, speed_pm_deg, speed_kp, speed_ki;
    uint8_t speed_unit; /* ctrl_speed_unit_t */
    double speed_out_max_nm;
    uint32_t speed_loop_hz;
    double overspeed_rpm;
    /* throttle input: mode, calibrated end points, dead band (the values of
     * thr_config_t, firmware/throttle/throttle.h, which checks them) */
    uint8_t thr_mode; /* settings_thr_mode_t */
    uint16_t thr_low_us, thr_high_us, thr_deadband_us;
    /* Not in the layout: 1 when the record holds the throttle input (format 2
     * on); 0 for a format-1 record, whose throttle fields are then cleared and
     * not listed (settings_item_at). settings_encode ignores it. */
    uint8_t thr_stored;
    /* identification results (cm_si_t; informational: what is applied is the
     * machine above, after "ident apply") */
    uint32_t id_have; /* CM_HAVE_* bits */
    double id_rs_ohm, id_ld_h, id_lq_h, id_psi_wb, id_inertia_kgm2, id_enc_offset_deg;
    int8_t id_enc_dir;
    uint32_t id_enc_cpr;
    /* format 3: friction. The drive's (fw_config_t.coulomb_nm, viscous_nms:
     * "ident apply" adopts the identified ones, as the inertia above) and the
     * identification's (informational, as id_* above); 0: none known. */
    double coulomb_nm, viscous_nms;       /* Coulomb (and passive load), N*m; viscous, N*m*s */
    double id_coulomb_nm, id_viscous_nms; /* idem, as identified */
} settings_t;

/* Why a record was not accepted (settings_decode). */
typedef enum {
    SETTINGS_OK = 0,
    SETTINGS_E_EMPTY,  /* erased flash (every byte 0xFF): no record */
    SETTINGS_E_MAGIC,  /* not a settings record */
    SETTINGS_E_OLD,    /* a format older than this firmware reads */
    SETTINGS_E_NEW,    /* a format newer than this firmware reads */
    SETTINGS_E_LENGTH, /* record or body length inconsistent */
    SETTINGS_E_CRC,    /* CRC-32 mismatch (torn write, bit flips) */
    SETTINGS_E_VALUE,  /* a field outside its type's values (non-finite, unterminated name) */
    SETTINGS_E_READ,   /* the flash could not be read (ECC error) */
    SETTINGS_E_COUNT
} settings_status_t;

const char *settings_status_name(settings_status_t st);

/* CRC-32 (IEEE 802.3) of n bytes. */
uint32_t settings_crc32(const uint8_t *data, size_t n);
/* The same in pieces: crc = SETTINGS_CRC_INIT, then each piece in order
 * through settings_crc32_update; the CRC is ~crc at the end. */
#define SETTINGS_CRC_INIT 0xFFFFFFFFu
uint32_t settings_crc32_update(uint32_t crc, const uint8_t *data, size_t n);

/* n <= 8 little-endian bytes at p: written from v / read. */
void settings_put(uint8_t *p, uint64_t v, unsigned n);
uint64_t settings_get(const uint8_t *p, unsigned n);

/* Record length in bytes for this format (a multiple of 8). */
size_t settings_record_size(void);

/* Serialise s with sequence number seq into buf (cap >= settings_record_size()).
 * Returns the length; 0 when cap is too small or a double is not finite
 * (such a record would never load). */
size_t settings_encode(const settings_t *s, uint32_t seq, uint8_t *buf, size_t cap);

/* Parse and check the record at buf (n bytes available). On SETTINGS_OK *s (s
 * may be NULL: a check only) and *seq hold it; otherwise they are untouched. *format (if not NULL)
 * receives the format version read from the header (0 when there is none). */
settings_status_t settings_decode(const uint8_t *buf, size_t n, settings_t *s, uint32_t *seq,
                                  uint16_t *format);

/* Field-by-field listing for "config show": the index-th field's key and
 * value as text (numbers in shortest round-trip-safe form are the caller's:
 * here the double's value through *num, integers through *num exactly, names
 * through *text); the throttle fields only when s->thr_stored. Returns false
 * past the end. */
typedef struct {
    const char *key;  /* e.g. "m.rs_ohm" */
    const char *text; /* non-NULL for a name field */
    double num;       /* the value otherwise */
} settings_item_t;
bool settings_item_at(const settings_t *s, size_t index, settings_item_t *it);

/* A scalar field by its key (settings_item_at's keys, not the tunables' nor
 * the controller's name), to read or write it in place: where it is in the
 * settings_t, and for an integer field the values it admits (its range in the
 * layout, else its type's). f64: the field is a double (read and written as
 * one at `at`). */
typedef struct {
    uint8_t *at;
    bool f64;
    uint8_t type; /* the layout's integer type (settings.c) */
    int64_t lo, hi;
} settings_field_ref_t;
bool settings_field_find(settings_t *s, const char *key, settings_field_ref_t *r);
int64_t settings_field_int(const settings_field_ref_t *r);
/* lo <= v <= hi (the caller checks). */
void settings_field_set_int(const settings_field_ref_t *r, int64_t v);

#endif /* FIRMWARE_SETTINGS_SETTINGS_H */
