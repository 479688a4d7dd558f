/*
 * The anti-cogging table's record (firmware/settings/settings_table.h) in the
 * two-page store, on the RAM model of the F405's 16 KiB settings sectors:
 * round trip bit for bit; the power cut during and right after every erase
 * and double-word program of a save with a table, from a page holding an
 * older record and table, and from one holding a record without a table: the
 * next boot finds the old record with the old table (or none), or the new
 * record with the new table, never a record with a half table; bit flips in
 * the table refused (CRC) while its record stays valid; a table another
 * record's refused; the G4's 2 KiB page does not take a table.
 */
#include <stdio.h>
#include <string.h>

#include "settings_flash_model.h"
#include "settings_gen.h"
#include "settings_store.h"
#include "settings_table.h"
#include "unity.h"

#define TAB_LOG2 11u
#define TAB_N (1u << TAB_LOG2)
/* Cuts tried: every operation on the host, every 13th in QEMU (the emulated
 * CRC over 4 KiB per boot). */
#if defined(__arm__)
#define CUT_STRIDE 13u
#else
#define CUT_STRIDE 1u
#endif

void setUp(void)
{
}

void tearDown(void)
{
}

static sfm_t fm;
static settings_flash_t fl;
static uint8_t buf[SETTINGS_REC_MAX];
static int16_t tab_a[TAB_N], tab_b[TAB_N], got[TAB_N];

static void gen_table(uint32_t *x, int16_t *t)
{
    for (uint32_t i = 0; i < TAB_N; i++) {
        t[i] = (int16_t)(int32_t)(sgen_rand(x) % 65536u - 32768u);
    }
}

static settings_tab_t tab_of(const int16_t *entries, uint32_t cpr, uint8_t on)
{
    settings_tab_t t;
    memset(&t, 0, sizeof t);
    t.hdr.enc_cpr = cpr;
    t.hdr.enc_offset = 0x12345678u;
    t.hdr.enc_dir = -1;
    t.hdr.n_log2 = (uint8_t)TAB_LOG2;
    t.hdr.ff_on = on;
    t.hdr.pole_pairs = 7;
    t.hdr.torque_rated_nm = 0.4;
    t.entries = entries;
    return t;
}

static int save(const settings_t *s, const settings_tab_t *t, uint32_t *seq)
{
    return settings_store_save_with(&fl, buf, sizeof buf, s,
                                    t != NULL ? settings_tab_program : NULL, t, seq);
}

/* What a boot finds: the record's sequence number (0: none) and the table's
 * status; the entries in got. */
static uint32_t boot(settings_status_t *ts, settings_tab_hdr_t *h)
{
    sfm_power_on(&fm);
    settings_scan_t scan;
    if (settings_store_load(&fl, buf, sizeof buf, NULL, &scan) != SETTINGS_OK) {
        *ts = SETTINGS_E_EMPTY;
        return 0u;
    }
    const unsigned p = (unsigned)scan.page;
    memset(got, 0x5A, sizeof got);
    *ts = settings_tab_load(&fl, p, scan.seq[p], buf, sizeof buf, h, got, TAB_N, NULL);
    return scan.seq[p];
}

static void test_round_trip_and_layout(void)
{
    sfm_init_size(&fm, 3u, SFM_PAGE_MAX);
    sfm_flash(&fm, &fl);
    TEST_ASSERT_TRUE(settings_tab_fits(&fl, TAB_LOG2));
    TEST_ASSERT_EQUAL_UINT(48u + 2u * TAB_N + 8u, settings_tab_size(TAB_LOG2));
    uint32_t x = 5u;
    settings_t s;
    sgen_settings(&x, &s);
    gen_table(&x, tab_a);
    const settings_tab_t t = tab_of(tab_a, 16384u, 1u);
    uint32_t seq = 0;
    TEST_ASSERT_EQUAL_INT(0, save(&s, &t, &seq));
    settings_status_t ts;
    settings_tab_hdr_t h;
    TEST_ASSERT_EQUAL_UINT32(seq, boot(&ts, &h));
    TEST_ASSERT_EQUAL_INT(SETTINGS_OK, ts);
    TEST_ASSERT_EQUAL_MEMORY(tab_a, got, sizeof tab_a);
    TEST_ASSERT_EQUAL_UINT32(seq, h.seq);
    TEST_ASSERT_EQUAL_UINT32(16384u, h.enc_cpr);
    TEST_ASSERT_EQUAL_HEX32(0x12345678u, h.enc_offset);
    TEST_ASSERT_EQUAL_INT8(-1, h.enc_dir);
    TEST_ASSERT_EQUAL_UINT8(TAB_LOG2, h.n_log2);
    TEST_ASSERT_EQUAL_UINT8(1u, h.ff_on);
    TEST_ASSERT_EQUAL_INT32(7, h.pole_pairs);
    TEST_ASSERT_TRUE(h.torque_rated_nm == 0.4);
    /* "PMSC", format 1, little-endian entries at the table's offset */
    uint8_t raw[56];
    TEST_ASSERT_EQUAL_INT(0, fl.read(fl.ctx, 0u, SETTINGS_TAB_OFFSET, raw, sizeof raw));
    TEST_ASSERT_EQUAL_MEMORY("PMSC", raw, 4);
    TEST_ASSERT_EQUAL_UINT8(SETTINGS_TAB_FORMAT, raw[4]);
    TEST_ASSERT_EQUAL_UINT8((uint8_t)tab_a[0], raw[48]);
    TEST_ASSERT_EQUAL_UINT8((uint8_t)((uint16_t)tab_a[0] >> 8), raw[49]);
    /* a save without a table: the next boot has none */
    TEST_ASSERT_EQUAL_INT(0, save(&s, NULL, &seq));
    TEST_ASSERT_EQUAL_UINT32(seq, boot(&ts, &h));
    TEST_ASSERT_EQUAL_INT(SETTINGS_E_EMPTY, ts);
    /* a header outside its values is not written */
    settings_tab_t bad = tab_of(tab_a, 16384u, 1u);
    bad.hdr.enc_dir = 0;
    TEST_ASSERT_EQUAL_INT(SETTINGS_STORE_E_ENCODE, save(&s, &bad, NULL));
    /* the G4's page holds the record, not the table */
    sfm_init(&fm, 3u);
    sfm_flash(&fm, &fl);
    TEST_ASSERT_FALSE(settings_tab_fits(&fl, TAB_LOG2));
    TEST_ASSERT_EQUAL_INT(SETTINGS_STORE_E_ARGS, save(&s, &t, NULL));
}

static void test_bit_flips_and_foreign_table(void)
{
    sfm_init_size(&fm, 4u, SFM_PAGE_MAX);
    sfm_flash(&fm, &fl);
    uint32_t x = 9u;
    settings_t s;
    sgen_settings(&x, &s);
    gen_table(&x, tab_a);
    const settings_tab_t t = tab_of(tab_a, 4096u, 0u);
    uint32_t seq = 0;
    TEST_ASSERT_EQUAL_INT(0, save(&s, &t, &seq));
    settings_status_t ts;
    settings_tab_hdr_t h;
    const size_t len = settings_tab_size(TAB_LOG2);
    for (int i = 0; i < 200; i++) {
        /* one bit of the table record flipped (the model's memory directly) */
        const uint32_t bit = sgen_rand(&x) % (uint32_t)(8u * len);
        uint8_t *at = &fm.mem[0][SETTINGS_TAB_OFFSET + bit / 8u];
        *at ^= (uint8_t)(1u << (bit % 8u));
        memset(&h, 0xA5, sizeof h);
        TEST_ASSERT_EQUAL_UINT32(seq, boot(&ts, &h)); /* the record itself intact */
        TEST_ASSERT_NOT_EQUAL(SETTINGS_OK, ts);
        TEST_ASSERT_TRUE(ts == SETTINGS_E_CRC || ts == SETTINGS_E_LENGTH || ts == SETTINGS_E_MAGIC);
        TEST_ASSERT_EQUAL_HEX8(0xA5u, ((const uint8_t *)&h)[0]);
        *at ^= (uint8_t)(1u << (bit % 8u));
    }
    TEST_ASSERT_EQUAL_UINT32(seq, boot(&ts, &h));
    TEST_ASSERT_EQUAL_INT(SETTINGS_OK, ts);
    /* the table read as another record's (its sequence number differs) */
    settings_scan_t scan;
    TEST_ASSERT_EQUAL_INT(SETTINGS_OK, settings_store_load(&fl, buf, sizeof buf, NULL, &scan));
    TEST_ASSERT_EQUAL_INT(SETTINGS_E_VALUE, settings_tab_load(&fl, 0u, seq + 1u, buf, sizeof buf,
                                                              &h, got, TAB_N, NULL));
    /* fewer entries than the record holds: refused, not cut */
    TEST_ASSERT_EQUAL_INT(SETTINGS_E_LENGTH, settings_tab_load(&fl, 0u, seq, buf, sizeof buf, &h,
                                                               got, TAB_N / 2u, NULL));
}

/* From a record with table tab_a (with_old) or a record without a table,
 * a save with tab_b cut at every operation: old or new, whole. */
static void cut_sweep(bool with_old, sfm_cut_t mode, unsigned *n_old, unsigned *n_new)
{
    uint32_t x = with_old ? 21u : 22u;
    settings_t s_old, s_new;
    sgen_settings(&x, &s_old);
    sgen_settings(&x, &s_new);
    gen_table(&x, tab_a);
    gen_table(&x, tab_b);
    const settings_tab_t ta = tab_of(tab_a, 8192u, 1u);
    const settings_tab_t tb = tab_of(tab_b, 8192u, 0u);
    for (uint32_t k = 1u;; k += CUT_STRIDE) {
        sfm_init_size(&fm, k, SFM_PAGE_MAX);
        sfm_flash(&fm, &fl);
        uint32_t seq_old = 0;
        TEST_ASSERT_EQUAL_INT(0, save(&s_old, with_old ? &ta : NULL, &seq_old));
        sfm_cut(&fm, k, mode);
        uint32_t seq_new = seq_old + 1u; /* a save cut short does not say it */
        const int rc = save(&s_new, &tb, &seq_new);
        settings_status_t ts;
        settings_tab_hdr_t h;
        const uint32_t seq = boot(&ts, &h);
        if (rc == 0) {
            /* the save completed before the k-th operation: the sweep is over */
            TEST_ASSERT_EQUAL_UINT32(seq_new, seq);
            TEST_ASSERT_EQUAL_INT(SETTINGS_OK, ts);
            TEST_ASSERT_EQUAL_MEMORY(tab_b, got, sizeof tab_b);
            break;
        }
        char what[96];
        (void)snprintf(what, sizeof what, "%s, cut %s operation %lu: record %lu, table %s",
                       with_old ? "old table" : "no table", mode == SFM_CUT_TORN ? "in" : "after",
                       (unsigned long)k, (unsigned long)seq, settings_status_name(ts));
        if (seq == seq_old) {
            (*n_old)++;
            if (with_old) {
                TEST_ASSERT_EQUAL_INT_MESSAGE(SETTINGS_OK, ts, what);
                TEST_ASSERT_EQUAL_MEMORY_MESSAGE(tab_a, got, sizeof tab_a, what);
                TEST_ASSERT_EQUAL_UINT8_MESSAGE(1u, h.ff_on, what);
            } else {
                TEST_ASSERT_EQUAL_INT_MESSAGE(SETTINGS_E_EMPTY, ts, what);
            }
        } else {
            /* a cut after the last double word: the new record, whole */
            (*n_new)++;
            TEST_ASSERT_EQUAL_UINT32_MESSAGE(seq_new, seq, what);
            TEST_ASSERT_EQUAL_INT_MESSAGE(SETTINGS_OK, ts, what);
            TEST_ASSERT_EQUAL_MEMORY_MESSAGE(tab_b, got, sizeof tab_b, what);
        }
        /* and the next save succeeds */
        TEST_ASSERT_EQUAL_INT(0, save(&s_new, &tb, NULL));
    }
}

static void test_power_cut_every_operation(void)
{
    for (unsigned w = 0; w < 2u; w++) {
        for (unsigned m = 0; m < 2u; m++) {
            unsigned n_old = 0, n_new = 0;
            cut_sweep(w != 0u, m == 0u ? SFM_CUT_TORN : SFM_CUT_AFTER, &n_old, &n_new);
            printf("save with a table over %s, cut %s: %u boots found the old record, %u the "
                   "new one\n",
                   w != 0u ? "a record and its table" : "a record without a table",
                   m == 0u ? "during" : "after", n_old, n_new);
            TEST_ASSERT_TRUE(n_old > 500u / CUT_STRIDE); /* every op of the table's ~520 */
        }
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_round_trip_and_layout);
    RUN_TEST(test_bit_flips_and_foreign_table);
    RUN_TEST(test_power_cut_every_operation);
    return UNITY_END();
}
