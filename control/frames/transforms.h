/*
 * Reference-frame transforms (thesis §3.2.2, Appendix A), Q24 per-unit.
 *
 * Clarke is amplitude-invariant (3.3): f_ab = 2/3 (f_a + f_b e^{j2pi/3} + f_c e^{j4pi/3})
 * with f_c = -f_a - f_b (three-wire machine), so f_alpha = f_a and
 * f_beta = (f_a + 2 f_b) / sqrt(3). Park (3.7): f_dq = f_ab e^{-j theta}.
 * The sine/cosine arguments are Q24 (from fx_sincos), |s|,|c| <= 1.
 * All outputs are rounded once and saturated.
 */
#ifndef CONTROL_TRANSFORMS_H
#define CONTROL_TRANSFORMS_H

#include "fx.h"

/* Clarke (3.3) from two phase currents (i_c = -i_a - i_b). */
void ctrl_clarke(q24_t ia, q24_t ib, q24_t *al, q24_t *be);

/* Inverse Clarke: a = al, b = -al/2 + sqrt(3)/2 be, c = -al/2 - sqrt(3)/2 be. */
void ctrl_inv_clarke(q24_t al, q24_t be, q24_t *a, q24_t *b, q24_t *c);

/* Park (3.7): d = c*al + s*be, q = -s*al + c*be, with s = sin(theta), c = cos(theta). */
void ctrl_park(q24_t al, q24_t be, q24_t s, q24_t c, q24_t *d, q24_t *q);

/* Inverse Park: al = c*d - s*q, be = s*d + c*q. */
void ctrl_inv_park(q24_t d, q24_t q, q24_t s, q24_t c, q24_t *al, q24_t *be);

#endif /* CONTROL_TRANSFORMS_H */
