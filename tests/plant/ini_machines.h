/*
 * The shipped machine files sim_host/machines/{thesis_spmsm,
 * thesis_ipmsm_80kw, chapter_ipmsm, mj5208_drone, gbm5208_gimbal,
 * outrunner_24v}.ini (the thesis's and the chapter's machines and three
 * small motors) as
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

/* mjbots mj5208 drone outrunner on 24 V (moteus mpat data; psi_pm from Kv 304). */
static const ctrl_machine_t ini_mj5208_drone = {
    .name = "mj5208_drone",
    .pole_pairs = 7,
    .rs_ohm = 0.047,
    .ld_h = 26.0e-6,
    .lq_h = 45.8e-6,
    .psi_pm_wb = 2.5908e-3,
    .vdc_v = 24.0,
    .inertia_kgm2 = 5.6e-5,
    .torque_rated_nm = 0.354,
    .speed_rated_rpm = 6000.0,
    .current_rated_a = 13.0,
    .current_max_a = 22.5,
    .psi_ref_wb = 0.0,
};

/* Rctimer GBM5208 gimbal motor on 12 V (moteus mpat data; psi_pm from Kv 25.5). */
static const ctrl_machine_t ini_gbm5208_gimbal = {
    .name = "gbm5208_gimbal",
    .pole_pairs = 11,
    .rs_ohm = 7.545,
    .ld_h = 2.129e-3,
    .lq_h = 3.308e-3,
    .psi_pm_wb = 0.019655,
    .vdc_v = 12.0,
    .inertia_kgm2 = 5.6e-5,
    .torque_rated_nm = 0.0973,
    .speed_rated_rpm = 190.0,
    .current_rated_a = 0.3,
    .current_max_a = 1.0,
    .psi_ref_wb = 0.0,
};

/* 24 V outrunner with 500 ns dead time (the file's derivation: 7 pole pairs,
 * Rs 0.461 ohm, L 64 uH, psi_pm 0.664 mWb; rated 6 A, 0.0418 N*m). */
static const ctrl_machine_t ini_outrunner_24v = {
    .name = "outrunner_24v",
    .pole_pairs = 7,
    .rs_ohm = 0.461,
    .ld_h = 64e-6,
    .lq_h = 64e-6,
    .psi_pm_wb = 0.664e-3,
    .vdc_v = 24.0,
    .inertia_kgm2 = 1e-5,
    .torque_rated_nm = 0.0418,
    .speed_rated_rpm = 6000.0,
    .current_rated_a = 6.0,
    .current_max_a = 10.0,
    .psi_ref_wb = 0.0,
};

#endif /* TESTS_PLANT_INI_MACHINES_H */
