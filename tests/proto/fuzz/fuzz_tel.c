/*
 * libFuzzer target for the telemetry codec.
 *  1. Arbitrary bytes into the stream decoder: it never crashes, and every
 *     frame it reports is checked against an independent reference (a plain
 *     COBS decoder and a bitwise CRC written here): the chunk really carried a
 *     payload with a valid CRC, and the reported fields re-serialise to it.
 *  2. Round trip: the input also describes a frame (type, seq, mask, values);
 *     encoder -> stream decoder must give it back exactly, and COBS of the raw
 *     input must decode to the input.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "telemetry_frame.h"

#define FZ_CHECK(cond)                                                                             \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "invariant failed: %s (line %d)\n", #cond, __LINE__);                  \
            abort();                                                                               \
        }                                                                                          \
    } while (0)

/* Reference CRC-16/CCITT-FALSE, bit by bit. */
static uint16_t ref_crc(const uint8_t *d, size_t n)
{
    uint16_t crc = 0xFFFFu;
    for (size_t i = 0; i < n; i++) {
        crc ^= (uint16_t)(d[i] << 8);
        for (int b = 0; b < 8; b++) {
            crc = (crc & 0x8000u) ? (uint16_t)((crc << 1) ^ 0x1021u) : (uint16_t)(crc << 1);
        }
    }
    return crc;
}

/* Reference COBS decoder; returns -1 on malformed input. */
static long ref_cobs(const uint8_t *in, size_t n, uint8_t *out, size_t cap)
{
    size_t o = 0;
    size_t i = 0;
    while (i < n) {
        unsigned code = in[i++];
        if (code == 0) {
            return -1;
        }
        for (unsigned j = 1; j < code; j++) {
            if (i >= n || in[i] == 0 || o >= cap) {
                return -1;
            }
            out[o++] = in[i++];
        }
        if (code < 0xFF && i < n) {
            if (o >= cap) {
                return -1;
            }
            out[o++] = 0;
        }
    }
    return (long)o;
}

static void check_reported(const uint8_t *chunk, size_t clen, const tel_frame_t *f)
{
    uint8_t p[TEL_PAYLOAD_MAX];
    const long n = ref_cobs(chunk, clen, p, sizeof p);
    FZ_CHECK(n >= (long)(TEL_HDR_SIZE + TEL_CRC_SIZE));
    FZ_CHECK(ref_crc(p, (size_t)n) == 0u); /* payload + CRC high byte first */
    uint8_t q[TEL_PAYLOAD_MAX];
    const size_t qn = tel_frame_serialise(f, q, sizeof q);
    FZ_CHECK(qn == (size_t)n);
    FZ_CHECK(memcmp(p, q, qn) == 0);
    unsigned pc = 0;
    for (uint32_t m = f->mask; m != 0u; m &= m - 1u) {
        pc++;
    }
    FZ_CHECK(pc == f->n && pc <= TEL_VALUES_MAX);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static tel_dec_t d;
    static uint8_t chunk[1 << 16];
    size_t clen = 0;
    tel_frame_t f;

    /* 1. stream decoder on raw bytes, with a shadow of the current chunk */
    tel_dec_init(&d);
    for (size_t i = 0; i < size; i++) {
        const bool got = tel_dec_feed(&d, data[i], &f);
        if (got) {
            FZ_CHECK(data[i] == 0u);
            check_reported(chunk, clen, &f);
        }
        if (data[i] == 0u) {
            clen = 0;
        } else if (clen < sizeof chunk) {
            chunk[clen++] = data[i];
        }
        /* the decoder may also drop a text line at LF: mirror it */
        if (data[i] == '\n' && d.len == 0 && !d.overflow) {
            clen = 0;
        }
    }
    FZ_CHECK(d.frames + d.bad + d.text <= (uint32_t)size);

    /* 2a. COBS round trip of the raw input */
    if (size <= 4096) {
        static uint8_t enc[4096 + 4096 / 254 + 2];
        static uint8_t dec[4096];
        size_t dn = 0;
        const size_t en = tel_cobs_encode(data, size, enc, sizeof enc);
        FZ_CHECK(en >= size + 1u && en <= TEL_COBS_SIZE(size));
        FZ_CHECK(memchr(enc, 0, en) == NULL);
        FZ_CHECK(tel_cobs_decode(enc, en, dec, sizeof dec, &dn) == 0);
        FZ_CHECK(dn == size && (size == 0 || memcmp(dec, data, size) == 0));
    }

    /* 2b. frame round trip through encoder and stream decoder */
    if (size >= 11) {
        tel_frame_t g;
        memset(&g, 0, sizeof g);
        g.type = (data[0] & 1u) ? TEL_TYPE_SAMPLE : TEL_TYPE_META;
        g.seq = (uint16_t)(data[1] | (data[2] << 8));
        memcpy(&g.mask, &data[3], 4);
        memcpy(&g.tick, &data[7], 4);
        g.fs_hz = g.tick ^ 0x5A5A5A5Au;
        g.every = g.tick >> 3;
        for (uint32_t m = g.mask; m != 0u; m &= m - 1u) {
            g.n++;
        }
        for (unsigned i = 0; i < g.n; i++) {
            uint32_t v = 0;
            const size_t off = 11u + 4u * i;
            if (off + 4u <= size) {
                memcpy(&v, &data[off], 4);
            }
            memcpy(&g.value[i], &v, 4);
            memcpy(&g.scale[i], &v, 4); /* any bit pattern, NaNs included */
        }
        uint8_t w[TEL_WIRE_MAX];
        const size_t wn = tel_frame_encode(&g, w, sizeof w);
        FZ_CHECK(wn > 2u && wn <= TEL_WIRE_MAX);
        FZ_CHECK(w[0] == 0u && w[wn - 1u] == 0u && memchr(&w[1], 0, wn - 2u) == NULL);
        tel_dec_init(&d);
        unsigned got = 0;
        for (size_t i = 0; i < wn; i++) {
            if (tel_dec_feed(&d, w[i], &f)) {
                got++;
            }
        }
        FZ_CHECK(got == 1u);
        FZ_CHECK(f.type == g.type && f.seq == g.seq && f.mask == g.mask && f.n == g.n);
        if (g.type == TEL_TYPE_SAMPLE) {
            FZ_CHECK(f.tick == g.tick);
            FZ_CHECK(memcmp(f.value, g.value, 4u * g.n) == 0);
        } else {
            FZ_CHECK(f.fs_hz == g.fs_hz && f.every == g.every);
            FZ_CHECK(memcmp(f.scale, g.scale, 4u * g.n) == 0);
        }
    }
    return 0;
}
