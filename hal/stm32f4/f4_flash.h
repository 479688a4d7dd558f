/*
 * STM32F405/407 embedded flash: erase and word programming of the two
 * settings sectors (RM0090 sec. 3: 3.3 organisation, 3.5.1 unlock, 3.5.3
 * sector erase, 3.5.4 programming, 3.9 registers; checked against ST's
 * stm32f405xx.h and stm32f4xx_hal_flash*.c).
 *
 * The 1 MB single bank has sectors 0..3 of 16 KB, 4 of 64 KB and 5..11 of
 * 128 KB (RM0090 table 5). The settings use sectors 1 and 2 (0x0800_4000 and
 * 0x0800_8000), the smallest ones after the vector table's sector 0, as
 * VESC keeps its configuration beside the vector table: the linker script
 * (stm32f405xg.ld) puts the vector table and start-up code in sector 0 and
 * the image from sector 3 on.
 *
 * While an erase or a program runs, every fetch from the flash stalls the
 * CPU (one bank: no read-while-write), interrupt vectors included: a 16 KB
 * sector erase takes 250 ms typical, 500 ms at most with x32 parallelism at
 * 2.7 .. 3.6 V, a word 16 us typical, 100 us at most (STM32F405 datasheet
 * DS8626, "Flash memory programming"; x8 parallelism: 400 / 800 ms; Zephyr's
 * STM32F4 driver allows 4 s for a 128 KB sector, this sector's x8 ceiling).
 * So the control interrupt would be held that long: a save is refused while
 * the gates are on or about to be (fw_settings.c), and the independent
 * watchdog, which nothing can refresh during the stall, is given a window
 * longer than the BSY time-out first (the application does that:
 * F4_FLASH_BSY_MS below is what it must exceed).
 *
 * Programming parallelism x32 (PSIZE = 10, VDD 2.7 .. 3.6 V: RM0090 table
 * 7); every board here runs the MCU from 3.3 V.
 *
 * Register access through f4_rd/f4_wr (f4_regs.h). With F4_MEM_ARRAYS the two
 * sectors are the array f4_mem_flash_settings[] (the test's flash model).
 */
#ifndef HAL_STM32F4_F4_FLASH_H
#define HAL_STM32F4_F4_FLASH_H

#include <stddef.h>
#include <stdint.h>

#include "f4_regs.h"

#define F4_FLASH_MEM_BASE 0x08000000u
#define F4_FLASH_SECTOR_SIZE 16384u /* sectors 0..3 */
#define F4_FLASH_SETTINGS_SECTOR 1u /* first of the two settings sectors */
/* sector 1 (table 5) */
#define F4_FLASH_SETTINGS_ADDR (F4_FLASH_MEM_BASE + F4_FLASH_SETTINGS_SECTOR * F4_FLASH_SECTOR_SIZE)

#if defined(F4_MEM_ARRAYS)
extern uint32_t f4_mem_flash_settings[2u * F4_FLASH_SECTOR_SIZE / 4u];
#define F4_FLASH_SETTINGS_BASE ((uintptr_t)f4_mem_flash_settings)
#else
#define F4_FLASH_SETTINGS_BASE ((uintptr_t)F4_FLASH_SETTINGS_ADDR)
#endif

/* FLASH_SR error flags (RM0090 sec. 3.9.4). */
#define F4_FLASH_SR_ERRORS                                                                         \
    (F4_FLASH_SR_OPERR | F4_FLASH_SR_WRPERR | F4_FLASH_SR_PGAERR | F4_FLASH_SR_PGPERR |            \
     F4_FLASH_SR_PGSERR)

/* BSY time-out of an erase or a program, ms: above the 16 KB sector's
 * longest erase at any parallelism (800 ms, x8). */
#define F4_FLASH_BSY_MS 1000

/* Return codes: 0, or -(F4_FLASH_E_SR + bit) for the FLASH_SR error bit the
 * operation ended with (lowest first), or one of the codes after it. */
#define F4_FLASH_E_SR 40
#define F4_FLASH_E_BUSY (-60)   /* BSY did not clear in time */
#define F4_FLASH_E_LOCKED (-61) /* KEYR sequence did not clear LOCK */
#define F4_FLASH_E_ADDR (-63)   /* outside the settings sectors, or not word aligned */
#define F4_FLASH_E_CLOCK (-64)  /* f4_flash_set_clock not called */

/* Name of a return code: "PGSERR (programming sequence)", ... */
const char *f4_flash_strerror(int rc);

/* The core clock, for the BSY time-out: before the first erase or program
 * (which return F4_FLASH_E_CLOCK until then). */
void f4_flash_set_clock(uint32_t hclk_hz);

/* Settings sector s (0, 1 = sectors 1, 2): erase (SER, SNB, STRT; BSY; the
 * caches reset after, as ST's FLASH_FlushCaches), program one 64-bit double
 * word as two words (PG, PSIZE x32, each word BSY) at byte offset off, read n
 * bytes at off. Each unlocks the control register (KEYR) and locks it again
 * (LOCK) before returning. */
int f4_flash_erase(unsigned s);
int f4_flash_program(unsigned s, uint32_t off, uint32_t lo, uint32_t hi);
int f4_flash_read(unsigned s, uint32_t off, uint8_t *buf, size_t n);

#endif /* HAL_STM32F4_F4_FLASH_H */
