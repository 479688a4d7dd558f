/*
 * What the chip says about the last reset and the next boot, for the
 * start-up report: the reset flags (RM0440 RCC_CSR) and the boot option
 * bytes (RM0440 FLASH_OPTR, table "Boot modes").
 *
 * Boot: with nSWBOOT0 = 0 the chip takes BOOT0 from the nBOOT0 option bit;
 * with nSWBOOT0 = 1 from the BOOT0 pin (PB8 on the STM32G431CB). BOOT0 = 1
 * starts ST's ROM bootloader (nBOOT1 = 1) or SRAM1 (nBOOT1 = 0), not the
 * flash image. On a
 * board where PB8 carries a pulled-up signal, nSWBOOT0 = 1 means the image
 * runs only when something holds PB8 low during reset.
 */
#ifndef HAL_STM32G4_G4_BOOT_H
#define HAL_STM32G4_G4_BOOT_H

#include <stdbool.h>
#include <stdint.h>

typedef struct {
    uint32_t csr;  /* RCC_CSR at start-up (reset flags) */
    uint32_t optr; /* FLASH_OPTR (option bytes as loaded) */
} g4_boot_info_t;

/* Reads RCC_CSR and FLASH_OPTR, then clears the reset flags (RMVF) so that
 * the next start-up sees only its own reset. */
void g4_boot_read(g4_boot_info_t *bi);

/* The reset's cause from the RCC_CSR flags, most specific first (every
 * internal reset also drives NRST low, so PINRSTF accompanies the others):
 * "low-power", "brown-out/power-on", "window watchdog", "watchdog",
 * "software", "option-byte load", "reset pin", or "unknown". The STM32G431
 * has no lockup reset: a lockup (or a fault handler's wait) ends in a
 * watchdog reset. */
const char *g4_reset_cause(uint32_t csr);

/* NULL when the option bytes boot the flash image whatever BOOT0's pin does;
 * otherwise what stops it: BOOT0 from nBOOT0 = 0 (ROM bootloader always), or
 * BOOT0 from the pin while the board pulls it up (boot0_pin_pulled_up). */
const char *g4_boot_risk(uint32_t optr, bool boot0_pin_pulled_up);

#endif /* HAL_STM32G4_G4_BOOT_H */
