/*
 * Space-vector PWM for the chapter's controllers (S1 §2 FOC, §4 SVM-DTC).
 *
 * Centre-aligned SVPWM by min-max zero-sequence injection, which is the
 * classical sector/dwell-time SVM with the zero time split equally between V0
 * and V7: with phase voltages v_x of the reference (inverse Clarke, (3.3)),
 *   d_x = 1/2 + (v_x - (max + min) / 2) / Vdc          (leg x duty)
 As vectors: sorting the legs by duty d_hi >= d_mid >= d_lo gives V7 for
 * d_lo, the two-legs-high active vector for d_mid - d_lo, the one-leg-high
 * active vector for d_hi - d_mid and V0 for 1 - d_hi, i.e. the two active
 * vectors adjacent to the reference with the dwell times of the sector
 * formulas and t0/2 for each zero vector. The controllers output the duties
 * (ctrl_out_t with no plan).
 *
 * Over-modulation: the two-level inverter can synthesise v iff
 * max(v_x) - min(v_x) <= Vdc (the hexagon spanned by V1..V6). Outside, v is
 * scaled by Vdc / (max - min): the result lies on the hexagon and keeps its
 * angle (one division, only when limiting).
 *
 * Arithmetic: v is taken in units of the DC link once (two products with
 * 1/Vdc, ctrl_svpwm_inv_vdc, the period's one division), in Q28 (Q16 for
 * a reference of 4 Vdc or more, only to limit it); the phases, the limit
 * test and the duties follow in 32 bits. Duties within about 1 LSB of the
 * exact formula for the vector realised. Below 1/128 pu, where 1/Vdc
 * saturates in Q24, the vector realised is the reference times Vdc 2^7
 * (the drive's under-voltage trip lies far above).
 *
 * All voltages Q24 per-unit (v_base = nominal Vdc, ctrl_params.h).
 */
#ifndef CONTROL_SVPWM_H
#define CONTROL_SVPWM_H

#include <stdint.h>

#include "ctrl_types.h"
#include "fx.h"

/* Scale (v_alpha, v_beta) onto the voltage hexagon of DC link vdc if it lies
 * outside, keeping its angle. Returns 1 if it was limited, 0 if unchanged.
 * vdc <= 0 (nothing can be synthesised): the vector becomes 0, returns 1. */
uint8_t ctrl_svpwm_limit(q24_t vdc, q24_t *v_alpha, q24_t *v_beta);

/* Leg duties (Q24 fraction of the period, [0, FX_ONE]) of a reference inside
 * the hexagon by min-max injection (formula above). Call ctrl_svpwm_limit
 * first; residual rounding is clamped. vdc <= 0 gives 0, 0, 0 (V0). */
void ctrl_svpwm_duties(q24_t v_alpha, q24_t v_beta, q24_t vdc, ctrl_legs_t *legs);

/* 1 / vdc in Q24 for vdc > 0: the value of fx_div(FX_ONE, vdc) (rounded half
 * up, saturated), without a 64-bit division for a DC link between 1/128 and
 * 4 pu (the duties' one division per period). */
q24_t ctrl_svpwm_inv_vdc(q24_t vdc);

/* Limit + duties in one call (the phase voltages formed once unless limited). Returns the
 * ctrl_svpwm_limit result; the limited reference is written back to *v_alpha, *v_beta. */
uint8_t ctrl_svpwm(q24_t *v_alpha, q24_t *v_beta, q24_t vdc, ctrl_legs_t *legs);

#endif /* CONTROL_SVPWM_H */
