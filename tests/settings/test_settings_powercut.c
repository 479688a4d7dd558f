/*
 * The two-page settings store (firmware/settings/settings_store.h) on the
 * RAM model of the G4 flash (settings_flash_model.h), with the power cut
 * during and right after every erase and every double-word program of a
 * save and of an erase. After each cut the next boot must apply either the
 * old record or the new one, never a mixture, never anything else, and never
 * the defaults while a valid record existed before the save; the next save
 * must then succeed. Starting states: no record, one, two, one beside a page
 * torn by an earlier cut, and an older-format record beside a valid one.
 */
#include <stdio.h>
#include <string.h>

#include "settings_flash_model.h"
#include "settings_gen.h"
#include "settings_store.h"
#include "unity.h"

/* Records per starting state: 8 on the host, 1 in QEMU (the same cuts of
 * every operation, fewer torn contents). */
#if defined(__arm__)
#define N_RECORDS 1u
#else
#define N_RECORDS 8u
#endif

void setUp(void)
{
}

void tearDown(void)
{
}

static sfm_t fm;
static sfm_t start;
static settings_flash_t fl;
static uint8_t buf[SETTINGS_REC_MAX];
static uint8_t enc_a[SETTINGS_REC_MAX];
static uint8_t enc_b[SETTINGS_REC_MAX];

/* Canonical bytes of a settings_t (sequence 0), for comparing contents. */
static size_t canon(const settings_t *s, uint8_t *out)
{
    const size_t n = settings_encode(s, 0u, out, SETTINGS_REC_MAX);
    TEST_ASSERT_TRUE(n > 0u);
    return n;
}

static void boot(settings_status_t *st, settings_t *s, settings_scan_t *scan)
{
    sfm_power_on(&fm);
    *st = settings_store_load(&fl, buf, sizeof buf, s, scan);
}

static void test_empty_then_alternating_pages(void)
{
    sfm_init(&fm, 1u);
    sfm_flash(&fm, &fl);
    settings_t s;
    settings_scan_t scan;
    TEST_ASSERT_EQUAL_INT(SETTINGS_E_EMPTY, settings_store_load(&fl, buf, sizeof buf, &s, &scan));
    char msg[160];
    settings_load_message(&scan, msg, sizeof msg);
    TEST_ASSERT_NOT_NULL(strstr(msg, "no record in flash, compiled-in defaults"));
    uint32_t x = 2u;
    for (uint32_t i = 1; i <= 5u; i++) {
        settings_t w;
        sgen_settings(&x, &w);
        uint32_t seq = 0;
        TEST_ASSERT_EQUAL_INT(0, settings_store_save(&fl, buf, sizeof buf, &w, &seq));
        TEST_ASSERT_EQUAL_UINT32(i, seq);
        TEST_ASSERT_EQUAL_INT(SETTINGS_OK, settings_store_load(&fl, buf, sizeof buf, &s, &scan));
        TEST_ASSERT_EQUAL_INT((int)((i - 1u) % 2u), scan.page); /* 0, 1, 0, ... */
        TEST_ASSERT_EQUAL_UINT(canon(&w, enc_a), canon(&s, enc_b));
        TEST_ASSERT_EQUAL_MEMORY(enc_a, enc_b, settings_record_size());
        settings_load_message(&scan, msg, sizeof msg);
        char want[64];
        (void)snprintf(want, sizeof want, "record %u (page %u) applied", (unsigned)i,
                       (unsigned)((i - 1u) % 2u));
        TEST_ASSERT_NOT_NULL(strstr(msg, want));
    }
}

/* Bring fm into one of the starting states; *old: the record a boot applies
 * before the save (has_old false: none). */
static void make_start(int kind, uint32_t seed, settings_t *old, bool *has_old)
{
    sfm_init(&fm, seed);
    sfm_flash(&fm, &fl);
    uint32_t x = seed * 2654435761u + 1u;
    settings_t a;
    sgen_settings(&x, &a);
    *has_old = kind != 0;
    switch (kind) {
    case 0: /* erased device */
        break;
    case 1: /* one record */
        TEST_ASSERT_EQUAL_INT(0, settings_store_save(&fl, buf, sizeof buf, &a, NULL));
        break;
    case 2: /* two records: the save goes to the older one's page */
        sgen_settings(&x, old);
        TEST_ASSERT_EQUAL_INT(0, settings_store_save(&fl, buf, sizeof buf, old, NULL));
        TEST_ASSERT_EQUAL_INT(0, settings_store_save(&fl, buf, sizeof buf, &a, NULL));
        break;
    case 3: { /* one record, the other page torn by a cut in an earlier save */
        settings_t b;
        sgen_settings(&x, &b);
        TEST_ASSERT_EQUAL_INT(0, settings_store_save(&fl, buf, sizeof buf, &a, NULL));
        sfm_cut(&fm, 1u + sgen_rand(&x) % 10u, SFM_CUT_TORN);
        TEST_ASSERT_NOT_EQUAL(0, settings_store_save(&fl, buf, sizeof buf, &b, NULL));
        sfm_power_on(&fm);
        break;
    }
    default: { /* a record of an older format in page 1, a valid one in page 0 */
        TEST_ASSERT_EQUAL_INT(0, settings_store_save(&fl, buf, sizeof buf, &a, NULL));
        const size_t len = settings_encode(&a, 7u, enc_a, sizeof enc_a);
        enc_a[4] = 0u; /* format 0, intact CRC */
        const uint32_t crc = settings_crc32(enc_a, len - 4u);
        for (unsigned i = 0; i < 4u; i++) {
            enc_a[len - 4u + i] = (uint8_t)(crc >> (8u * i));
        }
        TEST_ASSERT_EQUAL_INT(0, fl.erase(fl.ctx, 1u));
        for (size_t off = 0; off < len; off += 8u) {
            TEST_ASSERT_EQUAL_INT(0, fl.program(fl.ctx, 1u, (uint32_t)off, enc_a + off));
        }
        break;
    }
    }
    if (*has_old) {
        settings_status_t st;
        settings_scan_t scan;
        boot(&st, old, &scan);
        TEST_ASSERT_EQUAL_INT(SETTINGS_OK, st);
    }
}

/* One cut at operation k (mode) of a save of w from state kind: the boot's
 * record is old or w, exactly; then a save succeeds. Returns false once k is
 * past the save's last operation (the save completed). */
static bool cut_one(int kind, uint32_t seed, uint32_t k, sfm_cut_t mode, const settings_t *w,
                    int *applied_old, int *applied_new)
{
    settings_t old;
    bool has_old;
    make_start(kind, seed, &old, &has_old);
    const uint32_t ops0 = fm.ops;
    sfm_cut(&fm, k, mode);
    const int rc = settings_store_save(&fl, buf, sizeof buf, w, NULL);
    const bool cut = fm.off;
    const bool done = fm.ops - ops0 < k;
    if (done) {
        TEST_ASSERT_EQUAL_INT(0, rc);
        return false;
    }
    TEST_ASSERT_TRUE(cut);
    if (mode == SFM_CUT_TORN || rc != 0) {
        TEST_ASSERT_NOT_EQUAL(0, rc); /* the save knows it did not finish */
    }
    settings_t got;
    settings_scan_t scan;
    settings_status_t st;
    boot(&st, &got, &scan);
    const size_t len = canon(w, enc_a);
    if (st == SETTINGS_OK) {
        canon(&got, enc_b);
        const bool is_new = memcmp(enc_a, enc_b, len) == 0;
        bool is_old = false;
        if (has_old) {
            canon(&old, enc_a);
            is_old = memcmp(enc_a, enc_b, len) == 0;
        }
        if (!is_new && !is_old) {
            char m[96];
            (void)snprintf(m, sizeof m, "kind %d seed %u cut at op %u mode %d: a third record",
                           kind, (unsigned)seed, (unsigned)k, (int)mode);
            TEST_FAIL_MESSAGE(m);
        }
        *applied_new += is_new;
        *applied_old += is_old && !is_new;
    } else {
        /* defaults only when there was nothing before */
        if (has_old) {
            char m[96];
            (void)snprintf(m, sizeof m, "kind %d seed %u cut at op %u mode %d: defaults", kind,
                           (unsigned)seed, (unsigned)k, (int)mode);
            TEST_FAIL_MESSAGE(m);
        }
    }
    /* the store recovers: the next save and boot give the newer record */
    settings_t w2 = *w;
    w2.pole_pairs = w->pole_pairs % 50 + 1;
    TEST_ASSERT_EQUAL_INT(0, settings_store_save(&fl, buf, sizeof buf, &w2, NULL));
    boot(&st, &got, &scan);
    TEST_ASSERT_EQUAL_INT(SETTINGS_OK, st);
    TEST_ASSERT_EQUAL_INT32(w2.pole_pairs, got.pole_pairs);
    return true;
}

static void test_power_cut_every_operation_of_a_save(void)
{
    const char *const kinds[] = {"no record", "one record", "two records", "beside a torn page",
                                 "beside an older format"};
    for (int kind = 0; kind < 5; kind++) {
        int cuts = 0;
        int applied_old = 0;
        int applied_new = 0;
        uint32_t ops_max = 0;
        for (uint32_t seed = 1; seed <= N_RECORDS; seed++) {
            uint32_t x = seed * 40503u + 7u;
            settings_t w;
            sgen_settings(&x, &w);
            for (int mode = 0; mode < 2; mode++) {
                uint32_t k = 1;
                while (cut_one(kind, seed, k, (sfm_cut_t)mode, &w, &applied_old, &applied_new)) {
                    cuts++;
                    k++;
                }
                ops_max = k - 1u > ops_max ? k - 1u : ops_max;
            }
        }
        printf("save %-22s: %u operations (1 erase + %u double words), %d cuts: old record %d, "
               "new %d, defaults %d\n",
               kinds[kind], (unsigned)ops_max, (unsigned)(settings_record_size() / 8u), cuts,
               applied_old, applied_new, cuts - applied_old - applied_new);
        /* every operation of the save was cut: one erase and every double word */
        TEST_ASSERT_EQUAL_UINT32(1u + settings_record_size() / 8u, ops_max);
        TEST_ASSERT_EQUAL_INT((int)N_RECORDS * 2 * (int)ops_max, cuts);
    }
}

static void test_power_cut_during_erase(void)
{
    for (uint32_t seed = 1; seed <= 2u * N_RECORDS; seed++) {
        for (int mode = 0; mode < 2; mode++) {
            for (uint32_t k = 1; k <= 2u; k++) {
                settings_t old;
                bool has_old;
                make_start(2, seed, &old, &has_old); /* two records: newest = old */
                sfm_cut(&fm, k, (sfm_cut_t)mode);
                (void)settings_store_erase(&fl, buf, sizeof buf);
                settings_t got;
                settings_scan_t scan;
                settings_status_t st;
                boot(&st, &got, &scan);
                if (st == SETTINGS_OK) {
                    /* only the newest record may survive, never the older one */
                    const size_t len = canon(&old, enc_a);
                    canon(&got, enc_b);
                    TEST_ASSERT_EQUAL_MEMORY(enc_a, enc_b, len);
                }
                TEST_ASSERT_EQUAL_INT(0, settings_store_erase(&fl, buf, sizeof buf));
                boot(&st, &got, &scan);
                TEST_ASSERT_EQUAL_INT(SETTINGS_E_EMPTY, st);
            }
        }
    }
}

static void test_other_format_refused_with_message(void)
{
    settings_t old;
    bool has_old;
    make_start(4, 3u, &old, &has_old);
    /* page 0 valid, page 1 format 0: the valid one is applied */
    settings_scan_t scan;
    settings_t got;
    TEST_ASSERT_EQUAL_INT(SETTINGS_OK, settings_store_load(&fl, buf, sizeof buf, &got, &scan));
    TEST_ASSERT_EQUAL_INT(0, scan.page);
    TEST_ASSERT_EQUAL_INT(SETTINGS_E_OLD, scan.status[1]);
    /* without page 0: refused, named, defaults */
    TEST_ASSERT_EQUAL_INT(0, fl.erase(fl.ctx, 0u));
    memset(&got, 0x5A, sizeof got);
    TEST_ASSERT_EQUAL_INT(SETTINGS_E_OLD, settings_store_load(&fl, buf, sizeof buf, &got, &scan));
    TEST_ASSERT_EQUAL_HEX8(0x5Au, ((uint8_t *)&got)[0]); /* nothing read into it */
    char msg[160];
    settings_load_message(&scan, msg, sizeof msg);
    TEST_ASSERT_NOT_NULL(
        strstr(msg, "page 1: record format 0 (this firmware reads 1 to 3), refused"));
    TEST_ASSERT_NOT_NULL(strstr(msg, "compiled-in defaults"));
}

static void test_ecc_page_falls_back(void)
{
    settings_t old;
    bool has_old;
    make_start(2, 5u, &old, &has_old);
    /* the newest record's page with one double word unreadable */
    settings_scan_t scan;
    settings_t got;
    TEST_ASSERT_EQUAL_INT(SETTINGS_OK, settings_store_load(&fl, buf, sizeof buf, &got, &scan));
    const int newest = scan.page;
    const uint32_t seq_old = scan.seq[1 - newest];
    fm.ecc_bad[newest][3] = 1u;
    TEST_ASSERT_EQUAL_INT(SETTINGS_OK, settings_store_load(&fl, buf, sizeof buf, &got, &scan));
    TEST_ASSERT_EQUAL_INT(1 - newest, scan.page);
    TEST_ASSERT_EQUAL_INT(SETTINGS_E_READ, scan.status[newest]);
    TEST_ASSERT_EQUAL_INT(SFM_E_ECC, scan.read_rc[newest]);
    TEST_ASSERT_EQUAL_UINT32(seq_old, scan.seq[1 - newest]);
    /* a program onto a double word that is not erased is refused */
    const uint8_t dw[8] = {0};
    TEST_ASSERT_EQUAL_INT(SFM_E_PROGERR, fl.program(fl.ctx, 1u - (unsigned)newest, 0u, dw));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_empty_then_alternating_pages);
    RUN_TEST(test_power_cut_every_operation_of_a_save);
    RUN_TEST(test_power_cut_during_erase);
    RUN_TEST(test_other_format_refused_with_message);
    RUN_TEST(test_ecc_page_falls_back);
    return UNITY_END();
}
