/*
 * Hysteresis regulators of switching-table DTC (thesis §4.2, Fig. 4.2).
 *
 * Input is the error e = reference - estimate (Q24 pu); the output is the
 * requested direction of change: +1 increase, 0 maintain, -1 decrease.
 * The state (last output) is kept between samples, so inside the band the
 * output holds. Band edges are INCLUSIVE: reaching a limit switches.
 *
 * Two-level (flux, Fig. 4.2(a); also the torque regulator of AST/ZST):
 *   e >= +h           -> +1   (psi_s <= psi_ref - h_psi)
 *   e <= -h           -> -1   (psi_s >= psi_ref + h_psi)
 *   -h < e < +h       -> hold
 *   After reset there is no history: the first in-band sample takes +1 when
 *   e >= 0 and -1 otherwise.
 * Three-level (torque, Fig. 4.2(b)): changes when Te hits the reference or
 * the limits Tref +- h_T:
 *   e >= +h           -> +1
 *   e <= -h           -> -1
 *   out == +1, e <= 0 -> 0    (torque rose up to the reference)
 *   out == -1, e >= 0 -> 0    (torque fell down to the reference)
 *   otherwise         -> hold (reset state is 0)
 * With h == 0 the upper test has priority (e == 0 gives +1).
 */
#ifndef CONTROL_HYSTERESIS_H
#define CONTROL_HYSTERESIS_H

#include <stdint.h>

#include "fx.h"

typedef struct {
    q24_t band; /* half width h >= 0, Q24 pu */
    int8_t out; /* last output: +1, -1, or 0 = no history yet */
} ctrl_hyst2_t;

typedef struct {
    q24_t band; /* half width h >= 0, Q24 pu */
    int8_t out; /* last output: +1, 0, -1 */
} ctrl_hyst3_t;

/* Set the band (negative values are taken as 0) and reset the output. NULL-safe. */
void ctrl_hyst2_init(ctrl_hyst2_t *h, q24_t band);
void ctrl_hyst2_reset(ctrl_hyst2_t *h);
/* One sample; returns +1 or -1 (NULL h: sign of err, +1 for 0). */
int8_t ctrl_hyst2_update(ctrl_hyst2_t *h, q24_t err);

void ctrl_hyst3_init(ctrl_hyst3_t *h, q24_t band);
void ctrl_hyst3_reset(ctrl_hyst3_t *h);
/* One sample; returns +1, 0 or -1 (NULL h: 0). */
int8_t ctrl_hyst3_update(ctrl_hyst3_t *h, q24_t err);

#endif /* CONTROL_HYSTERESIS_H */
