/* Start-up report of the STM32F405 board images (f405_app.h). */
#include <stdio.h>

#include "drv8301.h"
#include "f405_app.h"
#include "f4_boot.h"
#include "f4_core.h"
#include "f4_periph.h"

void f405_report_line(f405_t *s, const char *a, const char *b, const char *c)
{
    board_uart_t *u = &s->app.uart;
    board_uart_puts_polled(u, f405_tag);
    board_uart_puts_polled(u, a);
    board_uart_puts_polled(u, b);
    board_uart_puts_polled(u, c);
    board_uart_puts_polled(u, "\r\n");
}

void f405_report_startup(f405_t *s, uint32_t csr)
{
    char line[112];
    f405_report_line(s, s->board->name, "", "");
    f405_report_line(s, "reset: ", f4_reset_cause(csr), "");
    if (s->had_fault) {
        char what[192];
        (void)stm32_fault_describe(&s->fault, what, sizeof what);
        f405_report_line(s, "previous run stopped: ", what, "; its gates were turned off");
    }
    if (s->clock_rc == F4_OK) {
        (void)snprintf(line, sizeof line, "%lu MHz from the %lu MHz crystal",
                       (unsigned long)(s->clk.sysclk_hz / 1000000u),
                       (unsigned long)(s->board->hse_hz / 1000000u));
        f405_report_line(s, "clock: ", line, "");
    } else {
        f405_report_line(s, "clock failed: ", f4_strerror(s->clock_rc),
                         "; running on HSI 16 MHz, gates held off");
    }
    uint32_t pr, rlr, lo, hi;
    if (s->wdg_rc != F4_OK) {
        f405_report_line(s, "watchdog: ", f4_strerror(s->wdg_rc), "; gates held off");
    } else if (stm32_iwdg_config(F405_IWDG_RUN_MS, F4_LSI_TYP_HZ, &pr, &rlr) == STM32_OK) {
        f4_iwdg_window(pr, rlr, &lo, &hi);
        (void)snprintf(line, sizeof line,
                       "%lu ms (%lu .. %lu ms with the LSI's spread), %lu ms around a flash "
                       "erase",
                       (unsigned long)F405_IWDG_RUN_MS, (unsigned long)lo, (unsigned long)hi,
                       (unsigned long)F405_IWDG_ERASE_MS);
        f405_report_line(s, "watchdog: ", line, "");
    }
}

void f405_report_stack(f405_t *s, uint32_t used, uint32_t size)
{
    char line[64];
    (void)snprintf(line, sizeof line, "%lu of %lu B used (high-water mark)", (unsigned long)used,
                   (unsigned long)size);
    f405_report_line(s, "stack: ", line, "");
}
