/*
 * Configuration side of the switching-table DTCs: SI values (double) converted to the
 * fixed-point state of st_dtc.h. Included only by *_config.c files, tests and
 * the firmware's configuration code; the per-sample code includes st_dtc.h
 * alone and stays integer-only.
 */
#ifndef CONTROL_ST_DTC_CONFIG_H
#define CONTROL_ST_DTC_CONFIG_H

#include "st_dtc.h"

/* SI configuration of BST/MBST/AST/ZST (tunables are the double fields). */
typedef struct {
    double h_t;   /* torque band half width h_T, N*m (Table 4.7: 2 % of T_rated) */
    double h_psi; /* flux band half width h_psi, Wb (Table 4.7: 2 % of psi_pm) */
} st_hyst_cfg_t;

/* SI configuration of FST. */
typedef struct {
    double sigma;   /* subsector width of (4.19), rad, [0, pi/12]; 0 = no replacement */
    double dt_step; /* |Delta T_ref| above which a reference step is detected, N*m;
                       0 = any change (thesis §4.5.3: Delta T_ref != 0) */
    double f_i;     /* corner of the mean-torque-error integrator (st_dtc.h), Hz;
                       0 = off (the thesis' FST); default: st_fst_f_i_default */
} st_fst_cfg_t;

/* Default f_i for a machine: 50 Hz when one 20 kHz period of an active vector
 * at standstill moves the torque by at least half the rated torque, A (5.9) /
 * T_rated = Vdc Ts / (1.5 Ld i_rated) >= 0.5 at Ts = 50 us (then the sign
 * decisions leave an offset of the order of a quarter of the rated torque; the
 * mj5208 drone motor: 2.4, the GBM5208 gimbal motor: 0.63), else 0 (the
 * thesis' machines: 0.07 .. 0.27). */
double st_fst_f_i_default(const ctrl_machine_t *m);

#endif /* CONTROL_ST_DTC_CONFIG_H */
