/*
 * Line helpers shared by the CSV loaders of sim_host (flux maps,
 * plant_fluxmap.c; switching-state replay files, sim_replay.c): comment and
 * blank lines, an exact header, a row of comma-separated finite numbers.
 * Host only (double precision).
 */
#ifndef SIM_HOST_SIM_CSV_H
#define SIM_HOST_SIM_CSV_H

#include <stddef.h>
#include <stdio.h>

/* 1 when fgets() read a whole line into line (it ends in '\n' or the file
 * ended), 0 when the line was longer than the buffer. */
int sim_csv_line_complete(const char *line, FILE *f);

/* The content of a line with leading blanks skipped, or NULL for a blank
 * line or a comment ('#'). */
char *sim_csv_content(char *line);

/* 1 when s is exactly header, followed only by blanks and the line end. */
int sim_csv_is_header(const char *s, const char *header);

/* Parse exactly n comma-separated finite numbers (blanks allowed after each)
 * and nothing else up to the line end into v. 0 on success, -1 otherwise. */
int sim_csv_numbers(const char *s, double *v, int n);

#endif /* SIM_HOST_SIM_CSV_H */
