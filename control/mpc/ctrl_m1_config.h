/*
 * Configuration side of m1: SI values (double) converted to the
 * fixed-point state of ctrl_m1.h. Included only by *_config.c files, tests and
 * the firmware's configuration code; the per-sample code includes ctrl_m1.h
 * alone and stays integer-only.
 */
#ifndef CONTROL_CTRL_M1_CONFIG_H
#define CONTROL_CTRL_M1_CONFIG_H

#include "ctrl_m1.h"
#include "ctrl_m2ptfc_model_config.h"

/* SI configuration: the layout shared by m1, m3 and mptfc
 * (ctrl_m2ptfc_model.h); trace the six active vectors with D_f (5.18). */
typedef ctrl_mpc_wcfg_t ctrl_m1_cfg_t;

#endif /* CONTROL_CTRL_M1_CONFIG_H */
