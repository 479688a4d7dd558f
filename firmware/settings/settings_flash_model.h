/*
 * A RAM model of the two settings pages of an STM32G4's flash (RM0440 sec.
 * 3.3.7-3.3.8), or of the STM32F405's two 16 KiB settings sectors
 * (sfm_init_size; the F4 programs words, the store double words: the model
 * keeps the G4's double-word ECC granule for both), behind settings_flash_t:
 * the store on the host simulator, in QEMU and in the power-cut tests.
 *   erase:    the page reads back as 0xFF;
 *   program:  one 64-bit double word, only onto an erased one (else the
 *             device's PROGERR), bits go 1 -> 0 only;
 *   ECC:      a double word whose programming or erase was interrupted reads
 *             back as an uncorrectable ECC error (the device's ECCD);
 *   power:    sfm_cut() cuts the power during (torn) or after (complete) the
 *             n-th erase or program from now; every later operation fails
 *             until sfm_power_on() (the next boot).
 * Torn contents come from a xorshift generator, seeded by sfm_init.
 */
#ifndef FIRMWARE_SETTINGS_SETTINGS_FLASH_MODEL_H
#define FIRMWARE_SETTINGS_SETTINGS_FLASH_MODEL_H

#include <stdbool.h>
#include <stdint.h>

#include "settings_store.h"

#define SFM_PAGE_SIZE 2048u /* STM32G431 page (RM0440 sec. 3.3.1, single bank) */
#define SFM_PAGE_MAX 16384u /* STM32F405 sectors 1 and 2 (RM0090 sec. 3.3, table 5) */
#define SFM_DW (SFM_PAGE_MAX / 8u)

/* Device codes (negative, as settings_flash_t wants). */
#define SFM_E_ECC (-1)     /* read of a double word with an ECC error */
#define SFM_E_PROGERR (-2) /* double word not erased before programming */
#define SFM_E_POWER (-3)   /* the power is off */
#define SFM_E_ADDR (-4)    /* page or offset outside the two pages */

typedef enum { SFM_CUT_TORN = 0, SFM_CUT_AFTER = 1 } sfm_cut_t;

typedef struct {
    uint32_t page_size; /* SFM_PAGE_SIZE (sfm_init) or sfm_init_size's */
    uint8_t mem[2][SFM_PAGE_MAX];
    uint8_t ecc_bad[2][SFM_DW]; /* 1: the double word reads as an ECC error */
    uint32_t ops;               /* erases and programs since sfm_init */
    uint32_t cut_at;            /* ops value at which the power goes; 0 = never */
    sfm_cut_t cut_mode;
    bool off;
    uint32_t rng;
} sfm_t;

/* Erased pages (a new device), seed for torn contents (any non-zero). */
void sfm_init(sfm_t *m, uint32_t seed);
/* The same with pages of page_size bytes (a multiple of 8, <= SFM_PAGE_MAX;
 * larger is taken as SFM_PAGE_MAX): F4_FLASH_SECTOR_SIZE for the F405. */
void sfm_init_size(sfm_t *m, uint32_t seed, uint32_t page_size);
/* The flash interface on this model. */
void sfm_flash(sfm_t *m, settings_flash_t *f);
/* Power off during (SFM_CUT_TORN) or right after (SFM_CUT_AFTER) the n-th
 * operation from now (n >= 1). */
void sfm_cut(sfm_t *m, uint32_t n, sfm_cut_t mode);
/* The next boot: power back, no cut pending. */
void sfm_power_on(sfm_t *m);
const char *sfm_strerror(int code);

#endif /* FIRMWARE_SETTINGS_SETTINGS_FLASH_MODEL_H */
