/*
 * The flash driver (hal/stm32g4/g4_flash.c) on a register model of the
 * STM32G431's flash interface (RM0440 chapter 3), every register starting
 * from its reset value (sec. 3.7: FLASH_ACR 0x0004_0600, FLASH_CR
 * 0xC000_0000, FLASH_SR and FLASH_ECCR 0). The model answers as the manual
 * describes: KEYR's two-key unlock (a wrong key locks FLASH_CR until reset),
 * writes to a locked FLASH_CR ignored, page erase on STRT with PER and PNB,
 * double-word programming with PG (first word, then second word at +4; PGAERR
 * for a misaligned or unpaired word, PROGERR onto a double word that is not
 * erased, PGSERR for STRT without PER), BSY held for some polls after each
 * operation, write protection (WRPERR) on request, ECCD on a read of a torn
 * double word, DCRST writable only while DCEN = 0. The writes are logged to
 * check their order. Builds for the host and as a QEMU image.
 */
#include <stdio.h>
#include <string.h>

#include "g4_flash.h"
#include "settings_store.h"
#include "unity.h"

/* ---- the model ---- */

uint32_t g4_mem_flash[0x400u / 4u];
uint32_t g4_mem_flash_settings[2u * G4_FLASH_PAGE_SIZE / 4u];

#define LOG_MAX 256u
static struct {
    uintptr_t reg[LOG_MAX];
    uint32_t val[LOG_MAX];
    unsigned n;
    unsigned key_state; /* 0: expect KEY1, 1: expect KEY2 */
    bool key_lockout;   /* wrong key: FLASH_CR locked until reset */
    bool pg_pending;    /* first word of a double word written */
    uintptr_t pg_addr;
    uint32_t pg_lo;
    unsigned busy_polls;    /* BSY stays set for this many SR reads */
    unsigned busy_after_op; /* ... after each operation */
    bool busy_stuck;
    bool wrp; /* both settings pages write-protected */
    uint8_t ecc_bad[2u * G4_FLASH_PAGE_SIZE / 8u];
    unsigned erases, programs;
    unsigned foreign_erase;  /* erases of a page that is not a settings page */
    unsigned dcrst_while_on; /* DCRST written with DCEN set */
    unsigned stray_writes;   /* flash memory written without PG */
    unsigned polls;          /* SR reads */
} fm;

#define REG(off) g4_mem_flash[(off) / 4u]

static void model_reset(void)
{
    memset(&fm, 0, sizeof fm);
    memset(g4_mem_flash, 0, sizeof g4_mem_flash);
    REG(G4_FLASH_ACR) = G4_FLASH_ACR_RESET;
    REG(G4_FLASH_CR) = G4_FLASH_CR_RESET;
    memset(g4_mem_flash_settings, 0xFF, sizeof g4_mem_flash_settings);
    fm.busy_after_op = 3u;
}

static bool in_settings(uintptr_t a)
{
    return a >= (uintptr_t)g4_mem_flash_settings &&
           a < (uintptr_t)g4_mem_flash_settings + sizeof g4_mem_flash_settings;
}

static void sr_set(uint32_t bits)
{
    REG(G4_FLASH_SR) |= bits;
}

static void op_done(void)
{
    fm.busy_polls = fm.busy_after_op;
    if ((REG(G4_FLASH_CR) & G4_BIT(24)) != 0u) { /* EOPIE */
        sr_set(G4_FLASH_SR_EOP);
    }
}

static void model_program(uintptr_t a, uint32_t v)
{
    const uint32_t cr = REG(G4_FLASH_CR);
    if ((cr & G4_FLASH_CR_PG) == 0u) {
        fm.stray_writes++;
        return;
    }
    const size_t w = (a - (uintptr_t)g4_mem_flash_settings) / 4u;
    if (!fm.pg_pending) {
        if ((w & 1u) != 0u) {
            sr_set(G4_FLASH_SR_PGAERR);
            return;
        }
        fm.pg_pending = true;
        fm.pg_addr = a;
        fm.pg_lo = v;
        return;
    }
    fm.pg_pending = false;
    if (a != fm.pg_addr + 4u) {
        sr_set(G4_FLASH_SR_PGAERR);
        return;
    }
    if (fm.wrp) {
        sr_set(G4_FLASH_SR_WRPERR);
        return;
    }
    uint32_t *mem = &g4_mem_flash_settings[w - 1u];
    if (mem[0] != 0xFFFFFFFFu || mem[1] != 0xFFFFFFFFu || fm.ecc_bad[(w - 1u) / 2u] != 0u) {
        sr_set(G4_FLASH_SR_PROGERR);
        return;
    }
    mem[0] &= fm.pg_lo;
    mem[1] &= v;
    fm.programs++;
    op_done();
}

static void model_cr(uint32_t v)
{
    uint32_t cr = REG(G4_FLASH_CR);
    if ((cr & G4_FLASH_CR_LOCK) != 0u) {
        return; /* locked: writes ignored */
    }
    cr = v & ~G4_FLASH_CR_STRT; /* STRT reads back 0 once the operation started */
    REG(G4_FLASH_CR) = cr | (v & G4_FLASH_CR_LOCK);
    if ((v & G4_FLASH_CR_STRT) == 0u) {
        return;
    }
    if ((v & G4_FLASH_CR_PER) == 0u || (v & G4_FLASH_CR_PG) != 0u) {
        sr_set(G4_FLASH_SR_PGSERR);
        return;
    }
    const uint32_t page = (v & G4_FLASH_CR_PNB_MASK) >> G4_FLASH_CR_PNB_POS;
    if (page < G4_FLASH_SETTINGS_PAGE) {
        fm.foreign_erase++;
        return;
    }
    if (fm.wrp) {
        sr_set(G4_FLASH_SR_WRPERR);
        return;
    }
    const unsigned p = page - G4_FLASH_SETTINGS_PAGE;
    memset(&g4_mem_flash_settings[p * G4_FLASH_PAGE_SIZE / 4u], 0xFF, G4_FLASH_PAGE_SIZE);
    memset(&fm.ecc_bad[p * G4_FLASH_PAGE_SIZE / 8u], 0, G4_FLASH_PAGE_SIZE / 8u);
    fm.erases++;
    op_done();
}

void g4_trace_write(uintptr_t reg, uint32_t value);
uint32_t g4_trace_read(uintptr_t reg);

void g4_trace_write(uintptr_t reg, uint32_t value)
{
    if (fm.n < LOG_MAX) {
        fm.reg[fm.n] = reg;
        fm.val[fm.n] = value;
        fm.n++;
    }
    if (in_settings(reg)) {
        model_program(reg, value);
        return;
    }
    const uintptr_t off = reg - (uintptr_t)g4_mem_flash;
    switch (off) {
    case G4_FLASH_KEYR:
        if (fm.key_lockout) {
            return;
        }
        if (fm.key_state == 0u && value == G4_FLASH_KEY1) {
            fm.key_state = 1u;
        } else if (fm.key_state == 1u && value == G4_FLASH_KEY2) {
            fm.key_state = 0u;
            REG(G4_FLASH_CR) &= ~G4_FLASH_CR_LOCK;
        } else {
            fm.key_lockout = true;
        }
        return;
    case G4_FLASH_SR:
        REG(G4_FLASH_SR) &= ~(value & (G4_FLASH_SR_ERRORS | G4_FLASH_SR_EOP)); /* rc_w1 */
        return;
    case G4_FLASH_CR:
        model_cr(value);
        return;
    case G4_FLASH_ECCR: {
        const uint32_t clr = value & (G4_FLASH_ECCR_ECCD | G4_FLASH_ECCR_ECCC);
        REG(G4_FLASH_ECCR) =
            (REG(G4_FLASH_ECCR) & ~clr & ~G4_FLASH_ECCR_ECCIE) | (value & G4_FLASH_ECCR_ECCIE);
        return;
    }
    case G4_FLASH_ACR:
        if ((value & G4_FLASH_ACR_DCRST) != 0u && (REG(G4_FLASH_ACR) & G4_FLASH_ACR_DCEN) != 0u) {
            fm.dcrst_while_on++;
        }
        REG(G4_FLASH_ACR) = value;
        return;
    default:
        REG(off) = value;
        return;
    }
}

uint32_t g4_trace_read(uintptr_t reg)
{
    if (in_settings(reg)) {
        const size_t w = (reg - (uintptr_t)g4_mem_flash_settings) / 4u;
        if (fm.ecc_bad[w / 2u] != 0u) {
            REG(G4_FLASH_ECCR) =
                (REG(G4_FLASH_ECCR) & G4_FLASH_ECCR_ECCIE) | G4_FLASH_ECCR_ECCD |
                ((G4_FLASH_SETTINGS_PAGE * G4_FLASH_PAGE_SIZE + (uint32_t)(w * 4u)) &
                 G4_FLASH_ECCR_ADDR_MASK);
        }
        return g4_mem_flash_settings[w];
    }
    const uintptr_t off = reg - (uintptr_t)g4_mem_flash;
    if (off == G4_FLASH_SR) {
        fm.polls++;
        if (fm.busy_stuck || fm.busy_polls > 0u) {
            if (fm.busy_polls > 0u) {
                fm.busy_polls--;
            }
            return REG(G4_FLASH_SR) | G4_FLASH_SR_BSY;
        }
    }
    return REG(off);
}

/* Index of the first logged write to FLASH + off with (value & mask) == want, from `from`. */
static int find(uintptr_t off, uint32_t mask, uint32_t want, int from)
{
    for (unsigned i = (unsigned)from; i < fm.n; i++) {
        if (fm.reg[i] == (uintptr_t)g4_mem_flash + off && (fm.val[i] & mask) == want) {
            return (int)i;
        }
    }
    return -1;
}

static int find_mem(int from)
{
    for (unsigned i = (unsigned)from; i < fm.n; i++) {
        if (in_settings(fm.reg[i])) {
            return (int)i;
        }
    }
    return -1;
}

void setUp(void)
{
    model_reset();
}

void tearDown(void)
{
}

/* ---- tests ---- */

static void assert_idle_locked(void)
{
    TEST_ASSERT_EQUAL_HEX32(G4_FLASH_CR_RESET, REG(G4_FLASH_CR)); /* LOCK, nothing else */
    TEST_ASSERT_EQUAL_HEX32(0u, REG(G4_FLASH_SR) & (G4_FLASH_SR_ERRORS | G4_FLASH_SR_EOP));
    TEST_ASSERT_EQUAL_HEX32(G4_FLASH_ACR_RESET, REG(G4_FLASH_ACR)); /* caches as they were */
    TEST_ASSERT_EQUAL_UINT(0u, fm.dcrst_while_on);
    TEST_ASSERT_EQUAL_UINT(0u, fm.foreign_erase);
    TEST_ASSERT_EQUAL_UINT(0u, fm.stray_writes);
}

static void test_erase_sequence(void)
{
    g4_mem_flash_settings[0] = 0x12345678u;
    g4_mem_flash_settings[G4_FLASH_PAGE_SIZE / 4u + 5u] = 0u;
    TEST_ASSERT_EQUAL_INT(0, g4_flash_erase(1u));
    TEST_ASSERT_EQUAL_UINT(1u, fm.erases);
    TEST_ASSERT_EQUAL_HEX32(0xFFFFFFFFu, g4_mem_flash_settings[G4_FLASH_PAGE_SIZE / 4u + 5u]);
    TEST_ASSERT_EQUAL_HEX32(0x12345678u, g4_mem_flash_settings[0]); /* page 62 untouched */
    /* KEY1, KEY2, then PER with PNB = 63, then STRT, then LOCK */
    const int k1 = find(G4_FLASH_KEYR, ~0u, G4_FLASH_KEY1, 0);
    const int k2 = find(G4_FLASH_KEYR, ~0u, G4_FLASH_KEY2, k1 + 1);
    const int per = find(G4_FLASH_CR, G4_FLASH_CR_PER | G4_FLASH_CR_PNB_MASK,
                         G4_FLASH_CR_PER | (63u << G4_FLASH_CR_PNB_POS), k2 + 1);
    const int strt = find(G4_FLASH_CR, G4_FLASH_CR_STRT, G4_FLASH_CR_STRT, per);
    const int lock = find(G4_FLASH_CR, G4_FLASH_CR_LOCK, G4_FLASH_CR_LOCK, strt + 1);
    TEST_ASSERT_TRUE(k1 >= 0 && k2 > k1 && per > k2 && strt >= per && lock > strt);
    /* the data cache off during the erase */
    const int dc_off = find(G4_FLASH_ACR, G4_FLASH_ACR_DCEN, 0u, 0);
    TEST_ASSERT_TRUE(dc_off >= 0 && dc_off < strt);
    /* the driver waited for BSY (the model holds it for 3 reads) */
    TEST_ASSERT_EQUAL_UINT(0u, fm.busy_polls);
    assert_idle_locked();
}

static void test_program_sequence(void)
{
    TEST_ASSERT_EQUAL_INT(0, g4_flash_program(0u, 16u, 0x03020100u, 0x07060504u));
    TEST_ASSERT_EQUAL_HEX32(0x03020100u, g4_mem_flash_settings[4]);
    TEST_ASSERT_EQUAL_HEX32(0x07060504u, g4_mem_flash_settings[5]);
    TEST_ASSERT_EQUAL_UINT(1u, fm.programs);
    const int pg = find(G4_FLASH_CR, G4_FLASH_CR_PG, G4_FLASH_CR_PG, 0);
    const int w0 = find_mem(0);
    const int w1 = find_mem(w0 + 1);
    TEST_ASSERT_TRUE(pg >= 0 && w0 > pg && w1 == w0 + 1);
    TEST_ASSERT_EQUAL_HEX32(0x03020100u, fm.val[w0]); /* low word first */
    const int pg_off = find(G4_FLASH_CR, G4_FLASH_CR_PG, 0u, w1);
    TEST_ASSERT_TRUE(pg_off > w1);
    TEST_ASSERT_EQUAL_UINT(0u, fm.busy_polls);
    assert_idle_locked();
    uint8_t b[8];
    TEST_ASSERT_EQUAL_INT(0, g4_flash_read(0u, 16u, b, sizeof b));
    const uint8_t want[8] = {0, 1, 2, 3, 4, 5, 6, 7};
    TEST_ASSERT_EQUAL_MEMORY(want, b, 8);
}

static void test_progerr_named(void)
{
    TEST_ASSERT_EQUAL_INT(0, g4_flash_program(1u, 0u, 0u, 0u));
    const int rc = g4_flash_program(1u, 0u, 0x1u, 0x2u);
    TEST_ASSERT_EQUAL_INT(-(G4_FLASH_E_SR + 3), rc);
    TEST_ASSERT_NOT_NULL(strstr(g4_flash_strerror(rc), "PROGERR"));
    TEST_ASSERT_EQUAL_HEX32(0u, g4_mem_flash_settings[G4_FLASH_PAGE_SIZE / 4u]);
    assert_idle_locked(); /* the flag cleared, PG off, locked */
}

static void test_wrperr_named(void)
{
    fm.wrp = true;
    int rc = g4_flash_erase(0u);
    TEST_ASSERT_EQUAL_INT(-(G4_FLASH_E_SR + 4), rc);
    TEST_ASSERT_NOT_NULL(strstr(g4_flash_strerror(rc), "WRPERR"));
    rc = g4_flash_program(0u, 8u, 0u, 0u);
    TEST_ASSERT_NOT_NULL(strstr(g4_flash_strerror(rc), "WRPERR"));
    assert_idle_locked();
}

static void test_old_error_flags_cleared_first(void)
{
    /* flags left by an earlier operation would stop the next one (PGSERR) */
    REG(G4_FLASH_SR) = G4_FLASH_SR_PGSERR | G4_FLASH_SR_PGAERR | G4_FLASH_SR_SIZERR;
    TEST_ASSERT_EQUAL_INT(0, g4_flash_erase(0u));
    TEST_ASSERT_EQUAL_UINT(1u, fm.erases);
    assert_idle_locked();
}

static void test_error_names(void)
{
    const struct {
        int bit;
        const char *name;
    } e[] = {{1, "OPERR"},  {3, "PROGERR"}, {4, "WRPERR"}, {5, "PGAERR"},
             {6, "SIZERR"}, {7, "PGSERR"},  {8, "MISERR"}, {9, "FASTERR"}};
    for (unsigned i = 0; i < sizeof e / sizeof e[0]; i++) {
        TEST_ASSERT_NOT_NULL(strstr(g4_flash_strerror(-(G4_FLASH_E_SR + e[i].bit)), e[i].name));
        TEST_ASSERT_TRUE((G4_FLASH_SR_ERRORS & G4_BIT(e[i].bit)) != 0u);
    }
    TEST_ASSERT_NOT_NULL(strstr(g4_flash_strerror(G4_FLASH_E_ECC), "ECCD"));
}

static void test_key_lockout(void)
{
    /* a wrong key earlier: FLASH_CR stays locked until reset */
    fm.key_lockout = true;
    TEST_ASSERT_EQUAL_INT(G4_FLASH_E_LOCKED, g4_flash_erase(0u));
    TEST_ASSERT_EQUAL_UINT(0u, fm.erases);
}

static void test_already_unlocked_no_keys(void)
{
    /* keys written only while LOCK is set (a KEYR write when unlocked would
     * be a wrong sequence on the chip) */
    REG(G4_FLASH_CR) = 0u;
    TEST_ASSERT_EQUAL_INT(0, g4_flash_erase(0u));
    TEST_ASSERT_EQUAL_INT(-1, find(G4_FLASH_KEYR, 0u, 0u, 0));
    TEST_ASSERT_FALSE(fm.key_lockout);
}

static void test_bad_addresses(void)
{
    TEST_ASSERT_EQUAL_INT(G4_FLASH_E_ADDR, g4_flash_erase(2u));
    TEST_ASSERT_EQUAL_INT(G4_FLASH_E_ADDR, g4_flash_program(0u, 4u, 0u, 0u));
    TEST_ASSERT_EQUAL_INT(G4_FLASH_E_ADDR, g4_flash_program(0u, G4_FLASH_PAGE_SIZE, 0u, 0u));
    uint8_t b[8];
    TEST_ASSERT_EQUAL_INT(G4_FLASH_E_ADDR, g4_flash_read(1u, G4_FLASH_PAGE_SIZE - 4u, b, 8u));
    TEST_ASSERT_EQUAL_UINT(0u, fm.n); /* nothing written */
}

static void test_ecc_read_and_nmi(void)
{
    fm.ecc_bad[3] = 1u; /* page 62, bytes 24..31 */
    uint8_t b[64];
    TEST_ASSERT_EQUAL_INT(0, g4_flash_read(0u, 0u, b, 24u));
    TEST_ASSERT_EQUAL_INT(G4_FLASH_E_ECC, g4_flash_read(0u, 0u, b, sizeof b));
    TEST_ASSERT_EQUAL_HEX32(0u, REG(G4_FLASH_ECCR) & G4_FLASH_ECCR_ECCD); /* cleared */
    /* the NMI: ECCD in a settings page is handled, elsewhere it is a fault */
    REG(G4_FLASH_ECCR) = G4_FLASH_ECCR_ECCD | (G4_FLASH_SETTINGS_PAGE * G4_FLASH_PAGE_SIZE + 24u);
    TEST_ASSERT_TRUE(g4_flash_nmi_ecc());
    TEST_ASSERT_EQUAL_HEX32(0u, REG(G4_FLASH_ECCR) & G4_FLASH_ECCR_ECCD);
    REG(G4_FLASH_ECCR) = G4_FLASH_ECCR_ECCD | 0x1000u; /* in the code */
    TEST_ASSERT_FALSE(g4_flash_nmi_ecc());
    REG(G4_FLASH_ECCR) = 0u; /* another NMI source */
    TEST_ASSERT_FALSE(g4_flash_nmi_ecc());
    /* the page erased: readable again */
    TEST_ASSERT_EQUAL_INT(0, g4_flash_erase(0u));
    TEST_ASSERT_EQUAL_INT(0, g4_flash_read(0u, 0u, b, sizeof b));
}

static void test_busy_timeout(void)
{
    /* BSY never clears: the driver gives up after G4_FLASH_BSY_POLLS reads
     * (1000 in this test's build) and says so, locked again */
    fm.busy_stuck = true;
    TEST_ASSERT_EQUAL_INT(G4_FLASH_E_BUSY, g4_flash_erase(0u));
    TEST_ASSERT_EQUAL_UINT(0u, fm.erases);
    TEST_ASSERT_TRUE(fm.polls >= 1000u && fm.polls <= 1010u);
    fm.busy_stuck = false;
    fm.busy_polls = 0u;
    TEST_ASSERT_EQUAL_INT(0, g4_flash_erase(0u)); /* BSY cleared: the next one goes */
}

/* ---- the settings store through the driver ---- */

static int dev_read(void *ctx, unsigned page, uint32_t off, uint8_t *buf, size_t n)
{
    (void)ctx;
    return g4_flash_read(page, off, buf, n);
}
static int dev_erase(void *ctx, unsigned page)
{
    (void)ctx;
    return g4_flash_erase(page);
}
static int dev_program(void *ctx, unsigned page, uint32_t off, const uint8_t dw[8])
{
    (void)ctx;
    const uint32_t lo =
        (uint32_t)dw[0] | (uint32_t)dw[1] << 8 | (uint32_t)dw[2] << 16 | (uint32_t)dw[3] << 24;
    const uint32_t hi =
        (uint32_t)dw[4] | (uint32_t)dw[5] << 8 | (uint32_t)dw[6] << 16 | (uint32_t)dw[7] << 24;
    return g4_flash_program(page, off, lo, hi);
}

static void test_store_through_driver(void)
{
    const settings_flash_t f = {NULL,      G4_FLASH_PAGE_SIZE, dev_read,
                                dev_erase, dev_program,        g4_flash_strerror};
    static uint8_t buf[SETTINGS_REC_MAX];
    settings_t s;
    memset(&s, 0, sizeof s);
    s.pole_pairs = 7;
    s.rs_ohm = 0.25;
    s.enc_direction = 1;
    strcpy(s.ctrl, "foc");
    uint32_t seq = 0;
    TEST_ASSERT_EQUAL_INT(0, settings_store_save(&f, buf, sizeof buf, &s, &seq));
    TEST_ASSERT_EQUAL_INT(0, settings_store_save(&f, buf, sizeof buf, &s, &seq));
    TEST_ASSERT_EQUAL_UINT32(2u, seq);
    TEST_ASSERT_EQUAL_UINT(2u, fm.erases);
    TEST_ASSERT_EQUAL_UINT(2u * settings_record_size() / 8u, fm.programs);
    settings_t back;
    settings_scan_t scan;
    TEST_ASSERT_EQUAL_INT(SETTINGS_OK, settings_store_load(&f, buf, sizeof buf, &back, &scan));
    TEST_ASSERT_EQUAL_INT(1, scan.page);
    TEST_ASSERT_EQUAL_INT32(7, back.pole_pairs);
    TEST_ASSERT_EQUAL_STRING("foc", back.ctrl);
    /* a torn double word in the newest page: the older record is applied */
    fm.ecc_bad[G4_FLASH_PAGE_SIZE / 8u + 2u] = 1u;
    TEST_ASSERT_EQUAL_INT(SETTINGS_OK, settings_store_load(&f, buf, sizeof buf, &back, &scan));
    TEST_ASSERT_EQUAL_INT(0, scan.page);
    TEST_ASSERT_EQUAL_INT(G4_FLASH_E_ECC, scan.read_rc[1]);
    assert_idle_locked();
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_erase_sequence);
    RUN_TEST(test_program_sequence);
    RUN_TEST(test_progerr_named);
    RUN_TEST(test_wrperr_named);
    RUN_TEST(test_old_error_flags_cleared_first);
    RUN_TEST(test_error_names);
    RUN_TEST(test_key_lockout);
    RUN_TEST(test_already_unlocked_no_keys);
    RUN_TEST(test_bad_addresses);
    RUN_TEST(test_ecc_read_and_nmi);
    RUN_TEST(test_busy_timeout);
    RUN_TEST(test_store_through_driver);
    return UNITY_END();
}
