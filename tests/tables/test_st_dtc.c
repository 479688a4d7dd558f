/*
 * The bst/mbst/ast/zst/fst controllers through their descriptors
 * (control/st_dtc.h): registry entries, defaults of Table 4.7, checked
 * configuration, the decision for every sector and regulator state on the
 * predicted state est->next (delay compensation), the flux reference, the
 * one-leg zero-vector rule, and the FST operating-state logic of §4.5.3.
 * Expected vectors come from the hand-written thesis tables (thesis_tables.h).
 */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "../plant/ini_machines.h"
#include "controller.h"
#include "ctrl_params.h"
#include "ctrl_units.h"
#include "mtpa.h"
#include "st_dtc.h"
#include "st_dtc_config.h"
#include "thesis_tables.h"
#include "unity.h"
#include "vectors.h"

void setUp(void)
{
}
void tearDown(void)
{
}

static const ctrl_machine_t SPMSM = {
    "thesis SPMSM", 4,   0.901,  6.552e-3, 6.552e-3, 0.09427, 220.0,
    1.2e-4,         2.4, 3000.0, 4.2,      8.4,      0.0,
};

typedef struct {
    ctrl_params_t params;
    ctrl_bases_t bases;
    ctrl_estimate_t est;
    ctrl_refs_t ref;
    ctrl_setup_t su;
    ctrl_plan_t applied;
    ctrl_ctx_t ctx;
    _Alignas(8) unsigned char state[CTRL_STATE_MAX];
    _Alignas(8) unsigned char cfg[CTRL_CFG_MAX];
    const ctrl_desc_t *d;
} rig_t;

static rig_t R;

static q24_t q24(double v)
{
    return (q24_t)lround(v * 16777216.0);
}

static void rig_open(const char *name)
{
    memset(&R, 0, sizeof R);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&R.params, &R.bases, &SPMSM, 20000u));
    R.d = ctrl_find(name);
    TEST_ASSERT_NOT_NULL(R.d);
    R.d->cfg_default(R.cfg, &SPMSM);
    R.su = (ctrl_setup_t){&SPMSM, &R.bases, &R.params};
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_init(R.d, R.state, R.cfg, &R.su));
    R.d->reset(R.state);
    R.ctx.params = &R.params;
    R.ctx.est = &R.est;
    R.ctx.ref = &R.ref;
}

/* Predicted state at k+1: flux |psi| = amp at angle theta, torque te (pu). The
 * state "now" is set far away on purpose: decisions must use est.next. */
static void set_next(double theta, double amp, double te, double omega)
{
    R.est.next.psi_alpha = q24(amp * cos(theta));
    R.est.next.psi_beta = q24(amp * sin(theta));
    R.est.next.psi_amp = q24(amp);
    R.est.next.psi_amp_sq = (uint64_t)((int64_t)R.est.next.psi_amp * R.est.next.psi_amp);
    R.est.next.torque = q24(te);
    R.est.now.psi_alpha = q24(-amp * cos(theta));
    R.est.now.psi_beta = q24(-amp * sin(theta));
    R.est.now.psi_amp = q24(3.0 * amp);
    R.est.now.torque = q24(-te);
    R.est.omega_e = q24(omega);
    R.est.vdc = FX_ONE;
    /* The sector at k+1 (4.5), as the estimator hands it over. */
    R.est.next.sector = ctrl_sector(R.est.next.psi_alpha, R.est.next.psi_beta);
    R.est.now.sector = ctrl_sector(R.est.now.psi_alpha, R.est.now.psi_beta);
}

static uint8_t g_prev; /* vector of the period before the last step() */

static uint8_t step(void)
{
    ctrl_out_t out;
    g_prev = R.applied.vec[0];
    memset(&out, 0xA5, sizeof out);
    R.d->step(R.state, &R.ctx, &out);
    TEST_ASSERT_EQUAL_UINT8(1, out.plan.n_seg); /* one vector for the whole period */
    TEST_ASSERT_EQUAL_INT32(FX_ONE, out.plan.dur[0]);
    TEST_ASSERT_TRUE(out.plan.vec[0] <= 7u);
    R.applied = out.plan;
    return out.plan.vec[0];
}

static int legs_changed(uint8_t a, uint8_t b)
{
    return (LEGS[a][0] != LEGS[b][0]) + (LEGS[a][1] != LEGS[b][1]) + (LEGS[a][2] != LEGS[b][2]);
}

/* ---------------------------------------------------------------- registry */

static void test_registry_and_defaults(void)
{
    static const char *const names[5] = {"bst", "mbst", "ast", "zst", "fst"};
    ctrl_params_t p;
    ctrl_bases_t b;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&p, &b, &SPMSM, 20000u));
    for (int i = 0; i < 5; i++) {
        const ctrl_desc_t *d = ctrl_find(names[i]);
        TEST_ASSERT_NOT_NULL(d);
        TEST_ASSERT_EQUAL_STRING(names[i], d->name);
        TEST_ASSERT_EQUAL_UINT32(20000u, d->fs_default_hz); /* Table 4.7 */
        TEST_ASSERT_TRUE(d->state_size <= CTRL_STATE_MAX);
        TEST_ASSERT_TRUE(d->cfg_size <= CTRL_CFG_MAX);
        TEST_ASSERT_TRUE(d->n_tunables >= 2u);
        _Alignas(8) unsigned char cfg[CTRL_CFG_MAX];
        d->cfg_default(cfg, &SPMSM);
        for (size_t k = 0; k < d->n_tunables; k++) {
            const ctrl_tunable_t *t = &d->tunables[k];
            double v;
            memcpy(&v, cfg + t->offset, sizeof v);
            TEST_ASSERT_TRUE(v >= t->min && v <= t->max); /* default inside its range */
            if (strcmp(t->name, "h_T") == 0) {
                TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.02 * 2.4, v); /* 2 % T_rated */
            } else if (strcmp(t->name, "h_psi") == 0) {
                TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.02 * 0.09427, v); /* 2 % psi_pm */
            } else if (strcmp(t->name, "sigma") == 0) {
                TEST_ASSERT_DOUBLE_WITHIN(1e-12, CTRL_PI / 12.0, v);     /* §4.6.2 */
                TEST_ASSERT_DOUBLE_WITHIN(1e-12, CTRL_PI / 6.0, t->max); /* half sector */
            } else if (strcmp(t->name, "dT_step") == 0) {
                TEST_ASSERT_DOUBLE_WITHIN(0.0, 0.0, v); /* Delta T_ref != 0 */
            } else if (strcmp(t->name, "f_i") == 0) {
                TEST_ASSERT_DOUBLE_WITHIN(0.0, 0.0, v); /* the thesis' FST on its machine */
            } else {
                TEST_FAIL_MESSAGE("unexpected tunable");
            }
        }
        _Alignas(8) unsigned char st[CTRL_STATE_MAX];
        const ctrl_setup_t su = {&SPMSM, &b, &p};
        TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_init(d, st, cfg, &su));
        /* bad configuration is refused, never a crash */
        const ctrl_setup_t no_bases = {&SPMSM, NULL, &p};
        TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_init(d, NULL, cfg, &su));
        TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_init(d, st, NULL, &su));
        TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_init(d, st, cfg, NULL));
        TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_init(d, st, cfg, &no_bases));
        TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_init(NULL, st, cfg, &su));
        const double bad = d->tunables[0].max * 2.0 + 1.0;
        memcpy(cfg + d->tunables[0].offset, &bad, sizeof bad);
        TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_init(d, st, cfg, &su));
        const double nan = NAN;
        memcpy(cfg + d->tunables[0].offset, &nan, sizeof nan);
        TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_init(d, st, cfg, &su));
        /* An incomplete context is not a crash: a zero vector. */
        d->cfg_default(cfg, &SPMSM);
        TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_init(d, st, cfg, &su));
        ctrl_out_t out;
        ctrl_step(d, st, NULL, &out);
        TEST_ASSERT_EQUAL_UINT8(1, out.plan.n_seg);
        TEST_ASSERT_EQUAL_UINT8(0, out.plan.vec[0]);
        ctrl_step(d, NULL, NULL, &out);
        TEST_ASSERT_EQUAL_UINT8(0, out.plan.vec[0]);
        ctrl_step(d, st, NULL, NULL);
        ctrl_reset(d, NULL);
    }
}

/* Tunables by name (ctrl_tunable_set/get): values in range are taken and used
 * at init (a wider torque band changes the decision), out of range and unknown
 * names are refused. */
static void test_tunables_by_name(void)
{
    rig_open("bst");
    double v = 0.0;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_get(R.d, R.cfg, "h_T", &v));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.048, v);
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_tunable_set(R.d, R.cfg, "h_T", -0.1));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_tunable_set(R.d, R.cfg, "h_psi", 1e3));
    TEST_ASSERT_EQUAL_INT(CTRL_ENOENT, ctrl_tunable_set(R.d, R.cfg, "sigma", 0.1));
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_set(R.d, R.cfg, "h_T", 1.0));
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_init(R.d, R.state, R.cfg, &R.su));
    const st_hyst_state_t *s = (const st_hyst_state_t *)R.state;
    TEST_ASSERT_INT32_WITHIN(2, q24(1.0 / R.bases.torque_nm), s->torque3.band);
    /* error of 0.5 N*m: inside the new band, the three-level regulator holds 0 */
    R.ref.torque = q24(0.3);
    R.ref.psi = q24(1.0);
    set_next(0.0, 0.9, 0.3 - 0.5 / R.bases.torque_nm, 0.1);
    const uint8_t v0 = step();
    TEST_ASSERT_TRUE(v0 == 0u || v0 == 7u);

    rig_open("fst");
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_get(R.d, R.cfg, "sigma", &v));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, CTRL_PI / 12.0, v);
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_tunable_set(R.d, R.cfg, "sigma", CTRL_PI / 6.0 + 1e-3));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_tunable_set(R.d, R.cfg, "sigma", NAN));
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_set(R.d, R.cfg, "sigma", 0.0));
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_set(R.d, R.cfg, "dT_step", 0.1));
    TEST_ASSERT_EQUAL_INT(CTRL_ENOENT, ctrl_tunable_set(R.d, R.cfg, "h_T", 0.1));
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_init(R.d, R.state, R.cfg, &R.su));
    const st_fst_state_t *f = (const st_fst_state_t *)R.state;
    TEST_ASSERT_EQUAL_UINT8(0, f->vr.enabled);
    TEST_ASSERT_INT32_WITHIN(2, q24(0.1 / R.bases.torque_nm), f->logic.dt_step);
}

/* ------------------------------------------------- hysteresis-based tables */

/* Drive the regulators into state (e_psi, e_t) with errors of 3 bands, at
 * flux angle theta, and return the vector chosen. For e_t = 0 (three-level)
 * the torque first goes below the band (+1), then hits the reference (0). */
static uint8_t hyst_decide(double theta, int e_psi, int e_t, int three_level)
{
    const st_hyst_state_t *s = (const st_hyst_state_t *)R.state;
    const double h_t = (double)s->torque3.band / 16777216.0;
    const double h_psi = (double)s->flux.h.band / 16777216.0;
    const double tref = 0.3;
    const double psi_ref = 1.05;
    R.ref.torque = q24(tref);
    R.ref.psi = q24(psi_ref);
    const double amp = psi_ref - 3.0 * h_psi * e_psi;
    if (three_level && e_t == 0) {
        set_next(theta, amp, tref - 3.0 * h_t, 0.1);
        (void)step();
        set_next(theta, amp, tref, 0.1);
    } else {
        set_next(theta, amp, tref - 3.0 * h_t * e_t, 0.1);
    }
    return step();
}

static void check_hyst_table(const char *name, const uint8_t (*tab3)[3][6],
                             const uint8_t (*tab2)[2][6], int mbst_sectors)
{
    static const int EP[2] = {1, -1};
    static const int ET3[3] = {1, 0, -1};
    static const int ET2[2] = {1, -1};
    rig_open(name);
    for (int x = 1; x <= 6; x++) {
        /* sector centre: (x-1) pi/3 for (4.5), (2x-1) pi/6 for (4.18) */
        const double theta =
            mbst_sectors ? (2.0 * x - 1.0) * CTRL_PI / 6.0 : (x - 1.0) * CTRL_PI / 3.0;
        for (int r = 0; r < 2; r++) {
            const int nc = tab3 != NULL ? 3 : 2;
            for (int c = 0; c < nc; c++) {
                const int et = tab3 != NULL ? ET3[c] : ET2[c];
                const uint8_t expect = tab3 != NULL ? tab3[r][c][x - 1] : tab2[r][c][x - 1];
                const uint8_t got = hyst_decide(theta, EP[r], et, tab3 != NULL);
                if (expect != 0u) {
                    TEST_ASSERT_EQUAL_UINT8(expect, got);
                } else {
                    /* ZVV: V0 or V7 by the vector before; one leg switches */
                    TEST_ASSERT_TRUE(got == 0u || got == 7u);
                    const int zero_before = g_prev == 0u || g_prev == 7u;
                    TEST_ASSERT_EQUAL_INT(zero_before ? 0 : 1, legs_changed(g_prev, got));
                }
            }
        }
    }
}

static void test_bst_controller(void)
{
    check_hyst_table("bst", BST, NULL, 0);
}

static void test_mbst_controller(void)
{
    check_hyst_table("mbst", MBST, NULL, 1);
}

static void test_ast_controller(void)
{
    check_hyst_table("ast", NULL, AST, 0);
}

static void test_zst_controller(void)
{
    check_hyst_table("zst", NULL, ZST, 0);
}

/* MBST uses the sectors (4.18): at theta = pi/12 (sector 1 of (4.5), sector 1
 * of (4.18)) and theta = -pi/12 (sector 1 of (4.5), sector 6 of (4.18)) the
 * "decrease torque, increase flux" state gives V_x of the (4.18) sector. */
static void test_mbst_uses_modified_sectors(void)
{
    rig_open("mbst");
    TEST_ASSERT_EQUAL_UINT8(1, hyst_decide(CTRL_PI / 12.0, 1, -1, 1));
    TEST_ASSERT_EQUAL_UINT8(6, hyst_decide(-CTRL_PI / 12.0, 1, -1, 1));
    rig_open("bst");
    TEST_ASSERT_EQUAL_UINT8(6, hyst_decide(CTRL_PI / 12.0, 1, -1, 1)); /* V_{x+5}, x = 1 */
    TEST_ASSERT_EQUAL_UINT8(6, hyst_decide(-CTRL_PI / 12.0, 1, -1, 1));
}

/* The zero vector after every vector: walk BST through increase (active) and
 * maintain (zero) in every sector and both flux rows; each ZVV switches one leg. */
static void test_zero_vector_one_leg(void)
{
    rig_open("bst");
    int zeros = 0;
    for (int x = 1; x <= 6; x++) {
        for (int r = 0; r < 2; r++) {
            const double theta = (x - 1.0) * CTRL_PI / 3.0;
            const uint8_t a = hyst_decide(theta, r == 0 ? 1 : -1, 1, 1);
            TEST_ASSERT_TRUE(a >= 1u && a <= 6u);
            /* now maintain: Te hits Tref */
            const st_hyst_state_t *s = (const st_hyst_state_t *)R.state;
            const double h_psi = (double)s->flux.h.band / 16777216.0;
            set_next(theta, 1.05 - 3.0 * h_psi * (r == 0 ? 1 : -1), 0.3, 0.1);
            const uint8_t z = step();
            TEST_ASSERT_TRUE(z == 0u || z == 7u);
            TEST_ASSERT_EQUAL_INT(1, legs_changed(a, z));
            /* and a zero vector after a zero vector does not switch */
            TEST_ASSERT_EQUAL_UINT8(z, step());
            zeros++;
        }
    }
    TEST_ASSERT_EQUAL_INT(12, zeros);
}

/* Flux reference: ref->psi, else params->psi_ref, else MTPA of T_ref (4.15). */
static void test_flux_reference(void)
{
    rig_open("bst");
    ctrl_refs_t ref = {q24(0.5), q24(1.1)};
    TEST_ASSERT_EQUAL_INT32(q24(1.1), ctrl_flux_ref(&R.params, ref.psi, ref.torque));
    ref.psi = 0;
    TEST_ASSERT_EQUAL_INT32(ctrl_mtpa_psi(&R.params, ref.torque),
                            ctrl_flux_ref(&R.params, ref.psi, ref.torque));
    /* SPMSM (4.15) in pu: sqrt(1 + (Lq T)^2), Lq = 1 pu */
    TEST_ASSERT_INT32_WITHIN(64, q24(sqrt(1.0 + 0.25)),
                             ctrl_flux_ref(&R.params, ref.psi, ref.torque));
    ref.psi = q24(-0.5); /* negative amplitude: ignored */
    TEST_ASSERT_EQUAL_INT32(ctrl_mtpa_psi(&R.params, ref.torque),
                            ctrl_flux_ref(&R.params, ref.psi, ref.torque));
    ref.psi = 0;
    R.params.psi_ref = q24(0.9);
    TEST_ASSERT_EQUAL_INT32(q24(0.9), ctrl_flux_ref(&R.params, ref.psi, ref.torque));
    /* with ref psi = 0 the controller follows MTPA: flux below it -> increase */
    R.params.psi_ref = 0;
    R.ref.torque = q24(0.5);
    R.ref.psi = 0;
    set_next(0.0, sqrt(1.25) - 0.05, 0.5 - 0.2, 0.1); /* sector 1, T below band */
    TEST_ASSERT_EQUAL_UINT8(2, step());               /* V_{x+1}: increase both */
    set_next(0.0, sqrt(1.25) + 0.05, 0.5 - 0.2, 0.1);
    TEST_ASSERT_EQUAL_UINT8(3, step()); /* V_{x+2}: increase T, decrease psi */
}

/* ------------------------------------------------------------ FST logic */

typedef struct {
    double tref, terr, omega;
    st_fst_mode_t expect;
} fst_step_t;

static void run_logic(st_fst_logic_t *l, const fst_step_t *seq, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        TEST_ASSERT_EQUAL_INT_MESSAGE(
            seq[i].expect,
            st_fst_logic_update(l, q24(seq[i].tref), q24(seq[i].terr), q24(seq[i].omega)),
            "FST operating state");
    }
}

static void test_fst_logic_forward_step(void)
{
    st_fst_logic_t l;
    l.dt_step = 0;
    st_fst_logic_reset(&l);
    const fst_step_t seq[] = {
        {0.0, 0.01, 0.2, ST_FST_STEADY_FWD},  {0.0, -0.01, 0.2, ST_FST_STEADY_FWD},
        {0.0, 0.01, -0.2, ST_FST_STEADY_BWD}, {0.0, 0.01, 0.0, ST_FST_STEADY_FWD},
        {1.0, 0.9, 0.2, ST_FST_DYNAMIC}, /* step up: AVVs at all states */
        {1.0, 0.5, 0.2, ST_FST_DYNAMIC},      {1.0, 0.1, 0.2, ST_FST_DYNAMIC},
        {1.0, -0.01, 0.2, ST_FST_STEADY_FWD}, /* Te crossed Tref, Tref*omega >= 0 */
        {1.0, 0.01, 0.2, ST_FST_STEADY_FWD},  /* no step: stays steady */
    };
    run_logic(&l, seq, sizeof seq / sizeof seq[0]);
}

/* 2 -> -2 N*m at forward speed (Fig. 4.14): regenerative braking keeps the
 * flag (Tref*omega < 0) through crossings; after the speed reverses the next
 * crossing resets it, steady state backward. */
static void test_fst_logic_braking_and_reversal(void)
{
    st_fst_logic_t l;
    l.dt_step = 0;
    st_fst_logic_reset(&l);
    const fst_step_t seq[] = {
        {0.5, 0.0, 0.3, ST_FST_DYNAMIC},
        {0.5, -0.01, 0.3, ST_FST_STEADY_FWD},
        {-0.5, -0.99, 0.3, ST_FST_DYNAMIC}, /* step down; the sign change here is the step */
        {-0.5, -0.5, 0.3, ST_FST_DYNAMIC},
        {-0.5, 0.01, 0.3, ST_FST_DYNAMIC}, /* crossed, but braking: Tref*omega < 0 */
        {-0.5, -0.01, 0.1, ST_FST_DYNAMIC},
        {-0.5, -0.01, -0.05, ST_FST_DYNAMIC},   /* reversed, but no crossing yet */
        {-0.5, 0.01, -0.05, ST_FST_STEADY_BWD}, /* crossing with Tref*omega >= 0 */
        {-0.5, -0.01, -0.1, ST_FST_STEADY_BWD},
    };
    run_logic(&l, seq, sizeof seq / sizeof seq[0]);
}

/* The step sample itself never resets the flag, even with an error sign change. */
static void test_fst_logic_step_sample_and_threshold(void)
{
    st_fst_logic_t l;
    l.dt_step = 0;
    st_fst_logic_reset(&l);
    l.flag = 1; /* already dynamic */
    l.terr_nonneg_prev = 1;
    const fst_step_t seq[] = {
        {0.2, -0.1, 0.3, ST_FST_DYNAMIC}, /* step and sign change in one sample */
        {0.2, 0.1, 0.3, ST_FST_STEADY_FWD},
    };
    run_logic(&l, seq, 2);
    /* threshold: changes up to dt_step are not steps */
    l.dt_step = q24(0.01);
    st_fst_logic_reset(&l);
    const fst_step_t seq2[] = {
        {0.01, 0.1, 0.3, ST_FST_STEADY_FWD}, /* |dT| = dt_step: not a step */
        {0.015, 0.1, 0.3, ST_FST_STEADY_FWD},
        {0.0251, 0.1, 0.3, ST_FST_DYNAMIC}, /* |dT| > dt_step */
    };
    run_logic(&l, seq2, 3);
    TEST_ASSERT_EQUAL_INT(ST_FST_DYNAMIC, st_fst_logic_update(NULL, 0, 0, 0));
    st_fst_logic_reset(NULL);
}

/* ------------------------------------------------------- FST controller */

static void test_fst_controller_all_states(void)
{
    /* modes: 0 steady forward (omega > 0), 1 steady backward (omega < 0),
     * 2 dynamic (a reference step at this sample) */
    rig_open("fst");
    const double psi_ref = 1.05;
    R.ref.psi = q24(psi_ref);
    for (int x = 1; x <= 6; x++) {
        const double theta = (x - 1.0) * CTRL_PI / 3.0; /* centre: outside both subsectors */
        for (int m = 0; m < 3; m++) {
            for (int t = 0; t < 2; t++) {
                for (int f = 0; f < 2; f++) {
                    const double omega = m == 1 ? -0.2 : 0.2;
                    const double terr = t == 0 ? 0.05 : -0.05;
                    const double amp = f == 0 ? psi_ref - 0.01 : psi_ref + 0.01;
                    R.d->reset(R.state);
                    /* settle: constant reference -> flag clear (reset has T_ref[k-1] = 0) */
                    const double tref = m == 1 ? -0.4 : 0.4;
                    R.ref.torque = q24(tref);
                    set_next(theta, amp, tref + 0.05, omega); /* first sample: step */
                    (void)step();
                    set_next(theta, amp, tref - 0.05, omega); /* crossing: steady */
                    (void)step();
                    if (m == 2) {
                        R.ref.torque = q24(tref + 0.1); /* a step: dynamic */
                        set_next(theta, amp, tref + 0.1 - terr, omega);
                    } else {
                        set_next(theta, amp, tref - terr, omega);
                    }
                    const uint8_t got = step();
                    const uint8_t expect = FST[t][f][m][x - 1];
                    if (expect != 0u) {
                        TEST_ASSERT_EQUAL_UINT8(expect, got);
                    } else {
                        TEST_ASSERT_TRUE(got == 0u || got == 7u);
                        const int zero_before = g_prev == 0u || g_prev == 7u;
                        TEST_ASSERT_EQUAL_INT(zero_before ? 0 : 1, legs_changed(g_prev, got));
                    }
                }
            }
        }
    }
}

/* Voltage replacement inside the controller: sector 1, subsector I at
 * theta = -pi/6 + pi/24 (sigma = pi/12): steady forward, T_err >= 0,
 * psi_err < 0 -> Table 4.6 gives V_{x+2} = V3, replaced by V_{x+1} = V2 (4.20).
 * With sigma = 0 (tunable) no replacement. */
static void test_fst_controller_replacement(void)
{
    for (int pass = 0; pass < 2; pass++) {
        rig_open("fst");
        if (pass == 1) {
            const double zero = 0.0;
            memcpy(R.cfg + offsetof(st_fst_cfg_t, sigma), &zero, sizeof zero);
            TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_init(R.d, R.state, R.cfg, &R.su));
        }
        R.ref.psi = q24(1.0);
        R.ref.torque = q24(0.4);
        const double th = -CTRL_PI / 6.0 + CTRL_PI / 24.0;
        set_next(th, 1.02, 0.45, 0.2);
        (void)step(); /* step from T_ref[k-1] = 0 */
        set_next(th, 1.02, 0.35, 0.2);
        TEST_ASSERT_EQUAL_UINT8(pass == 0 ? 2 : 3, step());
        /* subsector II of sector 1 (theta = pi/6 - pi/24): V_{x+1} = V2 -> V3 (4.21) */
        set_next(CTRL_PI / 6.0 - CTRL_PI / 24.0, 0.98, 0.35, 0.2);
        TEST_ASSERT_EQUAL_UINT8(pass == 0 ? 3 : 2, step());
    }
}

/* The mean-torque-error integrator (f_i): its default from the machine, its
 * gain 2 pi f_i Ts, integration of T_ref - T(k+1) in steady state only, the
 * rated-torque clamp, and decisions on T_ref + g. */
static void test_fst_integrator(void)
{
    /* Defaults: A (5.9) / T_rated = Vdc / (20 kHz 1.5 Ld i_rated): thesis SPMSM
     * 0.27 -> off; the mj5208 drone motor 2.4 and the GBM5208 gimbal motor
     * 0.63 -> 50 Hz; the thesis 80 kW IPMSM 0.075 -> off. */
    TEST_ASSERT_EQUAL_DOUBLE(0.0, st_fst_f_i_default(&SPMSM));
    TEST_ASSERT_EQUAL_DOUBLE(50.0, st_fst_f_i_default(&ini_mj5208_drone));
    TEST_ASSERT_EQUAL_DOUBLE(50.0, st_fst_f_i_default(&ini_gbm5208_gimbal));
    TEST_ASSERT_EQUAL_DOUBLE(0.0, st_fst_f_i_default(&ini_thesis_ipmsm80));
    TEST_ASSERT_EQUAL_DOUBLE(0.0, st_fst_f_i_default(NULL));

    rig_open("fst");
    double v = -1.0;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_get(R.d, R.cfg, "f_i", &v));
    TEST_ASSERT_EQUAL_DOUBLE(0.0, v);
    const st_fst_state_t *f = (const st_fst_state_t *)R.state;
    TEST_ASSERT_EQUAL_INT32(0, f->ki);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_set(R.d, R.cfg, "f_i", 100.0));
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_init(R.d, R.state, R.cfg, &R.su));
    const double ki = 2.0 * CTRL_PI * 100.0 / 20000.0;
    TEST_ASSERT_INT32_WITHIN(1, q24(ki), f->ki);
    TEST_ASSERT_EQUAL_INT32(R.params.torque_rated, f->g_max);
    /* outside the tunable's range: refused by name */
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_tunable_set(R.d, R.cfg, "f_i", 2000.0));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_tunable_set(R.d, R.cfg, "f_i", -1.0));

    R.ref.psi = q24(1.05);
    const double tref = 0.4;
    R.ref.torque = q24(tref);
    /* First sample: a reference step (dynamic mode): no integration. */
    set_next(0.0, 1.04, tref - 0.05, 0.2);
    (void)step();
    TEST_ASSERT_EQUAL_INT32(0, f->g);
    /* The torque crosses the reference: steady state, integrates -0.01. */
    set_next(0.0, 1.04, tref + 0.01, 0.2);
    (void)step();
    TEST_ASSERT_INT32_WITHIN(2, q24(-0.01 * ki), f->g);
    /* Steady, torque 0.01 above the reference for n samples: g = -(n+1) 0.01 ki;
     * the decisions use T_ref + g, so a torque 0.001 above T_ref + g (below
     * T_ref) is a decrease (zero vector in the steady forward column). */
    for (int n = 0; n < 50; n++) {
        (void)step();
    }
    const double g = -51.0 * 0.01 * ki;
    TEST_ASSERT_INT32_WITHIN(60, q24(g), f->g);
    set_next(0.0, 1.04, tref + g + 0.001, 0.2);
    const uint8_t dec = step();
    TEST_ASSERT_TRUE(dec == 0u || dec == 7u);
    set_next(0.0, 1.04, tref + g - 0.001, 0.2);
    TEST_ASSERT_TRUE(step() != 0u && R.applied.vec[0] != 7u); /* increase */
    /* Clamped to the rated torque. */
    set_next(0.0, 1.04, tref + 10.0, 0.2);
    for (int n = 0; n < 20000; n++) {
        (void)step();
    }
    TEST_ASSERT_EQUAL_INT32(fx_neg(R.params.torque_rated), f->g);
    /* reset clears it */
    R.d->reset(R.state);
    TEST_ASSERT_EQUAL_INT32(0, f->g);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_registry_and_defaults);
    RUN_TEST(test_tunables_by_name);
    RUN_TEST(test_bst_controller);
    RUN_TEST(test_mbst_controller);
    RUN_TEST(test_ast_controller);
    RUN_TEST(test_zst_controller);
    RUN_TEST(test_mbst_uses_modified_sectors);
    RUN_TEST(test_zero_vector_one_leg);
    RUN_TEST(test_flux_reference);
    RUN_TEST(test_fst_logic_forward_step);
    RUN_TEST(test_fst_logic_braking_and_reversal);
    RUN_TEST(test_fst_integrator);
    RUN_TEST(test_fst_logic_step_sample_and_threshold);
    RUN_TEST(test_fst_controller_all_states);
    RUN_TEST(test_fst_controller_replacement);
    return UNITY_END();
}
