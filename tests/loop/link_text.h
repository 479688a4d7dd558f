/* The firmware's serial link as a console for the host closed-loop tests:
 * lines sent through fw_link_rx, what the firmware writes kept as text. */
#ifndef TESTS_LOOP_LINK_TEXT_H
#define TESTS_LOOP_LINK_TEXT_H

#include <stddef.h>
#include <stdint.h>

#include "fw_link.h"
#include "sim_run.h"

typedef struct {
    char out[16384]; /* the bytes written since the last line sent; NUL bytes as '.' */
    size_t len;
    size_t zeros; /* NUL bytes written (frame delimiters), counted until reset by the test */
} link_text_t;

/* fw_link_write_fn: appends to the link_text_t ctx (silently full at its size). */
void link_text_capture(void *ctx, const uint8_t *bytes, size_t n);
/* Clears t->out, then sends line and its line end. */
void link_text_send(link_text_t *t, fw_link_t *link, const char *line);
/* n PWM periods of the run, the link polled after each; fails the test if a
 * period fails. */
void link_text_periods(sim_run_t *run, fw_link_t *link, int n);

#endif /* TESTS_LOOP_LINK_TEXT_H */
