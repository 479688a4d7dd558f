/*
 * Configuration side of foc and foc_hyst: SI values (double) converted to the
 * fixed-point state of ctrl_foc.h. Included only by *_config.c files, tests and
 * the firmware's configuration code; the per-sample code includes ctrl_foc.h
 * alone and stays integer-only.
 */
#ifndef CONTROL_CTRL_FOC_CONFIG_H
#define CONTROL_CTRL_FOC_CONFIG_H

#include "ctrl_foc.h"

/* SI configuration (tunables are the double fields listed in the descriptor). */
typedef struct {
    double wc;         /* current-loop bandwidth, rad/s; 0 = 2 pi fs / 20 */
    double kp_d, kp_q; /* V/A; 0 = Ld wc, Lq wc */
    double ki_d, ki_q; /* V/(A s); 0 = Rs wc */
    double mtpa;       /* 1 = MTPA i_d (IPMSM), 0 = i_d = 0 */
    double h_i;        /* foc_hyst current band half width, A */
} ctrl_foc_cfg_t;

#endif /* CONTROL_CTRL_FOC_CONFIG_H */
