/*
 * Machine parameter sets of REFERENCE.md §2 as ctrl_machine_t, for tests.
 * Include from one translation unit per test (static const objects).
 *
 * Values not in the sources are marked "assumed":
 *   - current_max_a (over-current trip): 2x rated for the SPMSM, 1.2x the
 *     400 A peak for the 80 kW IPMSM;
 *   - chapter IPMSM (S1 Table 2 gives no ratings): 4 N*m, 1000 r/min, 3 A
 *     rated, 6 A trip, chosen around its test point (70 rad/s, 2 N*m load).
 */
#ifndef TESTS_CORE_MACHINES_H
#define TESTS_CORE_MACHINES_H

#include "ctrl_params.h"

/* Thesis SPMSM, Table 3.2 (primary machine). */
static const ctrl_machine_t machine_thesis_spmsm = {
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
    .current_max_a = 8.4, /* assumed */
    .psi_ref_wb = 0.0,    /* MTPA (4.15) */
};

/* Thesis 80 kW IPMSM, Table 3.1 / §6.5.1. */
static const ctrl_machine_t machine_thesis_ipmsm80 = {
    .name = "thesis_ipmsm80",
    .pole_pairs = 4,
    .rs_ohm = 0.0075,
    .ld_h = 0.6e-3,
    .lq_h = 1.33e-3,
    .psi_pm_wb = 0.1875,
    .vdc_v = 540.0,
    .inertia_kgm2 = 0.16526,
    .torque_rated_nm = 400.0,
    .speed_rated_rpm = 3000.0,
    .current_rated_a = 400.0,
    .current_max_a = 480.0, /* assumed */
    .psi_ref_wb = 0.1837,
};

/* Book-chapter IPMSM, S1 Table 2 (Ld < Lq per REFERENCE §2). */
static const ctrl_machine_t machine_chapter_ipmsm = {
    .name = "chapter_ipmsm",
    .pole_pairs = 2,
    .rs_ohm = 5.8,
    .ld_h = 44.8e-3,
    .lq_h = 102.7e-3,
    .psi_pm_wb = 0.533,
    .vdc_v = 264.0,
    .inertia_kgm2 = 3.29e-4,
    .torque_rated_nm = 4.0,    /* assumed */
    .speed_rated_rpm = 1000.0, /* assumed */
    .current_rated_a = 3.0,    /* assumed */
    .current_max_a = 6.0,      /* assumed */
    .psi_ref_wb = 0.0,
};

#endif /* TESTS_CORE_MACHINES_H */
