/*
 * Machines (docs/README.md) used by the chapter tests: the shipped machine
 * files (tests/plant/ini_machines.h). The chapter IPMSM ratings are the
 * project's assumption in sim_host/machines/chapter_ipmsm.ini (S1 gives none).
 */
#ifndef TESTS_CHAPTER_CHAPTER_MACHINES_H
#define TESTS_CHAPTER_CHAPTER_MACHINES_H

#include <stdint.h>

#include "../plant/ini_machines.h" /* ini_thesis_spmsm, ini_chapter_ipmsm */

/* Deterministic xorshift64 in [0, 1). */
static inline double chapter_rand(uint64_t *s)
{
    uint64_t x = *s;
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
    *s = x;
    return (double)(x >> 11) / 9007199254740992.0;
}

#endif /* TESTS_CHAPTER_CHAPTER_MACHINES_H */
