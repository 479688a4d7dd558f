/*
 * Rotor angle at standstill from the saliency (Ld != Lq), modulo pi: voltage
 * pulses in six directions, the current's change against the voltage
 * (INFORM-style pulse injection; docs/algorithms.md, "Initial angle").
 *
 * With the back-EMF zero and the resistive drop negligible over one period,
 * a voltage v (alpha/beta) held for Ts changes the current by
 *   di = Ts L^-1 v,  L^-1 = S I + D [cos 2t  sin 2t; sin 2t  -cos 2t],
 *   S = (1/Ld + 1/Lq) / 2,  D = (1/Ld - 1/Lq) / 2,  t the d-axis angle.
 * The sums over the pulses
 *   A = sum(di_a v_a - di_b v_b) = Ts sum(S (v_a^2 - v_b^2) + D cos 2t |v|^2)
 *   B = sum(di_a v_b + di_b v_a) = Ts sum(S 2 v_a v_b     + D sin 2t |v|^2)
 * lose their S terms when the directions are spread evenly over half a turn
 * (sum cos 2phi = sum sin 2phi = 0), so 2t = atan2(B, A) for D > 0
 * (Ld < Lq; atan2(-B, -A) for Ld > Lq). The d axis and its opposite give the
 * same inductance: the result is t modulo pi, its polarity left to the
 * caller (sensorless.c: by the first motion).
 *
 * Each direction gets +v, -v, -v, +v (one period each): the current returns
 * to where it was and a constant drift (resistive decay, back-EMF of a
 * slowly turning rotor) cancels in the sums. The voltage and the current
 * change are paired by the caller: v the voltage actually applied in
 * [k-1, k) (the observer's reconstruction), i the current at k, so the
 * pipeline's one-period delay between the pulse asked for and the pulse
 * applied does not matter. Integer-only per period.
 */
#ifndef CONTROL_INITIAL_ANGLE_H
#define CONTROL_INITIAL_ANGLE_H

#include <stdint.h>

#include "fx.h"

#define CTRL_IA_DIRS 6u    /* directions, evenly over half a turn */
#define CTRL_IA_PER_DIR 4u /* +v, -v, -v, +v */
#define CTRL_IA_DELAY 2u   /* periods from a pulse asked for to its current change */
#define CTRL_IA_ROUNDS_MAX 64u

typedef struct {
    /* ---- configuration (ctrl_ia_init) ---- */
    q24_t v_amp;     /* pulse amplitude, Q24 pu (> 0) */
    uint8_t rounds;  /* rounds of the six directions, 1 .. CTRL_IA_ROUNDS_MAX */
    int8_t sal_sign; /* +1: Ld < Lq, -1: Ld > Lq */
    /* ---- state ---- */
    uint16_t n;               /* updates since ctrl_ia_start */
    q24_t i_prev_a, i_prev_b; /* current at the last update, Q24 pu */
    int64_t acc_a, acc_b;     /* A and B above, Q48 pu^2 */
} ctrl_ia_t;

/* Set the pulse amplitude (Q24 pu), the rounds and the saliency's sign (Ld
 * < Lq: +1). Returns 0, or -1 for an amplitude <= 0, rounds outside 1 ..
 * CTRL_IA_ROUNDS_MAX or a sign other than +-1 (ia untouched). */
int ctrl_ia_init(ctrl_ia_t *ia, q24_t v_amp, uint32_t rounds, int32_t sal_sign);

/* Start a measurement: sums cleared. */
void ctrl_ia_start(ctrl_ia_t *ia);

/* Periods one measurement takes (pulses and the delay). */
uint32_t ctrl_ia_periods(const ctrl_ia_t *ia);

/*
 * One period: v_alpha, v_beta the voltage applied in [k-1, k), i the current
 * at k (Q24 pu). Writes the voltage to apply next (Q24 pu, alpha/beta; zero
 * after the last pulse) and returns 1 while the measurement runs, 0 once it
 * is complete (then ctrl_ia_angle).
 */
uint8_t ctrl_ia_step(ctrl_ia_t *ia, q24_t v_alpha, q24_t v_beta, q24_t i_alpha, q24_t i_beta,
                     q24_t *v_alpha_out, q24_t *v_beta_out);

/* The d-axis angle modulo pi, in [0, pi) (fx_angle_t). */
fx_angle_t ctrl_ia_angle(const ctrl_ia_t *ia);

#endif /* CONTROL_INITIAL_ANGLE_H */
