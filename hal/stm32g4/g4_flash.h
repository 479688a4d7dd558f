/*
 * STM32G431 embedded flash: page erase and double-word programming of the two
 * settings pages at the end of the bank, reads that report an uncorrectable
 * ECC error instead of faulting (RM0440 chapter 3 "Embedded flash memory":
 * sec. 3.3.1 organisation, 3.3.5 unlock, 3.3.7 erase, 3.3.8 programming,
 * 3.3.9 ECC, 3.7 registers; checked against ST's stm32g431xx.h and
 * stm32g4xx_hal_flash*.c).
 *
 * The G431 (category 2) has one bank of 64 pages of 2 KB; the last two,
 * pages 62 and 63 at 0x0801_F000, hold the settings (the linker script
 * stm32g431cb.ld keeps the image out of them). While an erase or a program
 * runs, a fetch from flash stalls the CPU (one bank: no read-while-write);
 * a 2 KB page erase takes about 22 ms, a double word about 82 us (ST's
 * STM32G431 data sheet, flash characteristics, typical values; not measured
 * here): the interrupts of the control loop are held that long, which is why
 * the firmware refuses to save with the gates on.
 *
 * Register access through g4_rd/g4_wr (g4_regs.h). With G4_MEM_ARRAYS the two
 * pages are the array g4_mem_flash_settings[] (the test's flash model).
 */
#ifndef HAL_STM32G4_G4_FLASH_H
#define HAL_STM32G4_G4_FLASH_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "g4_regs.h"

/* RM0440 sec. 3.3.1, table "Flash module - 128 KB single bank organization". */
#define G4_FLASH_MEM_BASE 0x08000000u
#define G4_FLASH_PAGE_SIZE 2048u
#define G4_FLASH_PAGES 64u
#define G4_FLASH_SETTINGS_PAGE 62u /* first of the two settings pages */
#define G4_FLASH_SETTINGS_ADDR (G4_FLASH_MEM_BASE + G4_FLASH_SETTINGS_PAGE * G4_FLASH_PAGE_SIZE)

#if defined(G4_MEM_ARRAYS)
extern uint32_t g4_mem_flash_settings[2u * G4_FLASH_PAGE_SIZE / 4u];
#define G4_FLASH_SETTINGS_BASE ((uintptr_t)g4_mem_flash_settings)
#else
#define G4_FLASH_SETTINGS_BASE ((uintptr_t)G4_FLASH_SETTINGS_ADDR)
#endif

/* Registers (RM0440 sec. 3.7, = FLASH_TypeDef of stm32g431xx.h). */
#define G4_FLASH_KEYR 0x08u
#define G4_FLASH_SR 0x10u
#define G4_FLASH_CR 0x14u
#define G4_FLASH_ECCR 0x18u
#define G4_FLASH_ACR_ICRST G4_BIT(11)
#define G4_FLASH_ACR_DCRST G4_BIT(12)
#define G4_FLASH_KEY1 0x45670123u /* RM0440 sec. 3.3.5 (HAL: FLASH_KEY1) */
#define G4_FLASH_KEY2 0xCDEF89ABu
#define G4_FLASH_SR_EOP G4_BIT(0)
#define G4_FLASH_SR_OPERR G4_BIT(1)
#define G4_FLASH_SR_PROGERR G4_BIT(3)
#define G4_FLASH_SR_WRPERR G4_BIT(4)
#define G4_FLASH_SR_PGAERR G4_BIT(5)
#define G4_FLASH_SR_SIZERR G4_BIT(6)
#define G4_FLASH_SR_PGSERR G4_BIT(7)
#define G4_FLASH_SR_MISERR G4_BIT(8)
#define G4_FLASH_SR_FASTERR G4_BIT(9)
#define G4_FLASH_SR_RDERR G4_BIT(14)
#define G4_FLASH_SR_OPTVERR G4_BIT(15)
#define G4_FLASH_SR_BSY G4_BIT(16)
/* every error flag of FLASH_SR (HAL: FLASH_FLAG_SR_ERRORS) */
#define G4_FLASH_SR_ERRORS 0xC3FAu
#define G4_FLASH_CR_PG G4_BIT(0)
#define G4_FLASH_CR_PER G4_BIT(1)
#define G4_FLASH_CR_PNB_POS 3u
#define G4_FLASH_CR_PNB_MASK G4_FIELD(0x3Fu, 3) /* [8:3] on the G431 (64 pages) */
#define G4_FLASH_CR_STRT G4_BIT(16)
#define G4_FLASH_CR_LOCK G4_BIT(31)
/* FLASH_ECCR.ADDR_ECC (RM0440 sec. 3.7, FLASH_ECCR; sec. 3.3.9 ECC): the
 * address of the failing double word as a byte offset from the start of the
 * bank. Bits 17:0 on the G431/G441 as stm32g431xx.h has it
 * (FLASH_ECCR_ADDR_ECC_Msk = 0x3FFFF; the G47x/G49x headers have 0x7FFFF);
 * ST's EEPROM-emulation NMI handler adds the field to FLASH_BASE unscaled,
 * as g4_flash_nmi_ecc does. */
#define G4_FLASH_ECCR_ADDR_MASK 0x3FFFFu
#define G4_FLASH_ECCR_SYSF_ECC G4_BIT(22)
#define G4_FLASH_ECCR_ECCIE G4_BIT(24)
#define G4_FLASH_ECCR_ECCC G4_BIT(30)
#define G4_FLASH_ECCR_ECCD G4_BIT(31)

/* Reset value (RM0440 sec. 3.7, FLASH_CR): the register-image test starts from it
 * (FLASH_ACR's, G4_FLASH_ACR_RESET, is in g4_regs.h). */
#define G4_FLASH_CR_RESET 0xC0000000u /* LOCK, OPTLOCK */

/* Return codes: 0, or -(G4_FLASH_E_SR + bit) for the FLASH_SR error bit the
 * operation ended with (lowest first), or one of the codes after it. */
#define G4_FLASH_E_SR 40
#define G4_FLASH_E_BUSY (-60)   /* BSY did not clear in time */
#define G4_FLASH_E_LOCKED (-61) /* KEYR sequence did not clear LOCK */
#define G4_FLASH_E_ECC (-62)    /* uncorrectable ECC error (ECCD) in the data read */
#define G4_FLASH_E_ADDR (-63)   /* outside the settings pages, or not double-word aligned */
#define G4_FLASH_E_CLOCK (-64)  /* g4_flash_set_clock not called */

/* BSY time-out of every erase and program, ms: above the longest operation,
 * a 2 KB page erase (t_ERASE max 24.47 ms: STM32G431 data sheet, "Flash
 * memory characteristics", as Zephyr's STM32 flash driver quotes it for the
 * G4), and below the independent watchdog (100 ms), which nothing refreshes
 * while a save runs: a save (1 erase + 72 double words of about 82 us,
 * some 31 ms) plus one time-out stays under it, so a flash that never clears
 * BSY is reported as such (G4_FLASH_E_BUSY), not by a watchdog reset. */
#define G4_FLASH_BSY_MS 40

/* Name of a return code: "PROGERR (double word not erased)", ... */
const char *g4_flash_strerror(int rc);

/* The core clock (HCLK), for the BSY time-out: before the first erase or
 * program (which return G4_FLASH_E_CLOCK until then). */
void g4_flash_set_clock(uint32_t hclk_hz);

/* Settings page p (0, 1): erase (PER, PNB, STRT; BSY; the data cache reset
 * after, as ST's driver does), program one double word (PG, two word writes,
 * BSY, EOP) at byte offset off, read n bytes at off. Each unlocks the flash
 * control register (KEYR) and locks it again (LOCK) before returning. */
int g4_flash_erase(unsigned p);
int g4_flash_program(unsigned p, uint32_t off, uint32_t lo, uint32_t hi);
int g4_flash_read(unsigned p, uint32_t off, uint8_t *buf, size_t n);

/* The NMI's ECC case: an uncorrectable ECC error (FLASH_ECCR.ECCD) raises
 * the NMI (RM0440 sec. 3.3.9). It is a settings read's error when a read of
 * the settings pages is in progress (g4_flash_read marks it), ECCD is set and
 * its address lies in the settings pages (or cannot be told: ECCC set, the
 * address then a corrected error's); this clears ECCD and ECCC, notes it for
 * the read and returns true. False for anything else (no read in progress,
 * an instruction fetch's error, the system flash, another NMI source): the
 * caller then takes the fault path. */
bool g4_flash_nmi_ecc(void);
/* The NMI (NMI_Handler on the target): gates off, then g4_flash_nmi_ecc, or
 * the fault path (g4_fault_handler of g4_startup.c) for any other cause. */
void g4_flash_nmi(void);

#endif /* HAL_STM32G4_G4_FLASH_H */
