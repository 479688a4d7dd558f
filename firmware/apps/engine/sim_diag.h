/*
 * Diagnostics of the host simulator: the warnings of one run (every clamp or
 * input that does not act as written; printed on stderr when raised and
 * written to the metrics JSON) and the explanation of a configuration the
 * firmware refuses (which single value, changed alone, would be accepted).
 */
#ifndef FIRMWARE_HOST_SIM_DIAG_H
#define FIRMWARE_HOST_SIM_DIAG_H

#include <stddef.h>
#include <stdio.h>

#define SIM_WARN_MAX 32u
#define SIM_WARN_LEN 512u

typedef struct {
    size_t n;       /* stored warnings */
    size_t dropped; /* raised beyond SIM_WARN_MAX (printed, counted, not stored) */
    int quiet;      /* 1: do not print on stderr */
    char msg[SIM_WARN_MAX][SIM_WARN_LEN];
} sim_warnings_t;

/* Record a warning and print "sim: warning: ..." on stderr (unless quiet).
 * w == NULL: printed only. */
void sim_warn(sim_warnings_t *w, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* JSON array of the warnings (strings escaped), e.g. ["a", "b"]. */
void sim_warnings_json(FILE *f, const sim_warnings_t *w);

/* Writes s as a JSON string (quotes included). */
void sim_json_string(FILE *f, const char *s);

/* printf into buf at its current end (truncating at len). */
void sim_appendf(char *buf, size_t len, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

#endif /* FIRMWARE_HOST_SIM_DIAG_H */
