/*
 * Elementary functions of the configuration code (double, configuration time
 * only), built from IEEE-754 basic operations alone (+, -, *, / and exact
 * scaling by powers of two): host and target round them identically, so the
 * Q values they lead to are bit-identical (libm's sin, cos, exp and hypot
 * are not the same code on the host's C library and the target's newlib, and
 * newlib's pulled 6.8 KB into the board image: docs/board-b-g431b-esc1.md, "Flash budget").
 * Accuracy: a few ulp (Taylor series on a reduced argument, Horner's rule).
 */
#ifndef CTRL_CFG_MATH_H
#define CTRL_CFG_MATH_H

/* Largest |x| the trigonometric functions reduce exactly (n pi/2 with
 * n < 2^20); beyond it, and for a non-finite x, they return NaN. */
#define CTRL_CFG_TRIG_MAX 1e6

/* sin(x) and cos(x), x in rad; either output may be NULL. */
void ctrl_cfg_sincos(double x, double *s, double *c);
double ctrl_cfg_sin(double x);
double ctrl_cfg_cos(double x);

/* e^x; 0 below e^-708 (no subnormal results), +inf above e^709, NaN for NaN. */
double ctrl_cfg_exp(double x);

/* sqrt(x^2 + y^2) (without libm's guard against overflow of the squares:
 * configuration magnitudes are far from 1e154). */
double ctrl_cfg_hypot(double x, double y);

/* x 2^n for n in [-1022, 1023]: a product by a power of two, exact wherever
 * the result is a normal double (libm's ldexp, without its 0.4 KB). */
double ctrl_cfg_ldexp(double x, int n);

/* The binary exponent e of a finite x != 0, |x| in [2^(e-1), 2^e) (frexp's
 * exponent); 0 for 0, infinities and NaN. */
int ctrl_cfg_exponent(double x);

/* x to the nearest integer, halves away from zero (llround's result for
 * |x| < 2^63); NaN -> 0, beyond the int64 range the nearest end of it. */
long long ctrl_cfg_llround(double x);

#endif /* CTRL_CFG_MATH_H */
