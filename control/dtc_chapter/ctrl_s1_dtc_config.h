/*
 * Configuration side of hdtc, svm_dtc and hpdtc: SI values (double) converted to the
 * fixed-point state of ctrl_s1_dtc.h. Included only by *_config.c files, tests and
 * the firmware's configuration code; the per-sample code includes ctrl_s1_dtc.h
 * alone and stays integer-only.
 */
#ifndef CONTROL_CTRL_S1_DTC_CONFIG_H
#define CONTROL_CTRL_S1_DTC_CONFIG_H

#include <stdint.h>

#include "ctrl_s1_dtc.h"

/* SI configuration shared by the three (each lists its own tunables). */
typedef struct {
    double h_t;      /* torque hysteresis half band, N*m (hdtc, hpdtc) */
    double h_psi;    /* flux hysteresis half band, Wb (hdtc, hpdtc) */
    double psi_ref;  /* flux reference, Wb; 0 = psi_pm (see above) */
    double kp;       /* svm_dtc: rad per pu torque */
    double ki;       /* svm_dtc: rad per (pu torque * sample) */
    double omega_ff; /* svm_dtc: 1 = add omega_e Ts to Delta delta */
    double e_fs;     /* hpdtc: |T_err| of the full voltage level, N*m; 0 = computed */
    double tilt;     /* hpdtc: reference direction tilted towards V_k1, rad */
} ctrl_s1_cfg_t;

/* Generate the timing table (configuration; hpdtc_config): for level l
 * (m = l / 5 of the inscribed-circle voltage Vdc/sqrt(3)) and reflected
 * section j, the on-times of V_k1, V_k2 in points of Ts/20. tilt in rad.
 * Returns CTRL_OK or CTRL_EINVAL. */
int ctrl_hpdtc_timing_table(double tilt, uint8_t pts[HPDTC_LEVELS][HPDTC_SECTIONS][2]);

#endif /* CONTROL_CTRL_S1_DTC_CONFIG_H */
