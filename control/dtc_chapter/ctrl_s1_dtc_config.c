/*
 * Book-chapter DTC controllers (hdtc, svm_dtc, hpdtc): descriptors, tunables,
 * defaults, SI -> fixed-point initialisation and the HP-DTC timing-table
 * generator. Configuration only (may use double). Design: ctrl_s1_dtc.h.
 */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "ctrl_cfg_math.h"
#include "ctrl_params.h"
#include "ctrl_s1_dtc.h"
#include "ctrl_s1_dtc_config.h"
#include "ctrl_units.h"
#include "estimator.h"

#define S1_FS_HZ 10000u /* S1: Ts = 100 us */
#define S1_BAND 0.01    /* S1 §3.3, §6.1.4: +-0.01 (N*m and Wb) */
#define S1_KP 1.0       /* S1 §4.1 predictive controller */
#define S1_KI 0.03
#define S1_TILT_DEFAULT (CTRL_PI / 30.0) /* 6 deg: half a section */

static const ctrl_tunable_t hdtc_tunables[] = {
    {"h_T", "N*m", HELP_TEXT("torque hysteresis half band (S1 sec. 3.3: +-0.01)"),
     offsetof(ctrl_s1_cfg_t, h_t), 0.0, 1000.0},
    {"h_psi", "Wb", HELP_TEXT("flux hysteresis half band (S1 sec. 3.3: +-0.01)"),
     offsetof(ctrl_s1_cfg_t, h_psi), 0.0, 10.0},
    {"psi_ref", "Wb", HELP_TEXT("flux reference; 0 = psi_pm (S1 sec. 4, sec. 6.1.4)"),
     offsetof(ctrl_s1_cfg_t, psi_ref), 0.0, 100.0},
};

static const ctrl_tunable_t svm_tunables[] = {
    {"Kp", "rad/pu",
     HELP_TEXT("predictive-controller PI, Delta delta per pu torque error (S1 sec. 4.1: 1)"),
     offsetof(ctrl_s1_cfg_t, kp), 0.0, 100.0},
    {"Ki", "rad/(pu*sample)", HELP_TEXT("integral gain per sample (S1 sec. 4.1: 0.03)"),
     offsetof(ctrl_s1_cfg_t, ki), 0.0, 10.0},
    {"omega_ff", "-", HELP_TEXT("1: add the rotor advance omega_e Ts to Delta delta"),
     offsetof(ctrl_s1_cfg_t, omega_ff), 0.0, 1.0},
    {"psi_ref", "Wb", HELP_TEXT("flux reference; 0 = psi_pm (S1 sec. 4)"),
     offsetof(ctrl_s1_cfg_t, psi_ref), 0.0, 100.0},
};

static const ctrl_tunable_t hpdtc_tunables[] = {
    {"h_T", "N*m", HELP_TEXT("torque two-level hysteresis half band (tau of S1 Table 4)"),
     offsetof(ctrl_s1_cfg_t, h_t), 0.0, 1000.0},
    {"h_psi", "Wb", HELP_TEXT("flux two-level hysteresis half band (phi of S1 Table 4)"),
     offsetof(ctrl_s1_cfg_t, h_psi), 0.0, 10.0},
    {"psi_ref", "Wb", HELP_TEXT("flux reference; 0 = psi_pm"), offsetof(ctrl_s1_cfg_t, psi_ref),
     0.0, 100.0},
    {"e_fs", "N*m",
     HELP_TEXT("|T_err| of the full voltage level (5 levels of e_fs/5); 0 = Ts Lq-based, see "
               "ctrl_s1_dtc.h"),
     offsetof(ctrl_s1_cfg_t, e_fs), 0.0, 1000.0},
    {"tilt", "rad", HELP_TEXT("timing-table reference tilted from the flux tangent towards V_k1"),
     offsetof(ctrl_s1_cfg_t, tilt), 0.0, CTRL_PI / 6.0},
};

static void s1_cfg_default(void *cfg, const ctrl_machine_t *m)
{
    (void)m;
    ctrl_s1_cfg_t *c = cfg;
    memset(c, 0, sizeof *c);
    c->h_t = S1_BAND;
    c->h_psi = S1_BAND;
    c->psi_ref = 0.0;
    c->kp = S1_KP;
    c->ki = S1_KI;
    c->omega_ff = 1.0;
    c->tilt = S1_TILT_DEFAULT;
}

/* SI / base -> Q24 pu in [0, 127) (named refusal). */
static int s1_q24(const ctrl_setup_t *su, const char *quantity, double si, double base, q24_t *out)
{
    return ctrl_setup_q24(su, quantity, si, base, 0.0, 127.0, out);
}

/* Flux reference: tunable, else params->psi_ref, else psi_pm. */
static int s1_psi_ref(const ctrl_s1_cfg_t *c, const ctrl_setup_t *su, q24_t *out)
{
    if (c->psi_ref > 0.0) {
        return s1_q24(su, "psi_ref / flux base", c->psi_ref, su->bases->psi_wb, out);
    }
    const ctrl_params_t *p = su->params;
    *out = p->psi_ref > 0 ? p->psi_ref : p->psi_pm;
    return *out > 0 ? CTRL_OK : CTRL_EINVAL;
}

/* The hysteresis half bands h_T, h_psi in Q24 pu (hdtc and hpdtc share them,
 * S1 §3.3). */
static int s1_bands(const ctrl_s1_cfg_t *c, const ctrl_setup_t *su, q24_t *ht, q24_t *hp)
{
    int rc = s1_q24(su, "h_T / torque base", c->h_t, su->bases->torque_nm, ht);
    if (rc == CTRL_OK) {
        rc = s1_q24(su, "h_psi / flux base", c->h_psi, su->bases->psi_wb, hp);
    }
    return rc;
}

static int hdtc_init(void *state, const void *cfg, const ctrl_setup_t *su)
{
    const ctrl_s1_cfg_t *c = cfg;
    ctrl_hdtc_state_t *s = state;
    memset(s, 0, sizeof *s);
    if (ctrl_tunables_check(hdtc_tunables, sizeof hdtc_tunables / sizeof hdtc_tunables[0], c) !=
        CTRL_OK) {
        return CTRL_EINVAL;
    }
    q24_t ht;
    q24_t hp;
    int rc = s1_bands(c, su, &ht, &hp);
    if (rc == CTRL_OK) {
        rc = s1_psi_ref(c, su, &s->psi_ref);
    }
    if (rc != CTRL_OK) {
        memset(s, 0, sizeof *s);
        return rc;
    }
    ctrl_hyst2_sq_init(&s->flux, hp); /* limits for 0: formed at the first step */
    s->flux_lim_ref = 0;
    ctrl_hyst3_init(&s->torque, ht);
    ctrl_hdtc_reset(s);
    return CTRL_OK;
}

static int svm_dtc_init(void *state, const void *cfg, const ctrl_setup_t *su)
{
    const ctrl_params_t *p = su->params;
    const ctrl_s1_cfg_t *c = cfg;
    ctrl_svm_dtc_state_t *s = state;
    memset(s, 0, sizeof *s);
    if (ctrl_tunables_check(svm_tunables, sizeof svm_tunables / sizeof svm_tunables[0], c) !=
        CTRL_OK) {
        return CTRL_EINVAL;
    }
    int rc = s1_psi_ref(c, su, &s->psi_ref);
    const double ts = ctrl_q24_to_double(p->ts);
    if (rc == CTRL_OK && (!(ts > 0.0) || 1.0 / ts >= 32767.0)) {
        rc = CTRL_ERANGE; /* 1/Ts does not fit Q16 */
    }
    if (rc != CTRL_OK) {
        memset(s, 0, sizeof *s);
        return rc;
    }
    s->kp = ctrl_q24_from_double(c->kp);
    s->ki = (int32_t)ctrl_cfg_llround(c->ki * 1073741824.0); /* Q30, ki <= 10 < 2: checked below */
    if (c->ki >= 1.99) {
        memset(s, 0, sizeof *s);
        return CTRL_ERANGE;
    }
    s->inv_ts = (int32_t)ctrl_cfg_llround(65536.0 / ts);
    s->ff = (uint8_t)(c->omega_ff >= 0.5);
    ctrl_svm_dtc_reset(s);
    return CTRL_OK;
}

int ctrl_hpdtc_timing_table(double tilt, uint8_t pts[HPDTC_LEVELS][HPDTC_SECTIONS][2])
{
    if (pts == NULL || !isfinite(tilt) || tilt < 0.0 || tilt > CTRL_PI / 6.0) {
        return CTRL_EINVAL;
    }
    const double deg = CTRL_PI / 180.0;
    for (int l = 0; l < HPDTC_LEVELS; l++) {
        /* Amplitude m of the inscribed circle Vdc/sqrt(3) = (sqrt(3)/2) |V_k|. */
        const double m = (double)(l + 1) / HPDTC_LEVELS;
        for (int j = 0; j < HPDTC_SECTIONS; j++) {
            /* Section centre rho (seen from V_k1) and the angle of the flux
             * tangent from V_k1 towards V_k2: 30 deg + rho, tilted to V_k1. */
            const double rho = (j - 2) * 12.0 * deg;
            double a = 30.0 * deg + rho - tilt;
            a = a < 0.0 ? 0.0 : (a > 60.0 * deg ? 60.0 * deg : a);
            /* SVM dwell times: v = t1 V_k1 + t2 V_k2 (Ts = 1) gives
             * t1 = |v| sin(60 - a) / (|V_k| sin 60) = m sin(60 - a), t2 = m sin(a). */
            long long p1 = ctrl_cfg_llround(HPDTC_POINTS * m * ctrl_cfg_sin(60.0 * deg - a));
            long long p2 = ctrl_cfg_llround(HPDTC_POINTS * m * ctrl_cfg_sin(a));
            while (p1 + p2 > HPDTC_POINTS) { /* rounding only: never beyond the hexagon */
                if (p1 >= p2) {
                    p1--;
                } else {
                    p2--;
                }
            }
            pts[l][j][0] = (uint8_t)p1;
            pts[l][j][1] = (uint8_t)p2;
        }
    }
    return CTRL_OK;
}

static int hpdtc_init(void *state, const void *cfg, const ctrl_setup_t *su)
{
    const ctrl_params_t *p = su->params;
    const ctrl_s1_cfg_t *c = cfg;
    ctrl_hpdtc_state_t *s = state;
    memset(s, 0, sizeof *s);
    if (ctrl_tunables_check(hpdtc_tunables, sizeof hpdtc_tunables / sizeof hpdtc_tunables[0], c) !=
        CTRL_OK) {
        return CTRL_EINVAL;
    }
    q24_t ht;
    q24_t hp;
    q24_t efs = 0;
    int rc = s1_bands(c, su, &ht, &hp);
    if (rc == CTRL_OK && c->e_fs > 0.0) {
        rc = s1_q24(su, "e_fs / torque base", c->e_fs, su->bases->torque_nm, &efs);
    } else if (rc == CTRL_OK) {
        /* One level step (0.2 Vdc/sqrt(3)) turns the flux by 0.2 Ts Vdc/(sqrt(3) psi_pm)
         * per period; at delta = 0 dT/d delta = psi_pm^2 / Lq (pu, from S1(7)), so
         * the torque moves by 0.2 Ts Vdc psi_pm / (sqrt(3) Lq) pu per period and
         * level step. e_fs = 5 x that: one level step corrects one level's error
         * width in one period (loop gain 1 of the level quantiser). */
        const double e = ctrl_q24_to_double(p->ts) * ctrl_q24_to_double(p->vdc_nom) *
                         ctrl_q24_to_double(p->psi_pm) / (CTRL_SQRT3 * ctrl_q24_to_double(p->lq));
        rc = (isfinite(e) && e > 0.0 && e < 127.0) ? CTRL_OK : CTRL_ERANGE;
        efs = ctrl_q24_from_double(rc == CTRL_OK ? e : 0.0);
    }
    if (rc == CTRL_OK && efs <= 0) {
        rc = CTRL_ERANGE; /* e_fs below the Q24 resolution */
    }
    if (rc == CTRL_OK) {
        rc = s1_psi_ref(c, su, &s->psi_ref);
    }
    if (rc == CTRL_OK) {
        rc = ctrl_hpdtc_timing_table(c->tilt, s->pts);
    }
    if (rc != CTRL_OK) {
        memset(s, 0, sizeof *s);
        return rc;
    }
    for (int i = 0; i < HPDTC_LEVELS - 1; i++) {
        s->lvl_thr[i] = ctrl_q24_from_double(ctrl_q24_to_double(efs) * (i + 1) / HPDTC_LEVELS);
    }
    for (int l = 0; l < HPDTC_LEVELS; l++) {
        for (int j = 0; j < HPDTC_SECTIONS; j++) {
            for (int k = 0; k < 2; k++) {
                const int64_t num = (int64_t)s->pts[l][j][k] * FX_ONE;
                s->dur[l][j][k] = (q24_t)((num + HPDTC_POINTS / 2) / HPDTC_POINTS);
            }
        }
    }
    ctrl_hyst2_sq_init(&s->flux, hp); /* limits for 0: formed at the first step */
    s->flux_lim_ref = 0;
    ctrl_hyst2_init(&s->torque, ht);
    ctrl_hpdtc_reset(s);
    return CTRL_OK;
}

#define S1_DESC(id, label, st, tun, initfn, resetfn, stepfn, est)                                  \
    CTRL_DESC_DEFINE(id, label, S1_FS_HZ, st, ctrl_s1_cfg_t, tun, s1_cfg_default, initfn, resetfn, \
                     stepfn, est)

S1_DESC(hdtc, "HDTC, hysteresis DTC, S1 Table 3 on the sampled errors (S1 sec. 3)",
        ctrl_hdtc_state_t, hdtc_tunables, hdtc_init, ctrl_hdtc_reset, ctrl_hdtc_step,
        CTRL_EST_SECTOR_NOW);
S1_DESC(hdtc_pred, "HDTC on the k+1 prediction (S1 Table 3, delay-compensated)", ctrl_hdtc_state_t,
        hdtc_tunables, hdtc_init, ctrl_hdtc_reset, ctrl_hdtc_pred_step,
        CTRL_EST_AMP_SQ_NEXT | CTRL_EST_SECTOR_NEXT);
S1_DESC(svm_dtc, "SVM-DTC with the predictive controller (S1 sec. 4, S1(17)-(20))",
        ctrl_svm_dtc_state_t, svm_tunables, svm_dtc_init, ctrl_svm_dtc_reset, ctrl_svm_dtc_step,
        CTRL_EST_AMP_NEXT | CTRL_EST_PSI_AB_NEXT | CTRL_EST_I_AB_NEXT);
S1_DESC(hpdtc, "HP-DTC, two adjacent vectors + 20-point timing table (S1 sec. 5, Table 4)",
        ctrl_hpdtc_state_t, hpdtc_tunables, hpdtc_init, ctrl_hpdtc_reset, ctrl_hpdtc_step,
        CTRL_EST_AMP_SQ_NEXT | CTRL_EST_SECTOR_NEXT);
