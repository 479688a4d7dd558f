/*
 * Performance indices of the thesis, Appendix B (definitions made precise in metrics.h). See
 * metrics.h.
 */
#include "metrics.h"
#include "plant.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void metrics_init(metrics_acc_t *m, metrics_sampling_t sampling, double f1_hz)
{
    if (m == NULL) {
        return;
    }
    memset(m, 0, sizeof(*m));
    m->sampling = sampling;
    m->f1_hz = (isfinite(f1_hz) && f1_hz > 0.0) ? f1_hz : 0.0;
    m->thd_fmax_hz = 10e3;
    m->trans_window_s = 0.0;
    m->tq_min = INFINITY;
    m->tq_max = -INFINITY;
}

/* Append (t, x) to a pair of growing arrays; 0 or -1 (out of memory). */
static int push2(double **pt, double **px, size_t *n, size_t *cap, double t, double x)
{
    if (*n == *cap) {
        const size_t c = *cap ? 2 * *cap : 4096;
        double *nt = realloc(*pt, c * sizeof(double));
        if (nt == NULL) {
            return -1;
        }
        *pt = nt;
        double *nx = realloc(*px, c * sizeof(double));
        if (nx == NULL) {
            return -1;
        }
        *px = nx;
        *cap = c;
    }
    (*pt)[*n] = t;
    (*px)[*n] = x;
    (*n)++;
    return 0;
}

void metrics_add_voltage(metrics_acc_t *m, double t, double v_mean)
{
    if (m == NULL || !(m->f1_hz > 0.0) || m->oom) {
        return;
    }
    if (push2(&m->va_t, &m->va_v, &m->va_n, &m->va_cap, t, v_mean) != 0) {
        m->oom = 1;
    }
}

void metrics_add(metrics_acc_t *m, double t, double torque_nm, double torque_ref_nm,
                 double psi_amp_wb, double i_a)
{
    if (m == NULL) {
        return;
    }
    if (m->n == 0) {
        m->t_first = t;
    }
    m->t_last = t;
    m->n++;
    /* Welford: numerically stable mean and sum of squared deviations. */
    const double nn = (double)m->n;
    const double dt_ = torque_nm - m->tq_mean;
    m->tq_mean += dt_ / nn;
    m->tq_m2 += dt_ * (torque_nm - m->tq_mean);
    const double dp = psi_amp_wb - m->psi_mean;
    m->psi_mean += dp / nn;
    m->psi_m2 += dp * (psi_amp_wb - m->psi_mean);
    m->err_sum += torque_ref_nm - torque_nm;
    m->tq_min = fmin(m->tq_min, torque_nm);
    m->tq_max = fmax(m->tq_max, torque_nm);
    if (m->f1_hz > 0.0 && !m->oom) {
        if (push2(&m->ia_t, &m->ia_v, &m->ia_n, &m->ia_cap, t, i_a) != 0) {
            m->oom = 1;
        }
    }
}

void metrics_set_transitions(metrics_acc_t *m, uint64_t transitions, double window_s)
{
    if (m == NULL) {
        return;
    }
    m->transitions = transitions;
    m->trans_window_s = (isfinite(window_s) && window_s > 0.0) ? window_s : 0.0;
}

/* The analysis window of both THD forms: K whole fundamental periods from
 * t[0], harmonics up to fmax and half the mean sample rate, and the Fourier
 * sums of harmonics 1..N. */
typedef struct {
    double t_end; /* t[0] + K T1 */
    double w;     /* window length K T1, s */
    double w1;    /* fundamental, rad/s */
    int n_harm;   /* N */
    double *re, *im;
} thd_window_t;

static int thd_window_open(thd_window_t *win, const double *t, const double *x, size_t n,
                           double f1_hz, double fmax_hz, int *n_harm, double *window_s,
                           double *amp1)
{
    if (n_harm != NULL) {
        *n_harm = 0;
    }
    if (window_s != NULL) {
        *window_s = 0.0;
    }
    if (amp1 != NULL) {
        *amp1 = NAN;
    }
    if (t == NULL || x == NULL || n < 3 || !(f1_hz > 0.0)) {
        return 0;
    }
    const double T1 = 1.0 / f1_hz;
    const double span = t[n - 1] - t[0];
    const double K = floor(span / T1 + 1e-9);
    if (K < 1.0) {
        return 0;
    }
    const double fs_mean = (double)(n - 1) / span;
    double fm = (fmax_hz > 0.0) ? fmax_hz : 10e3;
    if (fm > 0.5 * fs_mean) {
        fm = 0.5 * fs_mean;
    }
    const int N = (int)floor(fm / f1_hz + 1e-9);
    if (N < 2) {
        return 0;
    }
    win->re = calloc((size_t)N + 1, sizeof(double));
    win->im = calloc((size_t)N + 1, sizeof(double));
    if (win->re == NULL || win->im == NULL) {
        free(win->re);
        free(win->im);
        return 0;
    }
    win->t_end = t[0] + K * T1;
    win->w = K * T1;
    win->w1 = 2.0 * PLANT_PI * f1_hz;
    win->n_harm = N;
    return 1;
}

/* Amplitudes 2/W |X_k|, THD (B.3) against harmonic 1; frees the sums. */
static double thd_window_close(thd_window_t *win, int *n_harm, double *window_s, double *amp1)
{
    double a1 = 0.0, sum = 0.0;
    for (int k = 1; k <= win->n_harm; ++k) {
        const double amp = 2.0 / win->w * hypot(win->re[k], win->im[k]);
        if (k == 1) {
            a1 = amp;
        } else {
            sum += amp * amp;
        }
    }
    free(win->re);
    free(win->im);
    if (n_harm != NULL) {
        *n_harm = win->n_harm;
    }
    if (window_s != NULL) {
        *window_s = win->w;
    }
    if (amp1 != NULL) {
        *amp1 = a1;
    }
    if (!(a1 > 0.0)) {
        return NAN;
    }
    return 100.0 * sqrt(sum) / a1; /* (B.3) */
}

/* Points c e^{-j k w1 tau} added to the window's sums of harmonics k = 1..N,
 * THD_BATCH at a time: each point's phasor of harmonic k by repeated
 * multiplication with its fundamental's (N products: rounding ~N * 1e-16),
 * the chains of the batch's points side by side so that their products
 * overlap in the pipeline instead of waiting on each other. */
#define THD_BATCH 8 /* the pairwise sum below is written for 8 */
typedef struct {
    double br[THD_BATCH], bi[THD_BATCH], c[THD_BATCH];
    int n;
} thd_batch_t;

static void thd_batch_flush(thd_window_t *win, thd_batch_t *b)
{
    for (int p = b->n; p < THD_BATCH; ++p) {
        b->br[p] = 1.0;
        b->bi[p] = 0.0;
        b->c[p] = 0.0;
    }
    double zr[THD_BATCH], zi[THD_BATCH];
    for (int p = 0; p < THD_BATCH; ++p) {
        zr[p] = 1.0;
        zi[p] = 0.0;
    }
    for (int k = 1; k <= win->n_harm; ++k) {
        double tr[THD_BATCH], ti[THD_BATCH];
        for (int p = 0; p < THD_BATCH; ++p) {
            const double nr = zr[p] * b->br[p] - zi[p] * b->bi[p];
            zi[p] = zr[p] * b->bi[p] + zi[p] * b->br[p];
            zr[p] = nr;
            tr[p] = b->c[p] * zr[p];
            ti[p] = b->c[p] * zi[p];
        }
        /* pairwise: three additions deep, not eight */
        win->re[k] += ((tr[0] + tr[1]) + (tr[2] + tr[3])) + ((tr[4] + tr[5]) + (tr[6] + tr[7]));
        win->im[k] += ((ti[0] + ti[1]) + (ti[2] + ti[3])) + ((ti[4] + ti[5]) + (ti[6] + ti[7]));
    }
    b->n = 0;
}

static void thd_batch_add(thd_window_t *win, thd_batch_t *b, double tau, double c)
{
    if (c == 0.0) {
        return; /* adds nothing (a staircase's step of zero) */
    }
    const double ph = win->w1 * tau;
    b->br[b->n] = cos(ph);
    b->bi[b->n] = -sin(ph);
    b->c[b->n] = c;
    if (++b->n == THD_BATCH) {
        thd_batch_flush(win, b);
    }
}

double metrics_thd_pct(const double *t, const double *x, size_t n, double f1_hz, double fmax_hz,
                       int *n_harm, double *window_s, double *i1_amp)
{
    thd_window_t win;
    if (!thd_window_open(&win, t, x, n, f1_hz, fmax_hz, n_harm, window_s, i1_amp)) {
        return NAN;
    }
    const double t_end = win.t_end;
    thd_batch_t batch = {.n = 0};
    /* Trapezoid as a weighted sum of points: every sample in the window gets
     * half of each adjacent segment; the last segment is cut at t_end, whose
     * value is interpolated. */
    for (size_t j = 0; j < n && t[j] < t_end; ++j) {
        double wgt = 0.0;
        if (j > 0) {
            wgt += 0.5 * (t[j] - t[j - 1]);
        }
        if (j + 1 < n) {
            const double tb = t[j + 1] < t_end ? t[j + 1] : t_end;
            const double h_end = tb - t[j];
            wgt += 0.5 * h_end;
            if (t[j + 1] >= t_end && h_end > 0.0) {
                /* the last, cut segment's interpolated end point, weight
                 * h_end / 2, phase w1 K T1 = 2 pi K for every harmonic */
                const double u = (t_end - t[j]) / (t[j + 1] - t[j]);
                const double x_end = x[j] + u * (x[j + 1] - x[j]);
                for (int k = 1; k <= win.n_harm; ++k) {
                    win.re[k] += 0.5 * h_end * x_end;
                }
            }
        }
        thd_batch_add(&win, &batch, t[j] - t[0], wgt * x[j]);
    }
    thd_batch_flush(&win, &batch);
    return thd_window_close(&win, n_harm, window_s, i1_amp);
}

double metrics_thd_zoh_pct(const double *t, const double *v, size_t n, double f1_hz, double fmax_hz,
                           int *n_harm, double *window_s, double *v1_amp)
{
    thd_window_t win;
    if (!thd_window_open(&win, t, v, n, f1_hz, fmax_hz, n_harm, window_s, v1_amp)) {
        return NAN;
    }
    const double t_end = win.t_end;
    /* Interval j = [t[j-1], t[j]] holds the constant v[j]; the integral of
     * e^{-j k w1 (t - t0)} over it is (z_k(b) - z_k(a)) / (-j k w1) with
     * z_k(tau) = e^{-j k w1 tau}. Summed by parts over the intervals, each
     * boundary tau_j = t[j] - t0 carries v[j] - v[j+1] (the last, cut at
     * t_end, v[J]; the first, tau = 0, -v[1]): one phasor chain per
     * boundary, and S_k / (-j k w1) = j S_k / (k w1) at the end. */
    thd_batch_t batch = {.n = 0};
    thd_batch_add(&win, &batch, 0.0, -v[1]); /* t[0] < t_end: K >= 1 */
    for (size_t j = 1; j < n && t[j - 1] < t_end; ++j) {
        const int last = !(j + 1 < n && t[j] < t_end);
        const double b = (t[j] < t_end ? t[j] : t_end) - t[0];
        thd_batch_add(&win, &batch, b, last ? v[j] : v[j] - v[j + 1]);
    }
    thd_batch_flush(&win, &batch);
    for (int k = 1; k <= win.n_harm; ++k) {
        const double kw = (double)k * win.w1;
        const double sr = win.re[k], si = win.im[k];
        win.re[k] = -si / kw;
        win.im[k] = sr / kw;
    }
    return thd_window_close(&win, n_harm, window_s, v1_amp);
}

int metrics_finish(const metrics_acc_t *m, metrics_result_t *r)
{
    if (m == NULL || r == NULL) {
        return -1;
    }
    memset(r, 0, sizeof(*r));
    r->sampling = m->sampling;
    r->f_av_hz = NAN;
    r->thd_i_pct = NAN;
    r->i1_amp_a = NAN;
    r->thd_v_pct = NAN;
    r->v1_amp_v = NAN;
    r->torque_pp_nm = NAN;
    if (m->n == 0 || m->oom) {
        r->torque_mean_nm = r->torque_ripple_nm = NAN;
        r->flux_mean_wb = r->flux_ripple_wb = r->torque_sse_nm = NAN;
        return -1;
    }
    const double nn = (double)m->n;
    r->samples = m->n;
    r->window_s = m->t_last - m->t_first;
    r->torque_mean_nm = m->tq_mean;
    r->torque_ripple_nm = sqrt(m->tq_m2 / nn); /* (B.1), 1/m */
    r->torque_pp_nm = m->tq_max - m->tq_min;
    r->flux_mean_wb = m->psi_mean;
    r->flux_ripple_wb = sqrt(m->psi_m2 / nn);
    r->torque_sse_nm = m->err_sum / nn; /* (B.2) */
    if (m->trans_window_s > 0.0) {
        r->f_av_hz = (double)m->transitions / (2.0 * 3.0 * m->trans_window_s);
    }
    if (m->f1_hz > 0.0) {
        r->thd_i_pct = metrics_thd_pct(m->ia_t, m->ia_v, m->ia_n, m->f1_hz, m->thd_fmax_hz,
                                       &r->thd_harmonics, &r->thd_window_s, &r->i1_amp_a);
        if (!(r->i1_amp_a >= m->thd_i1_min_a)) {
            r->thd_i_pct = NAN; /* no fundamental to refer to (metrics.h) */
        }
        r->thd_v_pct = metrics_thd_zoh_pct(m->va_t, m->va_v, m->va_n, m->f1_hz, m->thd_fmax_hz,
                                           NULL, NULL, &r->v1_amp_v);
    }
    return 0;
}

void metrics_free(metrics_acc_t *m)
{
    if (m == NULL) {
        return;
    }
    free(m->ia_t);
    free(m->ia_v);
    m->ia_t = m->ia_v = NULL;
    m->ia_n = m->ia_cap = 0;
    free(m->va_t);
    free(m->va_v);
    m->va_t = m->va_v = NULL;
    m->va_n = m->va_cap = 0;
}

static void put_num(FILE *f, const char *key, double v, int last)
{
    if (isfinite(v)) {
        fprintf(f, "  \"%s\": %.9g%s\n", key, v, last ? "" : ",");
    } else {
        fprintf(f, "  \"%s\": null%s\n", key, last ? "" : ",");
    }
}

void metrics_write_json(FILE *f, const metrics_result_t *r)
{
    if (f == NULL || r == NULL) {
        return;
    }
    fprintf(f, "{\n  \"sampling\": \"%s\",\n",
            r->sampling == METRICS_SAMPLING_CONTROL ? "control_instants" : "plant_grid");
    fprintf(f, "  \"samples\": %llu,\n", (unsigned long long)r->samples);
    put_num(f, "window_s", r->window_s, 0);
    put_num(f, "torque_mean_nm", r->torque_mean_nm, 0);
    put_num(f, "torque_ripple_nm", r->torque_ripple_nm, 0);
    put_num(f, "torque_ripple_pp_nm", r->torque_pp_nm, 0);
    put_num(f, "flux_mean_wb", r->flux_mean_wb, 0);
    put_num(f, "flux_ripple_wb", r->flux_ripple_wb, 0);
    put_num(f, "torque_sse_nm", r->torque_sse_nm, 0);
    put_num(f, "f_av_hz", r->f_av_hz, 0);
    put_num(f, "thd_i_pct", r->thd_i_pct, 0);
    put_num(f, "thd_window_s", r->thd_window_s, 0);
    fprintf(f, "  \"thd_harmonics\": %d,\n", r->thd_harmonics);
    put_num(f, "thd_v_pct", r->thd_v_pct, 0);
    put_num(f, "v1_amp_v", r->v1_amp_v, 0);
    put_num(f, "i1_amp_a", r->i1_amp_a, 1);
    fprintf(f, "}\n");
}
