/*
 * Matrix exponential of a small dense real matrix (n <= PLANT_EXPM_NMAX), for
 * the plant's output-filter path: scaling and squaring with the diagonal
 * Pade approximants of degree 3, 5, 7, 9 or 13 chosen from the 1-norm
 * (N. J. Higham, "The scaling and squaring method for the matrix exponential
 * revisited", SIAM J. Matrix Anal. Appl. 26(4), 2005, Table 2.3 and
 * Algorithm 2.3). Row-major storage, a[i * n + j].
 */
#ifndef SIM_HOST_PLANT_EXPM_H
#define SIM_HOST_PLANT_EXPM_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define PLANT_EXPM_NMAX 18

/* e = exp(a * t). Returns 0, or -1 (n out of range, non-finite input, or a
 * singular Pade denominator, which cannot happen for finite input). */
int plant_expm(const double *a, size_t n, double t, double *e);

#ifdef __cplusplus
}
#endif

#endif /* SIM_HOST_PLANT_EXPM_H */
