/*
 * The settings-sector driver (hal/stm32f4/f4_flash.c) on the flash
 * interface of the F4 register model (f4_model.c: FLASH_CR 0x8000_0000 =
 * LOCK after reset, KEYR's two-key unlock, writes to a locked FLASH_CR
 * ignored, sector erase on STRT with SER and SNB, word programming only
 * with PG and PSIZE x32 (PGSERR / PGPERR otherwise), bits that only go from
 * 1 to 0, WRPERR on a protected sector, BSY stuck on request), then the
 * settings store (two sectors used alternately) through it.
 */
#include <string.h>

#include "f4_core.h"
#include "f4_flash.h"
#include "f4_model.h"
#include "settings_store.h"
#include "unity.h"

#define REG(off) f4_model_get(F4_FLASH + (off))
#define MODEL_HZ 16000000u

void setUp(void)
{
    f4_model_reset();
    f4_cycle_counter_init();
    f4_flash_set_clock(MODEL_HZ);
}

void tearDown(void)
{
}

static void assert_idle_locked(void)
{
    TEST_ASSERT_EQUAL_HEX32(
        F4_FLASH_CR_LOCK, REG(F4_FLASH_CR) & (F4_FLASH_CR_LOCK | F4_FLASH_CR_PG | F4_FLASH_CR_SER));
}

/* Sector 2 (settings sector 1) erased: KEY1, KEY2 (RM0090 sec. 3.5.1) before
 * FLASH_CR is written; SER with SNB = 2 (bits 6:3 = 0x10) and PSIZE x32
 * (bits 9:8 = 10: 0x200) = 0x212 written before STRT; the sector reads 0xFF,
 * the other settings sector untouched; locked again with SER and SNB
 * cleared; both caches reset after it (ICRST, DCRST written). */
static void test_erase_sequence(void)
{
    memset(f4_mem_flash_settings, 0, 2u * F4_FLASH_SECTOR_SIZE);
    f4_model_put(F4_FLASH + F4_FLASH_ACR, F4_FLASH_ACR_ICEN | F4_FLASH_ACR_DCEN | 5u);
    TEST_ASSERT_EQUAL_INT(0, f4_flash_erase(1u));
    TEST_ASSERT_EQUAL_HEX32(0xFFFFFFFFu, f4_mem_flash_settings[F4_FLASH_SECTOR_SIZE / 4u]);
    TEST_ASSERT_EQUAL_HEX32(0xFFFFFFFFu,
                            f4_mem_flash_settings[2u * F4_FLASH_SECTOR_SIZE / 4u - 1u]);
    TEST_ASSERT_EQUAL_HEX32(0u, f4_mem_flash_settings[0]);
    const int key1 = f4_model_find(F4_FLASH + F4_FLASH_KEYR, 0xFFFFFFFFu, F4_FLASH_KEY1, 0);
    const int key2 = f4_model_find(F4_FLASH + F4_FLASH_KEYR, 0xFFFFFFFFu, F4_FLASH_KEY2, 0);
    const int ser = f4_model_find(F4_FLASH + F4_FLASH_CR, 0x37Bu, 0x212u, 0);
    const int strt = f4_model_find(F4_FLASH + F4_FLASH_CR, F4_FLASH_CR_STRT, F4_FLASH_CR_STRT, 0);
    TEST_ASSERT_TRUE(key1 >= 0 && key1 < key2 && key2 < ser && ser < strt);
    TEST_ASSERT_TRUE(f4_model_find(F4_FLASH + F4_FLASH_ACR, F4_FLASH_ACR_ICRST, F4_FLASH_ACR_ICRST,
                                   strt) > strt);
    TEST_ASSERT_TRUE(f4_model_find(F4_FLASH + F4_FLASH_ACR, F4_FLASH_ACR_DCRST, F4_FLASH_ACR_DCRST,
                                   strt) > strt);
    TEST_ASSERT_EQUAL_HEX32(F4_FLASH_ACR_ICEN | F4_FLASH_ACR_DCEN | 5u, REG(F4_FLASH_ACR));
    assert_idle_locked();
}

/* A double word as two words (x32), each in a PG sequence; the words read
 * back; a word onto one not erased gives the AND (flash bits only fall):
 * the driver reports no error for it (the F4 has none), the store's
 * read-back catches it (test_store_through_driver). */
static void test_program_sequence(void)
{
    TEST_ASSERT_EQUAL_INT(0, f4_flash_program(0u, 8u, 0x12345678u, 0x9ABCDEF0u));
    TEST_ASSERT_EQUAL_HEX32(0x12345678u, f4_mem_flash_settings[2]);
    TEST_ASSERT_EQUAL_HEX32(0x9ABCDEF0u, f4_mem_flash_settings[3]);
    TEST_ASSERT_TRUE(f4_model_find(F4_FLASH + F4_FLASH_CR, 0x301u, 0x201u, 0) >= 0);
    uint8_t buf[8];
    TEST_ASSERT_EQUAL_INT(0, f4_flash_read(0u, 8u, buf, sizeof buf));
    TEST_ASSERT_EQUAL_HEX8(0x78u, buf[0]);
    TEST_ASSERT_EQUAL_HEX8(0x9Au, buf[7]);
    TEST_ASSERT_EQUAL_INT(0, f4_flash_program(0u, 8u, 0xFFFF0000u, 0xFFFFFFFFu));
    TEST_ASSERT_EQUAL_HEX32(0x12340000u, f4_mem_flash_settings[2]);
    assert_idle_locked();
}

/* A write-protected sector: WRPERR by name, nothing erased; the error
 * flags of an earlier operation cleared before the next one starts. */
static void test_wrperr_named(void)
{
    memset(f4_mem_flash_settings, 0, 2u * F4_FLASH_SECTOR_SIZE);
    f4_model.flash_wrp[1] = true;
    const int rc = f4_flash_erase(0u);
    TEST_ASSERT_EQUAL_INT(-(F4_FLASH_E_SR + 4), rc);
    TEST_ASSERT_EQUAL_STRING("WRPERR (sector write-protected)", f4_flash_strerror(rc));
    TEST_ASSERT_EQUAL_HEX32(0u, f4_mem_flash_settings[0]);
    f4_model.flash_wrp[1] = false;
    TEST_ASSERT_EQUAL_INT(0, f4_flash_erase(0u));
    assert_idle_locked();
}

/* Outside the settings sectors, misaligned, or before the clock is known:
 * refused without touching the interface. */
static void test_bad_arguments(void)
{
    f4_model.n_log = 0u;
    TEST_ASSERT_EQUAL_INT(F4_FLASH_E_ADDR, f4_flash_erase(2u));
    TEST_ASSERT_EQUAL_INT(F4_FLASH_E_ADDR, f4_flash_program(0u, 4u, 0u, 0u));
    TEST_ASSERT_EQUAL_INT(F4_FLASH_E_ADDR, f4_flash_program(0u, F4_FLASH_SECTOR_SIZE, 0u, 0u));
    uint8_t b[4];
    TEST_ASSERT_EQUAL_INT(F4_FLASH_E_ADDR, f4_flash_read(1u, 2u, b, 4u));
    TEST_ASSERT_EQUAL_UINT32(0u, f4_model.n_log);
    f4_flash_set_clock(0u);
    TEST_ASSERT_EQUAL_INT(F4_FLASH_E_CLOCK, f4_flash_erase(0u));
}

/* BSY never clears: the erase gives up after F4_FLASH_BSY_MS (1 s, above a
 * 16 KB sector's 800 ms worst case) counted by the cycle counter, with
 * its name, and locks again. */
static void test_busy_timeout(void)
{
    f4_model.flash_bsy_stuck = true;
    const uint32_t t0 = f4_model_get(F4_DWT + F4_DWT_CYCCNT);
    const int rc = f4_flash_erase(0u);
    const uint32_t t1 = f4_model_get(F4_DWT + F4_DWT_CYCCNT);
    TEST_ASSERT_EQUAL_INT(F4_FLASH_E_BUSY, rc);
    TEST_ASSERT_EQUAL_STRING("BSY did not clear in 1000 ms", f4_flash_strerror(rc));
    const double ms = (double)(t1 - t0) / (MODEL_HZ / 1000u);
    TEST_ASSERT_TRUE(ms >= 1000.0 && ms < 1010.0);
}

/* ---- the settings store through the driver ---- */

static int dev_read(void *ctx, unsigned page, uint32_t off, uint8_t *buf, size_t n)
{
    (void)ctx;
    return f4_flash_read(page, off, buf, n);
}
static int dev_erase(void *ctx, unsigned page)
{
    (void)ctx;
    return f4_flash_erase(page);
}
static int dev_program(void *ctx, unsigned page, uint32_t off, const uint8_t dw[8])
{
    (void)ctx;
    const uint32_t lo =
        (uint32_t)dw[0] | (uint32_t)dw[1] << 8 | (uint32_t)dw[2] << 16 | (uint32_t)dw[3] << 24;
    const uint32_t hi =
        (uint32_t)dw[4] | (uint32_t)dw[5] << 8 | (uint32_t)dw[6] << 16 | (uint32_t)dw[7] << 24;
    return f4_flash_program(page, off, lo, hi);
}

static const settings_flash_t store_dev = {NULL,      F4_FLASH_SECTOR_SIZE, dev_read,
                                           dev_erase, dev_program,          f4_flash_strerror};

/* Two saves go to the two sectors in turn; the newest is loaded. A sector
 * that refuses (write-protected) fails the save by name and leaves the
 * previous record applied. */
static void test_store_through_driver(void)
{
    static uint8_t buf[SETTINGS_REC_MAX];
    settings_t s;
    memset(&s, 0, sizeof s);
    s.pole_pairs = 7;
    s.rs_ohm = 0.047;
    strcpy(s.ctrl, "m2ptfc");
    uint32_t seq = 0;
    TEST_ASSERT_EQUAL_INT(0, settings_store_save(&store_dev, buf, sizeof buf, &s, &seq));
    s.pole_pairs = 11;
    TEST_ASSERT_EQUAL_INT(0, settings_store_save(&store_dev, buf, sizeof buf, &s, &seq));
    TEST_ASSERT_EQUAL_UINT32(2u, seq);
    settings_t back;
    settings_scan_t scan;
    TEST_ASSERT_EQUAL_INT(SETTINGS_OK,
                          settings_store_load(&store_dev, buf, sizeof buf, &back, &scan));
    TEST_ASSERT_EQUAL_INT(1, scan.page);
    TEST_ASSERT_EQUAL_INT32(11, back.pole_pairs);
    TEST_ASSERT_EQUAL_STRING("m2ptfc", back.ctrl);
    f4_model.flash_wrp[1] = true; /* the next save goes to sector 1 */
    s.pole_pairs = 3;
    const int rc = settings_store_save(&store_dev, buf, sizeof buf, &s, &seq);
    TEST_ASSERT_NOT_EQUAL(0, rc);
    TEST_ASSERT_NOT_NULL(strstr(settings_store_strerror(&store_dev, rc), "WRPERR"));
    TEST_ASSERT_EQUAL_INT(SETTINGS_OK,
                          settings_store_load(&store_dev, buf, sizeof buf, &back, &scan));
    TEST_ASSERT_EQUAL_INT32(11, back.pole_pairs);
    assert_idle_locked();
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_erase_sequence);
    RUN_TEST(test_program_sequence);
    RUN_TEST(test_wrperr_named);
    RUN_TEST(test_bad_arguments);
    RUN_TEST(test_busy_timeout);
    RUN_TEST(test_store_through_driver);
    return UNITY_END();
}
