/*
 * Machines of REFERENCE §2 used by the chapter tests (one translation unit
 * each: static const objects). The chapter IPMSM ratings are the project's
 * assumption in sim_host/machines/chapter_ipmsm.ini (S1 gives none).
 */
#ifndef TESTS_CHAPTER_CHAPTER_MACHINES_H
#define TESTS_CHAPTER_CHAPTER_MACHINES_H

#include <stdint.h>

#include "ctrl_params.h"

static const ctrl_machine_t chapter_spmsm = {
    .name = "thesis_spmsm",
    .pole_pairs = 4,
    .rs_ohm = 0.901,
    .ld_h = 6.552e-3,
    .lq_h = 6.552e-3,
    .psi_pm_wb = 0.09427,
    .vdc_v = 220.0,
    .inertia_kgm2 = 1.2e-4,
    .torque_rated_nm = 2.4,
    .speed_rated_rpm = 3000.0,
    .current_rated_a = 4.2,
    .current_max_a = 8.4,
    .psi_ref_wb = 0.0,
};

static const ctrl_machine_t chapter_ipmsm = {
    .name = "chapter_ipmsm",
    .pole_pairs = 2,
    .rs_ohm = 5.8,
    .ld_h = 44.8e-3,
    .lq_h = 102.7e-3,
    .psi_pm_wb = 0.533,
    .vdc_v = 264.0,
    .inertia_kgm2 = 3.29e-4,
    .torque_rated_nm = 4.0,
    .speed_rated_rpm = 1000.0,
    .current_rated_a = 2.5,
    .current_max_a = 6.25,
    .psi_ref_wb = 0.0,
};

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
