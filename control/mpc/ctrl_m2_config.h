/*
 * Configuration side of M2: SI values (double) converted to the
 * fixed-point state of ctrl_m2.h. Included only by *_config.c files, tests and
 * the firmware's configuration code; the per-sample code includes ctrl_m2.h
 * alone and stays integer-only.
 */
#ifndef CONTROL_CTRL_M2_CONFIG_H
#define CONTROL_CTRL_M2_CONFIG_H

#include "ctrl_m2.h"
#include "ctrl_m2ptfc_model_config.h"

/* SI configuration (tunables by name). */
typedef struct {
    double eps_psi; /* "eps_psi", Wb, (6.17) */
    double y;       /* "y", number of duty levels (6.15), integer 1..16 */
    ctrl_mpc_model_cfg_t model;
} ctrl_m2_cfg_t;

#endif /* CONTROL_CTRL_M2_CONFIG_H */
