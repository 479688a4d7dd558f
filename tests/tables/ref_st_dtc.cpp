/*
 * Double-precision reference of the switching-table DTC decisions (thesis
 * chapter 4) against the fixed-point controllers bst/mbst/ast/zst/fst.
 *
 * The reference computes the sector with atan2 ((4.5), (4.18)), the subsector
 * of (4.19) from the angle, the hysteresis regulators of Fig. 4.2 and the FST
 * logic of §4.5.3 in double, from the unrounded random inputs; it uses the
 * hand-written thesis tables (thesis_tables.h), not the implementation's.
 *
 * Where the two may legitimately differ (derived from the Q24 formats):
 *  - angle: the controller sees psi rounded to Q24 (<= 2^-25 per component,
 *    i.e. <= 2^-24.5 / |psi| rad), and the rotated subsector boundary of
 *    ctrl_vreplace is rounded to Q24 (< 2^-23 rad with sin/cos sigma):
 *    margin MARGIN_TH = 2^-24.5/|psi|_min + 2^-22 = 5.2e-7 rad at |psi| >= 0.3 pu,
 *    taken as 1e-6 rad;
 *  - errors e = ref - estimate: both operands and the band are rounded to Q24
 *    (<= 2^-25 each): margin 3 * 2^-25, taken as MARGIN_E = 2^-22 pu; with the
 *    MTPA flux reference add the MTPA error (1e-6 pu budget);
 *  - signs of T_ref, omega: values below 2^-24 may round to 0.
 * A sample whose reference inputs lie within a margin of any decision boundary
 * is counted as "near-boundary" and not compared; the reference then copies
 * the controller's state (regulators, FST flag, previous vector) so the
 * sequence continues in step. Every other sample must agree exactly.
 * Near-boundary samples must be rare among uniformly random samples; 10 % of
 * the samples are placed deliberately at 2..20 margins from a boundary (these
 * are compared, they test that the margin is not hiding a real error).
 */
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

#include <Eigen/Dense>

extern "C" {
#include "controller.h"
#include "ctrl_params.h"
#include "st_dtc.h"
#include "st_dtc_config.h"
#include "vectors.h"
#include "vreplace.h"
#include "vreplace_config.h"
}
#include "thesis_tables.h"
#include "unity.h"

void setUp(void)
{
}
void tearDown(void)
{
}

namespace
{

const double PI = 3.14159265358979323846;
const double Q = 16777216.0;
const double MARGIN_TH = 1e-6;
const double MARGIN_E = 1.0 / 4194304.0; /* 2^-22 */
const double MARGIN_MTPA = 1e-6;

q24_t q24(double v)
{
    return static_cast<q24_t>(std::lround(v * Q));
}

/* ---------------------------------------------------------------- reference */

int wrap6(int x)
{
    return ((x - 1) % 6 + 6) % 6 + 1;
}

/* (4.5): (2x-3)pi/6 < theta <= (2x-1)pi/6 <=> x = ceil((6 theta/pi + 1) / 2) */
int ref_sector(double th)
{
    return wrap6(static_cast<int>(std::ceil((6.0 * th / PI + 1.0) / 2.0)));
}

/* (4.18): (2x-2)pi/6 < theta <= 2x pi/6 <=> x = ceil(3 theta / pi) */
int ref_sector_mbst(double th)
{
    return wrap6(static_cast<int>(std::ceil(3.0 * th / PI)));
}

/* distance of theta to the nearest multiple of step shifted by offset */
double dist_grid(double th, double offset, double step)
{
    double r = std::fmod(th - offset, step);
    if (r < 0) {
        r += step;
    }
    return std::fmin(r, step - r);
}

double wrap_pi(double a)
{
    while (a > PI) {
        a -= 2.0 * PI;
    }
    while (a <= -PI) {
        a += 2.0 * PI;
    }
    return a;
}

struct RefHyst2 {
    double h = 0.0;
    int out = 0;
    int update(double e)
    {
        if (e >= h) {
            out = 1;
        } else if (e <= -h) {
            out = -1;
        } else if (out == 0) {
            out = e >= 0.0 ? 1 : -1;
        }
        return out;
    }
};

struct RefHyst3 {
    double h = 0.0;
    int out = 0;
    int update(double e)
    {
        if (e >= h) {
            out = 1;
        } else if (e <= -h) {
            out = -1;
        } else if ((out > 0 && e <= 0.0) || (out < 0 && e >= 0.0)) {
            out = 0;
        }
        return out;
    }
};

int ref_zero_after(int v)
{
    return (v == 2 || v == 4 || v == 6 || v == 7) ? 7 : 0;
}

enum Kind { BSTK = 0, MBSTK, ASTK, ZSTK, FSTK };
const char *const NAMES[5] = {"bst", "mbst", "ast", "zst", "fst"};

struct RefCtrl {
    Kind kind;
    double h_t = 0.0, h_psi = 0.0, sigma = 0.0, dt_step = 0.0;
    RefHyst2 flux, torque2;
    RefHyst3 torque3;
    int prev_vec = 0;
    /* FST */
    double tref_prev = 0.0;
    int flag = 0, terr_nonneg_prev = 1;
    int last_mode = -1; /* FST column used at the last step */

    int replace(int v, int x, double th) const
    {
        if (sigma <= 0.0) {
            return v;
        }
        const double a = (2.0 * x - 3.0) * PI / 6.0;
        const double rel = wrap_pi(th - a); /* in (0, pi/3] inside sector x */
        const int n = ((v - x) % 6 + 6) % 6;
        if (rel <= sigma) { /* subsector I (4.20) */
            if (n == 2)
                return wrap6(x + 1);
            if (n == 5)
                return wrap6(x + 4);
        } else if (rel > PI / 3.0 - sigma) { /* subsector II (4.21) */
            if (n == 1)
                return wrap6(x + 2);
            if (n == 4)
                return wrap6(x + 5);
        }
        return v;
    }

    int step(double th, double psi_amp, double torque, double tref, double psi_ref, double omega)
    {
        const double e_t = tref - torque;
        const double e_psi = psi_ref - psi_amp;
        int v = 0;
        if (kind == FSTK) {
            const int nonneg = e_t >= 0.0;
            const int crossed = nonneg != terr_nonneg_prev;
            if (std::fabs(tref - tref_prev) > dt_step) {
                flag = 1;
            } else if (flag && crossed && tref * omega >= 0.0) {
                flag = 0;
            }
            tref_prev = tref;
            terr_nonneg_prev = nonneg;
            const int mode = flag ? 2 : (omega >= 0.0 ? 0 : 1);
            last_mode = mode;
            const int x = ref_sector(th);
            v = FST[nonneg ? 0 : 1][e_psi >= 0.0 ? 0 : 1][mode][x - 1];
            if (v != 0) {
                v = replace(v, x, th);
            }
        } else {
            const int ep = flux.update(e_psi);
            const int r = ep > 0 ? 0 : 1;
            switch (kind) {
            case BSTK: {
                const int et = torque3.update(e_t);
                v = BST[r][et > 0 ? 0 : (et == 0 ? 1 : 2)][ref_sector(th) - 1];
                break;
            }
            case MBSTK: {
                const int et = torque3.update(e_t);
                v = MBST[r][et > 0 ? 0 : (et == 0 ? 1 : 2)][ref_sector_mbst(th) - 1];
                break;
            }
            case ASTK:
                v = AST[r][torque2.update(e_t) > 0 ? 0 : 1][ref_sector(th) - 1];
                break;
            default:
                v = ZST[r][torque2.update(e_t) > 0 ? 0 : 1][ref_sector(th) - 1];
                break;
            }
        }
        if (v == 0) {
            v = ref_zero_after(prev_vec);
        }
        prev_vec = v;
        return v;
    }
};

/* ---------------------------------------------------------------- harness */

const ctrl_machine_t SPMSM = {
    "thesis SPMSM", 4,   0.901,  6.552e-3, 6.552e-3, 0.09427, 220.0,
    1.2e-4,         2.4, 3000.0, 4.2,      8.4,      0.0,
};

struct Stats {
    long samples = 0, compared = 0, mismatches = 0, near_uniform = 0, uniform = 0,
         near_targeted = 0, targeted = 0;
    long per_vec[8] = {0};
    long per_mode[3] = {0}; /* FST: steady fwd, steady bwd, dynamic */
};

void run_kind(Kind kind, std::mt19937_64 &rng, Stats &st)
{
    ctrl_params_t params;
    ctrl_bases_t bases;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&params, &bases, &SPMSM, 20000u));
    const ctrl_desc_t *d = ctrl_find(NAMES[kind]);
    TEST_ASSERT_NOT_NULL(d);
    alignas(8) unsigned char cfg[CTRL_CFG_MAX];
    alignas(8) unsigned char state[CTRL_STATE_MAX];
    d->cfg_default(cfg, &SPMSM);

    std::uniform_real_distribution<double> U(0.0, 1.0);
    RefCtrl ref{kind};
    if (kind == FSTK) {
        double sigma = U(rng) < 0.2 ? 0.0 : U(rng) * PI / 6.0;
        if (U(rng) < 0.3) {
            sigma = PI / 12.0;
        }
        const double dt_step_nm = U(rng) < 0.5 ? 0.0 : 0.05 * U(rng);
        std::memcpy(cfg + offsetof(st_fst_cfg_t, sigma), &sigma, sizeof sigma);
        std::memcpy(cfg + offsetof(st_fst_cfg_t, dt_step), &dt_step_nm, sizeof dt_step_nm);
        ref.sigma = sigma;
        ref.dt_step = dt_step_nm / bases.torque_nm;
    } else {
        /* bands between 0.5 % and 5 % */
        const double h_t = (0.005 + 0.045 * U(rng)) * SPMSM.torque_rated_nm;
        const double h_psi = (0.005 + 0.045 * U(rng)) * SPMSM.psi_pm_wb;
        std::memcpy(cfg + offsetof(st_hyst_cfg_t, h_t), &h_t, sizeof h_t);
        std::memcpy(cfg + offsetof(st_hyst_cfg_t, h_psi), &h_psi, sizeof h_psi);
        ref.h_t = h_t / bases.torque_nm;
        ref.h_psi = h_psi / bases.psi_wb;
        ref.flux.h = ref.h_psi;
        ref.torque2.h = ref.h_t;
        ref.torque3.h = ref.h_t;
    }
    const ctrl_setup_t su{&SPMSM, &bases, &params};
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_init(d, state, cfg, &su));
    d->reset(state);
    /* bands for the error generator (FST: errors around 0 with a 2 % scale) */
    const double gh_t = kind == FSTK ? 0.02 * params.torque_rated / Q : ref.h_t;
    const double gh_psi = kind == FSTK ? 0.02 : ref.h_psi;

    ctrl_estimate_t est;
    ctrl_refs_t refs;
    std::memset(&est, 0, sizeof est);
    std::memset(&refs, 0, sizeof refs);
    ctrl_ctx_t ctx{&params, &est, &refs};

    double tref = 0.0;
    double omega = 0.5;
    const int L = 40;
    for (int k = 0; k < L; k++) {
        const bool targeted = U(rng) < 0.1;
        /* flux angle: uniform, or 2..20 margins from a decision boundary */
        double th = -PI + 2.0 * PI * U(rng);
        const double amp = 0.3 + 1.2 * U(rng);
        const double off = (2.0 + 18.0 * U(rng)) * (U(rng) < 0.5 ? -1.0 : 1.0);
        int which = 0;
        if (targeted) {
            which = static_cast<int>(U(rng) * 3.0);
            const int j = static_cast<int>(U(rng) * 6.0);
            if (which == 0) { /* sector boundary of this controller */
                const double b = kind == MBSTK ? j * PI / 3.0 : (2.0 * j - 1.0) * PI / 6.0;
                th = wrap_pi(b + off * MARGIN_TH);
            }
            if (which == 1 && kind == FSTK) { /* a subsector boundary */
                const double a = (2.0 * j - 1.0) * PI / 6.0;
                th = wrap_pi((U(rng) < 0.5 ? a + ref.sigma : a - ref.sigma) + off * MARGIN_TH);
            }
        }
        /* references: occasional steps, rotation in both directions */
        if (U(rng) < 0.15) {
            tref = (2.0 * U(rng) - 1.0) * 1.5 * params.torque_rated / Q;
        }
        if (U(rng) < 0.05) {
            omega = (2.0 * U(rng) - 1.0) * 1.2;
        }
        const bool mtpa = U(rng) < 0.3;
        const double psi_ref = mtpa ? std::sqrt(1.0 + tref * tref) : 0.8 + 0.4 * U(rng);
        /* errors: uniform over 3 bands, or 2..20 margins from a band edge or 0 */
        double e_t = (2.0 * U(rng) - 1.0) * 3.0 * gh_t;
        double e_psi = (2.0 * U(rng) - 1.0) * 3.0 * gh_psi;
        if (targeted && which == 2) {
            const double edges[3] = {-1.0, 0.0, 1.0};
            const int ei = static_cast<int>(U(rng) * 3.0);
            const double ef = off * (MARGIN_E + (mtpa ? MARGIN_MTPA : 0.0));
            if (U(rng) < 0.5) {
                e_t = edges[ei] * gh_t + ef;
            } else {
                e_psi = edges[ei] * gh_psi + ef;
            }
        }
        const double torque = tref - e_t;
        const double psi_amp = psi_ref - e_psi;

        /* controller inputs: the same values in Q24 */
        refs.torque = q24(tref);
        refs.psi = mtpa ? 0 : q24(psi_ref);
        est.next.psi_alpha = q24(amp * std::cos(th));
        est.next.psi_beta = q24(amp * std::sin(th));
        est.next.sector = ctrl_sector(est.next.psi_alpha, est.next.psi_beta); /* (4.5) */
        est.next.psi_amp = q24(psi_amp);
        est.next.psi_amp_sq =
            static_cast<uint64_t>(static_cast<int64_t>(est.next.psi_amp) * est.next.psi_amp);
        est.next.torque = q24(torque);
        est.omega_e = q24(omega);
        est.vdc = FX_ONE;
        /* the point whose angle the controller sees is (alpha, beta) of amp; the
         * amplitude it compares is psi_amp (independent inputs, like an estimator
         * whose |psi| comes from the same flux) */

        /* near a boundary? */
        const double me = MARGIN_E + (mtpa ? MARGIN_MTPA : 0.0);
        bool near = false;
        if (kind == MBSTK) {
            near = near || dist_grid(th, 0.0, PI / 3.0) < MARGIN_TH;
        } else {
            near = near || dist_grid(th, PI / 6.0, PI / 3.0) < MARGIN_TH;
        }
        if (kind == FSTK) {
            near = near ||
                   (ref.sigma > 0.0 && (dist_grid(th, PI / 6.0 + ref.sigma, PI / 3.0) < MARGIN_TH ||
                                        dist_grid(th, PI / 6.0 - ref.sigma, PI / 3.0) < MARGIN_TH));
            near = near || std::fabs(e_t) < me || std::fabs(e_psi) < me;
            /* an exact 0 is exact in Q24 too; only tiny non-zero values may round to 0 */
            near = near || (tref != 0.0 && std::fabs(tref) < 2.0 / Q) ||
                   (omega != 0.0 && std::fabs(omega) < 2.0 / Q);
            const double dref = std::fabs(tref - ref.tref_prev); /* step test */
            near = near || (dref != 0.0 && std::fabs(dref - ref.dt_step) < 2.0 / Q);
        } else {
            near = near || std::fabs(std::fabs(e_t) - ref.h_t) < me ||
                   std::fabs(std::fabs(e_psi) - ref.h_psi) < me || std::fabs(e_t) < me ||
                   std::fabs(e_psi) < me;
        }

        ctrl_out_t out;
        d->step(state, &ctx, &out);
        const int want = ref.step(th, psi_amp, torque, tref, psi_ref, omega);
        const int got = out.plan.vec[0];
        st.samples++;
        (targeted ? st.targeted : st.uniform)++;
        if (near) {
            (targeted ? st.near_targeted : st.near_uniform)++;
            /* resynchronise the reference with the controller */
            ref.prev_vec = got;
            if (kind == FSTK) {
                const st_fst_state_t *s = reinterpret_cast<const st_fst_state_t *>(state);
                ref.flag = s->logic.flag;
                ref.terr_nonneg_prev = s->logic.terr_nonneg_prev;
            } else {
                const st_hyst_state_t *s = reinterpret_cast<const st_hyst_state_t *>(state);
                ref.flux.out = s->flux.h.out;
                ref.torque2.out = s->torque2.out;
                ref.torque3.out = s->torque3.out;
            }
            continue;
        }
        st.compared++;
        st.per_vec[got & 7]++;
        if (ref.last_mode >= 0) {
            st.per_mode[ref.last_mode]++;
        }
        if (got != want) {
            st.mismatches++;
            if (st.mismatches <= 10) {
                std::printf("mismatch %s: th=%.9f amp=%.4f e_t=%.3e e_psi=%.3e tref=%.4f w=%.3f "
                            "mtpa=%d got V%d want V%d\n",
                            NAMES[kind], th, amp, e_t, e_psi, tref, omega, mtpa ? 1 : 0, got, want);
            }
            ref.prev_vec = got;
        }
    }
}

void test_reference_decisions(void)
{
    std::mt19937_64 rng(20261121u);
    for (int kind = 0; kind < 5; kind++) {
        Stats st;
        for (int seq = 0; seq < 2500; seq++) {
            run_kind(static_cast<Kind>(kind), rng, st);
        }
        std::printf("%-4s samples %ld compared %ld mismatches %ld | near-boundary: uniform %ld of "
                    "%ld, targeted %ld of %ld | vectors V0..V7:",
                    NAMES[kind], st.samples, st.compared, st.mismatches, st.near_uniform,
                    st.uniform, st.near_targeted, st.targeted);
        for (int v = 0; v < 8; v++) {
            std::printf(" %ld", st.per_vec[v]);
        }
        if (kind == FSTK) {
            std::printf(" | FST states fwd %ld bwd %ld dynamic %ld", st.per_mode[0], st.per_mode[1],
                        st.per_mode[2]);
            /* every operating state of Table 4.6 was exercised */
            TEST_ASSERT_TRUE(st.per_mode[0] > 1000 && st.per_mode[1] > 1000 &&
                             st.per_mode[2] > 1000);
        }
        std::printf("\n");
        TEST_ASSERT_EQUAL_INT(0, static_cast<int>(st.mismatches));
        /* rare: the margins cover a fraction of about 1e-5 of the input space
         * for angles; the error margins are ~1e-5 of the band; allow 0.1 % */
        TEST_ASSERT_TRUE(st.near_uniform * 1000 <= st.uniform);
        /* the targeted samples sit 2..20 margins away: none is "near" through them,
         * only through the other (uniform) inputs */
        TEST_ASSERT_TRUE(st.near_targeted * 100 <= st.targeted);
        TEST_ASSERT_TRUE(st.compared > 90000);
    }
}

/* The voltage replacement alone: random sigma in [0, pi/12], random flux in
 * its sector, every vector; the double subsector test by angle. */
void test_reference_vreplace(void)
{
    std::mt19937_64 rng(7u);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    long n = 0, near = 0, bad = 0;
    for (int i = 0; i < 20000; i++) {
        const double sigma = U(rng) * PI / 6.0;
        ctrl_vreplace_t c;
        TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_vreplace_config(&c, sigma));
        const double th = -PI + 2.0 * PI * U(rng);
        const double amp = 0.05 + 2.0 * U(rng);
        Eigen::Vector2d psi(amp * std::cos(th), amp * std::sin(th));
        const q24_t pa = q24(psi.x());
        const q24_t pb = q24(psi.y());
        const int x = ref_sector(th);
        const double m = 2.0 / Q / amp + 4.0 / Q;
        if (dist_grid(th, PI / 6.0, PI / 3.0) < m ||
            dist_grid(th, PI / 6.0 + sigma, PI / 3.0) < m ||
            dist_grid(th, PI / 6.0 - sigma, PI / 3.0) < m) {
            near++;
            continue;
        }
        TEST_ASSERT_EQUAL_INT(x, ctrl_sector(pa, pb));
        RefCtrl r{FSTK};
        r.sigma = sigma;
        for (int v = 0; v <= 7; v++) {
            const int want = (v == 0 || v == 7 || c.enabled == 0) ? v : r.replace(v, x, th);
            const int got =
                ctrl_vreplace(&c, static_cast<uint8_t>(v), static_cast<uint8_t>(x), pa, pb);
            bad += got != want;
            n++;
        }
    }
    std::printf("vreplace: %ld comparisons, %ld mismatches, %ld near-boundary points skipped\n", n,
                bad, near);
    TEST_ASSERT_EQUAL_INT(0, static_cast<int>(bad));
    TEST_ASSERT_TRUE(near < 20);
}

} // namespace

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_reference_vreplace);
    RUN_TEST(test_reference_decisions);
    return UNITY_END();
}
