/*
 * Configuration side of the DRR-DTC family: SI values (double) converted to the
 * fixed-point state of ctrl_drr.h. Included only by *_config.c files, tests and
 * the firmware's configuration code; the per-sample code includes ctrl_drr.h
 * alone and stays integer-only.
 */
#ifndef CONTROL_CTRL_DRR_CONFIG_H
#define CONTROL_CTRL_DRR_CONFIG_H

#include "ctrl_drr.h"
#include "ctrl_params.h"

/* ---------------- drr: SI configuration (tunables are the doubles) ---------------- */
typedef struct {
    double a_nm;         /* A (5.9), N*m; 0 = from the machine at init */
    double b_nm;         /* B (5.10), N*m; 0 = from the machine at init */
    double c;            /* C (5.13), dimensionless, < 0; 0 = speed-dependent (5.13) */
    double lambda;       /* EMA smoothing factor (5.4), thesis 0.03 */
    double sigma;        /* subsector width (4.19) of the replacement, rad; 0 = off */
    double dpsi_max_wb;  /* Delta psi_max of §5.3.5, Wb; 0 = sqrt(3) Vdc Ts / 3 */
    double pred_516;     /* 0: model prediction of T(k+1) (default); 1: (5.16) */
    double gamma_max_nm; /* error band of the EMA (5.4), N*m; 0 = A (5.9) */
    double centre;       /* 1: plans realised centre-aligned (plan.h, default): T_e is
                            shifted to the active-vector start; 0: active vector first */
    double rs_dt;        /* 1: the zero-vector deviation includes -(Rs Ts/Ls) T_e of
                            (4.10); 0: the thesis' load-free (5.6)/(5.7); default 1
                            when Rs i_rated >= 10 % of w_rn psi_pm (ctrl_drr_config.c) */
} ctrl_drr_cfg_t;

/* ---------------- baselines: one SI configuration, each descriptor exposes its part ------ */
typedef struct {
    double c_t_nm;     /* D1 (5.19) C_T, N*m (thesis 1.2) */
    double c_psi_wb;   /* D1 (5.19) C_psi, Wb (thesis 0.09427) */
    double k_a_nm;     /* D2 (5.21) K_a, N*m (thesis 2) */
    double k_b_nm_rpm; /* D2 (5.21) K_b, N*m/(r/min) (thesis 6e-4) */
    double kp;         /* D_PI (5.20) K_P, 1/(N*m) */
    double ki;         /* D_PI (5.20) K_I, 1/(N*m*s) */
    double rms;        /* D_f: 0 = D_f (5.18), 1 = D_RMS (5.17) */
} ctrl_drr_base_cfg_t;

/* ---------------- configuration helpers (ctrl_drr_config.c, double) ---------------- */

/* (5.9) A = p Vdc psi_pm Ts / Ls and (5.10) B = 3 p w_rn psi_pm^2 Ts / (2 Ls),
 * w_rn = 2 pi n_rated / 60 * p (electrical), Ls = Ld, in N*m. CTRL_OK or
 * CTRL_EINVAL (NULL, non-finite or non-positive data). */
int ctrl_drr_ab_si(const ctrl_machine_t *m, double ts_s, double *a_nm, double *b_nm);

/* (5.5): cut-off frequency of the EMA (5.4) with factor lambda at fs, Hz
 * (NaN for lambda outside (0, 1) or fs <= 0). */
double ctrl_drr_ema_cutoff_hz(double lambda, double fs_hz);

#endif /* CONTROL_CTRL_DRR_CONFIG_H */
