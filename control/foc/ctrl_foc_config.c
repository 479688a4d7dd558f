/*
 * FOC (S1 §2, Algorithm 1) and its hysteresis-current variant: descriptors,
 * tunables, defaults, SI -> fixed-point initialisation and the current
 * reference table (MTPA locus). Configuration only (may use double).
 */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "ctrl_foc.h"
#include "ctrl_foc_config.h"
#include "ctrl_params.h"
#include "estimator.h"

#define FOC_FS_HZ 10000u   /* S1 §2: Ts = 100 us */
#define FOC_WC_PER_FS 20.0 /* default wc = 2 pi fs / 20 */
#define FOC_HI_REL 0.05    /* default foc_hyst band: 5 % of the rated current */
#define FOC_PI 3.14159265358979323846

static const ctrl_tunable_t foc_tunables[] = {
    {"wc", "rad/s", "current-loop bandwidth for Kp = L wc, Ki = R wc; 0 = 2 pi fs/20",
     offsetof(ctrl_foc_cfg_t, wc), 0.0, 1.0e6},
    {"Kp_d", "V/A", "d-current PI proportional gain; 0 = Ld wc", offsetof(ctrl_foc_cfg_t, kp_d),
     0.0, 1.0e5},
    {"Ki_d", "V/(A*s)", "d-current PI integral gain; 0 = Rs wc", offsetof(ctrl_foc_cfg_t, ki_d),
     0.0, 1.0e8},
    {"Kp_q", "V/A", "q-current PI proportional gain; 0 = Lq wc", offsetof(ctrl_foc_cfg_t, kp_q),
     0.0, 1.0e5},
    {"Ki_q", "V/(A*s)", "q-current PI integral gain; 0 = Rs wc", offsetof(ctrl_foc_cfg_t, ki_q),
     0.0, 1.0e8},
    {"mtpa", "-", "1: i_d from the MTPA locus (IPMSM); 0: i_d = 0 (S1 Algorithm 1)",
     offsetof(ctrl_foc_cfg_t, mtpa), 0.0, 1.0},
};

static const ctrl_tunable_t foc_hyst_tunables[] = {
    {"h_i", "A", "phase-current hysteresis half band (S1 sec. 2 current-controlled inverter)",
     offsetof(ctrl_foc_cfg_t, h_i), 0.0, 1.0e4},
    {"mtpa", "-", "1: i_d from the MTPA locus (IPMSM); 0: i_d = 0 (S1 Algorithm 1)",
     offsetof(ctrl_foc_cfg_t, mtpa), 0.0, 1.0},
};

static void foc_cfg_default(void *cfg, const ctrl_machine_t *m)
{
    ctrl_foc_cfg_t *c = cfg;
    if (c == NULL) {
        return;
    }
    memset(c, 0, sizeof *c);
    c->mtpa = 1.0;
    ctrl_params_t p;
    ctrl_bases_t b;
    if (m == NULL || ctrl_params_init(&p, &b, m, FOC_FS_HZ) != CTRL_OK) {
        return; /* bases 0: init refuses the configuration */
    }
    c->r_base_ohm = b.r_ohm;
    c->i_base_a = b.i_a;
    c->rs_ohm = m->rs_ohm;
    c->h_i = FOC_HI_REL * m->current_rated_a;
}

/* MTPA point at current amplitude i (pu, psi_pm = 1): i_d, i_q and torque. */
static void foc_mtpa_point(double ld, double lq, double i, double *id, double *iq, double *te)
{
    const double dl = lq - ld; /* > 0 for an IPMSM */
    *id = (1.0 - sqrt(1.0 + 8.0 * dl * dl * i * i)) / (4.0 * dl);
    *iq = sqrt(fmax(i * i - *id * *id, 0.0));
    *te = *iq * (1.0 + (ld - lq) * *id);
}

/* Torque -> (i_d, i_q) table over [0, T(current_max)]. */
static int foc_iref_table(ctrl_foc_iref_t *r, const ctrl_params_t *p, int mtpa)
{
    const double ld = ctrl_q24_to_double(p->ld);
    const double lq = ctrl_q24_to_double(p->lq);
    const double imax = ctrl_q24_to_double(p->current_max);
    if (!(imax > 0.0) || !(ld > 0.0) || !(lq > 0.0)) {
        return CTRL_EINVAL;
    }
    const int salient_mtpa = mtpa && p->salient && lq > ld;
    double t_max = imax; /* i_d = 0: T = i_q (psi_pm = 1 pu) */
    if (salient_mtpa) {
        double id;
        double iq;
        foc_mtpa_point(ld, lq, imax, &id, &iq, &t_max);
    }
    const double scale = (double)CTRL_FOC_MTPA_N / t_max;
    if (!(t_max > 0.0) || t_max >= 127.0 || scale * 65536.0 >= 2147483647.0) {
        return CTRL_ERANGE;
    }
    for (int k = 0; k <= CTRL_FOC_MTPA_N; k++) {
        const double tk = t_max * k / CTRL_FOC_MTPA_N;
        double id = 0.0;
        double iq = tk;
        if (salient_mtpa) {
            double lo = 0.0;
            double hi = imax;
            for (int it = 0; it < 60; it++) { /* torque increases with |i| on the locus */
                const double mid = 0.5 * (lo + hi);
                double te;
                foc_mtpa_point(ld, lq, mid, &id, &iq, &te);
                if (te < tk) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            double te;
            foc_mtpa_point(ld, lq, 0.5 * (lo + hi), &id, &iq, &te);
        }
        r->id_tab[k] = ctrl_q24_from_double(id);
        r->iq_tab[k] = ctrl_q24_from_double(iq);
    }
    r->t_max = ctrl_q24_from_double(t_max);
    r->scale = (int32_t)llround(scale * 65536.0);
    return CTRL_OK;
}

static int foc_pi_config(ctrl_foc_pi_t *pi, double kp_si, double ki_si, double l_pu, double wc,
                         const ctrl_foc_cfg_t *c, const ctrl_params_t *p)
{
    const double fs = (double)p->fs_hz;
    const double ts_pu = ctrl_q24_to_double(p->ts);
    const double r_pu = ctrl_q24_to_double(p->rs);
    /* Kp = L wc (pu: L_pu * wc / w_base, w_base = ts_pu * fs); Ki Ts = R wc Ts. */
    const double kp = kp_si > 0.0 ? kp_si / c->r_base_ohm : l_pu * (wc / fs) / ts_pu;
    const double ki_ts = ki_si > 0.0 ? ki_si / c->r_base_ohm / fs : r_pu * wc / fs;
    if (!isfinite(kp) || !isfinite(ki_ts) || kp >= 127.0 || ki_ts >= 1.99) {
        return CTRL_ERANGE;
    }
    pi->kp = ctrl_q24_from_double(kp);
    pi->ki_ts = (int32_t)llround(ki_ts * 1073741824.0);
    pi->integ = 0;
    return CTRL_OK;
}

static int foc_init_common(void *state, const void *cfg, const ctrl_params_t *p, int hyst)
{
    if (state == NULL || cfg == NULL || p == NULL) {
        return CTRL_EINVAL;
    }
    const ctrl_foc_cfg_t *c = cfg;
    ctrl_foc_state_t *s = state;
    memset(s, 0, sizeof *s);
    if (ctrl_tunables_check(foc_tunables, sizeof foc_tunables / sizeof foc_tunables[0], c) !=
            CTRL_OK ||
        ctrl_tunables_check(foc_hyst_tunables,
                            sizeof foc_hyst_tunables / sizeof foc_hyst_tunables[0], c) != CTRL_OK) {
        return CTRL_EINVAL;
    }
    if (!(c->r_base_ohm > 0.0) || !(c->i_base_a > 0.0) || !isfinite(c->r_base_ohm) ||
        !isfinite(c->i_base_a) || p->fs_hz == 0u) {
        return CTRL_EINVAL;
    }
    /* cfg_default must have been called with the machine of these params. */
    const double rs_pu = c->rs_ohm / c->r_base_ohm;
    if (fabs(rs_pu - ctrl_q24_to_double(p->rs)) > 1e-5 * fmax(1.0, rs_pu)) {
        return CTRL_EINVAL;
    }
    const double fs = (double)p->fs_hz;
    const double wc = c->wc > 0.0 ? c->wc : 2.0 * FOC_PI * fs / FOC_WC_PER_FS;
    if (wc / fs > 1.5) {
        return CTRL_EINVAL; /* discrete loop gain wc Ts beyond the stable range */
    }
    int rc = foc_iref_table(&s->iref, p, c->mtpa >= 0.5);
    if (rc == CTRL_OK) {
        rc = foc_pi_config(&s->pi_d, c->kp_d, c->ki_d, ctrl_q24_to_double(p->ld), wc, c, p);
    }
    if (rc == CTRL_OK) {
        rc = foc_pi_config(&s->pi_q, c->kp_q, c->ki_q, ctrl_q24_to_double(p->lq), wc, c, p);
    }
    const double h = c->h_i / c->i_base_a;
    if (rc == CTRL_OK && (!isfinite(h) || h >= 127.0)) {
        rc = CTRL_ERANGE;
    }
    if (rc != CTRL_OK) {
        memset(s, 0, sizeof *s);
        return rc;
    }
    s->h_i = ctrl_q24_from_double(h);
    s->hyst = (uint8_t)(hyst != 0);
    ctrl_foc_reset(s);
    return CTRL_OK;
}

static int foc_init(void *state, const void *cfg, const ctrl_params_t *p)
{
    return foc_init_common(state, cfg, p, 0);
}

static int foc_hyst_init(void *state, const void *cfg, const ctrl_params_t *p)
{
    return foc_init_common(state, cfg, p, 1);
}

const ctrl_desc_t ctrl_desc_foc = {
    "foc",
    "FOC, rotor-field oriented, dq current PI + SVPWM, MTPA/i_d=0 (S1 sec. 2, Algorithm 1)",
    FOC_FS_HZ,
    sizeof(ctrl_foc_state_t),
    sizeof(ctrl_foc_cfg_t),
    foc_tunables,
    sizeof foc_tunables / sizeof foc_tunables[0],
    foc_cfg_default,
    foc_init,
    ctrl_foc_reset,
    ctrl_foc_step,
    CTRL_EST_AMP_NEXT | CTRL_EST_SECTOR_NOW, /* FOC reads currents, not |psi| or sectors */
};

const ctrl_desc_t ctrl_desc_foc_hyst = {
    "foc_hyst",
    "FOC with per-phase hysteresis current control, one vector per period (S1 sec. 2)",
    FOC_FS_HZ,
    sizeof(ctrl_foc_state_t),
    sizeof(ctrl_foc_cfg_t),
    foc_hyst_tunables,
    sizeof foc_hyst_tunables / sizeof foc_hyst_tunables[0],
    foc_cfg_default,
    foc_hyst_init,
    ctrl_foc_reset,
    ctrl_foc_step,
    CTRL_EST_AMP_NEXT | CTRL_EST_SECTOR_NOW, /* FOC reads currents, not |psi| or sectors */
};
