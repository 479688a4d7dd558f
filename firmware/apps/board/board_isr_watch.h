/*
 * The control interrupt's progress, watched by the main loop while the gates
 * are on. An interrupt that stops (an ADC trigger lost, a higher-priority
 * handler that never returns) leaves its last compare values on the legs: a
 * fixed voltage vector, the current rising unchecked, until the independent
 * watchdog resets the chip (100 ms nominal, up to 188 ms with the LSI's
 * spread). The main loop turns the gates off itself once no period has run
 * for a limit of a few periods' worth while they are on.
 */
#ifndef FIRMWARE_APPS_BOARD_BOARD_ISR_WATCH_H
#define FIRMWARE_APPS_BOARD_BOARD_ISR_WATCH_H

#include <stdbool.h>
#include <stdint.h>

/* 2 ms: 40 periods at 20 kHz, 20 at the lowest 10 kHz; far above a masked
 * interval (a few microseconds) and far below the watchdog's 68 ms. */
#define BOARD_ISR_WATCH_US 2000u

typedef struct {
    uint32_t count; /* the interrupt count last seen changing */
    uint32_t since; /* ticks then (or when the gates were seen on first) */
    bool on;        /* the gates were on at the last check */
} board_isr_watch_t;

/* One look: `count` the interrupts so far, `now` a free-running tick counter
 * (wraps), `gates_on` the outputs' state as the hardware has it. True when
 * the gates are on and `count` has not changed for `limit` ticks (it stays
 * true until either changes). Gates off: false, and the window restarts when
 * they come on. */
bool board_isr_watch_check(board_isr_watch_t *w, uint32_t count, uint32_t now, bool gates_on,
                           uint32_t limit);

#endif /* FIRMWARE_APPS_BOARD_BOARD_ISR_WATCH_H */
