/*
 * Configuration side of M2PTFC: SI values (double) converted to the
 * fixed-point state of ctrl_m2ptfc.h. Included only by *_config.c files, tests and
 * the firmware's configuration code; the per-sample code includes ctrl_m2ptfc.h
 * alone and stays integer-only.
 */
#ifndef CONTROL_CTRL_M2PTFC_CONFIG_H
#define CONTROL_CTRL_M2PTFC_CONFIG_H

#include "ctrl_m2ptfc.h"
#include "ctrl_m2ptfc_model_config.h"

/* SI configuration (tunables by name). */
typedef struct {
    double lambda;              /* "lambda": EMA coefficient of (6.8), 0 < lambda <= 1 */
    double centre;              /* "centre": 1 = Te_c (**) for centre-aligned PWM (default),
                                   0 = the thesis' literal (6.5)-(6.8) */
    ctrl_mpc_model_cfg_t model; /* "rs_model", "ld_model", "lq_model", "psi_pm_model" */
} ctrl_m2ptfc_cfg_t;

#endif /* CONTROL_CTRL_M2PTFC_CONFIG_H */
