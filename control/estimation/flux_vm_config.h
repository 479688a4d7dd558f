/*
 * Configuration side of the voltage-model flux estimator: SI values (double) converted to the
 * fixed-point state of flux_vm.h. Included only by *_config.c files, tests and
 * the firmware's configuration code; the per-sample code includes flux_vm.h
 * alone and stays integer-only.
 */
#ifndef CONTROL_FLUX_VM_CONFIG_H
#define CONTROL_FLUX_VM_CONFIG_H

#include "ctrl_params.h"
#include "flux_vm.h"
#include "fx.h"

/* Gain k_corr = w_c Ts (Q24) for corner frequency fc_hz, in flux_vm_config.c.
 * Returns CTRL_OK or CTRL_EINVAL (fc not finite, <= 0, or k >= 0.5). */
int ctrl_flux_vm_gain(const ctrl_params_t *p, double fc_hz, q24_t *k_corr);

#endif /* CONTROL_FLUX_VM_CONFIG_H */
