/*
 * What the B-G431B-ESC1 says on its serial link at start-up, by polled
 * output (esc1_uart_puts_polled): the interrupt-driven path is not up yet, or
 * start-up has failed and never brings it up.
 */
#ifndef FIRMWARE_APPS_ESC1_ESC1_REPORT_H
#define FIRMWARE_APPS_ESC1_ESC1_REPORT_H

#include "esc1_uart.h"
#include "g4_board.h"
#include "g4_boot.h"

/* "esc1: reset: <cause>", "esc1: boot: <risk>; see docs/bringup.md step 1"
 * when the option bytes can keep the image from starting, "esc1: clock: ok"
 * or "esc1: clock failed: <why>; running on HSI16". */
void esc1_report_startup(esc1_uart_t *u, const g4_board_t *b, const g4_boot_info_t *bi,
                         int clock_rc);
/* "esc1: <what> failed: <why>", "esc1: gates off, not armable". */
void esc1_report_failure(esc1_uart_t *u, const char *what, const char *why);
/* After the start-up (through the transmit ring): "esc1: stack: <used> of
 * <size> B used (high-water mark); fw_init <us> us", the stack since reset
 * and the longest firmware initialisation so far (the interrupt held, the
 * watchdog not refreshed: the start-up's, a settings record's). */
void esc1_report_stack(esc1_uart_t *u, uint32_t used, uint32_t size, uint32_t init_us);

#endif /* FIRMWARE_APPS_ESC1_ESC1_REPORT_H */
