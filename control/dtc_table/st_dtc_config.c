/*
 * Switching-table DTC: descriptors, tunables, defaults (Table 4.7) and the
 * SI -> fixed-point initialisation. Configuration only (may use double).
 */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "ctrl_params.h"
#include "ctrl_units.h"
#include "estimator.h"
#include "st_dtc.h"
#include "st_dtc_config.h"
#include "vreplace_config.h"

#define ST_FS_HZ 20000u                   /* Table 4.7 */
#define ST_BAND_REL 0.02                  /* h_T = 2 % T_rated, h_psi = 2 % psi_pm (Table 4.7) */
#define ST_PU_MAX 100.0                   /* bands and steps beyond 100 pu are unit mistakes */
#define ST_SIGMA_DEFAULT (CTRL_PI / 12.0) /* §4.6.2 experiments */
#define ST_SIGMA_MAX CTRL_VR_SIGMA_MAX    /* (4.19): pi/12, accepted to pi/6 */
/* f_i default: the DRR EMA's corner (thesis §5.3.2, 1/20 of the bandwidth),
 * where A (5.9) at 20 kHz is at least half the rated torque. */
#define ST_FI_HZ 50.0
#define ST_FI_A_REL 0.5

static const ctrl_tunable_t hyst_tunables[] = {
    {"h_T", "N*m",
     HELP_TEXT("torque hysteresis half band h_T (Fig. 4.2, Table 4.7: 2 % of T_rated)"),
     offsetof(st_hyst_cfg_t, h_t), 0.0, 1000.0},
    {"h_psi", "Wb",
     HELP_TEXT("flux hysteresis half band h_psi (Fig. 4.2, Table 4.7: 2 % of psi_pm)"),
     offsetof(st_hyst_cfg_t, h_psi), 0.0, 10.0},
};

static const ctrl_tunable_t fst_tunables[] = {
    {"sigma", "rad", HELP_TEXT("subsector width of the voltage replacement (4.19), 0 = off"),
     offsetof(st_fst_cfg_t, sigma), 0.0, ST_SIGMA_MAX},
    {"dT_step", "N*m",
     HELP_TEXT("step detection |dT_ref| > dT_step (sec. 4.5.3; 0 = any change, as the thesis)"),
     offsetof(st_fst_cfg_t, dt_step), 0.0, 1000.0},
    {"f_i", "Hz",
     HELP_TEXT("corner of the mean-torque-error integrator; 0 = off (thesis), default 50 Hz or 0"),
     offsetof(st_fst_cfg_t, f_i), 0.0, 1000.0},
};

static void st_hyst_cfg_default(void *cfg, const ctrl_machine_t *m)
{
    st_hyst_cfg_t *c = cfg;
    memset(c, 0, sizeof *c);
    if (m != NULL) {
        c->h_t = ST_BAND_REL * m->torque_rated_nm;
        c->h_psi = ST_BAND_REL * m->psi_pm_wb;
    }
}

double st_fst_f_i_default(const ctrl_machine_t *m)
{
    if (m == NULL || !(m->ld_h > 0.0) || !(m->current_rated_a > 0.0)) {
        return 0.0;
    }
    /* A (5.9) / T_rated = (p Vdc psi_pm Ts / Ls) / (1.5 p psi_pm i_rated) */
    const double a_rel = m->vdc_v / ((double)ST_FS_HZ * 1.5 * m->ld_h * m->current_rated_a);
    return a_rel >= ST_FI_A_REL ? ST_FI_HZ : 0.0;
}

static void st_fst_cfg_default(void *cfg, const ctrl_machine_t *m)
{
    st_fst_cfg_t *c = cfg;
    memset(c, 0, sizeof *c);
    c->sigma = ST_SIGMA_DEFAULT;
    c->dt_step = 0.0;
    c->f_i = st_fst_f_i_default(m);
}

static int st_hyst_init(void *state, const void *cfg, const ctrl_setup_t *su, st_kind_t kind)
{
    const st_hyst_cfg_t *c = cfg;
    st_hyst_state_t *s = state;
    memset(s, 0, sizeof *s);
    if (ctrl_tunables_check(hyst_tunables, sizeof hyst_tunables / sizeof hyst_tunables[0], c) !=
        CTRL_OK) {
        return CTRL_EINVAL;
    }
    q24_t h_t;
    q24_t h_psi;
    if (ctrl_setup_q24(su, "h_T / torque base", c->h_t, su->bases->torque_nm, 0.0, ST_PU_MAX,
                       &h_t) != CTRL_OK ||
        ctrl_setup_q24(su, "h_psi / flux base", c->h_psi, su->bases->psi_wb, 0.0, ST_PU_MAX,
                       &h_psi) != CTRL_OK) {
        return CTRL_ERANGE;
    }
    s->kind = (uint8_t)kind;
    ctrl_hyst2_sq_init(&s->flux, h_psi);
    ctrl_hyst3_init(&s->torque3, h_t);
    ctrl_hyst2_init(&s->torque2, h_t);
    st_hyst_reset(s);
    return CTRL_OK;
}

static int st_bst_init(void *state, const void *cfg, const ctrl_setup_t *su)
{
    return st_hyst_init(state, cfg, su, ST_KIND_BST);
}

static int st_mbst_init(void *state, const void *cfg, const ctrl_setup_t *su)
{
    return st_hyst_init(state, cfg, su, ST_KIND_MBST);
}

static int st_ast_init(void *state, const void *cfg, const ctrl_setup_t *su)
{
    return st_hyst_init(state, cfg, su, ST_KIND_AST);
}

static int st_zst_init(void *state, const void *cfg, const ctrl_setup_t *su)
{
    return st_hyst_init(state, cfg, su, ST_KIND_ZST);
}

static int st_fst_init(void *state, const void *cfg, const ctrl_setup_t *su)
{
    const st_fst_cfg_t *c = cfg;
    st_fst_state_t *s = state;
    memset(s, 0, sizeof *s);
    if (ctrl_tunables_check(fst_tunables, sizeof fst_tunables / sizeof fst_tunables[0], c) !=
        CTRL_OK) {
        return CTRL_EINVAL;
    }
    int rc = ctrl_vreplace_config(&s->vr, c->sigma);
    if (rc != CTRL_OK) {
        return rc;
    }
    if (ctrl_setup_q24(su, "dT_step / torque base", c->dt_step, su->bases->torque_nm, 0.0,
                       ST_PU_MAX, &s->logic.dt_step) != CTRL_OK) {
        return CTRL_ERANGE;
    }
    /* k_i = 2 pi f_i Ts < 1 per period (a faster integrator is no mean). */
    const double ki = 2.0 * CTRL_PI * c->f_i / (double)su->params->fs_hz;
    if (ctrl_setup_q24(su, "FST 2 pi f_i Ts", ki, 1.0, 0.0, 0.5, &s->ki) != CTRL_OK) {
        return CTRL_ERANGE;
    }
    s->g_max = su->params->torque_rated;
    st_fst_reset(s);
    return CTRL_OK;
}

#if PMSM_LIVE_PARAMS
/* Both bands while running: the comparators keep their last outputs, the
 * flux reference's memo is cleared so that the next step forms the flux
 * limits with the new band (ctrl_hyst2_sq_limits). */
static void st_hyst_retune(void *state, const void *fresh)
{
    st_hyst_state_t *s = state;
    const st_hyst_state_t *f = fresh;
    s->flux.h.band = f->flux.h.band;
    s->torque3.band = f->torque3.band;
    s->torque2.band = f->torque2.band;
    s->flux_ref.valid = 0u;
}

/* sigma, dT_step and f_i while running: the voltage replacement's table, the
 * step threshold and the integrator's gain; the logic, the last vector and
 * the integrator's torque g stay (a new gain changes g's rate, not g). */
static void st_fst_retune(void *state, const void *fresh)
{
    st_fst_state_t *s = state;
    const st_fst_state_t *f = fresh;
    s->vr = f->vr;
    s->logic.dt_step = f->logic.dt_step;
    s->ki = f->ki;
}
#endif

#define ST_HYST_DESC(id, label, initfn, est)                                                       \
    CTRL_DESC_DEFINE_LIVE(id, label, ST_FS_HZ, st_hyst_state_t, st_hyst_cfg_t, hyst_tunables,      \
                          st_hyst_cfg_default, initfn, st_hyst_reset, st_hyst_step, est, 0u,       \
                          CTRL_RETUNE(st_hyst_retune), 0x3u)

ST_HYST_DESC(bst, "ST-DTC, basic switching table (thesis Table 4.1, S1 Table 3)", st_bst_init,
             CTRL_EST_AMP_SQ_NEXT | CTRL_EST_SECTOR_NEXT);
/* MBST's speed limit at 220 V: docs/algorithms.md, "MBST". */
ST_HYST_DESC(mbst, "ST-DTC, modified basic table, sectors (4.18) (thesis Table 4.3)", st_mbst_init,
             CTRL_EST_AMP_SQ_NEXT | CTRL_EST_PSI_AB_NEXT);
ST_HYST_DESC(ast, "ST-DTC, active vectors only, two-level torque (thesis Table 4.4)", st_ast_init,
             CTRL_EST_AMP_SQ_NEXT | CTRL_EST_SECTOR_NEXT);
ST_HYST_DESC(zst, "ST-DTC, zero vector at decrease/decrease, two-level torque (Table 4.5)",
             st_zst_init, CTRL_EST_AMP_SQ_NEXT | CTRL_EST_SECTOR_NEXT);

CTRL_DESC_DEFINE_LIVE(
    fst, "ST-DTC, flexible switching table + voltage replacement (thesis sec. 4.5, Table 4.6)",
    ST_FS_HZ, st_fst_state_t, st_fst_cfg_t, fst_tunables, st_fst_cfg_default, st_fst_init,
    st_fst_reset, st_fst_step, CTRL_EST_AMP_SQ_NEXT | CTRL_EST_SECTOR_NEXT, 0u,
    CTRL_RETUNE(st_fst_retune), 0x7u);
