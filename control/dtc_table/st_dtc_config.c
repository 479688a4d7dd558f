/*
 * Switching-table DTC: descriptors, tunables, defaults (Table 4.7) and the
 * SI -> fixed-point initialisation. Configuration only (may use double).
 */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "ctrl_params.h"
#include "estimator.h"
#include "st_dtc.h"
#include "st_dtc_config.h"
#include "vreplace_config.h"

#define ST_FS_HZ 20000u  /* Table 4.7 */
#define ST_BAND_REL 0.02 /* h_T = 2 % T_rated, h_psi = 2 % psi_pm (Table 4.7) */
#define ST_SIGMA_DEFAULT 0.26179938779914943653855361527329 /* pi/12, §4.6.2 experiments */
#define ST_SIGMA_MAX 0.26179938779914943653855361527329     /* (4.19) */

static const ctrl_tunable_t hyst_tunables[] = {
    {"h_T", "N*m", "torque hysteresis half band h_T (Fig. 4.2, Table 4.7: 2 % of T_rated)",
     offsetof(st_hyst_cfg_t, h_t), 0.0, 1000.0},
    {"h_psi", "Wb", "flux hysteresis half band h_psi (Fig. 4.2, Table 4.7: 2 % of psi_pm)",
     offsetof(st_hyst_cfg_t, h_psi), 0.0, 10.0},
};

static const ctrl_tunable_t fst_tunables[] = {
    {"sigma", "rad", "subsector width of the voltage replacement (4.19), 0 = off",
     offsetof(st_fst_cfg_t, sigma), 0.0, ST_SIGMA_MAX},
    {"dT_step", "N*m",
     "reference-step detection |dT_ref| > dT_step (sec. 4.5.3; 0 = any change, as the thesis)",
     offsetof(st_fst_cfg_t, dt_step), 0.0, 1000.0},
};

/* SI value of 1 pu torque and flux, the way ctrl_params_init defines them. */
static void st_machine_bases(const ctrl_machine_t *m, double *t_base, double *psi_base,
                             double *t_rated)
{
    ctrl_params_t p;
    ctrl_bases_t b;
    *t_base = 0.0;
    *psi_base = 0.0;
    *t_rated = 0.0;
    if (m == NULL || ctrl_params_init(&p, &b, m, ST_FS_HZ) != CTRL_OK) {
        return; /* init will then refuse the configuration */
    }
    *t_base = b.torque_nm;
    *psi_base = b.psi_wb;
    *t_rated = m->torque_rated_nm;
}

/* The bases in cfg must be those of the machine the params were made for. */
static int st_check_bases(double t_base, double psi_base, double t_rated, const ctrl_params_t *p)
{
    if (!isfinite(t_base) || !isfinite(psi_base) || !isfinite(t_rated) || t_base <= 0.0 ||
        psi_base <= 0.0 || t_rated <= 0.0) {
        return CTRL_EINVAL;
    }
    const double rated_pu = t_rated / t_base;
    const double got = ctrl_q24_to_double(p->torque_rated);
    if (fabs(rated_pu - got) > 1e-5 * fmax(1.0, fabs(rated_pu))) {
        return CTRL_EINVAL; /* cfg_default was called with another machine */
    }
    return CTRL_OK;
}

/* SI value / base -> Q24 pu, for a value already range-checked. */
static int st_to_q24(double si, double base, q24_t *out)
{
    const double pu = si / base;
    if (!isfinite(pu) || pu < 0.0 || pu >= 127.0) {
        return CTRL_ERANGE;
    }
    *out = ctrl_q24_from_double(pu);
    return CTRL_OK;
}

static void st_hyst_cfg_default(void *cfg, const ctrl_machine_t *m)
{
    st_hyst_cfg_t *c = cfg;
    if (c == NULL) {
        return;
    }
    memset(c, 0, sizeof *c);
    st_machine_bases(m, &c->torque_base_nm, &c->psi_base_wb, &c->torque_rated_nm);
    if (m != NULL) {
        c->h_t = ST_BAND_REL * m->torque_rated_nm;
        c->h_psi = ST_BAND_REL * m->psi_pm_wb;
    }
}

static void st_fst_cfg_default(void *cfg, const ctrl_machine_t *m)
{
    st_fst_cfg_t *c = cfg;
    if (c == NULL) {
        return;
    }
    memset(c, 0, sizeof *c);
    st_machine_bases(m, &c->torque_base_nm, &c->psi_base_wb, &c->torque_rated_nm);
    c->sigma = ST_SIGMA_DEFAULT;
    c->dt_step = 0.0;
}

static int st_hyst_init(void *state, const void *cfg, const ctrl_params_t *p, st_kind_t kind)
{
    if (state == NULL || cfg == NULL || p == NULL) {
        return CTRL_EINVAL;
    }
    const st_hyst_cfg_t *c = cfg;
    st_hyst_state_t *s = state;
    memset(s, 0, sizeof *s);
    int rc = st_check_bases(c->torque_base_nm, c->psi_base_wb, c->torque_rated_nm, p);
    if (rc != CTRL_OK) {
        return rc;
    }
    if (ctrl_tunables_check(hyst_tunables, sizeof hyst_tunables / sizeof hyst_tunables[0], c) !=
        CTRL_OK) {
        return CTRL_EINVAL;
    }
    q24_t h_t;
    q24_t h_psi;
    rc = st_to_q24(c->h_t, c->torque_base_nm, &h_t);
    if (rc == CTRL_OK) {
        rc = st_to_q24(c->h_psi, c->psi_base_wb, &h_psi);
    }
    if (rc != CTRL_OK) {
        return rc;
    }
    s->kind = (uint8_t)kind;
    ctrl_hyst2_init(&s->flux, h_psi);
    ctrl_hyst3_init(&s->torque3, h_t);
    ctrl_hyst2_init(&s->torque2, h_t);
    st_hyst_reset(s);
    return CTRL_OK;
}

static int st_bst_init(void *state, const void *cfg, const ctrl_params_t *p)
{
    return st_hyst_init(state, cfg, p, ST_KIND_BST);
}

static int st_mbst_init(void *state, const void *cfg, const ctrl_params_t *p)
{
    return st_hyst_init(state, cfg, p, ST_KIND_MBST);
}

static int st_ast_init(void *state, const void *cfg, const ctrl_params_t *p)
{
    return st_hyst_init(state, cfg, p, ST_KIND_AST);
}

static int st_zst_init(void *state, const void *cfg, const ctrl_params_t *p)
{
    return st_hyst_init(state, cfg, p, ST_KIND_ZST);
}

static int st_fst_init(void *state, const void *cfg, const ctrl_params_t *p)
{
    if (state == NULL || cfg == NULL || p == NULL) {
        return CTRL_EINVAL;
    }
    const st_fst_cfg_t *c = cfg;
    st_fst_state_t *s = state;
    memset(s, 0, sizeof *s);
    int rc = st_check_bases(c->torque_base_nm, c->psi_base_wb, c->torque_rated_nm, p);
    if (rc != CTRL_OK) {
        return rc;
    }
    if (ctrl_tunables_check(fst_tunables, sizeof fst_tunables / sizeof fst_tunables[0], c) !=
        CTRL_OK) {
        return CTRL_EINVAL;
    }
    rc = ctrl_vreplace_config(&s->vr, c->sigma);
    if (rc != CTRL_OK) {
        return rc;
    }
    rc = st_to_q24(c->dt_step, c->torque_base_nm, &s->logic.dt_step);
    if (rc != CTRL_OK) {
        return rc;
    }
    st_fst_reset(s);
    return CTRL_OK;
}

#define ST_HYST_DESC(id, label, initfn)                                                            \
    const ctrl_desc_t ctrl_desc_##id = {                                                           \
        #id,                                                                                       \
        label,                                                                                     \
        ST_FS_HZ,                                                                                  \
        sizeof(st_hyst_state_t),                                                                   \
        sizeof(st_hyst_cfg_t),                                                                     \
        hyst_tunables,                                                                             \
        sizeof hyst_tunables / sizeof hyst_tunables[0],                                            \
        st_hyst_cfg_default,                                                                       \
        initfn,                                                                                    \
        st_hyst_reset,                                                                             \
        st_hyst_step,                                                                              \
        CTRL_EST_SECTOR_NOW,                                                                       \
    }

ST_HYST_DESC(bst, "ST-DTC, basic switching table (thesis Table 4.1, S1 Table 3)", st_bst_init);
/* MBST cannot hold the thesis SPMSM above about 1830 r/min at 220 V (an
 * average-voltage limit of Table 4.3 with (4.18)): see ST_KIND_MBST in st_dtc.c. */
ST_HYST_DESC(mbst, "ST-DTC, modified basic table, sectors (4.18) (thesis Table 4.3)", st_mbst_init);
ST_HYST_DESC(ast, "ST-DTC, active vectors only, two-level torque (thesis Table 4.4)", st_ast_init);
ST_HYST_DESC(zst, "ST-DTC, zero vector at decrease/decrease, two-level torque (Table 4.5)",
             st_zst_init);

const ctrl_desc_t ctrl_desc_fst = {
    "fst",
    "ST-DTC, flexible switching table + voltage replacement (thesis sec. 4.5, Table 4.6)",
    ST_FS_HZ,
    sizeof(st_fst_state_t),
    sizeof(st_fst_cfg_t),
    fst_tunables,
    sizeof fst_tunables / sizeof fst_tunables[0],
    st_fst_cfg_default,
    st_fst_init,
    st_fst_reset,
    st_fst_step,
    CTRL_EST_SECTOR_NOW,
};
