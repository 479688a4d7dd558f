/* Reset cause and boot option bytes (g4_boot.h). */
#include "g4_boot.h"

#include <stddef.h>

#include "g4_regs.h"

void g4_boot_read(g4_boot_info_t *bi)
{
    bi->csr = g4_rd(G4_RCC + G4_RCC_CSR);
    bi->optr = g4_rd(G4_FLASH + G4_FLASH_OPTR);
    g4_set(G4_RCC + G4_RCC_CSR, G4_RCC_CSR_RMVF);
}

const char *g4_reset_cause(uint32_t csr)
{
    static const struct {
        uint32_t flag;
        const char *name;
    } causes[] = {
        {G4_RCC_CSR_LPWRRSTF, "low-power"},       {G4_RCC_CSR_BORRSTF, "brown-out/power-on"},
        {G4_RCC_CSR_WWDGRSTF, "window watchdog"}, {G4_RCC_CSR_IWDGRSTF, "watchdog"},
        {G4_RCC_CSR_SFTRSTF, "software"},         {G4_RCC_CSR_OBLRSTF, "option-byte load"},
        {G4_RCC_CSR_PINRSTF, "reset pin"},
    };
    for (unsigned i = 0; i < sizeof causes / sizeof causes[0]; i++) {
        if ((csr & causes[i].flag) != 0u) {
            return causes[i].name;
        }
    }
    return "unknown";
}

const char *g4_boot_risk(uint32_t optr, bool boot0_pin_pulled_up)
{
    /* BOOT0 = 1 starts the ROM bootloader (nBOOT1 = 1) or SRAM1 (nBOOT1 =
     * 0): not the flash image either way. */
    if ((optr & G4_FLASH_OPTR_nSWBOOT0) == 0u) {
        return (optr & G4_FLASH_OPTR_nBOOT0) != 0u ? NULL : "nBOOT0=0: resets skip the flash image";
    }
    return boot0_pin_pulled_up ? "nSWBOOT0=1: BOOT0 is PB8, pulled up: resets may skip the "
                                 "flash image"
                               : NULL;
}
