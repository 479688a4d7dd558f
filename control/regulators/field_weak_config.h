/*
 * Configuration side of the field-weakening limits (field_weak.h): SI values
 * (double) converted once to the fixed-point constants. Included only by
 * *_config.c files, tests and the firmware's configuration code.
 */
#ifndef CONTROL_FIELD_WEAK_CONFIG_H
#define CONTROL_FIELD_WEAK_CONFIG_H

#include <stddef.h>

#include "ctrl_params.h"
#include "field_weak.h"

/* Largest usable fundamental amplitude of a two-level inverter, as a fraction
 * of Vdc/sqrt(3): six-step operation, (2/pi) Vdc = 1.1027 Vdc/sqrt(3). */
#define CTRL_FIELDWEAK_VFRAC_MAX 1.1027
/* Defaults: the drive's field-weakening voltage limit (92 % of the linear range of
 * space-vector modulation, Vdc/sqrt(3): a margin for the current or flux
 * regulation's own voltage), the DTC load-angle margin of firmware/isr/speed_loop.h,
 * a DC-link filter that removes the ADC's noise but follows a sag within ~0.2 ms. */
#define CTRL_FIELDWEAK_VFRAC_DEFAULT 0.92
#define CTRL_FIELDWEAK_TORQUE_MARGIN_DEFAULT 0.95
/* The same margin in regenerative braking (w T < 0) on a fixed flux
 * reference: there the zero vector carries the load angle toward the pull-out
 * instead of away from it (field_weak.h). Measured, 80 kW IPMSM at its flux
 * reference: m2ptfc, drr and fst held 0.88 T_mtpv braking from a step at
 * 300-2700 r/min, m2ptfc slipped poles at 0.90 (600 r/min) and all three at
 * 0.95 (docs/algorithms.md, "Braking at the flux reference's limit"). */
#define CTRL_FIELDWEAK_TORQUE_MARGIN_BRAKE_DEFAULT 0.88
#define CTRL_FIELDWEAK_VDC_LPF_HZ_DEFAULT 1000.0

typedef struct {
    double
        v_frac; /* usable phase-voltage amplitude / (Vdc/sqrt(3)), (0, CTRL_FIELDWEAK_VFRAC_MAX] */
    double
        current_max_a; /* current limit, A peak, (0, machine's current_max_a]; 0 = rated current */
    double torque_margin;       /* fraction of the MTPV torque allowed, (0, 1] */
    double torque_margin_brake; /* the same braking on a fixed flux reference, (0, 1] */
    double vdc_lpf_hz;          /* DC-link filter cut-off, (0, fs/2) */
} ctrl_fieldweak_cfg_t;

void ctrl_fieldweak_cfg_default(ctrl_fieldweak_cfg_t *c);

/*
 * SI -> fixed point for machine m (bases b, parameters p of the control
 * frequency). Returns CTRL_OK, or CTRL_EINVAL (a value outside its range, or
 * Lq < Ld: reverse saliency is not supported) / CTRL_ERANGE (a constant does
 * not fit Q24) with a message naming the quantity, its value and the accepted
 * range in why (may be NULL). Leaves the state reset.
 */
int ctrl_fieldweak_init(ctrl_fieldweak_t *s, const ctrl_fieldweak_cfg_t *c, const ctrl_machine_t *m,
                        const ctrl_bases_t *b, const ctrl_params_t *p, char *why, size_t why_len);

#endif /* CONTROL_FIELD_WEAK_CONFIG_H */
