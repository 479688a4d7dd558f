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
/* the other registers the driver touches: the cycle counter (g4_core.c's
 * time-outs), TIM1 (the NMI's gates off); NVIC and SCB for g4_core.c */
uint32_t g4_mem_dwt[0x10u / 4u];
uint32_t g4_mem_tim1[0x400u / 4u];
uint32_t g4_mem_nvic[0x400u / 4u];
uint32_t g4_mem_scb[0x100u / 4u];

/* Core clock of the model: DWT_CYCCNT counts its cycles. */
#define MODEL_HZ 170000000u
#define MS_CYCLES(ms) ((uint32_t)((double)(ms) * (MODEL_HZ / 1000u)))

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
    uint32_t busy_until;   /* BSY set until DWT_CYCCNT reaches this */
    uint32_t erase_cycles; /* how long an erase keeps BSY set */
    uint32_t prog_cycles;  /* ... a double word's programming */
    uint32_t poll_cycles;  /* the core cycles one read of FLASH_SR takes */
    bool busy_stuck;
    unsigned stuck_at_program; /* BSY sticks from this double word on (0: never) */
    bool wrp;                  /* both settings pages write-protected */
    uint8_t ecc_bad[2u * G4_FLASH_PAGE_SIZE / 8u];
    unsigned erases, programs;
    unsigned foreign_erase;  /* erases of a page that is not a settings page */
    unsigned dcrst_while_on; /* DCRST written with DCEN set */
    unsigned stray_writes;   /* flash memory written without PG */
    unsigned polls;          /* SR reads */
    unsigned seq;            /* accesses (reads and writes) so far */
    unsigned moe_off_seq;    /* seq of the first write clearing TIM1_BDTR.MOE, 0: none */
    unsigned flash_reg_seq;  /* seq of the first flash register access, 0: none */
    unsigned faults;         /* calls of the fault path (g4_fault_handler) */
    /* The NMI (RM0440 sec. 3.3.9): a read of a torn double word sets ECCD
     * (its address only while neither ECCC nor ECCD is set) and runs
     * g4_flash_nmi at once, unless no_nmi; fetch_error: the next settings
     * read meets an instruction fetch's ECCD instead (address in the code). */
    bool no_nmi;
    bool fetch_error;
    bool eccc_first; /* a corrected error in the code just before the torn read */
    unsigned nmi_runs;
    bool nmi_gates_first; /* the last NMI cleared MOE before its first flash register access */
} fm;

#define NOW g4_mem_dwt[G4_DWT_CYCCNT / 4u]

#define REG(off) g4_mem_flash[(off) / 4u]

static void model_reset(void)
{
    memset(&fm, 0, sizeof fm);
    memset(g4_mem_flash, 0, sizeof g4_mem_flash);
    REG(G4_FLASH_ACR) = G4_FLASH_ACR_RESET;
    REG(G4_FLASH_CR) = G4_FLASH_CR_RESET;
    memset(g4_mem_flash_settings, 0xFF, sizeof g4_mem_flash_settings);
    memset(g4_mem_dwt, 0, sizeof g4_mem_dwt);
    memset(g4_mem_tim1, 0, sizeof g4_mem_tim1);
    /* BSY for three polls after each operation (the timing test sets the
     * data sheet's times) */
    fm.poll_cycles = 8u;
    fm.erase_cycles = fm.prog_cycles = 3u * fm.poll_cycles;
    g4_flash_set_clock(MODEL_HZ);
}

void g4_flash_nmi(void);

/* ECCD with an address (kept while ECCC or ECCD is already set), then the
 * NMI as the core takes it. */
static void model_ecc_nmi(uint32_t addr)
{
    if (fm.eccc_first) {
        fm.eccc_first = false;
        REG(G4_FLASH_ECCR) |= G4_FLASH_ECCR_ECCC | 0x1000u; /* its address is kept */
    }
    const uint32_t eccr = REG(G4_FLASH_ECCR);
    uint32_t v = eccr | G4_FLASH_ECCR_ECCD;
    if ((eccr & (G4_FLASH_ECCR_ECCC | G4_FLASH_ECCR_ECCD)) == 0u) {
        v = (v & ~G4_FLASH_ECCR_ADDR_MASK) | (addr & G4_FLASH_ECCR_ADDR_MASK);
    }
    REG(G4_FLASH_ECCR) = v;
    if (fm.no_nmi) {
        return;
    }
    fm.nmi_runs++;
    fm.moe_off_seq = fm.flash_reg_seq = 0u;
    g4_mem_tim1[G4_TIM_BDTR / 4u] |= G4_TIM_BDTR_MOE; /* gates on when it strikes */
    g4_flash_nmi();
    fm.nmi_gates_first = fm.moe_off_seq != 0u && fm.moe_off_seq < fm.flash_reg_seq;
}

/* The fault path of g4_startup.c, counted. */
void g4_fault_handler(void);
void g4_fault_handler(void)
{
    fm.faults++;
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

static void op_done(uint32_t cycles)
{
    fm.busy_until = NOW + cycles;
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
    op_done(fm.prog_cycles);
    fm.busy_stuck = fm.busy_stuck || fm.programs == fm.stuck_at_program;
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
    op_done(fm.erase_cycles);
}

void g4_trace_write(uintptr_t reg, uint32_t value);
uint32_t g4_trace_read(uintptr_t reg);

/* A register of the model's other arrays, or NULL. */
static uint32_t *other_cell(uintptr_t reg)
{
    static const struct {
        uint32_t *a;
        size_t bytes;
    } arr[] = {{g4_mem_dwt, sizeof g4_mem_dwt},
               {g4_mem_tim1, sizeof g4_mem_tim1},
               {g4_mem_nvic, sizeof g4_mem_nvic},
               {g4_mem_scb, sizeof g4_mem_scb}};
    for (size_t i = 0; i < sizeof arr / sizeof arr[0]; i++) {
        if (reg >= (uintptr_t)arr[i].a && reg < (uintptr_t)arr[i].a + arr[i].bytes) {
            return (uint32_t *)reg;
        }
    }
    return NULL;
}

static void note_flash_reg(uintptr_t reg)
{
    fm.seq++;
    if (fm.flash_reg_seq == 0u && reg >= (uintptr_t)g4_mem_flash &&
        reg < (uintptr_t)g4_mem_flash + sizeof g4_mem_flash) {
        fm.flash_reg_seq = fm.seq;
    }
}

void g4_trace_write(uintptr_t reg, uint32_t value)
{
    note_flash_reg(reg);
    uint32_t *o = other_cell(reg);
    if (o != NULL) {
        if (reg == G4_TIM1 + G4_TIM_BDTR && (*o & G4_TIM_BDTR_MOE) != 0u &&
            (value & G4_TIM_BDTR_MOE) == 0u && fm.moe_off_seq == 0u) {
            fm.moe_off_seq = fm.seq;
        }
        *o = value;
        return;
    }
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
    note_flash_reg(reg);
    const uint32_t *o = other_cell(reg);
    if (o != NULL) {
        return *o;
    }
    if (in_settings(reg)) {
        const size_t w = (reg - (uintptr_t)g4_mem_flash_settings) / 4u;
        const uint32_t v = g4_mem_flash_settings[w];
        if (fm.fetch_error) {
            fm.fetch_error = false;
            model_ecc_nmi(0x1000u); /* the code's own double word */
        } else if (fm.ecc_bad[w / 2u] != 0u) {
            model_ecc_nmi(G4_FLASH_SETTINGS_PAGE * G4_FLASH_PAGE_SIZE + (uint32_t)(w * 4u));
        }
        return v;
    }
    const uintptr_t off = reg - (uintptr_t)g4_mem_flash;
    if (off == G4_FLASH_SR) {
        fm.polls++;
        NOW += fm.poll_cycles;
        if (fm.busy_stuck || (int32_t)(fm.busy_until - NOW) > 0) {
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
    TEST_ASSERT_TRUE((int32_t)(NOW - fm.busy_until) >= 0);
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
    TEST_ASSERT_TRUE((int32_t)(NOW - fm.busy_until) >= 0);
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

/* An uncorrectable ECC error in a settings read: the NMI (run by the model as
 * the core takes it) turns the gates off first, takes it as the read's error
 * (a read is in progress), clears ECCD and ECCC; the read says ECCD. */
static void test_ecc_read_and_nmi(void)
{
    fm.ecc_bad[3] = 1u; /* page 62, bytes 24..31 */
    uint8_t b[64];
    TEST_ASSERT_EQUAL_INT(0, g4_flash_read(0u, 0u, b, 24u));
    TEST_ASSERT_EQUAL_INT(G4_FLASH_E_ECC, g4_flash_read(0u, 0u, b, sizeof b));
    TEST_ASSERT_EQUAL_UINT(1u, fm.nmi_runs);
    TEST_ASSERT_TRUE_MESSAGE(fm.nmi_gates_first, "flash read before gates off");
    TEST_ASSERT_EQUAL_UINT(0u, fm.faults);
    TEST_ASSERT_EQUAL_HEX32(0u, REG(G4_FLASH_ECCR) & (G4_FLASH_ECCR_ECCD | G4_FLASH_ECCR_ECCC));
    /* the page erased: readable again */
    TEST_ASSERT_EQUAL_INT(0, g4_flash_erase(0u));
    TEST_ASSERT_EQUAL_INT(0, g4_flash_read(0u, 0u, b, sizeof b));
}

/* An old corrected error elsewhere (ECCC set, never cleared by anything
 * else) keeps FLASH_ECCR's address (RM0440: ADDR_ECC is not updated while
 * ECCC or ECCD is set): the read clears it first, so its own error has its
 * address; and were it set during the read, the read in progress still
 * decides. A decision by the address alone took the fault path: a settings
 * read's ECC error halted the board. */
static void test_ecc_with_an_old_corrected_error(void)
{
    fm.ecc_bad[3] = 1u;
    uint8_t b[64];
    REG(G4_FLASH_ECCR) = G4_FLASH_ECCR_ECCC | 0x1000u; /* corrected, in the code, long ago */
    TEST_ASSERT_EQUAL_INT(G4_FLASH_E_ECC, g4_flash_read(0u, 0u, b, sizeof b));
    TEST_ASSERT_EQUAL_UINT(0u, fm.faults);
    TEST_ASSERT_EQUAL_UINT(1u, fm.nmi_runs);
    /* a corrected error (an instruction fetch's) during the read, right
     * before the torn double word: the address is the corrected one's, and
     * the read in progress decides */
    fm.eccc_first = true;
    TEST_ASSERT_EQUAL_INT(G4_FLASH_E_ECC, g4_flash_read(0u, 0u, b, sizeof b));
    TEST_ASSERT_EQUAL_UINT(0u, fm.faults);
    TEST_ASSERT_EQUAL_UINT(2u, fm.nmi_runs);
    REG(G4_FLASH_ECCR) = G4_FLASH_ECCR_ECCC | 0x1000u;
    fm.ecc_bad[3] = 0u;
    TEST_ASSERT_EQUAL_INT(0, g4_flash_read(0u, 0u, b, sizeof b));
    TEST_ASSERT_EQUAL_HEX32(0u, REG(G4_FLASH_ECCR) & G4_FLASH_ECCR_ECCC); /* cleared */
}

/* The NMI is a fault unless a settings read is in progress: an ECC error at
 * a settings address with no read (the address alone does not make it the
 * store's), an instruction fetch's error during a read (its address in the
 * code), any other NMI source. */
static void test_ecc_nmi_outside_a_read_is_a_fault(void)
{
    REG(G4_FLASH_ECCR) = G4_FLASH_ECCR_ECCD | (G4_FLASH_SETTINGS_PAGE * G4_FLASH_PAGE_SIZE + 24u);
    TEST_ASSERT_FALSE(g4_flash_nmi_ecc());
    REG(G4_FLASH_ECCR) = 0u; /* another NMI source (clock security) */
    TEST_ASSERT_FALSE(g4_flash_nmi_ecc());
    uint8_t b[16];
    fm.fetch_error = true;
    (void)g4_flash_read(0u, 0u, b, sizeof b);
    TEST_ASSERT_EQUAL_UINT(1u, fm.nmi_runs);
    TEST_ASSERT_EQUAL_UINT_MESSAGE(1u, fm.faults, "an instruction fetch's ECC error is a fault");
}

/* Where no NMI comes (a register model without one), the read waits a
 * moment for it, then reports the error itself and clears the flags. */
static void test_ecc_without_nmi(void)
{
    fm.no_nmi = true;
    fm.ecc_bad[2] = 1u;
    uint8_t b[32];
    TEST_ASSERT_EQUAL_INT(G4_FLASH_E_ECC, g4_flash_read(0u, 0u, b, sizeof b));
    TEST_ASSERT_EQUAL_HEX32(0u, REG(G4_FLASH_ECCR) & G4_FLASH_ECCR_ECCD);
    TEST_ASSERT_EQUAL_UINT(0u, fm.faults);
}

/* BSY never clears: the driver gives up after G4_FLASH_BSY_MS of core
 * cycles and says so, locked again. The bound is above the data sheet's
 * longest operation (t_ERASE max 24.47 ms) and below the independent
 * watchdog (100 ms at LSI 32 kHz; 94 ms at its 34 kHz maximum). */
static void test_busy_timeout(void)
{
    fm.busy_stuck = true;
    const uint32_t t0 = NOW;
    const int rc = g4_flash_erase(0u);
    const double ms = (double)(NOW - t0) / (MODEL_HZ / 1000u);
    TEST_ASSERT_EQUAL_INT(G4_FLASH_E_BUSY, rc);
    TEST_ASSERT_NOT_NULL(strstr(g4_flash_strerror(rc), "BSY"));
    TEST_ASSERT_EQUAL_UINT(0u, fm.erases);
    TEST_ASSERT_TRUE_MESSAGE(ms > 24.47 && ms < 94.0, "time-out outside (t_ERASE max, watchdog)");
    TEST_ASSERT_DOUBLE_WITHIN(0.01, (double)G4_FLASH_BSY_MS, ms);
    assert_idle_locked();
    fm.busy_stuck = false;
    TEST_ASSERT_EQUAL_INT(0, g4_flash_erase(0u)); /* BSY cleared: the next one goes */
}

/* Without the core clock the driver cannot time BSY: it refuses, by name,
 * before touching the flash. */
static void test_no_clock_refused(void)
{
    g4_flash_set_clock(0u);
    const int rc = g4_flash_erase(0u);
    TEST_ASSERT_EQUAL_INT(G4_FLASH_E_CLOCK, rc);
    TEST_ASSERT_NOT_NULL(strstr(g4_flash_strerror(rc), "clock"));
    TEST_ASSERT_EQUAL_UINT(0u, fm.n);
}

/* Any other NMI: the gates off (TIM1_BDTR.MOE cleared) before the NMI reads
 * any flash register, then the fault path. */
static void test_nmi_gates_off_first(void)
{
    g4_mem_tim1[G4_TIM_BDTR / 4u] = G4_TIM_BDTR_MOE | G4_TIM_BDTR_BKE;
    REG(G4_FLASH_ECCR) = G4_FLASH_ECCR_ECCD | 0x1000u; /* in the code: a fault */
    g4_flash_nmi();
    TEST_ASSERT_TRUE_MESSAGE(fm.moe_off_seq != 0u, "MOE not cleared");
    TEST_ASSERT_TRUE_MESSAGE(fm.moe_off_seq < fm.flash_reg_seq, "flash read before gates off");
    TEST_ASSERT_EQUAL_HEX32(G4_TIM_BDTR_BKE, g4_mem_tim1[G4_TIM_BDTR / 4u]);
    TEST_ASSERT_EQUAL_UINT(1u, fm.faults);
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

static const settings_flash_t store_dev = {NULL,      G4_FLASH_PAGE_SIZE, dev_read,
                                           dev_erase, dev_program,        g4_flash_strerror};

/* A record with a few fields set. */
static void record_fill(settings_t *s)
{
    memset(s, 0, sizeof *s);
    s->pole_pairs = 7;
    s->rs_ohm = 0.25;
    s->enc_direction = 1;
    strcpy(s->ctrl, "foc");
}

static void test_store_through_driver(void)
{
    const settings_flash_t f = store_dev;
    static uint8_t buf[SETTINGS_REC_MAX];
    settings_t s;
    record_fill(&s);
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

/* A save with the page erase at the data sheet's maximum (t_ERASE 24.47 ms)
 * and each double word at 100 us (its typical 82 us with margin; the
 * maximum is not checked here) takes about 32 ms with nothing refreshing
 * the independent watchdog; with BSY stuck on the last double word it ends
 * with the flash's error, still inside the watchdog's 94 ms (100 ms nominal
 * at LSI 32 kHz, 34 kHz at most). */
static void test_save_time_under_watchdog(void)
{
    const settings_flash_t f = store_dev;
    static uint8_t buf[SETTINGS_REC_MAX];
    settings_t st;
    record_fill(&st);
    fm.erase_cycles = MS_CYCLES(24.47);
    fm.prog_cycles = MS_CYCLES(0.1);
    const unsigned dw = settings_record_size() / 8u;
    uint32_t seq = 0;
    uint32_t t0 = NOW;
    TEST_ASSERT_EQUAL_INT(0, settings_store_save(&f, buf, sizeof buf, &st, &seq));
    const double ms_ok = (double)(NOW - t0) / (MODEL_HZ / 1000u);
    TEST_ASSERT_DOUBLE_WITHIN(0.5, 24.47 + dw * 0.1, ms_ok);
    fm.stuck_at_program = fm.programs + dw;
    t0 = NOW;
    const int rc = settings_store_save(&f, buf, sizeof buf, &st, &seq);
    const double ms_stuck = (double)(NOW - t0) / (MODEL_HZ / 1000u);
    TEST_ASSERT_NOT_EQUAL(0, rc);
    TEST_ASSERT_NOT_NULL(strstr(settings_store_strerror(&f, rc), "BSY"));
    TEST_ASSERT_TRUE_MESSAGE(ms_stuck < 94.0, "a stuck BSY outlasts the watchdog");
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
    RUN_TEST(test_ecc_with_an_old_corrected_error);
    RUN_TEST(test_ecc_nmi_outside_a_read_is_a_fault);
    RUN_TEST(test_ecc_without_nmi);
    RUN_TEST(test_busy_timeout);
    RUN_TEST(test_no_clock_refused);
    RUN_TEST(test_nmi_gates_off_first);
    RUN_TEST(test_save_time_under_watchdog);
    RUN_TEST(test_store_through_driver);
    return UNITY_END();
}
