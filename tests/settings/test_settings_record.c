/*
 * The settings record (firmware/settings/settings.h): layout, CRC-32, round
 * trip, and the loader against corrupted input: random bit flips, every
 * truncation, other format versions, random bodies with a valid CRC, random
 * bytes. Deterministic (xorshift seeds): the same cases on the host and in
 * QEMU. tests/settings/fuzz/ has the libFuzzer target over the same loader.
 */
#include <stdio.h>
#include <string.h>

#include "settings.h"
#include "settings_gen.h"
#include "unity.h"

/* Trials per case: the host runs the full sweep; QEMU the same code on a
 * tenth of it (an emulated CRC-32 over 576 bytes costs ~40 k instructions). */
#if defined(__arm__)
#define TRIALS(n) ((n) / 10)
#else
#define TRIALS(n) (n)
#endif

void setUp(void)
{
}

void tearDown(void)
{
}

static uint8_t rec[SETTINGS_REC_MAX];
static uint8_t rec2[SETTINGS_REC_MAX];

static void put32(uint8_t *p, uint32_t v)
{
    for (unsigned i = 0; i < 4u; i++) {
        p[i] = (uint8_t)(v >> (8u * i));
    }
}

static void recrc(uint8_t *r, size_t len)
{
    put32(r + len - 4u, settings_crc32(r, len - 4u));
}

static void test_crc32_check_value(void)
{
    /* the CRC catalogue's check value of CRC-32/ISO-HDLC for "123456789" */
    TEST_ASSERT_EQUAL_HEX32(0xCBF43926u, settings_crc32((const uint8_t *)"123456789", 9u));
}

static void test_layout(void)
{
    const size_t len = settings_record_size();
    TEST_ASSERT_EQUAL_UINT(0u, len % 8u); /* whole double words */
    TEST_ASSERT_TRUE(len <= SETTINGS_REC_MAX);
    TEST_ASSERT_TRUE(SETTINGS_REC_MAX <= 2048u); /* inside one G431 page */
    uint32_t x = 1u;
    settings_t s;
    sgen_settings(&x, &s);
    TEST_ASSERT_EQUAL_UINT(len, settings_encode(&s, 0x01020304u, rec, sizeof rec));
    TEST_ASSERT_EQUAL_UINT(0u, settings_encode(&s, 1u, rec, len - 1u)); /* too small */
    /* "PMSS", format, length, sequence, little-endian */
    TEST_ASSERT_EQUAL_MEMORY("PMSS", rec, 4);
    TEST_ASSERT_EQUAL_UINT8(SETTINGS_FORMAT, rec[4]);
    TEST_ASSERT_EQUAL_UINT8(0u, rec[5]);
    TEST_ASSERT_EQUAL_UINT(len, (size_t)rec[6] | ((size_t)rec[7] << 8));
    TEST_ASSERT_EQUAL_HEX8(0x04u, rec[8]);
    TEST_ASSERT_EQUAL_HEX8(0x01u, rec[11]);
}

static void test_round_trip(void)
{
    uint32_t x = 7u;
    for (int i = 0; i < TRIALS(300); i++) {
        settings_t s;
        settings_t d;
        uint32_t seq = 0;
        sgen_settings(&x, &s);
        const size_t len = settings_encode(&s, (uint32_t)i, rec, sizeof rec);
        TEST_ASSERT_EQUAL_INT(SETTINGS_OK, settings_decode(rec, len, &d, &seq, NULL));
        TEST_ASSERT_EQUAL_UINT32((uint32_t)i, seq);
        TEST_ASSERT_EQUAL_UINT(len, settings_encode(&d, (uint32_t)i, rec2, sizeof rec2));
        TEST_ASSERT_EQUAL_MEMORY(rec, rec2, len);
        /* every double kept bit for bit, names and integers as given */
        TEST_ASSERT_EQUAL_MEMORY(&s.rs_ohm, &d.rs_ohm, sizeof s.rs_ohm);
        TEST_ASSERT_EQUAL_STRING(s.ctrl, d.ctrl);
        TEST_ASSERT_EQUAL_INT8(s.enc_direction, d.enc_direction);
        TEST_ASSERT_EQUAL_INT8(s.id_enc_dir, d.id_enc_dir);
        TEST_ASSERT_EQUAL_INT32(s.pole_pairs, d.pole_pairs);
    }
}

static void test_non_finite_not_encoded(void)
{
    uint32_t x = 3u;
    settings_t s;
    sgen_settings(&x, &s);
    const uint64_t nan_bits = 0x7FF8000000000000ull;
    memcpy(&s.ld_h, &nan_bits, sizeof s.ld_h);
    TEST_ASSERT_EQUAL_UINT(0u, settings_encode(&s, 1u, rec, sizeof rec));
}

/* Decoding must fail and leave the output untouched. */
static void assert_refused(const uint8_t *r, size_t n, settings_status_t expect_or_ok_any)
{
    settings_t d;
    memset(&d, 0xA5, sizeof d);
    uint32_t seq = 0xA5A5A5A5u;
    const settings_status_t st = settings_decode(r, n, &d, &seq, NULL);
    TEST_ASSERT_NOT_EQUAL(SETTINGS_OK, st);
    if (expect_or_ok_any != SETTINGS_OK) {
        TEST_ASSERT_EQUAL_INT(expect_or_ok_any, st);
    }
    TEST_ASSERT_EQUAL_HEX32(0xA5A5A5A5u, seq);
    TEST_ASSERT_EQUAL_HEX8(0xA5u, ((const uint8_t *)&d)[0]);
}

static void test_bit_flips_refused(void)
{
    /* CRC-32 detects every error of up to 3 bits at this length and any
     * burst up to 32 bits; more flips pass with probability 2^-32 per try.
     * Every flipped record here must be refused (20 000 on the host). */
    uint32_t x = 11u;
    for (int i = 0; i < TRIALS(20000); i++) {
        settings_t s;
        sgen_settings(&x, &s);
        const size_t len = settings_encode(&s, sgen_rand(&x), rec, sizeof rec);
        memcpy(rec2, rec, len);
        const unsigned flips = 1u + sgen_rand(&x) % 8u;
        for (unsigned f = 0; f < flips; f++) {
            const uint32_t bit = sgen_rand(&x) % (uint32_t)(8u * len);
            rec[bit / 8u] ^= (uint8_t)(1u << (bit % 8u));
        }
        if (memcmp(rec, rec2, len) == 0) {
            continue; /* the flips cancelled out (one bit hit twice) */
        }
        assert_refused(rec, len, SETTINGS_OK);
    }
}

static void test_truncated_refused(void)
{
    uint32_t x = 5u;
    settings_t s;
    sgen_settings(&x, &s);
    const size_t len = settings_encode(&s, 9u, rec, sizeof rec);
    for (size_t n = 0; n < len; n++) {
        assert_refused(rec, n, SETTINGS_OK);
    }
    /* a record cut short inside its page: the tail erased (0xFF) */
    for (size_t n = SETTINGS_HDR_SIZE; n < len; n += 8u) {
        memcpy(rec2, rec, len);
        memset(rec2 + n, 0xFF, len - n);
        assert_refused(rec2, len, SETTINGS_E_CRC);
    }
}

static void test_other_formats_refused(void)
{
    uint32_t x = 6u;
    settings_t s;
    sgen_settings(&x, &s);
    const size_t len = settings_encode(&s, 9u, rec, sizeof rec);
    const uint16_t formats[] = {0u, 4u, 0x7FFFu, 0xFFFFu};
    for (unsigned i = 0; i < sizeof formats / sizeof formats[0]; i++) {
        memcpy(rec2, rec, len);
        rec2[4] = (uint8_t)formats[i];
        rec2[5] = (uint8_t)(formats[i] >> 8);
        recrc(rec2, len); /* an intact record of that format */
        uint16_t fmt = 0;
        settings_t d;
        uint32_t seq = 0;
        const settings_status_t st = settings_decode(rec2, len, &d, &seq, &fmt);
        TEST_ASSERT_EQUAL_INT(formats[i] < SETTINGS_FORMAT_MIN ? SETTINGS_E_OLD : SETTINGS_E_NEW,
                              st);
        TEST_ASSERT_EQUAL_UINT16(formats[i], fmt);
        assert_refused(rec2, len, st);
    }
    /* a different length in the header of this format: refused */
    memcpy(rec2, rec, len);
    rec2[6] = (uint8_t)(len - 8u);
    rec2[7] = (uint8_t)((len - 8u) >> 8);
    recrc(rec2, len - 8u);
    assert_refused(rec2, len, SETTINGS_E_LENGTH);
}

/* A record of this format rewritten as one of format 1 or 2: the same
 * fields up to id.enc_cpr, without format 3's friction (its last 4 doubles),
 * as those firmwares wrote it. Returns its length. */
static size_t as_format(uint8_t *r, size_t len, uint8_t fmt)
{
    const size_t body3 = (size_t)r[12] | ((size_t)r[13] << 8);
    const size_t body = body3 - 4u * 8u;
    const size_t n = (SETTINGS_HDR_SIZE + body + 4u + 7u) & ~(size_t)7u;
    TEST_ASSERT_TRUE(n < len);
    memset(r + SETTINGS_HDR_SIZE + body, 0xFF, len - SETTINGS_HDR_SIZE - body);
    r[4] = fmt;
    r[6] = (uint8_t)n;
    r[7] = (uint8_t)(n >> 8);
    r[12] = (uint8_t)body;
    r[13] = (uint8_t)(body >> 8);
    recrc(r, n);
    return n;
}

/* Format 1 (the first firmware's, which never wrote the throttle input: its
 * fields held zeroes) is read with format 2's layout, its throttle fields
 * cleared and marked as not stored, and not listed; format 2 keeps them.
 * Both are read without friction (format 3's): zero, the rest kept. */
static void test_format1_read_without_throttle(void)
{
    uint32_t x = 8u;
    settings_t s;
    sgen_settings(&x, &s);
    s.thr_mode = 1u;
    s.thr_low_us = 1100u;
    size_t len = settings_encode(&s, 4u, rec, sizeof rec);
    TEST_ASSERT_EQUAL_UINT8(3u, rec[4]);
    settings_t d;
    uint32_t seq = 0;
    uint16_t fmt = 0;
    TEST_ASSERT_EQUAL_INT(SETTINGS_OK, settings_decode(rec, len, &d, &seq, &fmt));
    TEST_ASSERT_EQUAL_UINT8(1u, d.thr_stored);
    TEST_ASSERT_EQUAL_UINT16(1100u, d.thr_low_us);
    TEST_ASSERT_EQUAL_MEMORY(&s.coulomb_nm, &d.coulomb_nm, sizeof s.coulomb_nm);
    TEST_ASSERT_EQUAL_MEMORY(&s.id_viscous_nms, &d.id_viscous_nms, sizeof s.id_viscous_nms);
    /* format 2: throttle kept, friction none */
    memcpy(rec2, rec, len);
    const size_t len2 = as_format(rec2, len, 2u);
    memset(&d, 0xA5, sizeof d);
    TEST_ASSERT_EQUAL_INT(SETTINGS_OK, settings_decode(rec2, len2, &d, &seq, &fmt));
    TEST_ASSERT_EQUAL_UINT16(2u, fmt);
    TEST_ASSERT_EQUAL_UINT8(1u, d.thr_stored);
    TEST_ASSERT_EQUAL_UINT16(1100u, d.thr_low_us);
    TEST_ASSERT_TRUE(d.coulomb_nm == 0.0 && d.viscous_nms == 0.0);
    TEST_ASSERT_TRUE(d.id_coulomb_nm == 0.0 && d.id_viscous_nms == 0.0);
    TEST_ASSERT_EQUAL_UINT32(s.id_enc_cpr, d.id_enc_cpr); /* the last field of format 2 */
    /* format 2's length with format 3's: refused */
    rec2[4] = 3u;
    recrc(rec2, len2);
    assert_refused(rec2, len2, SETTINGS_E_LENGTH);
    /* format 1 */
    len = as_format(rec, len, 1u);
    memset(&d, 0xA5, sizeof d);
    TEST_ASSERT_EQUAL_INT(SETTINGS_OK, settings_decode(rec, len, &d, &seq, &fmt));
    TEST_ASSERT_EQUAL_UINT16(1u, fmt);
    TEST_ASSERT_EQUAL_UINT32(4u, seq);
    TEST_ASSERT_EQUAL_UINT8(0u, d.thr_stored);
    TEST_ASSERT_EQUAL_UINT8(0u, d.thr_mode);
    TEST_ASSERT_EQUAL_UINT16(0u, d.thr_low_us);
    TEST_ASSERT_TRUE(d.coulomb_nm == 0.0 && d.id_viscous_nms == 0.0);
    TEST_ASSERT_EQUAL_MEMORY(&s.rs_ohm, &d.rs_ohm, sizeof s.rs_ohm); /* the rest kept */
    TEST_ASSERT_EQUAL_STRING(s.ctrl, d.ctrl);
    settings_item_t it;
    size_t listed[2] = {0u, 0u};
    for (unsigned stored = 0; stored < 2u; stored++) {
        d.thr_stored = (uint8_t)stored;
        for (size_t n = 0; settings_item_at(&d, n, &it); n++) {
            TEST_ASSERT_TRUE(stored == 1u || strncmp(it.key, "thr.", 4) != 0);
            listed[stored]++;
        }
    }
    TEST_ASSERT_EQUAL_UINT(listed[0] + 4u, listed[1]);
}

static void test_valid_crc_random_bodies(void)
{
    /* bytes of the body changed and the CRC made to match: the field checks
     * decide; an accepted record is a canonical one (re-encodes to a record
     * that decodes to the same) */
    uint32_t x = 13u;
    int accepted = 0;
    int refused = 0;
    for (int i = 0; i < TRIALS(20000); i++) {
        settings_t s;
        sgen_settings(&x, &s);
        const size_t len = settings_encode(&s, 1u, rec, sizeof rec);
        const unsigned n = 1u + sgen_rand(&x) % 4u;
        for (unsigned k = 0; k < n; k++) {
            const size_t at = SETTINGS_HDR_SIZE + sgen_rand(&x) % (uint32_t)(len - 4u - 16u);
            rec[at] = (uint8_t)sgen_rand(&x);
        }
        recrc(rec, len);
        settings_t d;
        uint32_t seq;
        const settings_status_t st = settings_decode(rec, len, &d, &seq, NULL);
        if (st == SETTINGS_OK) {
            accepted++;
            TEST_ASSERT_EQUAL_UINT(len, settings_encode(&d, seq, rec2, sizeof rec2));
            settings_t d2;
            uint32_t seq2;
            TEST_ASSERT_EQUAL_INT(SETTINGS_OK, settings_decode(rec2, len, &d2, &seq2, NULL));
            TEST_ASSERT_EQUAL_UINT(len, settings_encode(&d2, seq2, rec, sizeof rec));
            TEST_ASSERT_EQUAL_MEMORY(rec2, rec, len);
        } else {
            refused++;
            TEST_ASSERT_EQUAL_INT(SETTINGS_E_VALUE, st);
        }
    }
    printf("valid-CRC random bodies: %d accepted (canonical), %d refused by the field checks\n",
           accepted, refused);
    TEST_ASSERT_TRUE(refused > 0);
    TEST_ASSERT_TRUE(accepted > 0);
}

static void test_erased_and_garbage(void)
{
    memset(rec, 0xFF, sizeof rec);
    assert_refused(rec, sizeof rec, SETTINGS_E_EMPTY);
    uint32_t x = 17u;
    for (int i = 0; i < TRIALS(2000); i++) {
        for (size_t k = 0; k < sizeof rec; k++) {
            rec[k] = (uint8_t)sgen_rand(&x);
        }
        if ((i & 1) != 0) {
            memcpy(rec, "PMSS\x01\x00", 6); /* past the magic and version */
        }
        assert_refused(rec, sizeof rec, SETTINGS_OK);
    }
}

static void test_listing(void)
{
    uint32_t x = 21u;
    settings_t s;
    sgen_settings(&x, &s);
    s.n_tunables = 2;
    settings_item_t it;
    size_t n = 0;
    bool saw_ctrl = false;
    bool saw_rs = false;
    while (settings_item_at(&s, n, &it)) {
        if (strcmp(it.key, "ctrl") == 0) {
            saw_ctrl = it.text != NULL && strcmp(it.text, s.ctrl) == 0;
        }
        if (strcmp(it.key, "m.rs_ohm") == 0) {
            saw_rs = it.text == NULL && memcmp(&it.num, &s.rs_ohm, sizeof it.num) == 0;
        }
        n++;
    }
    TEST_ASSERT_TRUE(saw_ctrl);
    TEST_ASSERT_TRUE(saw_rs);
    /* the last two items are the tunables in use */
    TEST_ASSERT_TRUE(settings_item_at(&s, n - 1u, &it));
    TEST_ASSERT_EQUAL_STRING(s.tunable_name[1], it.key);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_crc32_check_value);
    RUN_TEST(test_layout);
    RUN_TEST(test_round_trip);
    RUN_TEST(test_non_finite_not_encoded);
    RUN_TEST(test_bit_flips_refused);
    RUN_TEST(test_truncated_refused);
    RUN_TEST(test_other_formats_refused);
    RUN_TEST(test_format1_read_without_throttle);
    RUN_TEST(test_valid_crc_random_bodies);
    RUN_TEST(test_erased_and_garbage);
    RUN_TEST(test_listing);
    return UNITY_END();
}
