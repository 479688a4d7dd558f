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

/* The two-level regulator of an amplitude known by its square S = x^2 + y^2
 * (Q48, e.g. ctrl_mstate_t.psi_amp_sq): the outputs of
 * ctrl_hyst2_update(&h, ref - fx_mag(x, y)) without the square root, S
 * compared with the band edges as limits on S (fx_mag_le_lim, fx_mag_ge_lim;
 * exact, as ref - fx_mag never overflows for ref >= 0 and band >= 0). The
 * owner forms the limits again when the reference moves (it knows when:
 * ctrl_flux_memo_hit of mtpa.h); the band is fixed by the init. */
typedef struct {
    ctrl_hyst2_t h;      /* band and last output, as ctrl_hyst2_update's */
    uint64_t inc_lim;    /* S < inc_lim: ref - |.| >= +band (output +1) */
    uint64_t dec_lim;    /* S >= dec_lim: ref - |.| <= -band (output -1) */
    uint64_t nonneg_lim; /* S < nonneg_lim: ref - |.| >= 0 */
} ctrl_hyst2_sq_t;

/* Band (negative taken as 0), output reset, limits for ref = 0. NULL-safe. */
void ctrl_hyst2_sq_init(ctrl_hyst2_sq_t *h, q24_t band);
/* The limits for the reference ref (>= 0) and the band. */
void ctrl_hyst2_sq_limits(ctrl_hyst2_sq_t *h, q24_t ref);

/* One sample with S; returns +1 or -1. */
static inline int8_t ctrl_hyst2_sq_update(ctrl_hyst2_sq_t *h, uint64_t amp_sq)
{
    if (amp_sq < h->inc_lim) {
        h->h.out = 1;
    } else if (amp_sq >= h->dec_lim) {
        h->h.out = -1;
    } else if (h->h.out == 0) {
        h->h.out = amp_sq < h->nonneg_lim ? (int8_t)1 : (int8_t)-1; /* no history: the sign */
    }
    return h->h.out;
}

void ctrl_hyst3_init(ctrl_hyst3_t *h, q24_t band);
void ctrl_hyst3_reset(ctrl_hyst3_t *h);
/* One sample; returns +1, 0 or -1 (NULL h: 0). */
int8_t ctrl_hyst3_update(ctrl_hyst3_t *h, q24_t err);

#endif /* CONTROL_HYSTERESIS_H */
