/*
 * Flux maps psi_d(id, iq), psi_q(id, iq) (thesis 3.2.3, (3.11)) and their
 * inverse (3.14). The thesis fits inverse maps with Gridfit; here the inverse
 * is solved by Newton on the bilinear interpolant, so psi(i(psi)) == psi to
 * 1e-12 Wb and no second table (and its fitting error, 0.7 % in Fig. 3.6) is
 * needed.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "plant.h"
#include "sim_csv.h"

void plant_fluxmap_free(plant_fluxmap_t *m)
{
    if (m == NULL) {
        return;
    }
    free(m->psi_d);
    free(m->psi_q);
    memset(m, 0, sizeof(*m));
}

typedef struct {
    double id, iq, pd, pq;
} fm_row_t;

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Sorted unique values of v[0..n) into u; returns count. */
static size_t unique_sorted(double *v, size_t n, double tol)
{
    qsort(v, n, sizeof(double), cmp_double);
    size_t k = 0;
    for (size_t i = 0; i < n; ++i) {
        if (k == 0 || fabs(v[i] - v[k - 1]) > tol) {
            v[k++] = v[i];
        }
    }
    return k;
}

int plant_fluxmap_load(plant_fluxmap_t *m, const char *path, char *err, size_t errlen)
{
    if (m == NULL || path == NULL) {
        if (err != NULL && errlen > 0) {
            snprintf(err, errlen, "fluxmap: NULL argument");
        }
        return PLANT_EINVAL;
    }
    memset(m, 0, sizeof(*m));
    FILE *f = fopen(path, "r");
    if (f == NULL) {
        snprintf(err, errlen, "%s: cannot open: %s", path, strerror(errno));
        return PLANT_EINVAL;
    }
    fm_row_t *rows = NULL;
    size_t n = 0, cap = 0;
    char line[512];
    long lineno = 0;
    int header_seen = 0;
    int rc = PLANT_OK;
    while (fgets(line, sizeof line, f) != NULL) {
        ++lineno;
        if (!sim_csv_line_complete(line, f)) {
            snprintf(err, errlen, "%s:%ld: line too long", path, lineno);
            rc = PLANT_EINVAL;
            break;
        }
        const char *s = sim_csv_content(line);
        if (s == NULL) {
            continue;
        }
        if (!header_seen) {
            header_seen = 1;
            if (!sim_csv_is_header(s, "id_a,iq_a,psi_d_wb,psi_q_wb")) {
                snprintf(err, errlen, "%s:%ld: expected header id_a,iq_a,psi_d_wb,psi_q_wb", path,
                         lineno);
                rc = PLANT_EINVAL;
                break;
            }
            continue;
        }
        double v[4];
        if (sim_csv_numbers(s, v, 4) != 0) {
            snprintf(err, errlen, "%s:%ld: expected 4 numbers id_a,iq_a,psi_d_wb,psi_q_wb", path,
                     lineno);
            rc = PLANT_EINVAL;
            break;
        }
        if (n == cap) {
            cap = cap ? 2 * cap : 256;
            fm_row_t *nr = realloc(rows, cap * sizeof(*rows));
            if (nr == NULL) {
                snprintf(err, errlen, "%s: out of memory", path);
                rc = PLANT_EINVAL;
                break;
            }
            rows = nr;
        }
        rows[n].id = v[0];
        rows[n].iq = v[1];
        rows[n].pd = v[2];
        rows[n].pq = v[3];
        ++n;
    }
    fclose(f);
    if (rc == PLANT_OK && n < 4) {
        snprintf(err, errlen, "%s: need at least a 2x2 grid, got %zu rows", path, n);
        rc = PLANT_EINVAL;
    }
    double *ud = NULL, *uq = NULL;
    if (rc == PLANT_OK) {
        ud = malloc(n * sizeof(double));
        uq = malloc(n * sizeof(double));
        if (ud == NULL || uq == NULL) {
            snprintf(err, errlen, "%s: out of memory", path);
            rc = PLANT_EINVAL;
        }
    }
    if (rc == PLANT_OK) {
        for (size_t i = 0; i < n; ++i) {
            ud[i] = rows[i].id;
            uq[i] = rows[i].iq;
        }
        const size_t nd = unique_sorted(ud, n, 1e-9);
        const size_t nq = unique_sorted(uq, n, 1e-9);
        if (nd < 2 || nq < 2 || nd * nq != n) {
            snprintf(err, errlen,
                     "%s: rows do not form a full grid (%zu id x %zu iq values, %zu rows)", path,
                     nd, nq, n);
            rc = PLANT_EINVAL;
        } else {
            const double sd = (ud[nd - 1] - ud[0]) / (double)(nd - 1);
            const double sq = (uq[nq - 1] - uq[0]) / (double)(nq - 1);
            for (size_t i = 0; i < nd && rc == PLANT_OK; ++i) {
                if (fabs(ud[i] - (ud[0] + sd * (double)i)) > 1e-6 * sd) {
                    snprintf(err, errlen, "%s: id values are not evenly spaced", path);
                    rc = PLANT_EINVAL;
                }
            }
            for (size_t i = 0; i < nq && rc == PLANT_OK; ++i) {
                if (fabs(uq[i] - (uq[0] + sq * (double)i)) > 1e-6 * sq) {
                    snprintf(err, errlen, "%s: iq values are not evenly spaced", path);
                    rc = PLANT_EINVAL;
                }
            }
            if (rc == PLANT_OK) {
                m->n_d = nd;
                m->n_q = nq;
                m->id_min = ud[0];
                m->id_max = ud[nd - 1];
                m->iq_min = uq[0];
                m->iq_max = uq[nq - 1];
                m->psi_d = malloc(n * sizeof(double));
                m->psi_q = malloc(n * sizeof(double));
                unsigned char *seen = calloc(n, 1);
                if (m->psi_d == NULL || m->psi_q == NULL || seen == NULL) {
                    snprintf(err, errlen, "%s: out of memory", path);
                    rc = PLANT_EINVAL;
                }
                for (size_t r = 0; r < n && rc == PLANT_OK; ++r) {
                    const long kd = lround((rows[r].id - m->id_min) / sd);
                    const long kq = lround((rows[r].iq - m->iq_min) / sq);
                    const size_t k = (size_t)kd * nq + (size_t)kq;
                    if (seen[k]) {
                        snprintf(err, errlen, "%s: duplicate grid point id=%g iq=%g", path,
                                 rows[r].id, rows[r].iq);
                        rc = PLANT_EINVAL;
                        break;
                    }
                    seen[k] = 1;
                    m->psi_d[k] = rows[r].pd;
                    m->psi_q[k] = rows[r].pq;
                }
                free(seen);
            }
        }
    }
    free(ud);
    free(uq);
    free(rows);
    if (rc != PLANT_OK) {
        plant_fluxmap_free(m);
    }
    return rc;
}

/* Cell and local coordinates, with linear extrapolation outside the grid. */
static void fm_cell(const plant_fluxmap_t *m, double id, double iq, size_t *kd, size_t *kq,
                    double *u, double *w, double *hd, double *hq)
{
    *hd = (m->id_max - m->id_min) / (double)(m->n_d - 1);
    *hq = (m->iq_max - m->iq_min) / (double)(m->n_q - 1);
    double xd = (id - m->id_min) / *hd;
    double xq = (iq - m->iq_min) / *hq;
    double fd = floor(xd), fq = floor(xq);
    if (!(fd >= 0.0)) {
        fd = 0.0;
    }
    if (fd > (double)(m->n_d - 2)) {
        fd = (double)(m->n_d - 2);
    }
    if (!(fq >= 0.0)) {
        fq = 0.0;
    }
    if (fq > (double)(m->n_q - 2)) {
        fq = (double)(m->n_q - 2);
    }
    *kd = (size_t)fd;
    *kq = (size_t)fq;
    *u = xd - fd;
    *w = xq - fq;
}

static void fm_eval(const plant_fluxmap_t *m, double id, double iq, double psi[2], double jac[4])
{
    size_t kd, kq;
    double u, w, hd, hq;
    fm_cell(m, id, iq, &kd, &kq, &u, &w, &hd, &hq);
    const size_t n_q = m->n_q;
    const double *tab[2] = {m->psi_d, m->psi_q};
    for (int c = 0; c < 2; ++c) {
        const double f00 = tab[c][kd * n_q + kq], f01 = tab[c][kd * n_q + kq + 1];
        const double f10 = tab[c][(kd + 1) * n_q + kq], f11 = tab[c][(kd + 1) * n_q + kq + 1];
        psi[c] = f00 * (1 - u) * (1 - w) + f10 * u * (1 - w) + f01 * (1 - u) * w + f11 * u * w;
        if (jac != NULL) {
            jac[2 * c + 0] = ((f10 - f00) * (1 - w) + (f11 - f01) * w) / hd;
            jac[2 * c + 1] = ((f01 - f00) * (1 - u) + (f11 - f10) * u) / hq;
        }
    }
}

void plant_fluxmap_psi(const plant_fluxmap_t *m, double id, double iq, double *psi_d, double *psi_q)
{
    double psi[2];
    fm_eval(m, id, iq, psi, NULL);
    *psi_d = psi[0];
    *psi_q = psi[1];
}

int plant_fluxmap_current(const plant_fluxmap_t *m, double psi_d, double psi_q, double *id,
                          double *iq)
{
    double x[2];
    if (isfinite(*id) && isfinite(*iq)) {
        x[0] = *id;
        x[1] = *iq;
    } else {
        /* secant guess through the origin's Jacobian */
        double p0[2], j0[4];
        fm_eval(m, 0.0, 0.0, p0, j0);
        x[0] = (psi_d - p0[0]) / j0[0];
        x[1] = (psi_q - p0[1]) / j0[3];
        if (!isfinite(x[0]) || !isfinite(x[1])) {
            x[0] = x[1] = 0.0;
        }
    }
    const double target[2] = {psi_d, psi_q};
    for (int it = 0; it < 60; ++it) {
        double psi[2], j[4];
        fm_eval(m, x[0], x[1], psi, j);
        const double r0 = psi[0] - target[0], r1 = psi[1] - target[1];
        if (fabs(r0) + fabs(r1) < 1e-12) {
            *id = x[0];
            *iq = x[1];
            return PLANT_OK;
        }
        const double det = j[0] * j[3] - j[1] * j[2];
        if (!(fabs(det) > 0.0) || !isfinite(det)) {
            return PLANT_ERANGE;
        }
        double dx0 = (j[3] * r0 - j[1] * r1) / det;
        double dx1 = (-j[2] * r0 + j[0] * r1) / det;
        /* damping after many iterations (cell-boundary cycling) */
        const double lam = (it < 20) ? 1.0 : 0.5;
        x[0] -= lam * dx0;
        x[1] -= lam * dx1;
        if (!isfinite(x[0]) || !isfinite(x[1])) {
            return PLANT_ERANGE;
        }
    }
    return PLANT_ERANGE;
}
