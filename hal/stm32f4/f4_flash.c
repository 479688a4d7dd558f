/*
 * STM32F405/407 flash: the settings sectors (f4_flash.h). Sequences of RM0090
 * sec. 3.5.1 (unlock), 3.5.3 (sector erase) and 3.5.4 (programming).
 */
#include "f4_flash.h"

#include "f4_core.h"

#define F4_FLASH_STR2(x) #x
#define F4_FLASH_STR(x) F4_FLASH_STR2(x)

/* PSIZE = 10: x32 (RM0090 table 7, 2.7 .. 3.6 V). */
#define F4_FLASH_PSIZE_X32 F4_FIELD(2u, F4_FLASH_CR_PSIZE_POS)

static uint32_t f4_flash_bsy_cycles;

static const char *const f4_flash_sr_names[8] = {
    "EOP",
    "OPERR (operation error)",
    "?",
    "?",
    "WRPERR (sector write-protected)",
    "PGAERR (programming alignment)",
    "PGPERR (programming parallelism)",
    "PGSERR (programming sequence)",
};

const char *f4_flash_strerror(int rc)
{
    if (rc == 0) {
        return "ok";
    }
    if (rc <= -F4_FLASH_E_SR && rc > -F4_FLASH_E_SR - 8) {
        return f4_flash_sr_names[-rc - F4_FLASH_E_SR];
    }
    switch (rc) {
    case F4_FLASH_E_BUSY:
        return "BSY did not clear in " F4_FLASH_STR(F4_FLASH_BSY_MS) " ms";
    case F4_FLASH_E_CLOCK:
        return "no core clock for the BSY time-out (f4_flash_set_clock)";
    case F4_FLASH_E_LOCKED:
        return "LOCK still set after the KEYR sequence";
    case F4_FLASH_E_ADDR:
        return "address outside the settings sectors";
    default:
        return "flash error";
    }
}

void f4_flash_set_clock(uint32_t hclk_hz)
{
    f4_flash_bsy_cycles = hclk_hz / 1000u * (uint32_t)F4_FLASH_BSY_MS;
}

/* Timed by the cycle counter, which also counts the cycles the core spends
 * stalled on a fetch from the bank being erased. */
static bool f4_flash_wait_idle(void)
{
    return f4_wait_bits(F4_FLASH + F4_FLASH_SR, F4_FLASH_SR_BSY, 0u, f4_flash_bsy_cycles);
}

static int f4_flash_sr_error(uint32_t sr)
{
    const uint32_t e = sr & F4_FLASH_SR_ERRORS;
    if (e == 0u) {
        return 0;
    }
    int bit = 0;
    while ((e & F4_BIT(bit)) == 0u) {
        bit++;
    }
    return -(F4_FLASH_E_SR + bit);
}

/* No operation running, the error flags of an earlier one cleared (rc_w1),
 * the control register unlocked (KEY1 then KEY2, only while LOCK is set: a
 * wrong sequence locks FLASH_CR until the next reset). */
static int f4_flash_begin(void)
{
    if (f4_flash_bsy_cycles == 0u) {
        return F4_FLASH_E_CLOCK;
    }
    if (!f4_flash_wait_idle()) {
        return F4_FLASH_E_BUSY;
    }
    f4_wr(F4_FLASH + F4_FLASH_SR, F4_FLASH_SR_ERRORS | F4_FLASH_SR_EOP);
    if ((f4_rd(F4_FLASH + F4_FLASH_CR) & F4_FLASH_CR_LOCK) != 0u) {
        f4_wr(F4_FLASH + F4_FLASH_KEYR, F4_FLASH_KEY1);
        f4_wr(F4_FLASH + F4_FLASH_KEYR, F4_FLASH_KEY2);
        if ((f4_rd(F4_FLASH + F4_FLASH_CR) & F4_FLASH_CR_LOCK) != 0u) {
            return F4_FLASH_E_LOCKED;
        }
    }
    return 0;
}

/* Wait for the end and return the operation's result (its flags cleared). */
static int f4_flash_wait_done(void)
{
    const bool idle = f4_flash_wait_idle();
    const uint32_t sr = f4_rd(F4_FLASH + F4_FLASH_SR);
    f4_wr(F4_FLASH + F4_FLASH_SR, (sr & F4_FLASH_SR_ERRORS) | F4_FLASH_SR_EOP);
    if (!idle) {
        return F4_FLASH_E_BUSY;
    }
    return f4_flash_sr_error(sr);
}

/* Operation bits cleared, LOCK set. */
static void f4_flash_end(uint32_t op_bits)
{
    f4_mod(F4_FLASH + F4_FLASH_CR, op_bits, 0u);
    f4_mod(F4_FLASH + F4_FLASH_CR, F4_FLASH_CR_LOCK, F4_FLASH_CR_LOCK);
}

/* The caches may hold words of the sector from before the operation: each
 * one off, reset (xCRST is writable only while xCEN = 0), on again, as ST's
 * FLASH_FlushCaches. */
static void f4_flash_caches_flush(void)
{
    const uint32_t acr = f4_rd(F4_FLASH + F4_FLASH_ACR);
    if ((acr & F4_FLASH_ACR_ICEN) != 0u) {
        f4_mod(F4_FLASH + F4_FLASH_ACR, F4_FLASH_ACR_ICEN, 0u);
        f4_mod(F4_FLASH + F4_FLASH_ACR, F4_FLASH_ACR_ICRST, F4_FLASH_ACR_ICRST);
        f4_mod(F4_FLASH + F4_FLASH_ACR, F4_FLASH_ACR_ICRST | F4_FLASH_ACR_ICEN, F4_FLASH_ACR_ICEN);
    }
    if ((acr & F4_FLASH_ACR_DCEN) != 0u) {
        f4_mod(F4_FLASH + F4_FLASH_ACR, F4_FLASH_ACR_DCEN, 0u);
        f4_mod(F4_FLASH + F4_FLASH_ACR, F4_FLASH_ACR_DCRST, F4_FLASH_ACR_DCRST);
        f4_mod(F4_FLASH + F4_FLASH_ACR, F4_FLASH_ACR_DCRST | F4_FLASH_ACR_DCEN, F4_FLASH_ACR_DCEN);
    }
}

int f4_flash_erase(unsigned s)
{
    if (s > 1u) {
        return F4_FLASH_E_ADDR;
    }
    int rc = f4_flash_begin();
    if (rc != 0) {
        return rc;
    }
    const uint32_t sector = F4_FLASH_SETTINGS_SECTOR + s;
    f4_mod(F4_FLASH + F4_FLASH_CR, F4_FLASH_CR_PSIZE_MASK | F4_FLASH_CR_SNB_MASK | F4_FLASH_CR_SER,
           F4_FLASH_PSIZE_X32 | F4_FIELD(sector, F4_FLASH_CR_SNB_POS) | F4_FLASH_CR_SER);
    f4_mod(F4_FLASH + F4_FLASH_CR, F4_FLASH_CR_STRT, F4_FLASH_CR_STRT);
    rc = f4_flash_wait_done();
    f4_flash_end(F4_FLASH_CR_SER | F4_FLASH_CR_SNB_MASK);
    f4_flash_caches_flush();
    return rc;
}

int f4_flash_program(unsigned s, uint32_t off, uint32_t lo, uint32_t hi)
{
    if (s > 1u || (off & 7u) != 0u || off >= F4_FLASH_SECTOR_SIZE) {
        return F4_FLASH_E_ADDR;
    }
    int rc = f4_flash_begin();
    if (rc != 0) {
        return rc;
    }
    const uintptr_t at = F4_FLASH_SETTINGS_BASE + s * F4_FLASH_SECTOR_SIZE + off;
    f4_mod(F4_FLASH + F4_FLASH_CR, F4_FLASH_CR_PSIZE_MASK | F4_FLASH_CR_PG,
           F4_FLASH_PSIZE_X32 | F4_FLASH_CR_PG);
    /* One word at a time, each waited for (sec. 3.5.4 steps 3-4). */
    f4_wr(at, lo);
    rc = f4_flash_wait_done();
    if (rc == 0) {
        f4_wr(at + 4u, hi);
        rc = f4_flash_wait_done();
    }
    f4_flash_end(F4_FLASH_CR_PG);
    f4_flash_caches_flush();
    return rc;
}

int f4_flash_read(unsigned s, uint32_t off, uint8_t *buf, size_t n)
{
    if (s > 1u || off > F4_FLASH_SECTOR_SIZE || n > F4_FLASH_SECTOR_SIZE - off ||
        (off & 3u) != 0u) {
        return F4_FLASH_E_ADDR;
    }
    const uintptr_t base = F4_FLASH_SETTINGS_BASE + s * F4_FLASH_SECTOR_SIZE;
    for (size_t i = 0; i < n; i += 4u) {
        const uint32_t w = f4_rd(base + off + i);
        const size_t k = n - i < 4u ? n - i : 4u;
        for (size_t b = 0; b < k; b++) {
            buf[i + b] = (uint8_t)(w >> (8u * b));
        }
    }
    return 0;
}
