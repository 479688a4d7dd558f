/*
 * Configuration side of mptfc: SI values (double) converted to the
 * fixed-point state of ctrl_mptfc.h. Included only by *_config.c files, tests and
 * the firmware's configuration code; the per-sample code includes ctrl_mptfc.h
 * alone and stays integer-only.
 */
#ifndef CONTROL_CTRL_MPTFC_CONFIG_H
#define CONTROL_CTRL_MPTFC_CONFIG_H

#include "ctrl_m2ptfc_model_config.h"
#include "ctrl_mptfc.h"

/* SI configuration: the layout shared by m1, m3 and mptfc
 * (ctrl_m2ptfc_model.h); trace vec 0 (zero vector, duty 0), then V1..V6 (duty 1). */
typedef ctrl_mpc_wcfg_t ctrl_mptfc_cfg_t;

#endif /* CONTROL_CTRL_MPTFC_CONFIG_H */
