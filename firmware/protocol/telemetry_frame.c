/*
 * Telemetry frame codec: CRC-16/CCITT-FALSE, COBS, payload layout and the
 * resynchronising stream decoder. Layout in telemetry_frame.h / PROTOCOL.md.
 */
#include "telemetry_frame.h"

#include <string.h>

/* CRC-16 with poly 0x1021, one nibble at a time (16-entry table: 32 bytes of
 * flash instead of 512, about half the speed of a byte table). */
static const uint16_t tel_crc_nibble[16] = {0x0000, 0x1021, 0x2042, 0x3063, 0x4084, 0x50A5,
                                            0x60C6, 0x70E7, 0x8108, 0x9129, 0xA14A, 0xB16B,
                                            0xC18C, 0xD1AD, 0xE1CE, 0xF1EF};

uint16_t tel_crc16_update(uint16_t crc, const uint8_t *data, size_t n)
{
    if (data == NULL) {
        return crc;
    }
    for (size_t i = 0; i < n; i++) {
        const unsigned b = data[i];
        unsigned c = crc;
        c = ((c << 4) & 0xFFFFu) ^ tel_crc_nibble[((c >> 12) ^ (b >> 4)) & 0xFu];
        c = ((c << 4) & 0xFFFFu) ^ tel_crc_nibble[((c >> 12) ^ b) & 0xFu];
        crc = (uint16_t)c;
    }
    return crc;
}

uint16_t tel_crc16(const uint8_t *data, size_t n)
{
    return tel_crc16_update((uint16_t)TEL_CRC_INIT, data, n);
}

size_t tel_cobs_encode(const uint8_t *in, size_t n, uint8_t *out, size_t cap)
{
    if ((in == NULL && n != 0) || out == NULL || cap < TEL_COBS_SIZE(n)) {
        return 0;
    }
    size_t code_pos = 0; /* where the current block's code byte goes */
    size_t o = 1;
    uint8_t code = 1; /* 1 + data bytes in the current block */
    for (size_t i = 0; i < n; i++) {
        if (in[i] == 0u) {
            out[code_pos] = code;
            code_pos = o++;
            code = 1;
        } else {
            out[o++] = in[i];
            code++;
            if (code == 0xFFu && i + 1u < n) {
                /* a full block of 254 bytes carries no implicit zero; at the
                 * end of the input no new block is opened (canonical COBS) */
                out[code_pos] = code;
                code_pos = o++;
                code = 1;
            }
        }
    }
    out[code_pos] = code;
    return o;
}

int tel_cobs_decode(const uint8_t *in, size_t n, uint8_t *out, size_t cap, size_t *out_len)
{
    if ((in == NULL && n != 0) || out == NULL || out_len == NULL) {
        return -1;
    }
    size_t i = 0;
    size_t o = 0;
    while (i < n) {
        const uint8_t code = in[i++];
        if (code == 0u) {
            return -1;
        }
        const size_t k = (size_t)code - 1u; /* data bytes in this block */
        if (k > n - i) {
            return -1;
        }
        for (size_t j = 0; j < k; j++) {
            if (in[i] == 0u || o >= cap) {
                return -1;
            }
            out[o++] = in[i++];
        }
        /* implicit zero after a short block, except after the last block */
        if (code != 0xFFu && i < n) {
            if (o >= cap) {
                return -1;
            }
            out[o++] = 0u;
        }
    }
    *out_len = o;
    return 0;
}

static unsigned tel_popcount(uint32_t m)
{
    unsigned c = 0;
    while (m != 0u) {
        m &= m - 1u;
        c++;
    }
    return c;
}

size_t tel_payload_size(uint8_t type, uint32_t mask)
{
    if (type != TEL_TYPE_SAMPLE && type != TEL_TYPE_META) {
        return 0;
    }
    const size_t extra = (type == TEL_TYPE_SAMPLE) ? 4u : 8u;
    return TEL_HDR_SIZE + extra + 4u * tel_popcount(mask) + TEL_CRC_SIZE;
}

static void tel_put_u16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)(v & 0xFFu);
    p[1] = (uint8_t)(v >> 8);
}

static void tel_put_u32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v & 0xFFu);
    p[1] = (uint8_t)((v >> 8) & 0xFFu);
    p[2] = (uint8_t)((v >> 16) & 0xFFu);
    p[3] = (uint8_t)(v >> 24);
}

static uint16_t tel_get_u16(const uint8_t *p)
{
    return (uint16_t)((unsigned)p[0] | ((unsigned)p[1] << 8));
}

static uint32_t tel_get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

/* Two's-complement bits -> int32_t without implementation-defined conversion. */
static int32_t tel_i32_from_bits(uint32_t u)
{
    if (u <= (uint32_t)INT32_MAX) {
        return (int32_t)u;
    }
    return -(int32_t)(~u) - 1;
}

size_t tel_frame_serialise(const tel_frame_t *f, uint8_t *out, size_t cap)
{
    if (f == NULL || out == NULL) {
        return 0;
    }
    const size_t n = tel_payload_size(f->type, f->mask);
    if (n == 0 || cap < n) {
        return 0;
    }
    out[0] = f->type;
    tel_put_u16(&out[1], f->seq);
    tel_put_u32(&out[3], f->mask);
    size_t o = TEL_HDR_SIZE;
    const unsigned nv = tel_popcount(f->mask);
    if (f->type == TEL_TYPE_SAMPLE) {
        tel_put_u32(&out[o], f->tick);
        o += 4u;
        for (unsigned i = 0; i < nv; i++) {
            tel_put_u32(&out[o], (uint32_t)f->value[i]); /* modulo 2^32: defined */
            o += 4u;
        }
    } else {
        tel_put_u32(&out[o], f->fs_hz);
        tel_put_u32(&out[o + 4u], f->every);
        o += 8u;
        for (unsigned i = 0; i < nv; i++) {
            uint32_t bits;
            memcpy(&bits, &f->scale[i], sizeof bits); /* IEEE-754 binary32 */
            tel_put_u32(&out[o], bits);
            o += 4u;
        }
    }
    const uint16_t crc = tel_crc16(out, o);
    out[o] = (uint8_t)(crc >> 8);
    out[o + 1u] = (uint8_t)(crc & 0xFFu);
    return o + 2u;
}

int tel_frame_parse(const uint8_t *p, size_t n, tel_frame_t *f)
{
    if (p == NULL || f == NULL || n < TEL_HDR_SIZE + TEL_CRC_SIZE) {
        return -1;
    }
    /* CRC first: the residue over payload + CRC (high byte first) is zero */
    if (tel_crc16(p, n) != 0u) {
        return -1;
    }
    const uint8_t type = p[0];
    const uint32_t mask = tel_get_u32(&p[3]);
    if (tel_payload_size(type, mask) != n) {
        return -1;
    }
    memset(f, 0, sizeof *f);
    f->type = type;
    f->seq = tel_get_u16(&p[1]);
    f->mask = mask;
    f->n = (uint8_t)tel_popcount(mask);
    size_t o = TEL_HDR_SIZE;
    if (type == TEL_TYPE_SAMPLE) {
        f->tick = tel_get_u32(&p[o]);
        o += 4u;
        for (unsigned i = 0; i < f->n; i++) {
            f->value[i] = tel_i32_from_bits(tel_get_u32(&p[o]));
            o += 4u;
        }
    } else {
        f->fs_hz = tel_get_u32(&p[o]);
        f->every = tel_get_u32(&p[o + 4u]);
        o += 8u;
        for (unsigned i = 0; i < f->n; i++) {
            const uint32_t bits = tel_get_u32(&p[o]);
            memcpy(&f->scale[i], &bits, sizeof bits);
            o += 4u;
        }
    }
    return 0;
}

size_t tel_frame_encode(const tel_frame_t *f, uint8_t *wire, size_t cap)
{
    uint8_t payload[TEL_PAYLOAD_MAX];
    const size_t n = tel_frame_serialise(f, payload, sizeof payload);
    if (n == 0 || wire == NULL || cap < TEL_COBS_SIZE(n) + 2u) {
        return 0;
    }
    wire[0] = 0u;
    const size_t e = tel_cobs_encode(payload, n, &wire[1], cap - 2u);
    if (e == 0) {
        return 0;
    }
    wire[1u + e] = 0u;
    return e + 2u;
}

void tel_dec_init(tel_dec_t *d)
{
    if (d == NULL) {
        return;
    }
    memset(d, 0, sizeof *d);
    d->all_text = true;
}

static bool tel_is_text_byte(uint8_t b)
{
    return (b >= 0x20u && b <= 0x7Eu) || b == '\r' || b == '\n' || b == '\t';
}

static void tel_dec_reset_chunk(tel_dec_t *d)
{
    d->len = 0;
    d->overflow = false;
    d->all_text = true;
}

bool tel_dec_feed(tel_dec_t *d, uint8_t byte, tel_frame_t *out)
{
    if (d == NULL) {
        return false;
    }
    if (byte != 0u) {
        if (!tel_is_text_byte(byte)) {
            d->all_text = false;
        }
        if (d->len < sizeof d->buf) {
            d->buf[d->len++] = byte;
        } else {
            d->overflow = true;
        }
        /* A text response line between frames. A frame chunk is never all
         * text from its second byte on (byte 1 is the type, 0x01/0x02). */
        if (byte == '\n' && d->all_text && (d->len >= 2u || d->overflow)) {
            d->text++;
            tel_dec_reset_chunk(d);
        }
        return false;
    }
    /* delimiter: decode the chunk, if any */
    if (d->len == 0 && !d->overflow) {
        return false; /* empty chunk between two delimiters */
    }
    bool ok = false;
    if (!d->overflow) {
        uint8_t payload[TEL_PAYLOAD_MAX];
        size_t n = 0;
        if (tel_cobs_decode(d->buf, d->len, payload, sizeof payload, &n) == 0 && out != NULL &&
            tel_frame_parse(payload, n, out) == 0) {
            ok = true;
        }
    }
    if (ok) {
        d->frames++;
    } else if (d->all_text) {
        d->text++;
    } else {
        d->bad++;
    }
    tel_dec_reset_chunk(d);
    return ok;
}
