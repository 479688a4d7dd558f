/* Machine sets of REFERENCE.md §2 used by the DRR tests (own copy: tests/drr only). */
#ifndef TESTS_DRR_MACHINES_H
#define TESTS_DRR_MACHINES_H

#include "ctrl_params.h"

/* Thesis SPMSM, Table 3.2 (sim_host/machines/thesis_spmsm.ini). */
static const ctrl_machine_t drr_spmsm = {
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
};

/* Thesis 80 kW IPMSM, Table 3.1 (a second machine for the reference test). */
static const ctrl_machine_t drr_ipmsm80 = {
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
    .current_max_a = 1000.0,
    .psi_ref_wb = 0.0,
};

#endif /* TESTS_DRR_MACHINES_H */
