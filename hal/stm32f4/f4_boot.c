/* Reset cause (f4_boot.h). */
#include "f4_boot.h"

#include "f4_regs.h"

uint32_t f4_boot_read_csr(void)
{
    const uint32_t csr = f4_rd(F4_RCC + F4_RCC_CSR);
    f4_set(F4_RCC + F4_RCC_CSR, F4_RCC_CSR_RMVF);
    return csr;
}

const char *f4_reset_cause(uint32_t csr)
{
    static const struct {
        uint32_t flag;
        const char *name;
    } causes[] = {
        {F4_RCC_CSR_LPWRRSTF, "low-power"}, {F4_RCC_CSR_WWDGRSTF, "window watchdog"},
        {F4_RCC_CSR_IWDGRSTF, "watchdog"},  {F4_RCC_CSR_SFTRSTF, "software"},
        {F4_RCC_CSR_PORRSTF, "power-on"},   {F4_RCC_CSR_BORRSTF, "brown-out"},
        {F4_RCC_CSR_PINRSTF, "reset pin"},
    };
    for (unsigned i = 0; i < sizeof causes / sizeof causes[0]; i++) {
        if ((csr & causes[i].flag) != 0u) {
            return causes[i].name;
        }
    }
    return "unknown";
}
