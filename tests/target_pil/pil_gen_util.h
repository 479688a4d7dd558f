/*
 * What the host generators of the replay recordings (pil_ident_gen.c,
 * pil_cog_gen.c) share: their arguments, a period's recorded inputs, and
 * the generated file's tables and HAL and machine data.
 */
#ifndef TESTS_TARGET_PIL_PIL_GEN_UTIL_H
#define TESTS_TARGET_PIL_PIL_GEN_UTIL_H

#include <stdint.h>
#include <stdio.h>

#include "pil_ident.h"
#include "sim_run.h"

/* "--machine FILE --out FILE.c": 0, or 1 with the usage on stderr. */
int pil_gen_args(int argc, char **argv, const char *prog, const char **machine, const char **out);
/* 1 with "prog: msg arg" on stderr. */
int pil_gen_die(const char *prog, const char *msg, const char *arg);
/* The period's ISR inputs from the simulated HAL, with the main loop's cmd. */
void pil_gen_in(const hal_t *h, uint8_t cmd, pil_ident_in_t *i);
/* "static const pil_ident_in_t in_[n]" and "static const uint32_t hash_[n]". */
void pil_gen_write_in_hash(FILE *f, const pil_ident_in_t *in, const uint32_t *hash, uint32_t n);
/* The hal_info_t and ctrl_machine_t initialisers, each on a line ending in ",\n". */
void pil_gen_write_info_machine(FILE *f, const hal_info_t *hi, const ctrl_machine_t *m);

#endif /* TESTS_TARGET_PIL_PIL_GEN_UTIL_H */
