/* Start-up report of the B-G431B-ESC1 (esc1_report.h). */
#include "esc1_report.h"

#include <stdio.h>

#include "g4_core.h"

static void esc1_report_line(esc1_uart_t *u, const char *a, const char *b, const char *c)
{
    esc1_uart_puts_polled(u, "esc1: ");
    esc1_uart_puts_polled(u, a);
    esc1_uart_puts_polled(u, b);
    esc1_uart_puts_polled(u, c);
    esc1_uart_puts_polled(u, "\r\n");
}

void esc1_report_startup(esc1_uart_t *u, const g4_board_t *b, const g4_boot_info_t *bi,
                         int clock_rc)
{
    esc1_report_line(u, "reset: ", g4_reset_cause(bi->csr), "");
    const char *risk = g4_boot_risk(bi->optr, b->boot0_pulled_up);
    if (risk != NULL) {
        esc1_report_line(u, "boot: ", risk, "; see docs/bringup.md step 1");
    }
    if (clock_rc == G4_OK) {
        esc1_report_line(u, "clock: ok", "", "");
    } else {
        esc1_report_line(u, "clock failed: ", g4_strerror(clock_rc), "; running on HSI16");
    }
}

void esc1_report_failure(esc1_uart_t *u, const char *what, const char *why)
{
    esc1_report_line(u, what, " failed: ", why);
    esc1_report_line(u, "gates off, not armable", "", "");
}

void esc1_report_stack(esc1_uart_t *u, uint32_t used, uint32_t size, uint32_t init_us)
{
    char line[100];
    const int n = snprintf(line, sizeof line,
                           "esc1: stack: %lu of %lu B used (high-water mark); fw_init %lu us\r\n",
                           (unsigned long)used, (unsigned long)size, (unsigned long)init_us);
    if (n > 0) {
        esc1_uart_puts(u, line);
    }
}
