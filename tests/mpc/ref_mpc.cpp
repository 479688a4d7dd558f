/*
 * Double-precision reference of the chapter-6 predictive controllers (thesis
 * §6.3-§6.4) against the fixed-point code, on randomised operating points:
 * all sectors (random rotor angle), both rotation directions, motoring and
 * braking (random current and speed signs), thesis SPMSM and 80 kW IPMSM.
 *
 * The reference works from the machine's SI data (its own per-unit bases, as
 * defined in ctrl_params.h) and the same k+1 estimate the controller receives
 * (Q24 values converted exactly to double), and implements:
 *   (6.10) psi(k+2) = psi(k+1) + D Ts V - Ts Rs i(k+1), theta(k+2) = theta(k+1) + omega Ts,
 *   (6.12) i_d = (psi_d - psi_pm)/Ld, i_q = psi_q/Lq,  (6.11)/(3.6) Te = psi x i,
 *   m2ptfc: (6.8), (6.7), (6.5)-(6.6), (6.9);  m1: (5.18) + (6.13) over V1..V6;
 *   mptfc: (6.13) over V0..V6 at D = 1;  m3: (6.1) + (5.18) + (6.13);
 *   m2: Table 4.1 on the zero-vector prediction, (6.15)-(6.17).
 *
 * Error budget of the fixed point (Q24 LSB = 2^-24 pu): k+2 flux amplitude
 * within TOL_PSI = 16 LSB + 1.5 LSB per pu of DC link (roundings of Ts V (the
 * Q24 Ts 2/3 times Vdc), of the rotation and of the sum) + 0.25 LSB / |psi|
 * (the rounding of |psi|^2, through the square root); the k+1 state is
 * the estimator's rotor-frame one, turned to k+2 by fx_rot_q30; k+2 torque
 * within the state-dependent RefPoint::tol_torque (fx_sincos error EPS_SC on
 * the turned voltage, fx_rot_q30's EPS_ROT on the flux, Q24 roundings). A duty num/den then differs
 * by at most (d_num + D d_den)/|den| + 1 LSB. A decision whose reference costs (or clamp / band /
 * sign tests) are closer than the error this budget allows is a tie: counted, not compared,
 * asserted rare.
 */
#include <Eigen/Dense>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>

extern "C" {
#include "../core/est_fixture.h"
#include "controller.h"
#include "ctrl_m1.h"
#include "ctrl_m2.h"
#include "ctrl_m2_config.h"
#include "ctrl_m2ptfc.h"
#include "ctrl_m2ptfc_config.h"
#include "ctrl_m3.h"
#include "ctrl_mptfc.h"
#include "plan.h"
#include "unity.h"
}

#include "../core/machines.h"
#include "mpc_machines.h"

using Eigen::Rotation2Dd;
using Eigen::Vector2d;

static const double LSB = 1.0 / 16777216.0;
static const double TOL_PSI0 = 16.0 * LSB;
/* The k+2 flux amplitude budget at DC link vdc (pu): the rounding of Ts 2/3
 * (0.5 LSB) scales with the DC link, twice through V3 = V2 - V1, per component. */
static double tol_psi(double vdc)
{
    return TOL_PSI0 + 1.5 * vdc * LSB;
}
static const double EPS_SC = 3.18e-8; /* fx_sincos maximum error (fx.h) */
static const double EPS_ROT = 3.0e-9; /* fx_rot_q30 maximum error up to pi/2 (fx.h) */
static const int N_POINTS = 3000;
static const double TIE_RATE_MAX = 0.02; /* "rare": at most 2 % of the decisions */

void setUp(void)
{
}
void tearDown(void)
{
}

static uint64_t rng = 0xD1B54A32D192ED03u;
static uint32_t rng_u32()
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (uint32_t)(rng >> 32);
}
static double uni(double lo, double hi)
{
    return lo + (hi - lo) * (rng_u32() / 4294967296.0);
}
static double d24(q24_t x)
{
    return (double)x * LSB;
}

/* Per-unit machine from SI (bases of ctrl_params.h). */
struct RefMachine {
    double ts, rs, ld, lq, psi_pm, vdc, t_base, psi_base;
    RefMachine(const ctrl_machine_t &m, uint32_t fs)
    {
        /* The bases of docs/fixed-point.md: psi_pm, the rated electrical
         * speed, v = psi w, Ld. */
        const double psi_b = m.psi_pm_wb;
        const double w_b = m.pole_pairs * m.speed_rated_rpm * 2.0 * 3.14159265358979323846 / 60.0;
        const double v_b = psi_b * w_b;
        const double i_b = psi_b / m.ld_h, r_b = v_b / i_b;
        ts = w_b / fs;
        rs = m.rs_ohm / r_b;
        ld = 1.0;
        lq = m.lq_h / m.ld_h;
        psi_pm = 1.0;
        vdc = m.vdc_v / v_b;
        t_base = 1.5 * m.pole_pairs * psi_b * i_b;
        psi_base = psi_b;
    }
};

/* The k+1 estimate as doubles, and the k+2 predictions. */
struct RefPoint {
    const RefMachine *m;
    Vector2d psi1, i1;
    double t1, th1, omega, vdc;
    int sector;
    double th2;
    Vector2d psi0; /* psi(k+2) with a zero vector */

    RefPoint(const RefMachine &mm, const ctrl_estimate_t &e) : m(&mm)
    {
        th1 = (double)e.next.theta_e * (2.0 * M_PI / 4294967296.0);
        /* the rotor-frame state turned exactly into the stator frame */
        psi1 = Rotation2Dd(th1) * Vector2d(d24(e.next.psi_d), d24(e.next.psi_q));
        i1 = Rotation2Dd(th1) * Vector2d(d24(e.next.i_d), d24(e.next.i_q));
        t1 = d24(e.next.torque);
        omega = d24(e.omega_e);
        vdc = d24(e.vdc);
        sector = e.next.sector;
        th2 = th1 + omega * m->ts;        /* (6.12) angle */
        psi0 = psi1 - m->ts * m->rs * i1; /* (6.10), V = 0 */
    }
    Vector2d V(int k) const /* Table 4.2 */
    {
        if (k < 1 || k > 6) {
            return Vector2d(0.0, 0.0);
        }
        const double a = (k - 1) * M_PI / 3.0;
        return 2.0 / 3.0 * vdc * Vector2d(std::cos(a), std::sin(a));
    }
    /* Te and |psi| at k+2 with V_k on for duty; *tol_t (optional): the torque
     * error budget of the fixed point at this state (see tol_torque). */
    void at(int k, double duty, double *te, double *amp, double *tol_t = nullptr) const
    {
        const Vector2d psi = psi0 + duty * m->ts * V(k);
        const Vector2d dq = Rotation2Dd(-th2) * psi;
        const double id = (dq.x() - m->psi_pm) / m->ld, iq = dq.y() / m->lq; /* (6.12) */
        *te = dq.x() * iq - dq.y() * id;                                     /* (6.11) */
        *amp = psi.norm();
        if (tol_t != nullptr) {
            *tol_t = tol_torque(dq, duty * tsv());
        }
    }
    /* Te = psi_q (a + b psi_d): an error dpsi in each rotor-frame component
     * gives (|a + b psi_d| + |b psi_q|) dpsi. dpsi: the voltage D Ts V turned
     * with table sine/cosine values (error EPS_SC on each: sqrt(2) EPS_SC
     * D Ts |V|), the flux turned by omega Ts with fx_rot_q30 (sqrt(2) EPS_ROT
     * |psi|, EPS_SC beyond pi/2), plus 8 LSB of roundings (Ts V, rotation, sum); plus 4 LSB for
     * the torque's own roundings and the Q24 quantisation of a and b. */
    double tol_torque(const Vector2d &dq, double tsv_d) const
    {
        const double a = m->psi_pm / m->ld, bb = 1.0 / m->lq - 1.0 / m->ld;
        /* fx_rot_q30 takes fx_sincos beyond pi/2 per period */
        const double e_rot = std::fabs(omega * m->ts) <= M_PI / 2 ? EPS_ROT : EPS_SC;
        const double dpsi = std::sqrt(2.0) * (EPS_SC * tsv_d + e_rot * dq.norm()) + 8.0 * LSB;
        return (std::fabs(a + bb * dq.x()) + std::fabs(bb * dq.y())) * dpsi + 4.0 * LSB;
    }
    double tsv() const
    {
        return m->ts * 2.0 / 3.0 * vdc;
    }
};

static int wrap(int x)
{
    return ((x - 1) % 6 + 6) % 6 + 1;
}

struct Stats {
    const char *name;
    int decisions = 0, ties = 0, compared = 0;
    double worst_duty = 0.0, worst_ratio = 0.0;
    void duty(double fixed, double ref, double bound)
    {
        const double e = std::fabs(fixed - ref);
        worst_duty = std::max(worst_duty, e);
        worst_ratio = std::max(worst_ratio, e / bound);
        char msg[160];
        snprintf(msg, sizeof msg, "%s: duty %.9f vs reference %.9f (bound %.2e)", name, fixed, ref,
                 bound);
        TEST_ASSERT_TRUE_MESSAGE(e <= bound, msg);
    }
    void report()
    {
        printf("  %-7s decisions %5d compared %5d ties %3d (%.2f %%)  worst duty error %.3e "
               "(%.2f of its bound)\n",
               name, decisions, compared, ties, 100.0 * ties / decisions, worst_duty, worst_ratio);
        char msg[120];
        snprintf(msg, sizeof msg, "%s: %d ties of %d decisions", name, ties, decisions);
        TEST_ASSERT_TRUE_MESSAGE(ties <= TIE_RATE_MAX * decisions, msg);
        TEST_ASSERT_TRUE(compared > decisions / 2);
    }
};

/* A random k+1 estimate (as in test_mpc.c) and references; psi_ref explicit. */
static void random_point(const ctrl_params_t &p, ctrl_estimate_t &est, ctrl_refs_t &ref)
{
    const double imax = 1.2 * d24(p.current_rated);
    const double id = uni(-0.6 * imax, 0.3 * imax), iq = uni(-imax, imax);
    const fx_angle_t theta = rng_u32();
    std::memset(&est, 0, sizeof est);
    /* the rotor-frame state, as the estimator hands it */
    fixture_state_dq(&p, ctrl_q24_from_double(id), ctrl_q24_from_double(iq), theta, &est.next);
    est.now = est.next;
    est.omega_e = ctrl_q24_from_double(uni(-1.1, 1.1) * d24(p.speed_rated_e));
    est.vdc = ctrl_q24_from_double(d24(p.vdc_nom) * uni(0.9, 1.1));
    fixture_rotation(&p, &est);
    ref.torque = ctrl_q24_from_double(d24(est.next.torque) + uni(-0.3, 0.3) * d24(p.torque_rated));
    ref.psi = ctrl_q24_from_double(d24(est.next.psi_amp) * uni(0.95, 1.05));
}

/* Sector (4.5) of the reference flux; -1 when within the error budget of a boundary. */
static int ref_sector(const Vector2d &psi)
{
    double a = std::atan2(psi.y(), psi.x());
    const double x = (a + M_PI / 6.0) / (M_PI / 3.0); /* sector boundary at integers */
    if (std::fabs(x - std::round(x)) * (M_PI / 3.0) * psi.norm() < 4.0 * LSB) {
        return -1;
    }
    int s = (int)std::ceil(x); /* (2s-3)pi/6 < a <= (2s-1)pi/6 */
    return wrap(s);
}

static void plan_choice(const ctrl_plan_t &out, int *vec, double *duty)
{
    if (out.n_seg == 1u && (out.vec[0] == 0u || out.vec[0] == 7u)) {
        *vec = 0;
        *duty = 0.0;
    } else {
        *vec = out.vec[0];
        *duty = d24(out.dur[0]);
    }
}

/* ------------------------------------------------- k+2 model itself */

/* The fast k+2 model (ctrl_mpc_basis + ctrl_mpc_torque / ctrl_mpc_amp2) against
 * (6.10)-(6.12) in double for every vector and random duties: within the budget. */
static void run_model(const ctrl_machine_t &mach, uint32_t fs, double *e_t, double *e_psi)
{
    ctrl_params_t p;
    ctrl_bases_t b;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&p, &b, &mach, fs));
    const ctrl_setup_t su{&mach, &b, &p};
    const RefMachine rm(mach, fs);
    ctrl_m2ptfc_t s;
    ctrl_m2ptfc_cfg_t cfg;
    ctrl_desc_m2ptfc.cfg_default(&cfg, &mach);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_init(&ctrl_desc_m2ptfc, &s, &cfg, &su));
    for (int n = 0; n < N_POINTS; n++) {
        ctrl_estimate_t est;
        ctrl_refs_t ref;
        random_point(p, est, ref);
        ctrl_mpc_basis_t bs;
        ctrl_mpc_basis(&s.model, &est, &bs);
        const RefPoint rp(rm, est);
        for (uint8_t v = 0; v <= 6; v++) {
            const q24_t duty = v == 0 ? 0 : ctrl_q24_from_double(uni(0.0, 1.0));
            q24_t vd = 0, vq = 0, pd, pq;
            if (v != 0) {
                ctrl_mpc_vec_dq(&bs, v, &vd, &vq);
            }
            ctrl_mpc_flux(&bs, vd, vq, duty, &pd, &pq);
            double te, amp, tol_t;
            rp.at(v, d24(duty), &te, &amp, &tol_t);
            /* ... plus the square's rounding (0.5 LSB of pu^2) seen through the
             * root: 0.25 LSB / |psi| (large only near zero flux), and the scale
             * of the rotations: D Ts V turned with table values (EPS_SC of
             * D Ts |V|), the zero-vector flux by fx_rot_q30 (EPS_ROT of |psi|, the
             * EPS_SC of fx_sincos beyond pi/2 per period) */
            const double e_rot = std::fabs(rp.omega * rm.ts) <= M_PI / 2 ? EPS_ROT : EPS_SC;
            const double tp = tol_psi(rp.vdc) + 0.25 * LSB / std::max(amp, 1e-3) +
                              EPS_SC * d24(duty) * rp.tsv() + e_rot * amp;
            const double et = std::fabs(d24(ctrl_mpc_torque(&s.model, pd, pq)) - te);
            *e_t = std::max(*e_t, et / tol_t);
            /* beyond 8 pu ctrl_mpc_amp2 saturates at 64 pu^2 (ctrl_m2ptfc_model.h):
             * reachable only with flux steps Ts |V| of several pu (small motors
             * on a high DC link), far above any flux reference */
            const double a_fix = std::sqrt(d24(ctrl_mpc_amp2(pd, pq)));
            if (amp < 8.0 - 1e-3) {
                *e_psi = std::max(*e_psi, std::fabs(a_fix - amp) / tp);
            } else {
                TEST_ASSERT_TRUE(a_fix >= 8.0 - 1e-3);
            }
            TEST_ASSERT_TRUE(et <= tol_t);
        }
    }
}

static void test_model_reference(void)
{
    double e_t = 0.0, e_psi = 0.0;
    run_model(ini_thesis_spmsm, 10000u, &e_t, &e_psi);
    run_model(ini_thesis_ipmsm80, 20000u, &e_t, &e_psi);
    /* corner cases of the range (tests/core/machines.h) */
    run_model(machine_small_8v(), 40000u, &e_t, &e_psi);
    run_model(machine_small_60v(), 20000u, &e_t, &e_psi);
    run_model(machine_small_10khz(), 10000u, &e_t, &e_psi);
    run_model(machine_spmsm_1000v(), 10000u, &e_t, &e_psi);
    printf("  k+2 model: worst torque error %.2f of its budget, worst |psi| error %.2f of its "
           "budget\n",
           e_t, e_psi);
    TEST_ASSERT_TRUE(e_t <= 1.0);
    TEST_ASSERT_TRUE(e_psi <= 1.0);
}

/* ---------------------------------------------------------- m2ptfc */

/* centre: the tunable; 1 takes Te of (6.5), (6.7), (6.8) as Te(k+1) + dT0/2
 * (ctrl_m2ptfc.h (**)), dT0 the k+2 zero-vector change of the reference model. */
static void run_m2ptfc(const ctrl_machine_t &mach, uint32_t fs, double centre, Stats &st)
{
    ctrl_params_t p;
    ctrl_bases_t b;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&p, &b, &mach, fs));
    const ctrl_setup_t su{&mach, &b, &p};
    const RefMachine rm(mach, fs);
    ctrl_m2ptfc_t s;
    ctrl_m2ptfc_cfg_t cfg;
    ctrl_desc_m2ptfc.cfg_default(&cfg, &mach);
    cfg.centre = centre;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_init(&ctrl_desc_m2ptfc, &s, &cfg, &su));
    for (int n = 0; n < N_POINTS; n++) {
        ctrl_estimate_t est;
        ctrl_refs_t ref;
        random_point(p, est, ref);
        s.sigma = ctrl_q24_from_double(uni(-0.03, 0.03) * d24(p.torque_rated));
        const double sigma_old = d24(s.sigma);
        ctrl_out_t out_o;
        const ctrl_ctx_t ctx = {&p, &est, &ref};
        ctrl_desc_m2ptfc.step(&s, &ctx, &out_o);
        const ctrl_plan_t &out = out_o.plan;
        st.decisions++;

        const RefPoint rp(rm, est);
        const double t_ref = d24(ref.torque), psi_ref = d24(ref.psi);
        double t0, amp0, tol0;
        rp.at(0, 0.0, &t0, &amp0, &tol0);
        const double d_num = LSB + (centre != 0.0 ? 0.5 * tol0 : 0.0); /* budget of up */
        const double te = centre != 0.0 ? rp.t1 + 0.5 * (t0 - rp.t1) : rp.t1;
        /* (6.8), holding while the error exceeds one period's largest change:
         * A (5.9) plus the zero vector's */
        const double a_step = mach.pole_pairs * mach.vdc_v * mach.psi_pm_wb /
                                  (static_cast<double>(fs) * mach.ld_h) / b.torque_nm +
                              std::fabs(t0 - rp.t1);
        if (std::fabs(std::fabs(t_ref - te) - a_step) < 4.0 * d_num) {
            st.ties++; /* hold or not decided within the rounding of Te */
            continue;
        }
        const double sigma = std::fabs(t_ref - te) > a_step
                                 ? sigma_old
                                 : 0.03 * (t_ref - te) + 0.97 * sigma_old; /* (6.8) */
        const int x = ref_sector(rp.psi1);
        if (x < 0) {
            st.ties++;
            continue;
        }
        TEST_ASSERT_EQUAL_INT(x, est.next.sector);
        const double up = t_ref + sigma - te; /* numerator of (6.5) */
        if (std::fabs(up) < 2.0 * d_num) {
            st.ties++; /* (6.7) set undecided within the sigma rounding */
            continue;
        }
        const int base = up >= 0.0 ? 1 : 4; /* (6.7) */
        int cand[2] = {wrap(x + base), wrap(x + base + 1)};
        double duty[2], bound[2], g[2];
        bool tie = false;
        for (int k = 0; k < 2; k++) {
            double t_full, amp, tol_full;
            rp.at(cand[k], 1.0, &t_full, &amp, &tol_full);
            const double den = t_full - rp.t1 + 2.0 * sigma;
            const double d_den = tol_full + 2.0 * LSB;
            double d = up / den;
            bound[k] = (d_num + std::fabs(d) * d_den) / std::fabs(den) + LSB;
            if (std::fabs(den) <= d_den || std::fabs(d) <= bound[k]) {
                tie = true; /* (6.6) edge: D = 0 vs 1 flips within the budget */
            }
            if (d < 0.0 || d > 1.0) {
                if (d < -bound[k] || d > 1.0 + bound[k]) {
                    bound[k] = 0.0; /* clamped beyond the budget: exact */
                }
                d = 1.0; /* (6.6) */
            }
            duty[k] = d;
            double te;
            rp.at(cand[k], d, &te, &amp);
            g[k] = std::fabs(psi_ref - amp); /* (6.9) */
        }
        const double g_tol = 2.0 * tol_psi(rp.vdc) + rp.tsv() * (bound[0] + bound[1]);
        if (tie || std::fabs(g[0] - g[1]) <= g_tol) {
            st.ties++;
            continue;
        }
        const int best = g[1] < g[0] ? 1 : 0;
        int vec;
        double dfix;
        plan_choice(out, &vec, &dfix);
        char msg[160];
        snprintf(msg, sizeof msg, "m2ptfc: vector %d vs reference %d (g %.3e %.3e)", vec,
                 cand[best], g[0], g[1]);
        TEST_ASSERT_EQUAL_INT_MESSAGE(cand[best], vec, msg);
        st.compared++;
        st.duty(dfix, duty[best], bound[best] + LSB);
        st.duty(d24(s.trace.duty[1 - best]), duty[1 - best], bound[1 - best] + LSB);
    }
}

static void test_m2ptfc_reference(void)
{
    Stats st{"m2ptfc"};
    run_m2ptfc(ini_thesis_spmsm, 10000u, 1.0, st);
    run_m2ptfc(ini_thesis_ipmsm80, 20000u, 1.0, st);
    run_m2ptfc(ini_thesis_spmsm, 10000u, 0.0, st);
    run_m2ptfc(machine_small_8v(), 40000u, 1.0, st);
    run_m2ptfc(machine_small_60v(), 20000u, 1.0, st);
    run_m2ptfc(machine_small_10khz(), 10000u, 1.0, st);
    st.report();
}

/* ------------------------------------------------ weighted baselines */

enum Kind { K_M1, K_MPTFC, K_M3 };

struct Cand {
    int vec;
    double duty, bound, g, g_tol;
};

static void run_weighted(Kind kind, const ctrl_machine_t &mach, uint32_t fs, Stats &st)
{
    const ctrl_desc_t *d = kind == K_M1      ? &ctrl_desc_m1
                           : kind == K_MPTFC ? &ctrl_desc_mptfc
                                             : &ctrl_desc_m3;
    ctrl_params_t p;
    ctrl_bases_t b;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&p, &b, &mach, fs));
    const ctrl_setup_t su{&mach, &b, &p};
    const RefMachine rm(mach, fs);
    alignas(8) unsigned char state[CTRL_STATE_MAX], cfg[CTRL_CFG_MAX];
    d->cfg_default(cfg, &mach);
    double zeta_si = 0.0;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_tunable_get(d, cfg, "zeta", &zeta_si));
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_init(d, state, cfg, &su));
    if (zeta_si == 0.0) {
        zeta_si = mach.torque_rated_nm / mach.psi_pm_wb; /* 0 = equal importance (6.5) */
    }
    const double zeta = zeta_si * rm.psi_base / rm.t_base; /* N*m/Wb -> pu */
    for (int n = 0; n < N_POINTS; n++) {
        ctrl_estimate_t est;
        ctrl_refs_t ref;
        random_point(p, est, ref);
        ctrl_out_t out_o;
        const ctrl_ctx_t ctx = {&p, &est, &ref};
        d->step(state, &ctx, &out_o);
        const ctrl_plan_t &out = out_o.plan;
        st.decisions++;

        const RefPoint rp(rm, est);
        const double t_ref = d24(ref.torque), psi_ref = d24(ref.psi);
        double t0, a0, tol0;
        rp.at(0, 0.0, &t0, &a0, &tol0);
        Cand c[8];
        int nc = 0;
        bool tie = false;
        auto add = [&](int v, bool full) {
            Cand k{v, 0.0, 0.0, 0.0, 0.0};
            double t_full = t0, amp, tol_full = tol0;
            if (v != 0) {
                rp.at(v, 1.0, &t_full, &amp, &tol_full);
            }
            if (v == 0) {
                k.duty = 0.0;
            } else if (full) {
                k.duty = 1.0;
            } else { /* (5.18) saturated */
                const double num = t_ref - t0, den = t_full - t0;
                const double d_num = tol0, d_den = tol0 + tol_full;
                double df = den != 0.0 ? num / den : (num > 0.0 ? 1.0 : 0.0);
                k.bound = (d_num + std::fabs(df) * d_den) / std::fabs(den) + LSB;
                if (std::fabs(den) <= d_den) {
                    tie = true;
                }
                k.duty = df < 0.0 ? 0.0 : (df > 1.0 ? 1.0 : df);
                if (df < -k.bound || df > 1.0 + k.bound) {
                    k.bound = 0.0; /* saturated beyond the budget: duty exact */
                }
            }
            double te, tol_te;
            rp.at(v, k.duty, &te, &amp, &tol_te);
            k.g = std::fabs(t_ref - te) + zeta * std::fabs(psi_ref - amp); /* (6.13) */
            k.g_tol = tol_te + zeta * tol_psi(rp.vdc) +
                      (std::fabs(t_full - t0) + zeta * rp.tsv()) * k.bound;
            c[nc++] = k;
        };
        if (kind == K_M1) {
            for (int v = 1; v <= 6; v++) {
                add(v, false);
            }
        } else if (kind == K_MPTFC) {
            for (int v = 0; v <= 6; v++) {
                add(v, true);
            }
        } else {
            const int x = ref_sector(rp.psi1);
            if (x < 0 || std::fabs(t_ref - rp.t1) < LSB) {
                st.ties++;
                continue;
            }
            if (t_ref >= rp.t1) { /* (6.1) by the torque-error sign */
                add(wrap(x + 1), false);
                add(wrap(x + 2), false);
            } else {
                add(wrap(x + 5), false);
                add(wrap(x + 4), false);
            }
            add(0, true);
        }
        int best = 0;
        for (int k = 1; k < nc; k++) {
            if (c[k].g < c[best].g) {
                best = k;
            }
        }
        /* A zero duty is the zero vector all period whatever the active vector:
         * such candidates are one action (same prediction, same cost). */
        auto is_zero = [&](const Cand &k) { return k.vec == 0 || k.duty == 0.0; };
        for (int k = 0; k < nc; k++) {
            if (k != best && !(is_zero(c[k]) && is_zero(c[best])) &&
                c[k].g - c[best].g <= c[k].g_tol + c[best].g_tol) {
                tie = true;
            }
        }
        if (tie) {
            st.ties++;
            continue;
        }
        int vec;
        double dfix;
        plan_choice(out, &vec, &dfix);
        st.compared++;
        if (is_zero(c[best])) { /* any vector at (about) zero duty is this action */
            TEST_ASSERT_TRUE_MESSAGE(vec == 0 || dfix <= c[best].bound + LSB,
                                     "zero-vector action expected");
            continue;
        }
        char msg[160];
        snprintf(msg, sizeof msg, "%s: vector %d vs reference %d", st.name, vec, c[best].vec);
        TEST_ASSERT_EQUAL_INT_MESSAGE(c[best].vec, vec, msg);
        st.duty(dfix, c[best].duty, c[best].bound + LSB);
    }
}

static void test_m1_reference(void)
{
    Stats st{"m1"};
    run_weighted(K_M1, ini_thesis_spmsm, 10000u, st);
    run_weighted(K_M1, ini_thesis_ipmsm80, 20000u, st);
    st.report();
}

static void test_mptfc_reference(void)
{
    Stats st{"mptfc"};
    run_weighted(K_MPTFC, ini_thesis_spmsm, 10000u, st);
    run_weighted(K_MPTFC, ini_thesis_ipmsm80, 20000u, st);
    st.report();
}

static void test_m3_reference(void)
{
    Stats st{"m3"};
    run_weighted(K_M3, ini_thesis_spmsm, 12000u, st);
    run_weighted(K_M3, ini_thesis_ipmsm80, 20000u, st);
    st.report();
}

/* --------------------------------------------------------------- m2 */

static void run_m2(const ctrl_machine_t &mach, uint32_t fs, Stats &st)
{
    ctrl_params_t p;
    ctrl_bases_t b;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&p, &b, &mach, fs));
    const ctrl_setup_t su{&mach, &b, &p};
    const RefMachine rm(mach, fs);
    ctrl_m2_t s;
    ctrl_m2_cfg_t cfg;
    ctrl_desc_m2.cfg_default(&cfg, &mach);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_init(&ctrl_desc_m2, &s, &cfg, &su));
    const double eps = cfg.eps_psi / rm.psi_base;
    const int y = (int)cfg.y;
    for (int n = 0; n < N_POINTS; n++) {
        ctrl_estimate_t est;
        ctrl_refs_t ref;
        random_point(p, est, ref);
        ctrl_out_t out_o;
        const ctrl_ctx_t ctx = {&p, &est, &ref};
        ctrl_desc_m2.step(&s, &ctx, &out_o);
        const ctrl_plan_t &out = out_o.plan;
        st.decisions++;

        const RefPoint rp(rm, est);
        const double t_ref = d24(ref.torque), psi_ref = d24(ref.psi);
        double t0, a0, tol0;
        rp.at(0, 0.0, &t0, &a0, &tol0);
        const int x = ref_sector(rp.psi1);
        if (x < 0 || std::fabs(t_ref - t0) <= tol0 || std::fabs(psi_ref - a0) <= tol_psi(rp.vdc)) {
            st.ties++;
            continue;
        }
        const bool t_up = t_ref >= t0, f_up = psi_ref >= a0; /* Table 4.1 */
        const int v = wrap(x + (t_up ? (f_up ? 1 : 2) : (f_up ? 5 : 4)));
        int best = -1, best_f = 0;
        double best_g = 1e300, best_fe = 1e300;
        bool tie = false;
        double gs[CTRL_M2_Y_MAX + 1], tols[CTRL_M2_Y_MAX + 1];
        bool feas[CTRL_M2_Y_MAX + 1];
        for (int nu = 0; nu <= y; nu++) {
            double te, amp;
            rp.at(v, (double)nu / y, &te, &amp, &tols[nu]); /* (6.15) */
            const double fe = std::fabs(psi_ref - amp);
            if (std::fabs(fe - eps) <= 2.0 * tol_psi(rp.vdc)) {
                tie = true; /* band edge (6.17) within the budget */
            }
            feas[nu] = fe <= eps;
            gs[nu] = std::fabs(t_ref - te); /* (6.16) */
            if (feas[nu] && gs[nu] < best_g) {
                best_g = gs[nu];
                best = nu;
            }
            if (fe < best_fe) {
                best_fe = fe;
                best_f = nu;
            }
        }
        for (int nu = 0; nu <= y && best >= 0; nu++) {
            if (nu != best && feas[nu] && gs[nu] - best_g <= tols[nu] + tols[best]) {
                tie = true;
            }
        }
        if (tie) {
            st.ties++;
            continue;
        }
        if (best < 0) {
            best = best_f; /* no feasible candidate: smallest flux error */
        }
        int vec;
        double dfix;
        plan_choice(out, &vec, &dfix);
        const int want = best == 0 ? 0 : v;
        char msg[120];
        snprintf(msg, sizeof msg, "m2: vector %d vs reference %d (nu %d)", vec, want, best);
        TEST_ASSERT_EQUAL_INT_MESSAGE(want, vec, msg);
        st.compared++;
        if (vec != 0) {
            st.duty(dfix, (double)best / y, 2.0 * LSB);
        }
    }
}

static void test_m2_reference(void)
{
    Stats st{"m2"};
    run_m2(ini_thesis_spmsm, 10000u, st);
    run_m2(ini_thesis_ipmsm80, 20000u, st);
    st.report();
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_model_reference);
    RUN_TEST(test_m2ptfc_reference);
    RUN_TEST(test_m1_reference);
    RUN_TEST(test_mptfc_reference);
    RUN_TEST(test_m3_reference);
    RUN_TEST(test_m2_reference);
    return UNITY_END();
}
