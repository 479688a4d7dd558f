/*
 * The settings record in flash sectors 1 and 2 (f405_app.h), through the
 * register-level driver (hal/stm32f4/f4_flash.h).
 *
 * A sector erase stalls the CPU for up to the erase's duration (a 16 KB
 * sector: 500 ms at most with x32 parallelism, 800 ms with x8; the driver
 * gives up after F4_FLASH_BSY_MS = 1 s): the control interrupt with it, so
 * a save is refused while the gates are on or about to be (fw_settings.c:
 * "err 8 state ... disarm first"), and the independent watchdog, which
 * nothing refreshes during the stall, is given F405_IWDG_ERASE_MS (2 s
 * nominal, 1.36 s at the fastest LSI: above the BSY time-out) for the
 * erase and set back to F405_IWDG_RUN_MS after it. Programming a word
 * stalls 100 us at most; the record's few hundred words stay well inside
 * the run window.
 */
#include <string.h>

#include "f405_app.h"
#include "f4_core.h"
#include "f4_flash.h"
#include "f4_periph.h"

void f405_watchdog_set(const f405_t *s, uint32_t ms)
{
    uint32_t pr, rlr;
    if (stm32_iwdg_config(ms, F4_LSI_TYP_HZ, &pr, &rlr) == STM32_OK) {
        (void)f4_iwdg_start(pr, rlr, s->clk.sysclk_hz);
    }
}

static int f405_flash_read(void *ctx, unsigned page, uint32_t off, uint8_t *buf, size_t n)
{
    (void)ctx;
    return f4_flash_read(page, off, buf, n);
}

static int f405_flash_erase(void *ctx, unsigned page)
{
    const f405_t *s = ctx;
    f405_watchdog_set(s, F405_IWDG_ERASE_MS);
    const int rc = f4_flash_erase(page);
    f405_watchdog_set(s, F405_IWDG_RUN_MS);
    return rc;
}

static int f405_flash_program(void *ctx, unsigned page, uint32_t off, const uint8_t dw[8])
{
    (void)ctx;
    uint32_t w[2];
    memcpy(w, dw, sizeof w); /* little-endian target: dw[0] is the low byte */
    return f4_flash_program(page, off, w[0], w[1]);
}

void f405_settings_start(f405_t *s)
{
    settings_flash_t f;
    memset(&f, 0, sizeof f);
    f.ctx = s;
    f.page_size = F4_FLASH_SECTOR_SIZE;
    f.read = f405_flash_read;
    f.erase = f405_flash_erase;
    f.program = f405_flash_program;
    f.strerror = f4_flash_strerror;
    f4_flash_set_clock(s->clk.sysclk_hz);
    board_app_settings_start(&s->app, &f);
}
