/*
 * STM32G431 flash: the settings pages (g4_flash.h). Sequences of RM0440
 * sec. 3.3.5 (unlock), 3.3.7 (page erase) and 3.3.8 (standard programming).
 */
#include "g4_flash.h"

#include <string.h>

#include "g4_core.h"

#define G4_FLASH_STR2(x) #x
#define G4_FLASH_STR(x) G4_FLASH_STR2(x)

/* The fault path of g4_startup.c: gates off, waits for the watchdog. */
void g4_fault_handler(void);

/* Core cycles a BSY wait may take (g4_flash_set_clock; 0: not given). */
static uint32_t g4_flash_bsy_cycles;

/* A read of the settings pages in progress (g4_flash_read): the NMI takes an
 * uncorrectable ECC error as that read's by it, as ST's EEPROM emulation
 * decides by the read it has in progress. */
static volatile uint32_t g4_flash_reading;
/* Set by the NMI when it took the read's ECC error. */
static volatile uint32_t g4_flash_eccd;

static const char *const g4_flash_sr_names[16] = {
    "EOP",
    "OPERR (operation error)",
    "?",
    "PROGERR (double word not erased)",
    "WRPERR (page write-protected)",
    "PGAERR (programming alignment)",
    "SIZERR (not a double word)",
    "PGSERR (programming sequence)",
    "MISERR (fast programming data miss)",
    "FASTERR (fast programming)",
    "?",
    "?",
    "?",
    "?",
    "RDERR (PCROP read)",
    "OPTVERR (option validity)",
};

const char *g4_flash_strerror(int rc)
{
    if (rc == 0) {
        return "ok";
    }
    if (rc <= -G4_FLASH_E_SR && rc > -G4_FLASH_E_SR - 16) {
        return g4_flash_sr_names[-rc - G4_FLASH_E_SR];
    }
    switch (rc) {
    case G4_FLASH_E_BUSY:
        return "BSY did not clear in " G4_FLASH_STR(G4_FLASH_BSY_MS) " ms";
    case G4_FLASH_E_CLOCK:
        return "no core clock for the BSY time-out (g4_flash_set_clock)";
    case G4_FLASH_E_LOCKED:
        return "LOCK still set after the KEYR sequence";
    case G4_FLASH_E_ECC:
        return "ECCD (uncorrectable ECC error)";
    case G4_FLASH_E_ADDR:
        return "address outside the settings pages";
    default:
        return "flash error";
    }
}

void g4_flash_set_clock(uint32_t hclk_hz)
{
    g4_flash_bsy_cycles = hclk_hz / 1000u * (uint32_t)G4_FLASH_BSY_MS;
}

/* Timed by the cycle counter, which also counts the cycles the core spends
 * stalled on a fetch from the bank being erased. */
static bool g4_flash_wait_idle(void)
{
    return g4_wait_bits(G4_FLASH + G4_FLASH_SR, G4_FLASH_SR_BSY, 0u, g4_flash_bsy_cycles);
}

/* The first error flag of FLASH_SR as a return code, 0 if none. */
static int g4_flash_sr_error(uint32_t sr)
{
    const uint32_t e = sr & G4_FLASH_SR_ERRORS;
    if (e == 0u) {
        return 0;
    }
    int bit = 0;
    while ((e & G4_BIT(bit)) == 0u) {
        bit++;
    }
    return -(G4_FLASH_E_SR + bit);
}

/* No operation running, error flags of an earlier one cleared (rc_w1), the
 * control register unlocked: steps 1-2 of RM0440's erase and programming
 * sequences, then sec. 3.3.5 (KEY1 then KEY2; a wrong sequence would lock
 * FLASH_CR until reset, so the keys are written only while LOCK is set). */
static int g4_flash_begin(void)
{
    if (g4_flash_bsy_cycles == 0u) {
        return G4_FLASH_E_CLOCK;
    }
    if (!g4_flash_wait_idle()) {
        return G4_FLASH_E_BUSY;
    }
    g4_wr(G4_FLASH + G4_FLASH_SR, G4_FLASH_SR_ERRORS | G4_FLASH_SR_EOP);
    if ((g4_rd(G4_FLASH + G4_FLASH_CR) & G4_FLASH_CR_LOCK) != 0u) {
        g4_wr(G4_FLASH + G4_FLASH_KEYR, G4_FLASH_KEY1);
        g4_wr(G4_FLASH + G4_FLASH_KEYR, G4_FLASH_KEY2);
        if ((g4_rd(G4_FLASH + G4_FLASH_CR) & G4_FLASH_CR_LOCK) != 0u) {
            return G4_FLASH_E_LOCKED;
        }
    }
    return 0;
}

/* Wait for the end, clear the operation bits, lock; the operation's result. */
static int g4_flash_end(uint32_t op_bits)
{
    const bool idle = g4_flash_wait_idle();
    const uint32_t sr = g4_rd(G4_FLASH + G4_FLASH_SR);
    g4_wr(G4_FLASH + G4_FLASH_SR, (sr & G4_FLASH_SR_ERRORS) | G4_FLASH_SR_EOP);
    g4_mod(G4_FLASH + G4_FLASH_CR, op_bits, 0u);
    g4_mod(G4_FLASH + G4_FLASH_CR, G4_FLASH_CR_LOCK, G4_FLASH_CR_LOCK);
    if (!idle) {
        return G4_FLASH_E_BUSY;
    }
    return g4_flash_sr_error(sr);
}

/* The data cache may hold words of the page from before the operation: off,
 * reset (DCRST is writable only while DCEN = 0), on again, as ST's
 * FLASH_FlushCaches. */
static void g4_flash_dcache_flush(uint32_t acr)
{
    if ((acr & G4_FLASH_ACR_DCEN) != 0u) {
        g4_mod(G4_FLASH + G4_FLASH_ACR, G4_FLASH_ACR_DCEN, 0u);
        g4_mod(G4_FLASH + G4_FLASH_ACR, G4_FLASH_ACR_DCRST, G4_FLASH_ACR_DCRST);
        g4_mod(G4_FLASH + G4_FLASH_ACR, G4_FLASH_ACR_DCRST, 0u);
        g4_mod(G4_FLASH + G4_FLASH_ACR, G4_FLASH_ACR_DCEN, G4_FLASH_ACR_DCEN);
    }
}

int g4_flash_erase(unsigned p)
{
    if (p > 1u) {
        return G4_FLASH_E_ADDR;
    }
    int rc = g4_flash_begin();
    if (rc != 0) {
        return rc;
    }
    /* ST's driver turns the data cache off for an erase and resets it after */
    const uint32_t acr = g4_rd(G4_FLASH + G4_FLASH_ACR);
    g4_mod(G4_FLASH + G4_FLASH_ACR, G4_FLASH_ACR_DCEN, 0u);
    const uint32_t page = G4_FLASH_SETTINGS_PAGE + p;
    g4_mod(G4_FLASH + G4_FLASH_CR, G4_FLASH_CR_PNB_MASK | G4_FLASH_CR_PER,
           G4_FIELD(page, G4_FLASH_CR_PNB_POS) | G4_FLASH_CR_PER);
    g4_mod(G4_FLASH + G4_FLASH_CR, G4_FLASH_CR_STRT, G4_FLASH_CR_STRT);
    rc = g4_flash_end(G4_FLASH_CR_PER | G4_FLASH_CR_PNB_MASK);
    if ((acr & G4_FLASH_ACR_DCEN) != 0u) {
        g4_mod(G4_FLASH + G4_FLASH_ACR, G4_FLASH_ACR_DCEN, G4_FLASH_ACR_DCEN);
    }
    g4_flash_dcache_flush(acr);
    return rc;
}

int g4_flash_program(unsigned p, uint32_t off, uint32_t lo, uint32_t hi)
{
    if (p > 1u || (off & 7u) != 0u || off >= G4_FLASH_PAGE_SIZE) {
        return G4_FLASH_E_ADDR;
    }
    int rc = g4_flash_begin();
    if (rc != 0) {
        return rc;
    }
    const uintptr_t at = G4_FLASH_SETTINGS_BASE + p * G4_FLASH_PAGE_SIZE + off;
    g4_mod(G4_FLASH + G4_FLASH_CR, G4_FLASH_CR_PG, G4_FLASH_CR_PG);
    /* the low word first, then the high one: the second write starts the
     * programming of the double word (sec. 3.3.8); volatile stores keep their
     * order, and the Cortex-M4 does not reorder stores */
    g4_wr(at, lo);
    g4_wr(at + 4u, hi);
    rc = g4_flash_end(G4_FLASH_CR_PG);
    g4_flash_dcache_flush(g4_rd(G4_FLASH + G4_FLASH_ACR));
    return rc;
}

/* ECCD and ECCC are rc_w1 (RM0440 sec. 3.7, FLASH_ECCR); ECCIE kept. Both
 * cleared: ADDR_ECC is not updated while either is set, so an old corrected
 * error (ECCC, which nothing else clears) would keep the address of a new
 * one from being recorded. */
static void g4_flash_ecc_clear(void)
{
    const uint32_t eccr = g4_rd(G4_FLASH + G4_FLASH_ECCR);
    g4_wr(G4_FLASH + G4_FLASH_ECCR,
          (eccr & G4_FLASH_ECCR_ECCIE) | G4_FLASH_ECCR_ECCD | G4_FLASH_ECCR_ECCC);
}

int g4_flash_read(unsigned p, uint32_t off, uint8_t *buf, size_t n)
{
    if (p > 1u || off > G4_FLASH_PAGE_SIZE || n > G4_FLASH_PAGE_SIZE - off || (off & 3u) != 0u) {
        return G4_FLASH_E_ADDR;
    }
    const uintptr_t base = G4_FLASH_SETTINGS_BASE + p * G4_FLASH_PAGE_SIZE;
    g4_flash_ecc_clear(); /* this read's error gets its own address */
    g4_flash_eccd = 0u;
    g4_flash_reading = 1u;
    int rc = 0;
    for (size_t i = 0; i < n; i += 4u) {
        const uint32_t w = g4_rd(base + off + i);
        if (g4_flash_eccd != 0u || (g4_rd(G4_FLASH + G4_FLASH_ECCR) & G4_FLASH_ECCR_ECCD) != 0u) {
            /* The NMI takes it (and clears ECCD) as soon as the core gets to
             * it: waited for, a little, with the read still marked in
             * progress, so that a late NMI does not take it for a fault. */
            for (unsigned k = 0; k < 64u && g4_flash_eccd == 0u; k++) {
            }
            rc = G4_FLASH_E_ECC;
            break;
        }
        const size_t k = n - i < 4u ? n - i : 4u;
        for (size_t b = 0; b < k; b++) {
            buf[i + b] = (uint8_t)(w >> (8u * b));
        }
    }
    g4_flash_reading = 0u;
    if (rc != 0) {
        g4_flash_ecc_clear(); /* no NMI came (none reaches the register model) */
        g4_flash_eccd = 0u;
    }
    return rc;
}

bool g4_flash_nmi_ecc(void)
{
    const uint32_t eccr = g4_rd(G4_FLASH + G4_FLASH_ECCR);
    if (g4_flash_reading == 0u || (eccr & G4_FLASH_ECCR_ECCD) == 0u ||
        (eccr & G4_FLASH_ECCR_SYSF_ECC) != 0u) {
        return false; /* no settings read, another NMI source, the system flash */
    }
    /* During the read the only data read from the bank is the settings
     * pages; an address elsewhere is an instruction fetch's (the code's own
     * error: a fault). With ECCC also set the address is the corrected
     * error's, which the read's flag has to cover. */
    const uint32_t at = eccr & G4_FLASH_ECCR_ADDR_MASK;
    const uint32_t lo = G4_FLASH_SETTINGS_PAGE * G4_FLASH_PAGE_SIZE;
    if ((eccr & G4_FLASH_ECCR_ECCC) == 0u && (at < lo || at >= lo + 2u * G4_FLASH_PAGE_SIZE)) {
        return false;
    }
    g4_flash_ecc_clear();
    g4_flash_eccd = 1u;
    return true;
}

void g4_flash_nmi(void)
{
    /* Gates off first, as in every fault handler: MOE cleared (RM0440 TIM1
     * BDTR), not a software break, whose BIF the break interrupt would count
     * as an over-current when this NMI is a settings read's ECC error. Reads
     * of the settings pages are made with the gates off (fw_settings.c). */
    g4_clr(G4_TIM1 + G4_TIM_BDTR, G4_TIM_BDTR_MOE);
    /* An ECC error in the settings pages is a read result, not a fault: it is
     * cleared and the read reports it; any other NMI (clock security, an ECC
     * error in the code, SRAM parity) goes to the fault path. */
    if (!g4_flash_nmi_ecc()) {
        g4_fault_handler();
    }
}

#if !defined(G4_MEM_ARRAYS)
/* Replaces g4_startup.c's weak NMI_Handler when the flash driver is linked. */
void NMI_Handler(void);
void NMI_Handler(void)
{
    g4_flash_nmi();
}
#endif
