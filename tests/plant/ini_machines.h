/*
 * The shipped machine files sim_host/machines/{thesis_spmsm,
 * thesis_ipmsm_80kw, chapter_ipmsm}.ini (REFERENCE.md section 2) as
 * ctrl_machine_t, for the unit tests that configure a controller without the
 * INI loader (also built for the QEMU target, no file access).
 * tests/plant/test_plant_files.c checks every field against the INI files.
 * static const objects: include it from the translation units that use them.
 */
#ifndef TESTS_PLANT_INI_MACHINES_H
#define TESTS_PLANT_INI_MACHINES_H

#include "ctrl_params.h"

/* Thesis SPMSM, Table 3.2 (current peak; trip 2.5 x rated). */
static const ctrl_machine_t ini_thesis_spmsm = {
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
    .current_max_a = 10.5,
    .psi_ref_wb = 0.0,
    .speed_max_rpm = 3750.0,
};

/* Thesis 80 kW IPMSM, Table 3.1 and section 6.5.1 (psi_s_ref 0.1837 Wb). */
static const ctrl_machine_t ini_thesis_ipmsm80 = {
    .name = "thesis_ipmsm_80kw",
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
    .current_max_a = 800.0,
    .psi_ref_wb = 0.1837,
    .speed_max_rpm = 6000.0,
};

/* Book-chapter IPMSM, S1 Table 2 (rated values: the project's assumption). */
static const ctrl_machine_t ini_chapter_ipmsm = {
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

#endif /* TESTS_PLANT_INI_MACHINES_H */
