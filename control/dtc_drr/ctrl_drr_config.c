/*
 * DRR-DTC and its baselines: descriptors, tunables, thesis defaults (Table 5.1,
 * §5.6) and the SI -> fixed-point initialisation. Configuration only (double).
 */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "ctrl_drr.h"
#include "ctrl_drr_config.h"
#include "ctrl_params.h"
#include "ctrl_units.h"
#include "estimator.h"
#include "vreplace.h"
#include "vreplace_config.h"

#define DRR_LAMBDA_DEFAULT 0.03                    /* §5.3.2: f_c = 50 Hz at 10 kHz by (5.5) */
#define DRR_SIGMA_DEFAULT (10.0 * CTRL_PI / 180.0) /* §5.3.5, Fig. 5.9: sigma = 10 deg */
#define DRR_SIGMA_MAX CTRL_VR_SIGMA_MAX            /* (4.19): pi/12, accepted to pi/6 */
#define DRR_PU_MAX 4.0                             /* A, B/w_rn must fit the per-sample clamps */
#define DRR_RS_DT_REL 0.1 /* rs_dt default on when Rs i_rated >= 10 % of the rated back-EMF */

/* Thesis baseline parameters (Table 5.1) for the thesis SPMSM (2.4 N*m, 3000 r/min). */
#define DRR_THESIS_T_RATED 2.4
#define DRR_THESIS_N_RATED 3000.0
#define DRR_D1_CT_REL (1.2 / DRR_THESIS_T_RATED) /* C_T = 1.2 N*m = T_rated / 2 */
#define DRR_D2_KA 2.0                            /* N*m */
#define DRR_D2_KB 6e-4                           /* N*m/(r/min) */
#define DRR_PI_FI_HZ 50.0 /* D_PI integral corner (our choice, = the EMA cut-off) */

static const ctrl_tunable_t drr_tunables[] = {
    {"A", "N*m", HELP_TEXT("(5.9) AVV torque deviation at zero speed; 0 = p Vdc psi_pm Ts / Ls"),
     offsetof(ctrl_drr_cfg_t, a_nm), 0.0, 1e5},
    {"B", "N*m",
     HELP_TEXT("(5.10) ZVV torque deviation at rated speed; 0 = 3 p w_rn psi_pm^2 Ts / (2 Ls)"),
     offsetof(ctrl_drr_cfg_t, b_nm), 0.0, 1e5},
    {"C", "-", HELP_TEXT("(5.12)-(5.13) Delta T[0] / gamma (< 0); 0 = speed-dependent (5.13)"),
     offsetof(ctrl_drr_cfg_t, c), -(double)CTRL_DRR_C_MAX, 0.0},
    {"lambda", "-", HELP_TEXT("EMA smoothing factor (5.4); 0.03 = 48.5 Hz at 10 kHz by (5.5)"),
     offsetof(ctrl_drr_cfg_t, lambda), 1e-6, 0.999999},
    {"sigma", "rad",
     HELP_TEXT("subsector width (4.19) of the voltage replacement (5.3.5); 0 = off"),
     offsetof(ctrl_drr_cfg_t, sigma), 0.0, DRR_SIGMA_MAX},
    {"dpsi_max", "Wb",
     HELP_TEXT("Delta psi_max of 5.3.5 (replace while |psi_err| < half); 0 = sqrt(3) Vdc Ts/3"),
     offsetof(ctrl_drr_cfg_t, dpsi_max_wb), 0.0, 10.0},
    {"pred_516", "-", HELP_TEXT("torque prediction: 0 = estimator model (4.6)/(5.15), 1 = (5.16)"),
     offsetof(ctrl_drr_cfg_t, pred_516), 0.0, 1.0},
    {"gamma_max", "N*m",
     HELP_TEXT("EMA (5.4) holds while |error| > this + zero-vector step; 0 = A (5.9)"),
     offsetof(ctrl_drr_cfg_t, gamma_max_nm), 0.0, 1e5},
    {"centre", "-",
     HELP_TEXT("1 = centre-aligned PWM: T_e at the active-vector start (Fig. 5.4); 0 = AVV first"),
     offsetof(ctrl_drr_cfg_t, centre), 0.0, 1.0},
    {"rs_dt", "-",
     HELP_TEXT("1 = ZVV deviation with -(Rs Ts/Ls) T_e of (4.10), default if Rs i_rated >= 10 % "
               "of the back-EMF"),
     offsetof(ctrl_drr_cfg_t, rs_dt), 0.0, 1.0},
};

static const ctrl_tunable_t d1_tunables[] = {
    {"C_T", "N*m", HELP_TEXT("D1 (5.19) torque constant C_T (Table 5.1: 1.2 N*m)"),
     offsetof(ctrl_drr_base_cfg_t, c_t_nm), 1e-6, 1e5},
    {"C_psi", "Wb", HELP_TEXT("D1 (5.19) flux constant C_psi (Table 5.1: 0.09427 Wb)"),
     offsetof(ctrl_drr_base_cfg_t, c_psi_wb), 1e-6, 1e3},
};

static const ctrl_tunable_t d2_tunables[] = {
    {"K_a", "N*m", HELP_TEXT("D2 (5.21) K_a (Table 5.1: 2 N*m)"),
     offsetof(ctrl_drr_base_cfg_t, k_a_nm), 1e-6, 1e5},
    {"K_b", "N*m/(r/min)", HELP_TEXT("D2 (5.21) K_b (Table 5.1: 6e-4 N*m/(r/min))"),
     offsetof(ctrl_drr_base_cfg_t, k_b_nm_rpm), 0.0, 1e3},
};

static const ctrl_tunable_t pi_tunables[] = {
    {"K_P", "1/(N*m)", HELP_TEXT("D_PI (5.20) proportional gain"),
     offsetof(ctrl_drr_base_cfg_t, kp), 0.0, 1e3},
    {"K_I", "1/(N*m*s)", HELP_TEXT("D_PI (5.20) integral gain"), offsetof(ctrl_drr_base_cfg_t, ki),
     0.0, 1e6},
};

static const ctrl_tunable_t df_tunables[] = {
    {"rms", "-", HELP_TEXT("0 = D_f (5.18) final-error duty, 1 = D_RMS (5.17)"),
     offsetof(ctrl_drr_base_cfg_t, rms), 0.0, 1.0},
};

int ctrl_drr_ab_si(const ctrl_machine_t *m, double ts_s, double *a_nm, double *b_nm)
{
    if (m == NULL || a_nm == NULL || b_nm == NULL) {
        return CTRL_EINVAL;
    }
    const double p = (double)m->pole_pairs;
    const double ls = m->ld_h; /* Ls of the SPMSM; the d-axis value for a salient machine */
    if (!(m->pole_pairs > 0) || !(isfinite(m->vdc_v) && m->vdc_v > 0.0) ||
        !(isfinite(m->psi_pm_wb) && m->psi_pm_wb > 0.0) || !(isfinite(ls) && ls > 0.0) ||
        !(isfinite(m->speed_rated_rpm) && m->speed_rated_rpm > 0.0) ||
        !(isfinite(ts_s) && ts_s > 0.0)) {
        return CTRL_EINVAL;
    }
    const double w_rn = ctrl_rpm_to_elec(m->speed_rated_rpm, m->pole_pairs);  /* electrical */
    *a_nm = p * m->vdc_v * m->psi_pm_wb * ts_s / ls;                          /* (5.9) */
    *b_nm = 3.0 * p * w_rn * m->psi_pm_wb * m->psi_pm_wb * ts_s / (2.0 * ls); /* (5.10) */
    return CTRL_OK;
}

double ctrl_drr_ema_cutoff_hz(double lambda, double fs_hz)
{
    if (!(lambda > 0.0 && lambda < 1.0) || !(fs_hz > 0.0)) {
        return NAN;
    }
    /* (5.5) */
    return fs_hz / (2.0 * CTRL_PI) *
           acos((lambda * lambda + 2.0 * lambda - 2.0) / (2.0 * lambda - 2.0));
}

/* A per-unit value into Q24 when it lies in [lo, hi], else CTRL_ERANGE (named). */
static int drr_q24(const ctrl_setup_t *su, const char *quantity, double pu, double lo, double hi,
                   q24_t *out)
{
    return ctrl_setup_q24(su, quantity, pu, 1.0, lo, hi, out);
}

/* ---------------- drr ---------------- */

static void drr_cfg_default(void *cfg, const ctrl_machine_t *m)
{
    ctrl_drr_cfg_t *c = cfg;
    if (c == NULL) {
        return;
    }
    (void)m;
    memset(c, 0, sizeof *c);
    c->a_nm = 0.0; /* (5.9) at init */
    c->b_nm = 0.0; /* (5.10) at init */
    c->c = 0.0;    /* (5.13) per sample */
    c->lambda = DRR_LAMBDA_DEFAULT;
    c->sigma = DRR_SIGMA_DEFAULT;
    c->dpsi_max_wb = 0.0;
    c->pred_516 = 0.0;
    c->gamma_max_nm = 0.0;
    c->centre = 1.0; /* plan.h realises every plan centre-aligned */
    /* §5.3.3 neglects the load's effect on the deviations "compared to that of
     * the operating speed": at the rated point the resistive zero-vector
     * deviation (Rs Ts/Ls) T_rated over B (5.10) is Rs i_rated / (w_rn psi_pm),
     * the resistive drop over the back-EMF (thesis SPMSM 0.03). Kept when it
     * is not small (the GBM5208 gimbal motor: 0.53). */
    c->rs_dt = 0.0;
    if (m != NULL &&
        m->rs_ohm * m->current_rated_a >=
            DRR_RS_DT_REL * ctrl_rpm_to_elec(m->speed_rated_rpm, m->pole_pairs) * m->psi_pm_wb) {
        c->rs_dt = 1.0;
    }
}

static int drr_init(void *state, const void *cfg, const ctrl_setup_t *su)
{
    const ctrl_drr_cfg_t *c = cfg;
    const ctrl_params_t *p = su->params;
    const ctrl_machine_t *m = su->machine;
    const ctrl_bases_t b = *su->bases;
    ctrl_drr_state_t *s = state;
    memset(s, 0, sizeof *s);
    if (ctrl_tunables_check(drr_tunables, sizeof drr_tunables / sizeof drr_tunables[0], c) !=
        CTRL_OK) {
        return CTRL_EINVAL;
    }
    const double ts = 1.0 / (double)p->fs_hz;
    double a_nm;
    double b_nm;
    int rc = ctrl_drr_ab_si(m, ts, &a_nm, &b_nm);
    if (rc != CTRL_OK) {
        return rc;
    }
    if (c->a_nm > 0.0) {
        a_nm = c->a_nm;
    }
    if (c->b_nm > 0.0) {
        b_nm = c->b_nm;
    }
    const double w_rn_pu = ctrl_rpm_to_elec(m->speed_rated_rpm, m->pole_pairs) / b.w_rad_s;
    const double a_pu = a_nm / b.torque_nm;
    const double kb_pu = b_nm / b.torque_nm / w_rn_pu; /* B / w_rn in pu */
    rc = drr_q24(su, "DRR A (5.9)", a_pu, 1e-6, DRR_PU_MAX, &s->a);
    if (rc == CTRL_OK) {
        rc = drr_q24(su, "DRR B / w_rn (5.10)", kb_pu, 0.0, DRR_PU_MAX, &s->kb);
    }
    if (rc == CTRL_OK) {
        rc = drr_q24(su, "DRR sqrt(3) A (5.13)", CTRL_SQRT3 * a_pu, 0.0, 2.0 * DRR_PU_MAX,
                     &s->sqrt3_a);
    }
    if (rc != CTRL_OK) {
        return rc;
    }
    {
        /* per pu of PM flux, for the tracking in ctrl_drr_step (0: fixed) */
        const double psi = ctrl_q24_to_double(p->psi_pm);
        s->a_psi = c->a_nm > 0.0 ? 0 : ctrl_q24_from_double(a_pu / psi);
        s->kb_psi2 = c->b_nm > 0.0 ? 0 : ctrl_q24_from_double(kb_pu / (psi * psi));
        s->psi_seen = p->psi_pm;
    }
    if (c->c == 0.0) {
        /* (5.13) per sample: C = 2 sqrt(3) A / (2 B |w| / w_rn - sqrt(3) A) */
        s->c_num = ctrl_q24_from_double(2.0 * CTRL_SQRT3 * a_pu);
        s->dc_fixed = 0;
        s->dc_max = ctrl_q24_from_double(-2.0 * CTRL_SQRT3 * a_pu / (double)CTRL_DRR_C_MAX);
        if (s->dc_max >= 0) {
            s->dc_max = -1;
        }
    } else {
        /* fixed C (< 0): C = c_num / dc with dc = -1 */
        s->c_num = ctrl_q24_from_double(-c->c);
        s->dc_fixed = -FX_ONE;
        s->dc_max = -FX_ONE;
    }
    rc = drr_q24(su, "DRR lambda (5.4)", c->lambda, 0.0, 1.0, &s->lambda);
    if (rc == CTRL_OK && s->lambda <= 0) {
        rc = ctrl_setup_refuse(su, CTRL_ERANGE, "DRR lambda (5.4)", "", c->lambda, 1.0 / 16777216.0,
                               1.0);
    }
    if (rc != CTRL_OK) {
        return rc;
    }
    /* Delta psi_max ~ sqrt(3) Vdc Ts / 3 (from (4.13), §5.3.5) */
    const double dpsi = c->dpsi_max_wb > 0.0 ? c->dpsi_max_wb : CTRL_SQRT3 * m->vdc_v * ts / 3.0;
    rc = drr_q24(su, "DRR dpsi_max / 2", 0.5 * dpsi / b.psi_wb, 0.0, DRR_PU_MAX, &s->half_dpsi);
    if (rc == CTRL_OK) {
        /* the error band of the EMA (5.4) at zero speed: A (5.9) */
        const double g_max = c->gamma_max_nm > 0.0 ? c->gamma_max_nm : a_nm;
        rc = drr_q24(su, "DRR gamma_max", g_max / b.torque_nm, 0.0, DRR_PU_MAX, &s->gamma_max);
    }
    if (rc != CTRL_OK) {
        return rc;
    }
    rc = ctrl_vreplace_config(&s->vr, c->sigma);
    if (rc != CTRL_OK) {
        return rc;
    }
    s->pred_516 = c->pred_516 >= 0.5 ? 1u : 0u;
    s->centre = c->centre >= 0.5 ? 1u : 0u;
    /* Rs Ts / Ls with Ls = Ld as in (5.9)-(5.10); <= 1 by the core's range. */
    s->r_ts = c->rs_dt >= 0.5 ? fx_mul(p->ts_rs, p->inv_ld) : 0;
    ctrl_drr_reset(s);
    return CTRL_OK;
}

CTRL_DESC_DEFINE(drr,
                 "DRR-DTC: multiobjective duty-ratio regulation, virtual reference (thesis ch. 5, "
                 "(5.1)-(5.16))",
                 CTRL_DRR_FS_HZ, ctrl_drr_state_t, ctrl_drr_cfg_t, drr_tunables, drr_cfg_default,
                 drr_init, ctrl_drr_reset, ctrl_drr_step, CTRL_EST_AMP_NEXT | CTRL_EST_SECTOR_NEXT);

/* ---------------- baselines ---------------- */

static void base_cfg_default(void *cfg, const ctrl_machine_t *m)
{
    ctrl_drr_base_cfg_t *c = cfg;
    if (c == NULL) {
        return;
    }
    memset(c, 0, sizeof *c);
    if (m == NULL) {
        return;
    }
    /* Table 5.1 values for the thesis SPMSM; for another machine scaled by its
     * rated torque (C_T = T_rated / 2, K_a) and rated speed (K_b), C_psi = psi_pm. */
    const double t_scale = m->torque_rated_nm / DRR_THESIS_T_RATED;
    const double n_scale = m->speed_rated_rpm > 0.0 ? DRR_THESIS_N_RATED / m->speed_rated_rpm : 1.0;
    c->c_t_nm = DRR_D1_CT_REL * m->torque_rated_nm;
    c->c_psi_wb = m->psi_pm_wb;
    c->k_a_nm = DRR_D2_KA * t_scale;
    c->k_b_nm_rpm = DRR_D2_KB * t_scale * n_scale;
    /* D_PI: the thesis gives no gains. K_P = 1 / A (a torque error of A asks for a
     * full period of the active vector at zero speed, (5.9) at 10 kHz); K_I puts
     * the PI corner at 50 Hz, the EMA cut-off of the proposed method. */
    double a_nm;
    double b_nm;
    if (ctrl_drr_ab_si(m, 1.0 / (double)CTRL_DRR_FS_HZ, &a_nm, &b_nm) == CTRL_OK) {
        c->kp = 1.0 / a_nm;
        c->ki = c->kp * 2.0 * CTRL_PI * DRR_PI_FI_HZ;
    }
    c->rms = 0.0;
}

static int base_init(void *state, const void *cfg, const ctrl_setup_t *su,
                     ctrl_drr_base_kind_t kind, const ctrl_tunable_t *tun, size_t ntun)
{
    const ctrl_drr_base_cfg_t *c = cfg;
    const ctrl_params_t *p = su->params;
    const ctrl_bases_t b = *su->bases;
    ctrl_drr_base_state_t *s = state;
    memset(s, 0, sizeof *s);
    if (ctrl_tunables_check(tun, ntun, c) != CTRL_OK) {
        return CTRL_EINVAL;
    }
    int rc;
    const double lim = 127.0;
    s->kind = (uint8_t)kind;
    switch (kind) {
    case CTRL_DRR_BASE_D1:
        rc = drr_q24(su, "D1 1 / C_T", b.torque_nm / c->c_t_nm, 0.0, lim, &s->inv_ct);
        if (rc == CTRL_OK) {
            rc = drr_q24(su, "D1 1 / C_psi", b.psi_wb / c->c_psi_wb, 0.0, lim, &s->inv_cpsi);
        }
        break;
    case CTRL_DRR_BASE_D2: {
        /* K_b w with w in r/min (mechanical): w_rpm = w_pu w_base 60 / (2 pi p) */
        const double rpm_per_pu = ctrl_elec_to_rpm(b.w_rad_s, p->pole_pairs);
        rc = drr_q24(su, "D2 K_a", c->k_a_nm / b.torque_nm, 0.0, DRR_PU_MAX, &s->ka);
        if (rc == CTRL_OK) {
            rc = drr_q24(su, "D2 K_b", c->k_b_nm_rpm * rpm_per_pu / b.torque_nm, 0.0, DRR_PU_MAX,
                         &s->kb);
        }
        break;
    }
    case CTRL_DRR_BASE_PI:
        rc = drr_q24(su, "D_PI K_P", c->kp * b.torque_nm, 0.0, lim, &s->kp);
        if (rc == CTRL_OK) {
            rc = drr_q24(su, "D_PI K_I Ts", c->ki * b.torque_nm / (double)p->fs_hz, 0.0, lim,
                         &s->ki_ts);
        }
        if (rc == CTRL_OK) {
            /* 3 |w| psi_pm / (2 Vdc) in pu of w: 1.5 psi_pm / Vdc (nominal DC link) */
            rc = drr_q24(su, "D_PI feed-forward 3 psi_pm / (2 Vdc)",
                         1.5 * ctrl_q24_to_double(p->psi_pm) / ctrl_q24_to_double(p->vdc_nom), 0.0,
                         lim, &s->ff);
        }
        break;
    case CTRL_DRR_BASE_DF:
        s->rms = c->rms >= 0.5 ? 1u : 0u;
        rc = drr_q24(su, "D_f Ts / Ls", ctrl_q24_to_double(p->ts) * ctrl_q24_to_double(p->inv_ld),
                     0.0, lim, &s->ts_l);
        if (rc == CTRL_OK) {
            rc = drr_q24(su, "D_f Rs / Ls",
                         ctrl_q24_to_double(p->rs) * ctrl_q24_to_double(p->inv_ld), 0.0, lim,
                         &s->rs_l);
        }
        break;
    default:
        rc = CTRL_EINVAL;
        break;
    }
    if (rc != CTRL_OK) {
        return rc;
    }
    ctrl_drr_base_reset(s);
    return CTRL_OK;
}

static int d1_init(void *state, const void *cfg, const ctrl_setup_t *su)
{
    return base_init(state, cfg, su, CTRL_DRR_BASE_D1, d1_tunables,
                     sizeof d1_tunables / sizeof d1_tunables[0]);
}

static int d2_init(void *state, const void *cfg, const ctrl_setup_t *su)
{
    return base_init(state, cfg, su, CTRL_DRR_BASE_D2, d2_tunables,
                     sizeof d2_tunables / sizeof d2_tunables[0]);
}

static int pi_init(void *state, const void *cfg, const ctrl_setup_t *su)
{
    return base_init(state, cfg, su, CTRL_DRR_BASE_PI, pi_tunables,
                     sizeof pi_tunables / sizeof pi_tunables[0]);
}

static int df_init(void *state, const void *cfg, const ctrl_setup_t *su)
{
    return base_init(state, cfg, su, CTRL_DRR_BASE_DF, df_tunables,
                     sizeof df_tunables / sizeof df_tunables[0]);
}

#define DRR_BASE_DESC(id, label, tun, initfn, est)                                                 \
    CTRL_DESC_DEFINE(id, label, CTRL_DRR_FS_HZ, ctrl_drr_base_state_t, ctrl_drr_base_cfg_t, tun,   \
                     base_cfg_default, initfn, ctrl_drr_base_reset, ctrl_drr_base_step, est)

DRR_BASE_DESC(drr_d1, "DRR baseline D1: D = |T_err/C_T| + |psi_err/C_psi| (thesis (5.19))",
              d1_tunables, d1_init, CTRL_EST_AMP_NEXT | CTRL_EST_SECTOR_NEXT);
DRR_BASE_DESC(drr_d2, "DRR baseline D2: speed-proportional deviation K_a, K_b (thesis (5.21))",
              d2_tunables, d2_init, CTRL_EST_AMP_NEXT | CTRL_EST_SECTOR_NEXT);
DRR_BASE_DESC(drr_pi, "DRR baseline D_PI: back-EMF feed-forward + PI duty (thesis (5.20))",
              pi_tunables, pi_init, CTRL_EST_AMP_NEXT | CTRL_EST_SECTOR_NEXT);
DRR_BASE_DESC(drr_df, "DRR baseline D_f / D_RMS with (4.10) deviations (thesis (5.17)-(5.18))",
              df_tunables, df_init, CTRL_EST_AMP_NEXT | CTRL_EST_SECTOR_NEXT | CTRL_EST_SC_NEXT);
