/*
 * Matrix exponential by scaling and squaring with diagonal Pade approximants
 * (Higham 2005, see plant_expm.h). exp(A) ~ (V - U)^-1 (V + U), U odd and V
 * even in A; for ||A||_1 > theta_13 the matrix is scaled by 2^-s first and
 * the result squared s times.
 */
#include "plant_expm.h"

#include <math.h>
#include <string.h>

#define NM PLANT_EXPM_NMAX

/* Higham 2005, Table 2.3: largest ||A||_1 for which degree m is accurate to
 * double precision (backward error <= 2^-53). */
static const double theta_m[5] = {1.495585217958292e-2, 2.539398330063230e-1, 9.504178996162932e-1,
                                  2.097847961257068e0, 5.371920351148152e0};
static const int degree_m[5] = {3, 5, 7, 9, 13};

/* Pade coefficients b_0..b_m of degree m. */
static const double b3[4] = {120.0, 60.0, 12.0, 1.0};
static const double b5[6] = {30240.0, 15120.0, 3360.0, 420.0, 30.0, 1.0};
static const double b7[8] = {17297280.0, 8648640.0, 1995840.0, 277200.0,
                             25200.0,    1512.0,    56.0,      1.0};
static const double b9[10] = {17643225600.0, 8821612800.0, 2075673600.0, 302702400.0, 30270240.0,
                              2162160.0,     110880.0,     3960.0,       90.0,        1.0};
static const double b13[14] = {64764752532480000.0,
                               32382376266240000.0,
                               7771770303897600.0,
                               1187353796428800.0,
                               129060195264000.0,
                               10559470521600.0,
                               670442572800.0,
                               33522128640.0,
                               1323241920.0,
                               40840800.0,
                               960960.0,
                               16380.0,
                               182.0,
                               1.0};

static void mat_mul(const double *a, const double *b, size_t n, double *c)
{
    for (size_t i = 0; i < n; ++i) {
        for (size_t j = 0; j < n; ++j) {
            c[i * n + j] = 0.0;
        }
        for (size_t k = 0; k < n; ++k) {
            const double aik = a[i * n + k];
            if (aik == 0.0) {
                continue;
            }
            for (size_t j = 0; j < n; ++j) {
                c[i * n + j] += aik * b[k * n + j];
            }
        }
    }
}

static double norm1(const double *a, size_t n)
{
    double m = 0.0;
    for (size_t j = 0; j < n; ++j) {
        double s = 0.0;
        for (size_t i = 0; i < n; ++i) {
            s += fabs(a[i * n + j]);
        }
        m = s > m ? s : m;
    }
    return m;
}

/* Solve P X = Q (n x n, in place into q) by LU with partial pivoting. */
static int solve(double *p, double *q, size_t n)
{
    for (size_t k = 0; k < n; ++k) {
        size_t piv = k;
        double best = fabs(p[k * n + k]);
        for (size_t i = k + 1; i < n; ++i) {
            if (fabs(p[i * n + k]) > best) {
                best = fabs(p[i * n + k]);
                piv = i;
            }
        }
        if (!(best > 0.0)) {
            return -1;
        }
        if (piv != k) {
            for (size_t j = 0; j < n; ++j) {
                double t = p[k * n + j];
                p[k * n + j] = p[piv * n + j];
                p[piv * n + j] = t;
                t = q[k * n + j];
                q[k * n + j] = q[piv * n + j];
                q[piv * n + j] = t;
            }
        }
        const double inv = 1.0 / p[k * n + k];
        for (size_t i = k + 1; i < n; ++i) {
            const double f = p[i * n + k] * inv;
            if (f == 0.0) {
                continue;
            }
            for (size_t j = k; j < n; ++j) {
                p[i * n + j] -= f * p[k * n + j];
            }
            for (size_t j = 0; j < n; ++j) {
                q[i * n + j] -= f * q[k * n + j];
            }
        }
    }
    for (size_t kk = n; kk-- > 0;) {
        const double inv = 1.0 / p[kk * n + kk];
        for (size_t j = 0; j < n; ++j) {
            double s = q[kk * n + j];
            for (size_t i = kk + 1; i < n; ++i) {
                s -= p[kk * n + i] * q[i * n + j];
            }
            q[kk * n + j] = s * inv;
        }
    }
    return 0;
}

int plant_expm(const double *a, size_t n, double t, double *e)
{
    if (a == NULL || e == NULL || n == 0u || n > NM || !isfinite(t)) {
        return -1;
    }
    const size_t nn = n * n;
    double x[NM * NM];
    for (size_t k = 0; k < nn; ++k) {
        x[k] = a[k] * t;
        if (!isfinite(x[k])) {
            return -1;
        }
    }
    const double nrm = norm1(x, n);
    int mi = 4;
    int s = 0;
    for (int k = 0; k < 4; ++k) {
        if (nrm <= theta_m[k]) {
            mi = k;
            break;
        }
    }
    if (mi == 4 && nrm > theta_m[4]) {
        s = (int)ceil(log2(nrm / theta_m[4]));
        const double sc = ldexp(1.0, -s);
        for (size_t k = 0; k < nn; ++k) {
            x[k] *= sc;
        }
    }
    const int m = degree_m[mi];
    double a2[NM * NM], a4[NM * NM], a6[NM * NM], u[NM * NM], v[NM * NM], w[NM * NM];
    double tmp[NM * NM];
    mat_mul(x, x, n, a2);
    if (m == 13) {
        const double *b = b13;
        mat_mul(a2, a2, n, a4);
        mat_mul(a4, a2, n, a6);
        /* U = A [A6 (b13 A6 + b11 A4 + b9 A2) + b7 A6 + b5 A4 + b3 A2 + b1 I]
         * V = A6 (b12 A6 + b10 A4 + b8 A2) + b6 A6 + b4 A4 + b2 A2 + b0 I */
        for (size_t k = 0; k < nn; ++k) {
            tmp[k] = b[13] * a6[k] + b[11] * a4[k] + b[9] * a2[k];
        }
        mat_mul(a6, tmp, n, w);
        for (size_t k = 0; k < nn; ++k) {
            w[k] += b[7] * a6[k] + b[5] * a4[k] + b[3] * a2[k];
        }
        for (size_t i = 0; i < n; ++i) {
            w[i * n + i] += b[1];
        }
        mat_mul(x, w, n, u);
        for (size_t k = 0; k < nn; ++k) {
            tmp[k] = b[12] * a6[k] + b[10] * a4[k] + b[8] * a2[k];
        }
        mat_mul(a6, tmp, n, v);
        for (size_t k = 0; k < nn; ++k) {
            v[k] += b[6] * a6[k] + b[4] * a4[k] + b[2] * a2[k];
        }
        for (size_t i = 0; i < n; ++i) {
            v[i * n + i] += b[0];
        }
    } else {
        const double *b = m == 3 ? b3 : (m == 5 ? b5 : (m == 7 ? b7 : b9));
        /* Powers A^0, A^2, A^4, ... accumulated: U = A sum b_{2k+1} A^{2k},
         * V = sum b_{2k} A^{2k}. */
        double pw[NM * NM];
        memset(w, 0, nn * sizeof w[0]);
        memset(v, 0, nn * sizeof v[0]);
        memset(pw, 0, nn * sizeof pw[0]);
        for (size_t i = 0; i < n; ++i) {
            pw[i * n + i] = 1.0;
        }
        for (int k = 0; 2 * k <= m; ++k) {
            for (size_t j = 0; j < nn; ++j) {
                v[j] += b[2 * k] * pw[j];
                if (2 * k + 1 <= m) {
                    w[j] += b[2 * k + 1] * pw[j];
                }
            }
            if (2 * k + 2 <= m) {
                mat_mul(pw, a2, n, tmp);
                memcpy(pw, tmp, nn * sizeof pw[0]);
            }
        }
        mat_mul(x, w, n, u);
    }
    /* (V - U) E = (V + U) */
    for (size_t k = 0; k < nn; ++k) {
        tmp[k] = v[k] - u[k];
        e[k] = v[k] + u[k];
    }
    if (solve(tmp, e, n) != 0) {
        return -1;
    }
    for (int k = 0; k < s; ++k) {
        mat_mul(e, e, n, tmp);
        memcpy(e, tmp, nn * sizeof e[0]);
    }
    for (size_t k = 0; k < nn; ++k) {
        if (!isfinite(e[k])) {
            return -1;
        }
    }
    return 0;
}
