/*
 * Performance indices of the thesis, Appendix B, computed
 * over a steady-state window from samples the caller feeds:
 *   - plant-grid sampling: the plant observer (plant_set_observer) at a fixed
 *     step (>= 10 samples per control period) feeds the TRUE signals;
 *   - control-instant sampling: a second accumulator fed at the control
 *     instants (label it with METRICS_SAMPLING_CONTROL).
 * T_rip = population std of torque (B.1); psi_rip the same for |psi_s|;
 * T_sse = mean(T_ref - T) (B.2); f_av = leg transitions (on and off, three legs)
 * / (2 * 3 * window); THD_I (B.3) of phase a: Fourier coefficients at the
 * harmonic frequencies k f1 of the KNOWN fundamental f1, by trapezoidal
 * integration of the uniformly sampled i_a over the largest integer number of
 * fundamental periods that fits in the window (the end is linearly
 * interpolated), harmonics 2..N with N f1 <= min(10 kHz, f_sample/2).
 * THD is undefined (NaN, "null" in JSON) without a fundamental to refer to:
 * f1 = 0 (standstill), less than one fundamental period in the window, or a
 * fundamental amplitude below thd_i1_min_a (set by the caller; the simulator
 * uses 5 % of the rated current: below it the ratio measures the switching
 * ripple, not distortion, and ran to ~1000 % at zero torque).
 * Samples are assumed uniformly spaced (the ripple figures are plain sample
 * statistics; THD uses the sample times).
 * Also: the peak-to-peak torque ripple (max - min of the samples, as the book
 * chapter quotes it) and THD_V of the motor-terminal phase voltage from the
 * interval means the plant observer provides (plant_v_motor_mean_abc): the
 * voltage is taken constant over each sample interval and its Fourier
 * integrals are exact for that staircase (exact for the inverter's voltage
 * when it switches on the sample grid; for a smooth voltage harmonic k is
 * low by sinc(pi k f1 h), 1.6 % at 10 kHz with h = 10 us), harmonics as THD_I.
 */
#ifndef SIM_HOST_METRICS_H
#define SIM_HOST_METRICS_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum { METRICS_SAMPLING_PLANT = 0, METRICS_SAMPLING_CONTROL = 1 } metrics_sampling_t;

typedef struct {
    metrics_sampling_t sampling;
    double f1_hz;        /* fundamental for THD (0 = no THD) */
    double thd_fmax_hz;  /* highest harmonic frequency, default 10 kHz */
    double thd_i1_min_a; /* least fundamental amplitude for a THD, default 0 */
    /* Welford accumulators */
    uint64_t n;
    double t_first, t_last;
    double tq_mean, tq_m2, psi_mean, psi_m2, err_sum;
    /* phase-a samples for THD (heap, grows) */
    double *ia_t, *ia_v;
    size_t ia_n, ia_cap;
    /* motor-terminal phase-a voltage: interval ends and interval means */
    double *va_t, *va_v;
    size_t va_n, va_cap;
    double tq_min, tq_max;
    int oom;
    /* transitions */
    uint64_t transitions;
    double trans_window_s; /* <= 0: not given */
} metrics_acc_t;

typedef struct {
    metrics_sampling_t sampling;
    uint64_t samples;
    double window_s; /* t_last - t_first of the samples */
    double torque_mean_nm, torque_ripple_nm;
    double flux_mean_wb, flux_ripple_wb;
    double torque_sse_nm;
    double f_av_hz;      /* NaN if no transition count was given */
    double thd_i_pct;    /* NaN if f1 == 0, under one fundamental period, or i1 < thd_i1_min_a */
    double thd_window_s; /* the integer-period window used for THD */
    int thd_harmonics;   /* N */
    double i1_amp_a;     /* fundamental amplitude of i_a */
    double torque_pp_nm; /* max - min of the torque samples */
    double thd_v_pct;    /* THD of the motor phase voltage (NaN without voltage samples) */
    double v1_amp_v;     /* its fundamental amplitude */
} metrics_result_t;

/* f1_hz: fundamental (electrical) frequency for THD, 0 to skip THD. */
void metrics_init(metrics_acc_t *m, metrics_sampling_t sampling, double f1_hz);
/* One sample at time t. i_a is stored only when f1_hz > 0. */
void metrics_add(metrics_acc_t *m, double t, double torque_nm, double torque_ref_nm,
                 double psi_amp_wb, double i_a);
/* Motor-terminal phase-a voltage: its mean over the interval that ends at t
 * (since the previous call; the first call only opens the first interval).
 * Stored only when f1_hz > 0. */
void metrics_add_voltage(metrics_acc_t *m, double t, double v_mean);
/* Leg transitions of the three legs counted over a window of window_s seconds
 * (e.g. the difference of plant_transitions between the window's ends). */
void metrics_set_transitions(metrics_acc_t *m, uint64_t transitions, double window_s);
/* Compute the indices. Returns 0, or -1 (no samples, or out of memory). */
int metrics_finish(const metrics_acc_t *m, metrics_result_t *r);
void metrics_free(metrics_acc_t *m);

/* {"sampling": "...", "window_s": ..., "torque_mean_nm": ..., ...}; NaN as null. */
void metrics_write_json(FILE *f, const metrics_result_t *r);

/* Standalone THD (B.3) of uniformly or non-uniformly sampled x(t) for the
 * fundamental f1 (used by metrics_finish). Returns NaN if under one period. */
double metrics_thd_pct(const double *t, const double *x, size_t n, double f1_hz, double fmax_hz,
                       int *n_harm, double *window_s, double *i1_amp);

/* THD (B.3) of a staircase: v[j] is the mean over [t[j-1], t[j]] (v[0] is
 * unused), integrated exactly over the largest whole number of fundamental
 * periods from t[0]. Harmonics 2..N, N f1 <= min(fmax, f_sample/2). */
double metrics_thd_zoh_pct(const double *t, const double *v, size_t n, double f1_hz, double fmax_hz,
                           int *n_harm, double *window_s, double *v1_amp);

#ifdef __cplusplus
}
#endif

#endif /* SIM_HOST_METRICS_H */
