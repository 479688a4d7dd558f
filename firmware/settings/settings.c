/*
 * The settings record's serialisation and checks (settings.h). One table,
 * settings_fields[], gives every field's key, place in settings_t, type and
 * the values its type admits; encoding, decoding and the listing all walk it,
 * so the layout has one home.
 */
#include "settings.h"

#include <string.h>

typedef enum { ST_U8, ST_I8, ST_U16, ST_I32, ST_U32, ST_F64, ST_NAME } settings_type_t;

typedef struct {
    const char *key;
    uint16_t offset; /* offsetof(settings_t, field) */
    uint8_t type;    /* settings_type_t */
    uint8_t count;   /* array length (1 for a scalar) */
    int16_t lo;      /* integer types: the values accepted (inclusive; */
    uint16_t hi;     /* lo = hi = 0: every value of the type) */
} settings_field_t;

#define SF(key, field, type, lo, hi)                                                               \
    {                                                                                              \
        key, (uint16_t)offsetof(settings_t, field), type, 1u, lo, hi                               \
    }
#define SF_F64(key, field) SF(key, field, ST_F64, 0, 0)
#define SF_U32(key, field) SF(key, field, ST_U32, 0, 0) /* every value */

/* The body, in order: formats 1 and 2 have the fields up to id.enc_cpr,
 * format 3 the friction after them (settings_nfields). The tunables are
 * listed separately by settings_item_at (their names are data). */
static const settings_field_t settings_fields[] = {
    SF("m.p", pole_pairs, ST_I32, 1, 1000),
    SF_F64("m.rs_ohm", rs_ohm),
    SF_F64("m.ld_h", ld_h),
    SF_F64("m.lq_h", lq_h),
    SF_F64("m.psi_wb", psi_pm_wb),
    SF_F64("m.vdc_v", vdc_v),
    SF_F64("m.j_kgm2", inertia_kgm2),
    SF_F64("m.t_rated_nm", torque_rated_nm),
    SF_F64("m.n_rated_rpm", speed_rated_rpm),
    SF_F64("m.i_rated_a", current_rated_a),
    SF_F64("m.i_max_a", current_max_a),
    SF_F64("m.psi_ref_wb", psi_ref_wb),
    SF_F64("m.n_max_rpm", speed_max_rpm),
    SF_U32("enc.cpr", enc_cpr),
    SF("enc.dir", enc_direction, ST_I8, -1, 1),
    SF_U32("enc.offset", enc_offset),
    SF("est.sensorless", sensorless, ST_U8, 0, 2),
    SF_F64("inv.dead_time_s", dead_time_s),
    SF_F64("inv.v_fwd_v", v_fwd_v),
    SF("est.psi_adapt", psi_adapt, ST_U8, 0, 1),
    {"ctrl", (uint16_t)offsetof(settings_t, ctrl), ST_NAME, 1u, 0, 0},
    SF("ctrl.n_tunables", n_tunables, ST_U8, 0, (uint16_t)SETTINGS_TUNABLES_MAX),
    {"", (uint16_t)offsetof(settings_t, tunable_name), ST_NAME, SETTINGS_TUNABLES_MAX, 0, 0},
    {"", (uint16_t)offsetof(settings_t, tunable_value), ST_F64, SETTINGS_TUNABLES_MAX, 0, 0},
    SF_F64("speed.bw_hz", speed_bw_hz),
    SF_F64("speed.pm_deg", speed_pm_deg),
    SF_F64("speed.kp", speed_kp),
    SF_F64("speed.ki", speed_ki),
    SF("speed.unit", speed_unit, ST_U8, 0, 2),
    SF_F64("lim.torque_nm", speed_out_max_nm),
    SF_U32("speed.loop_hz", speed_loop_hz),
    SF_F64("prot.overspeed_rpm", overspeed_rpm),
    SF("thr.mode", thr_mode, ST_U8, 0, 2),
    SF("thr.low_us", thr_low_us, ST_U16, 0, 65535),
    SF("thr.high_us", thr_high_us, ST_U16, 0, 65535),
    SF("thr.deadband_us", thr_deadband_us, ST_U16, 0, 65535),
    SF_U32("id.have", id_have),
    SF_F64("id.rs_ohm", id_rs_ohm),
    SF_F64("id.ld_h", id_ld_h),
    SF_F64("id.lq_h", id_lq_h),
    SF_F64("id.psi_wb", id_psi_wb),
    SF_F64("id.j_kgm2", id_inertia_kgm2),
    SF_F64("id.enc_offset_deg", id_enc_offset_deg),
    SF("id.enc_dir", id_enc_dir, ST_I8, -1, 1),
    SF_U32("id.enc_cpr", id_enc_cpr),
    /* format 3 */
    SF_F64("m.coulomb_nm", coulomb_nm),
    SF_F64("m.viscous_nms", viscous_nms),
    SF_F64("id.coulomb_nm", id_coulomb_nm),
    SF_F64("id.viscous_nms", id_viscous_nms),
};
#define SETTINGS_NFIELDS (sizeof settings_fields / sizeof settings_fields[0])
#define SETTINGS_NFIELDS_F2 (SETTINGS_NFIELDS - 4u) /* formats 1 and 2 */

/* The fields a record of format fmt (SETTINGS_FORMAT_MIN .. SETTINGS_FORMAT) has. */
static size_t settings_nfields(unsigned fmt)
{
    return fmt >= 3u ? SETTINGS_NFIELDS : SETTINGS_NFIELDS_F2;
}

static const uint8_t settings_type_size[] = {1u, 1u, 2u, 4u, 4u, 8u, SETTINGS_NAME_MAX};

static const char *const settings_status_names[SETTINGS_E_COUNT] = {
    "ok",
    "empty (erased)",
    "not a settings record",
    "format older than this firmware reads",
    "format newer than this firmware reads",
    "length inconsistent",
    "CRC mismatch",
    "field value outside its type",
    "flash read error (ECC)",
};

const char *settings_status_name(settings_status_t st)
{
    return (unsigned)st < (unsigned)SETTINGS_E_COUNT ? settings_status_names[st] : "?";
}

uint32_t settings_crc32_update(uint32_t crc, const uint8_t *data, size_t n)
{
    /* bitwise: no 1 KB table in flash; a record is checked once per boot */
    for (size_t i = 0; i < n; i++) {
        crc ^= data[i];
        for (unsigned b = 0; b < 8u; b++) {
            crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
        }
    }
    return crc;
}

uint32_t settings_crc32(const uint8_t *data, size_t n)
{
    return ~settings_crc32_update(SETTINGS_CRC_INIT, data, n);
}

static size_t settings_body_size(unsigned fmt)
{
    size_t n = 0;
    for (size_t i = 0; i < settings_nfields(fmt); i++) {
        n += (size_t)settings_type_size[settings_fields[i].type] * settings_fields[i].count;
    }
    return n;
}

static size_t settings_record_size_of(unsigned fmt)
{
    /* header, body, CRC, rounded up to whole double words */
    return (SETTINGS_HDR_SIZE + settings_body_size(fmt) + 4u + 7u) & ~(size_t)7u;
}

size_t settings_record_size(void)
{
    return settings_record_size_of(SETTINGS_FORMAT);
}

void settings_put(uint8_t *p, uint64_t v, unsigned n)
{
    for (unsigned i = 0; i < n; i++) {
        p[i] = (uint8_t)(v >> (8u * i));
    }
}

uint64_t settings_get(const uint8_t *p, unsigned n)
{
    uint64_t v = 0;
    for (unsigned i = 0; i < n; i++) {
        v |= (uint64_t)p[i] << (8u * i);
    }
    return v;
}

/* The integer at a field's place as int64 (sign-extended for signed types). */
static int64_t settings_int_of(const void *at, settings_type_t t)
{
    switch (t) {
    case ST_U8:
        return *(const uint8_t *)at;
    case ST_I8:
        return *(const int8_t *)at;
    case ST_U16:
        return *(const uint16_t *)at;
    case ST_I32:
        return *(const int32_t *)at;
    default:
        return *(const uint32_t *)at;
    }
}

static void settings_int_to(void *at, settings_type_t t, uint64_t raw)
{
    switch (t) {
    case ST_U8:
        *(uint8_t *)at = (uint8_t)raw;
        break;
    case ST_I8:
        /* two's complement byte -> value without implementation-defined conversion */
        *(int8_t *)at = (int8_t)((int32_t)(raw & 0xFFu) - (int32_t)((raw & 0x80u) << 1));
        break;
    case ST_U16:
        *(uint16_t *)at = (uint16_t)raw;
        break;
    case ST_I32: {
        const uint32_t u = (uint32_t)raw;
        *(int32_t *)at = (u & 0x80000000u) != 0u ? -(int32_t)(~u) - 1 : (int32_t)u;
        break;
    }
    default:
        *(uint32_t *)at = (uint32_t)raw;
        break;
    }
}

size_t settings_encode(const settings_t *s, uint32_t seq, uint8_t *buf, size_t cap)
{
    const size_t len = settings_record_size();
    if (s == NULL || buf == NULL || cap < len) {
        return 0;
    }
    memset(buf, 0xFF, len);
    settings_put(buf, SETTINGS_MAGIC, 4u);
    settings_put(buf + 4, SETTINGS_FORMAT, 2u);
    settings_put(buf + 6, len, 2u);
    settings_put(buf + 8, seq, 4u);
    settings_put(buf + 12, settings_body_size(SETTINGS_FORMAT), 4u);
    uint8_t *p = buf + SETTINGS_HDR_SIZE;
    const uint8_t *base = (const uint8_t *)s;
    for (size_t i = 0; i < SETTINGS_NFIELDS; i++) {
        const settings_field_t *f = &settings_fields[i];
        const unsigned sz = settings_type_size[f->type];
        for (unsigned k = 0; k < f->count; k++) {
            const uint8_t *at = base + f->offset + (size_t)k * sz;
            if (f->type == ST_NAME) {
                /* up to the NUL, zero after it (a settings_t need not be cleared) */
                memset(p, 0, sz);
                for (unsigned c = 0; c + 1u < sz && at[c] != 0u; c++) {
                    p[c] = at[c];
                }
            } else if (f->type == ST_F64) {
                uint64_t bits;
                memcpy(&bits, at, sizeof bits);
                if (((bits >> 52) & 0x7FFu) == 0x7FFu) {
                    return 0; /* infinity or NaN: the loader would refuse it */
                }
                settings_put(p, bits, 8u);
            } else {
                settings_put(p, (uint64_t)settings_int_of(at, (settings_type_t)f->type), sz);
            }
            p += sz;
        }
    }
    settings_put(buf + len - 4u, settings_crc32(buf, len - 4u), 4u);
    return len;
}

/* A name: printable, no spaces, NUL-terminated inside its field. */
static bool settings_name_ok(const uint8_t *p)
{
    for (unsigned i = 0; i < SETTINGS_NAME_MAX; i++) {
        if (p[i] == 0u) {
            return true;
        }
        if (p[i] <= 0x20u || p[i] > 0x7Eu) {
            return false;
        }
    }
    return false;
}

settings_status_t settings_decode(const uint8_t *buf, size_t n, settings_t *s, uint32_t *seq,
                                  uint16_t *format)
{
    if (format != NULL) {
        *format = 0;
    }
    if (buf == NULL || n < SETTINGS_HDR_SIZE) {
        return SETTINGS_E_LENGTH;
    }
    const uint32_t magic = (uint32_t)settings_get(buf, 4u);
    if (magic != SETTINGS_MAGIC) {
        bool erased = true;
        for (size_t i = 0; i < SETTINGS_HDR_SIZE; i++) {
            erased = erased && buf[i] == 0xFFu;
        }
        return erased ? SETTINGS_E_EMPTY : SETTINGS_E_MAGIC;
    }
    const uint16_t fmt = (uint16_t)settings_get(buf + 4, 2u);
    if (format != NULL) {
        *format = fmt;
    }
    const size_t len = (size_t)settings_get(buf + 6, 2u);
    /* the CRC first: a version field is only believed when the record is intact */
    if (len < SETTINGS_HDR_SIZE + 4u || len > n || len > SETTINGS_REC_MAX || (len & 7u) != 0u) {
        return SETTINGS_E_LENGTH;
    }
    if (settings_get(buf + len - 4u, 4u) != settings_crc32(buf, len - 4u)) {
        return SETTINGS_E_CRC;
    }
    if (fmt < SETTINGS_FORMAT_MIN) {
        return SETTINGS_E_OLD;
    }
    if (fmt > SETTINGS_FORMAT) {
        return SETTINGS_E_NEW;
    }
    if (len != settings_record_size_of(fmt) ||
        settings_get(buf + 12, 4u) != settings_body_size(fmt)) {
        return SETTINGS_E_LENGTH;
    }
    settings_t t;
    memset(&t, 0, sizeof t);
    const uint8_t *p = buf + SETTINGS_HDR_SIZE;
    uint8_t *base = (uint8_t *)&t;
    for (size_t i = 0; i < settings_nfields(fmt); i++) {
        const settings_field_t *f = &settings_fields[i];
        const unsigned sz = settings_type_size[f->type];
        for (unsigned k = 0; k < f->count; k++) {
            uint8_t *at = base + f->offset + (size_t)k * sz;
            if (f->type == ST_NAME) {
                if (!settings_name_ok(p)) {
                    return SETTINGS_E_VALUE;
                }
                memcpy(at, p, sz);
                at[sz - 1u] = 0u;
            } else if (f->type == ST_F64) {
                const uint64_t bits = settings_get(p, 8u);
                if (((bits >> 52) & 0x7FFu) == 0x7FFu) {
                    return SETTINGS_E_VALUE; /* infinity or NaN */
                }
                memcpy(at, &bits, sizeof bits);
            } else {
                settings_int_to(at, (settings_type_t)f->type, settings_get(p, sz));
                const int64_t v = settings_int_of(at, (settings_type_t)f->type);
                if ((f->lo != 0 || f->hi != 0) && (v < f->lo || v > f->hi)) {
                    return SETTINGS_E_VALUE;
                }
            }
            p += sz;
        }
    }
    /* Format 1: the throttle fields were never written (settings.h) */
    t.thr_stored = fmt >= 2u ? 1u : 0u;
    if (t.thr_stored == 0u) {
        t.thr_mode = 0u;
        t.thr_low_us = t.thr_high_us = t.thr_deadband_us = 0u;
    }
    /* the controller's name is required; the tunables in use have names */
    if (t.ctrl[0] == '\0') {
        return SETTINGS_E_VALUE;
    }
    for (unsigned k = 0; k < t.n_tunables; k++) {
        if (t.tunable_name[k][0] == '\0') {
            return SETTINGS_E_VALUE;
        }
    }
    if (s != NULL) {
        *s = t;
    }
    *seq = (uint32_t)settings_get(buf + 8, 4u);
    return SETTINGS_OK;
}

bool settings_item_at(const settings_t *s, size_t index, settings_item_t *it)
{
    /* the table's scalar fields, then the tunables in use */
    size_t i = 0;
    for (size_t k = 0; k < SETTINGS_NFIELDS; k++) {
        const settings_field_t *f = &settings_fields[k];
        if (f->count != 1u || (s->thr_stored == 0u && f->offset >= offsetof(settings_t, thr_mode) &&
                               f->offset <= offsetof(settings_t, thr_deadband_us))) {
            continue;
        }
        if (i++ != index) {
            continue;
        }
        const uint8_t *at = (const uint8_t *)s + f->offset;
        it->key = f->key;
        it->text = NULL;
        it->num = 0.0;
        if (f->type == ST_NAME) {
            it->text = (const char *)at;
        } else if (f->type == ST_F64) {
            memcpy(&it->num, at, sizeof it->num);
        } else {
            it->num = (double)settings_int_of(at, (settings_type_t)f->type);
        }
        return true;
    }
    const size_t t = index - i;
    if (t >= s->n_tunables || t >= SETTINGS_TUNABLES_MAX) {
        return false;
    }
    it->key = s->tunable_name[t];
    it->text = NULL;
    it->num = s->tunable_value[t];
    return true;
}

bool settings_field_find(settings_t *s, const char *key, settings_field_ref_t *r)
{
    /* the values of each integer type (settings_type_t order up to ST_U32) */
    static const int64_t type_lo[] = {0, -128, 0, -2147483647 - 1, 0};
    static const int64_t type_hi[] = {255, 127, 65535, 2147483647, 4294967295};
    for (size_t k = 0; k < SETTINGS_NFIELDS; k++) {
        const settings_field_t *f = &settings_fields[k];
        if (f->count != 1u || f->type == ST_NAME || strcmp(f->key, key) != 0) {
            continue;
        }
        r->at = (uint8_t *)s + f->offset;
        r->f64 = f->type == ST_F64;
        r->type = f->type;
        const bool ranged = f->lo != 0 || f->hi != 0;
        r->lo = r->f64 ? 0 : (ranged ? f->lo : type_lo[f->type]);
        r->hi = r->f64 ? 0 : (ranged ? (int64_t)f->hi : type_hi[f->type]);
        return true;
    }
    return false;
}

int64_t settings_field_int(const settings_field_ref_t *r)
{
    return settings_int_of(r->at, (settings_type_t)r->type);
}

void settings_field_set_int(const settings_field_ref_t *r, int64_t v)
{
    settings_int_to(r->at, (settings_type_t)r->type, (uint64_t)v);
}
