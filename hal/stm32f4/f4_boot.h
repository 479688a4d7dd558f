/*
 * What the chip says about the last reset, for the start-up report: the
 * reset flags of RCC_CSR (RM0090 sec. 7.3.21).
 */
#ifndef HAL_STM32F4_F4_BOOT_H
#define HAL_STM32F4_F4_BOOT_H

#include <stdint.h>

/* RCC_CSR at start-up, then the flags cleared (RMVF) so that the next
 * start-up sees only its own reset. */
uint32_t f4_boot_read_csr(void);

/* The reset's cause from the RCC_CSR flags, most specific first (every
 * internal reset also drives NRST low, so PINRSTF accompanies the others; a
 * power-on sets PORRSTF and BORRSTF together): "low-power", "window
 * watchdog", "watchdog", "software", "power-on", "brown-out", "reset pin",
 * or "unknown" (no flag: QEMU, which does not model the RCC). */
const char *f4_reset_cause(uint32_t csr);

#endif /* HAL_STM32F4_F4_BOOT_H */
