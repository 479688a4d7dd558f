/*
 * Machine parameter sets of docs/README.md ("Machines") as ctrl_machine_t, for tests:
 * the shipped machine files (tests/plant/ini_machines.h, checked against
 * sim_host/machines/*.ini by tests/plant/test_plant_files.c), with the
 * ratings the core tests were written for where those differ (marked
 * "assumed"; test_params checks the 8.4 A trip in per unit, ref_core and
 * bench_core_qemu draw currents up to current_max_a):
 *   - current_max_a (over-current trip): 2x rated for the SPMSM, 1.2x the
 *     400 A peak for the 80 kW IPMSM;
 *   - chapter IPMSM (S1 Table 2 gives no ratings): 3 A rated, 6 A trip,
 *     chosen around its test point (70 rad/s, 2 N*m load).
 * Functions (not static objects) because a C constant initializer cannot
 * copy another object.
 */
#ifndef TESTS_CORE_MACHINES_H
#define TESTS_CORE_MACHINES_H

#include "ctrl_params.h"

#include "../plant/ini_machines.h"

/* Thesis SPMSM, Table 3.2 (primary machine). */
static inline ctrl_machine_t machine_thesis_spmsm(void)
{
    ctrl_machine_t m = ini_thesis_spmsm;
    m.current_max_a = 8.4; /* assumed */
    return m;
}

/* Thesis 80 kW IPMSM, Table 3.1 / §6.5.1. */
static inline ctrl_machine_t machine_thesis_ipmsm80(void)
{
    ctrl_machine_t m = ini_thesis_ipmsm80;
    m.current_max_a = 480.0; /* assumed */
    return m;
}

/* Book-chapter IPMSM, S1 Table 2 (printed with the labels crossed; Ld < Lq for an IPMSM). */
static inline ctrl_machine_t machine_chapter_ipmsm(void)
{
    ctrl_machine_t m = ini_chapter_ipmsm;
    m.current_rated_a = 3.0; /* assumed */
    m.current_max_a = 6.0;   /* assumed */
    return m;
}

/*
 * Corner cases of the range the core takes (docs/fixed-point.md, "Range"):
 * small motors at the low end of flux linkage, inductance and resistance
 * (0.3 mWb, 10 uH, 20 mOhm: a drone motor of about 2300 rpm/V), on an 8 V and
 * a 60 V DC link, with the rated speed the sampling frequency allows (at most
 * one radian per period at rated speed).
 */
static inline ctrl_machine_t machine_small_8v(void)
{
    const ctrl_machine_t m = {"small_8v", 7,     0.02,    10e-6, 10e-6, 0.3e-3, 8.0,
                              1e-6,       0.063, 18000.0, 20.0,  40.0,  0.0};
    return m;
}

static inline ctrl_machine_t machine_small_60v(void)
{
    ctrl_machine_t m = machine_small_8v();
    m.name = "small_60v";
    m.vdc_v = 60.0;
    return m;
}

/* The same motor with 4 pole pairs and a lower rated speed: usable at 10 kHz. */
static inline ctrl_machine_t machine_small_10khz(void)
{
    ctrl_machine_t m = machine_small_8v();
    m.name = "small_10khz";
    m.pole_pairs = 4;
    m.torque_rated_nm = 0.036;
    m.speed_rated_rpm = 10000.0;
    return m;
}

/* The thesis SPMSM on a 1000 V DC link (8.4 x its rated back-EMF). */
static inline ctrl_machine_t machine_spmsm_1000v(void)
{
    ctrl_machine_t m = machine_thesis_spmsm();
    m.name = "spmsm_1000v";
    m.vdc_v = 1000.0;
    return m;
}

#endif /* TESTS_CORE_MACHINES_H */
