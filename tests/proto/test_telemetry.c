/*
 * Telemetry codec and producer: CRC against the published check value, COBS
 * against the reference examples and in round trips, frame layout, and the
 * stream decoder's resynchronisation after dropped or corrupted bytes (it
 * must lose at most the damaged frame and never report a wrong one).
 */
#include <stddef.h>
#include <string.h>

#include "telemetry.h"
#include "telemetry_frame.h"
#include "unity.h"

void setUp(void)
{
}

void tearDown(void)
{
}

static uint32_t lcg(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s;
}

static void test_crc_check_value(void)
{
    const uint8_t msg[] = "123456789";
    /* CRC-16/CCITT-FALSE check value (RevEng catalogue) */
    TEST_ASSERT_EQUAL_HEX16(0x29B1u, tel_crc16(msg, 9));
    TEST_ASSERT_EQUAL_HEX16(0xFFFFu, tel_crc16(msg, 0));
    /* incremental update equals one pass */
    TEST_ASSERT_EQUAL_HEX16(0x29B1u, tel_crc16_update(tel_crc16(msg, 4), &msg[4], 5));
    /* CRC appended high byte first: the residue is zero */
    uint8_t buf[11];
    memcpy(buf, msg, 9);
    buf[9] = 0x29u;
    buf[10] = 0xB1u;
    TEST_ASSERT_EQUAL_HEX16(0u, tel_crc16(buf, 11));
}

static void check_cobs(const uint8_t *in, size_t n, const uint8_t *want, size_t wn)
{
    uint8_t enc[600];
    uint8_t dec[600];
    size_t dn = 0;
    const size_t en = tel_cobs_encode(in, n, enc, sizeof enc);
    TEST_ASSERT_EQUAL_UINT(wn, en);
    TEST_ASSERT_EQUAL_UINT8_ARRAY(want, enc, wn);
    TEST_ASSERT_EQUAL_INT(0, tel_cobs_decode(enc, en, dec, sizeof dec, &dn));
    TEST_ASSERT_EQUAL_UINT(n, dn);
    if (n > 0) {
        TEST_ASSERT_EQUAL_UINT8_ARRAY(in, dec, n);
    }
}

/* The examples of Cheshire & Baker / the Wikipedia COBS article. */
static void test_cobs_reference_examples(void)
{
    const uint8_t i1[] = {0x00}, o1[] = {0x01, 0x01};
    const uint8_t i2[] = {0x00, 0x00}, o2[] = {0x01, 0x01, 0x01};
    const uint8_t i3[] = {0x00, 0x11, 0x00}, o3[] = {0x01, 0x02, 0x11, 0x01};
    const uint8_t i4[] = {0x11, 0x22, 0x00, 0x33}, o4[] = {0x03, 0x11, 0x22, 0x02, 0x33};
    const uint8_t i5[] = {0x11, 0x22, 0x33, 0x44}, o5[] = {0x05, 0x11, 0x22, 0x33, 0x44};
    const uint8_t i6[] = {0x11, 0x00, 0x00, 0x00}, o6[] = {0x02, 0x11, 0x01, 0x01, 0x01};
    const uint8_t o0[] = {0x01};
    check_cobs(NULL, 0, o0, 1);
    check_cobs(i1, 1, o1, 2);
    check_cobs(i2, 2, o2, 3);
    check_cobs(i3, 3, o3, 4);
    check_cobs(i4, 4, o4, 5);
    check_cobs(i5, 4, o5, 5);
    check_cobs(i6, 4, o6, 5);

    uint8_t in[256];
    uint8_t out[260];
    /* 01..FE (254 bytes) -> FF 01..FE */
    for (int i = 0; i < 254; i++) {
        in[i] = (uint8_t)(i + 1);
    }
    out[0] = 0xFF;
    memcpy(&out[1], in, 254);
    check_cobs(in, 254, out, 255);
    /* 00 01..FE (255 bytes) -> 01 FF 01..FE */
    in[0] = 0x00;
    for (int i = 1; i < 255; i++) {
        in[i] = (uint8_t)i;
    }
    out[0] = 0x01;
    out[1] = 0xFF;
    memcpy(&out[2], &in[1], 254);
    check_cobs(in, 255, out, 256);
    /* 01..FF (255 bytes) -> FF 01..FE 02 FF */
    for (int i = 0; i < 255; i++) {
        in[i] = (uint8_t)(i + 1);
    }
    out[0] = 0xFF;
    memcpy(&out[1], in, 254);
    out[255] = 0x02;
    out[256] = 0xFF;
    check_cobs(in, 255, out, 257);
    /* 02..FF 00 (255 bytes) -> FF 02..FF 01 01 */
    for (int i = 0; i < 254; i++) {
        in[i] = (uint8_t)(i + 2);
    }
    in[254] = 0x00;
    out[0] = 0xFF;
    memcpy(&out[1], in, 254);
    out[255] = 0x01;
    out[256] = 0x01;
    check_cobs(in, 255, out, 257);
    /* 03..FF 00 01 (255 bytes) -> FE 03..FF 02 01 */
    for (int i = 0; i < 253; i++) {
        in[i] = (uint8_t)(i + 3);
    }
    in[253] = 0x00;
    in[254] = 0x01;
    out[0] = 0xFE;
    memcpy(&out[1], in, 253);
    out[254] = 0x02;
    out[255] = 0x01;
    check_cobs(in, 255, out, 256);
}

static void test_cobs_round_trip(void)
{
    uint8_t in[600];
    uint8_t enc[620];
    uint8_t dec[600];
    uint32_t s = 1u;
    /* lengths around the 254-byte block boundary, zero densities from none to all */
    static const size_t lens[] = {0, 1, 2, 253, 254, 255, 256, 507, 508, 509, 600};
    static const unsigned zero_per_256[] = {0, 1, 16, 128, 255, 256};
    for (size_t li = 0; li < sizeof lens / sizeof lens[0]; li++) {
        for (size_t zi = 0; zi < sizeof zero_per_256 / sizeof zero_per_256[0]; zi++) {
            const size_t n = lens[li];
            for (size_t i = 0; i < n; i++) {
                const uint32_t r = lcg(&s) >> 8;
                in[i] = ((r & 0xFFu) < zero_per_256[zi]) ? 0u : (uint8_t)(1u + (r >> 8) % 255u);
            }
            const size_t en = tel_cobs_encode(in, n, enc, sizeof enc);
            TEST_ASSERT_TRUE(en >= n + 1u && en <= TEL_COBS_SIZE(n));
            TEST_ASSERT_NULL(memchr(enc, 0, en)); /* no delimiter inside */
            size_t dn = 0;
            TEST_ASSERT_EQUAL_INT(0, tel_cobs_decode(enc, en, dec, sizeof dec, &dn));
            TEST_ASSERT_EQUAL_UINT(n, dn);
            if (n > 0) {
                TEST_ASSERT_EQUAL_MEMORY(in, dec, n);
            }
            /* too small a buffer is refused, never overrun */
            TEST_ASSERT_EQUAL_UINT(0, tel_cobs_encode(in, n, enc, TEL_COBS_SIZE(n) - 1u));
            if (n > 0) {
                TEST_ASSERT_EQUAL_INT(-1, tel_cobs_decode(enc, en, dec, n - 1u, &dn));
            }
        }
    }
}

static void test_cobs_decode_rejects(void)
{
    uint8_t dec[16];
    size_t dn = 0;
    const uint8_t zero_inside[] = {0x03, 0x11, 0x00};
    const uint8_t overrun[] = {0x05, 0x11, 0x22};
    const uint8_t code_zero[] = {0x00};
    TEST_ASSERT_EQUAL_INT(-1, tel_cobs_decode(zero_inside, 3, dec, sizeof dec, &dn));
    TEST_ASSERT_EQUAL_INT(-1, tel_cobs_decode(overrun, 3, dec, sizeof dec, &dn));
    TEST_ASSERT_EQUAL_INT(-1, tel_cobs_decode(code_zero, 1, dec, sizeof dec, &dn));
    TEST_ASSERT_EQUAL_INT(-1, tel_cobs_decode(NULL, 3, dec, sizeof dec, &dn));
}

static tel_frame_t make_sample(uint16_t seq, uint32_t mask, uint32_t tick, uint32_t *s)
{
    tel_frame_t f;
    memset(&f, 0, sizeof f);
    f.type = TEL_TYPE_SAMPLE;
    f.seq = seq;
    f.mask = mask;
    f.tick = tick;
    unsigned n = 0;
    for (uint32_t m = mask; m != 0u; m &= m - 1u) {
        n++;
    }
    f.n = (uint8_t)n;
    for (unsigned i = 0; i < n; i++) {
        /* include zeros, extremes and negative values */
        const uint32_t r = lcg(s);
        f.value[i] = (r % 5u == 0u)   ? 0
                     : (r % 7u == 0u) ? INT32_MIN
                                      : (int32_t)(r >> 1) - (1 << 30);
    }
    return f;
}

static void assert_frame_equal(const tel_frame_t *a, const tel_frame_t *b)
{
    TEST_ASSERT_EQUAL_UINT8(a->type, b->type);
    TEST_ASSERT_EQUAL_UINT16(a->seq, b->seq);
    TEST_ASSERT_EQUAL_HEX32(a->mask, b->mask);
    TEST_ASSERT_EQUAL_UINT8(a->n, b->n);
    if (a->type == TEL_TYPE_SAMPLE) {
        TEST_ASSERT_EQUAL_UINT32(a->tick, b->tick);
        if (a->n > 0) {
            TEST_ASSERT_EQUAL_INT32_ARRAY(a->value, b->value, a->n);
        }
    } else {
        TEST_ASSERT_EQUAL_UINT32(a->fs_hz, b->fs_hz);
        TEST_ASSERT_EQUAL_UINT32(a->every, b->every);
        if (a->n > 0) {
            TEST_ASSERT_EQUAL_MEMORY(a->scale, b->scale, sizeof(float) * a->n);
        }
    }
}

static void test_frame_layout(void)
{
    uint32_t s = 7u;
    tel_frame_t f = make_sample(0x1234u, 0x80000005u, 0xA1B2C3D4u, &s);
    f.value[0] = -2;
    f.value[1] = 0x01020304;
    f.value[2] = INT32_MIN;
    uint8_t p[TEL_PAYLOAD_MAX];
    const size_t n = tel_frame_serialise(&f, p, sizeof p);
    TEST_ASSERT_EQUAL_UINT(7u + 4u + 12u + 2u, n);
    TEST_ASSERT_EQUAL_UINT(n, tel_payload_size(TEL_TYPE_SAMPLE, f.mask));
    const uint8_t head[] = {0x01, 0x34, 0x12, 0x05, 0x00, 0x00, 0x80, 0xD4, 0xC3, 0xB2, 0xA1, 0xFE,
                            0xFF, 0xFF, 0xFF, 0x04, 0x03, 0x02, 0x01, 0x00, 0x00, 0x00, 0x80};
    TEST_ASSERT_EQUAL_UINT8_ARRAY(head, p, sizeof head);
    const uint16_t crc = tel_crc16(p, n - 2u);
    TEST_ASSERT_EQUAL_HEX8(crc >> 8, p[n - 2u]);
    TEST_ASSERT_EQUAL_HEX8(crc & 0xFFu, p[n - 1u]);
    tel_frame_t g;
    TEST_ASSERT_EQUAL_INT(0, tel_frame_parse(p, n, &g));
    assert_frame_equal(&f, &g);
    /* every single-bit error is detected (CRC-16 guarantees it) */
    for (size_t i = 0; i < n; i++) {
        for (unsigned b = 0; b < 8u; b++) {
            p[i] ^= (uint8_t)(1u << b);
            TEST_ASSERT_EQUAL_INT(-1, tel_frame_parse(p, n, &g));
            p[i] ^= (uint8_t)(1u << b);
        }
    }
    /* wrong length, unknown type, too short */
    TEST_ASSERT_EQUAL_INT(-1, tel_frame_parse(p, n - 1u, &g));
    TEST_ASSERT_EQUAL_INT(-1, tel_frame_parse(p, 3, &g));
    f.type = 0x07;
    TEST_ASSERT_EQUAL_UINT(0, tel_frame_serialise(&f, p, sizeof p));
    /* META with float scales */
    tel_frame_t meta;
    memset(&meta, 0, sizeof meta);
    meta.type = TEL_TYPE_META;
    meta.seq = 9;
    meta.mask = 0x3u;
    meta.n = 2;
    meta.fs_hz = 20000;
    meta.every = 10;
    meta.scale[0] = 1.5e-7f;
    meta.scale[1] = -3.0f;
    const size_t mn = tel_frame_serialise(&meta, p, sizeof p);
    TEST_ASSERT_EQUAL_UINT(7u + 8u + 8u + 2u, mn);
    TEST_ASSERT_EQUAL_INT(0, tel_frame_parse(p, mn, &g));
    assert_frame_equal(&meta, &g);
}

/* A stream of frames with text lines between some of them. */
typedef struct {
    uint8_t bytes[16384];
    size_t len;
    size_t start[64]; /* wire offset of frame i */
    size_t end[64];
    tel_frame_t f[64];
    unsigned n;
    unsigned text_lines;
} stream_t;

static void build_stream(stream_t *st, unsigned nframes)
{
    uint32_t s = 99u;
    memset(st, 0, sizeof *st);
    for (unsigned k = 0; k < nframes; k++) {
        if (k % 5u == 2u) {
            static const char line[] = "ok tel mask=0x00000043 every=10 bytes=27\r\n";
            memcpy(&st->bytes[st->len], line, sizeof line - 1u);
            st->len += sizeof line - 1u;
            st->text_lines++;
        }
        uint32_t mask = lcg(&s) & TEL_MASK_ALL;
        if (k % 7u == 0u) {
            mask = TEL_MASK_ALL;
        }
        if (mask == 0u) {
            mask = 1u;
        }
        st->f[k] = make_sample((uint16_t)k, mask, 1000u + 10u * k, &s);
        st->start[k] = st->len;
        st->len += tel_frame_encode(&st->f[k], &st->bytes[st->len], sizeof st->bytes - st->len);
        st->end[k] = st->len;
    }
    st->n = nframes;
}

/* Decode; returns how many frames came out; each must equal the frame of its seq. */
static unsigned decode_stream(const stream_t *st, const uint8_t *b, size_t n, tel_dec_t *d,
                              bool *seen)
{
    tel_frame_t out;
    unsigned got = 0;
    tel_dec_init(d);
    memset(seen, 0, st->n * sizeof *seen);
    for (size_t i = 0; i < n; i++) {
        if (tel_dec_feed(d, b[i], &out)) {
            TEST_ASSERT_LESS_THAN_UINT32(st->n, out.seq);
            assert_frame_equal(&st->f[out.seq], &out); /* never a wrong frame */
            TEST_ASSERT_FALSE(seen[out.seq]);
            seen[out.seq] = true;
            got++;
        }
    }
    return got;
}

static stream_t g_st;
static uint8_t g_buf[16384];

static void test_stream_clean(void)
{
    bool seen[64];
    tel_dec_t d;
    build_stream(&g_st, 40);
    TEST_ASSERT_EQUAL_UINT(40, decode_stream(&g_st, g_st.bytes, g_st.len, &d, seen));
    TEST_ASSERT_EQUAL_UINT32(40u, d.frames);
    TEST_ASSERT_EQUAL_UINT32(0u, d.bad);
    TEST_ASSERT_EQUAL_UINT32(g_st.text_lines, d.text);
}

/* Drop any one byte of frame k: only frame k is lost. */
static void test_resync_after_dropped_byte(void)
{
    bool seen[64];
    tel_dec_t d;
    build_stream(&g_st, 12);
    for (unsigned k = 0; k < g_st.n; k += 5u) {
        for (size_t pos = g_st.start[k]; pos < g_st.end[k]; pos++) {
            memcpy(g_buf, g_st.bytes, pos);
            memcpy(&g_buf[pos], &g_st.bytes[pos + 1u], g_st.len - pos - 1u);
            const unsigned got = decode_stream(&g_st, g_buf, g_st.len - 1u, &d, seen);
            /* dropping a delimiter of a frame loses nothing but that frame */
            TEST_ASSERT_TRUE(got >= g_st.n - 1u);
            for (unsigned j = 0; j < g_st.n; j++) {
                if (j != k) {
                    TEST_ASSERT_TRUE(seen[j]);
                }
            }
        }
    }
}

/* Corrupt any one byte of frame k with several patterns: only frame k is lost,
 * and it is never reported with wrong content. */
static void test_resync_after_corrupted_byte(void)
{
    static const uint8_t flips[] = {0x01, 0x80, 0xFF, 0x5A};
    bool seen[64];
    tel_dec_t d;
    build_stream(&g_st, 12);
    for (unsigned k = 1; k < g_st.n; k += 4u) {
        for (size_t pos = g_st.start[k]; pos < g_st.end[k]; pos++) {
            for (size_t fi = 0; fi < sizeof flips; fi++) {
                memcpy(g_buf, g_st.bytes, g_st.len);
                g_buf[pos] ^= flips[fi];
                (void)decode_stream(&g_st, g_buf, g_st.len, &d, seen);
                for (unsigned j = 0; j < g_st.n; j++) {
                    if (j != k) {
                        TEST_ASSERT_TRUE(seen[j]);
                    }
                }
            }
            /* a byte turned into a delimiter */
            memcpy(g_buf, g_st.bytes, g_st.len);
            g_buf[pos] = 0x00;
            (void)decode_stream(&g_st, g_buf, g_st.len, &d, seen);
            for (unsigned j = 0; j < g_st.n; j++) {
                if (j != k) {
                    TEST_ASSERT_TRUE(seen[j]);
                }
            }
        }
    }
}

static void test_decoder_garbage_and_overlong(void)
{
    tel_dec_t d;
    tel_frame_t out;
    tel_dec_init(&d);
    /* a long run without delimiter (longer than any frame), then a good frame */
    for (int i = 0; i < 1000; i++) {
        TEST_ASSERT_FALSE(tel_dec_feed(&d, (uint8_t)(0x80 + (i % 100)), &out));
    }
    uint32_t s = 3u;
    const tel_frame_t f = make_sample(5, 0x7u, 77u, &s);
    uint8_t w[TEL_WIRE_MAX];
    const size_t n = tel_frame_encode(&f, w, sizeof w);
    unsigned got = 0;
    for (size_t i = 0; i < n; i++) {
        if (tel_dec_feed(&d, w[i], &out)) {
            got++;
            assert_frame_equal(&f, &out);
        }
    }
    TEST_ASSERT_EQUAL_UINT(1, got);
    TEST_ASSERT_EQUAL_UINT32(1u, d.bad);
    /* a long text line (longer than the buffer) is text, not a bad frame */
    tel_dec_init(&d);
    for (int i = 0; i < 500; i++) {
        (void)tel_dec_feed(&d, 'a', &out);
    }
    (void)tel_dec_feed(&d, '\r', &out);
    (void)tel_dec_feed(&d, '\n', &out);
    TEST_ASSERT_EQUAL_UINT32(1u, d.text);
    TEST_ASSERT_EQUAL_UINT32(0u, d.bad);
}

static void test_producer(void)
{
    tel_t t;
    tel_init(&t);
    TEST_ASSERT_FALSE(tel_active(&t));
    TEST_ASSERT_EQUAL_INT(-1, tel_start(&t, 0u, 1u));
    TEST_ASSERT_EQUAL_INT(-1, tel_start(&t, 1u << TEL_SIG_COUNT, 1u));
    TEST_ASSERT_EQUAL_INT(-1, tel_start(&t, 1u, 0u));
    TEST_ASSERT_EQUAL_INT(-1, tel_start(&t, 1u, TEL_EVERY_MAX + 1u));
    TEST_ASSERT_FALSE(tel_active(&t));
    const uint32_t mask = (1u << TEL_SIG_I_A) | (1u << TEL_SIG_TORQUE) | (1u << TEL_SIG_SPEED) |
                          (1u << TEL_SIG_CYCLES);
    TEST_ASSERT_EQUAL_INT(0, tel_start(&t, mask, 3u));
    TEST_ASSERT_TRUE(tel_active(&t));
    TEST_ASSERT_EQUAL_UINT32(3u, t.every); /* the decimation is the producer's (fw_tm_stream) */

    ctrl_bases_t b;
    memset(&b, 0, sizeof b);
    b.i_a = 14.388;
    b.torque_nm = 8.138;
    b.w_rad_s = 2333.7;
    uint8_t w[TEL_WIRE_MAX];
    tel_dec_t dec;
    tel_frame_t out;
    tel_dec_init(&dec);
    size_t n = tel_encode_meta(&t, 20000u, &b, 4, w, sizeof w);
    TEST_ASSERT_TRUE(n > 0u);
    bool got = false;
    for (size_t i = 0; i < n; i++) {
        got = tel_dec_feed(&dec, w[i], &out) || got;
    }
    TEST_ASSERT_TRUE(got);
    TEST_ASSERT_EQUAL_UINT8(TEL_TYPE_META, out.type);
    TEST_ASSERT_EQUAL_UINT32(20000u, out.fs_hz);
    TEST_ASSERT_EQUAL_UINT32(3u, out.every);
    TEST_ASSERT_EQUAL_UINT8(4, out.n);
    TEST_ASSERT_FLOAT_WITHIN(1e-12f, (float)(14.388 / 16777216.0), out.scale[0]);
    TEST_ASSERT_FLOAT_WITHIN(1e-12f, (float)(8.138 / 16777216.0), out.scale[1]);
    /* omega_e base / p -> r/min: 2333.7 / 4 * 60 / (2 pi) */
    TEST_ASSERT_FLOAT_WITHIN(1e-9f, (float)(2333.7 / 4.0 * 60.0 / 6.283185307179586 / 16777216.0),
                             out.scale[2]);
    TEST_ASSERT_FLOAT_WITHIN(0.0f, 1.0f, out.scale[3]);

    tel_sample_t smp;
    memset(&smp, 0, sizeof smp);
    smp.tick = 4242u;
    smp.i_a = -FX_ONE / 2;
    smp.i_b = 111; /* not in the mask */
    smp.torque = FX_ONE;
    smp.speed = INT32_MIN;
    smp.cycles = 1234;
    n = tel_encode_sample(&t, &smp, w, sizeof w);
    TEST_ASSERT_EQUAL_UINT(tel_wire_size(mask), n);
    got = false;
    for (size_t i = 0; i < n; i++) {
        got = tel_dec_feed(&dec, w[i], &out) || got;
    }
    TEST_ASSERT_TRUE(got);
    TEST_ASSERT_EQUAL_UINT8(TEL_TYPE_SAMPLE, out.type);
    TEST_ASSERT_EQUAL_UINT16(1u, out.seq); /* after the META frame */
    TEST_ASSERT_EQUAL_UINT32(4242u, out.tick);
    const int32_t want[4] = {-FX_ONE / 2, FX_ONE, INT32_MIN, 1234};
    TEST_ASSERT_EQUAL_INT32_ARRAY(want, out.value, 4);
    /* stop: nothing encoded */
    tel_stop(&t);
    TEST_ASSERT_FALSE(tel_active(&t));
    TEST_ASSERT_EQUAL_UINT(0, tel_encode_sample(&t, &smp, w, sizeof w));
    TEST_ASSERT_EQUAL_UINT(0, tel_encode_sample(NULL, &smp, w, sizeof w));
}

static void test_signal_table(void)
{
    for (size_t i = 0; i < (size_t)TEL_SIG_COUNT; i++) {
        const tel_signal_t *s = tel_signal_at(i);
        TEST_ASSERT_NOT_NULL(s);
        TEST_ASSERT_EQUAL_INT((int)i, tel_signal_find(s->name, strlen(s->name)));
        TEST_ASSERT_TRUE(s->offset >= offsetof(tel_sample_t, i_a));
        TEST_ASSERT_TRUE(s->offset + 4u <= sizeof(tel_sample_t));
        /* fields are distinct */
        for (size_t j = 0; j < i; j++) {
            TEST_ASSERT_NOT_EQUAL((int)tel_signal_at(j)->offset, (int)s->offset);
        }
    }
    TEST_ASSERT_NULL(tel_signal_at(TEL_SIG_COUNT));
    TEST_ASSERT_EQUAL_INT(-1, tel_signal_find("i_", 2));
    TEST_ASSERT_EQUAL_INT(TEL_SIG_TORQUE_REF, tel_signal_find("torque_ref", 10));
    /* the largest frame fits the wire buffer */
    TEST_ASSERT_TRUE(tel_wire_size(TEL_MASK_ALL) <= TEL_WIRE_MAX);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_crc_check_value);
    RUN_TEST(test_cobs_reference_examples);
    RUN_TEST(test_cobs_round_trip);
    RUN_TEST(test_cobs_decode_rejects);
    RUN_TEST(test_frame_layout);
    RUN_TEST(test_stream_clean);
    RUN_TEST(test_resync_after_dropped_byte);
    RUN_TEST(test_resync_after_corrupted_byte);
    RUN_TEST(test_decoder_garbage_and_overlong);
    RUN_TEST(test_producer);
    RUN_TEST(test_signal_table);
    return UNITY_END();
}
