/*
 * Double-precision reference of the control core (C++17, Eigen 3), driven with
 * the same randomised inputs as the fixed-point code over the whole operating
 * range: the thesis SPMSM, the 80 kW IPMSM and the chapter IPMSM at 10 and
 * 20 kHz, and the corner cases of the range the core takes (machines.h: a
 * 0.3 mWb / 10 uH / 20 mOhm motor on 8 V and 60 V at 20 and 40 kHz, with
 * 4 pole pairs at 10, 20 and 40 kHz, the SPMSM on 1000 V), current vectors of
 * any direction up to current_max (motoring and braking), both rotation
 * directions up to 1.2x rated speed, any rotor angle, every voltage vector
 * with any duty and the DC link within +-10 % of nominal.
 *
 * Equations (reference side, all in double, parameters from the SI data):
 *   Clarke (3.3), Park (3.7), current model (3.9), torque (3.10)/(3.6),
 *   amplitude (4.3), sector (4.5), average plan voltage (4.4),
 *   prediction (5.15)/(6.10)-(6.12) generalised to Ld != Lq, MTPA (4.15).
 *
 * Each comparison is asserted against the error bound derived from the Q
 * formats (docs/error-budget.md); the bound is evaluated per
 * sample from the magnitudes involved. The worst measured errors are printed.
 */
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>

extern "C" {
#include "angle_source.h"
#include "ctrl_params.h"
#include "ctrl_types.h"
#include "estimator.h"
#include "fx.h"
#include "machines.h"
#include "mtpa.h"
#include "plan.h"
#include "transforms.h"
#include "unity.h"
#include "vectors.h"
}

void setUp(void)
{
}
void tearDown(void)
{
}

namespace
{

using Eigen::Matrix2d;
using Eigen::Vector2d;

constexpr double kPi = 3.14159265358979323846;
constexpr double L = 1.0 / 16777216.0; // 1 LSB of Q24
constexpr double S = 0.5 * L + 2.0e-9; // fx_sincos bound (docs/fixed-point.md)
constexpr double EROT = 3.0e-9;        // fx_rot_q30 bound up to pi/2

double d(q24_t x)
{
    return static_cast<double>(x) * L;
}
q24_t q(double x)
{
    return ctrl_q24_from_double(x);
}

// Exact per-unit model of one machine (from the SI data and the bases of
// docs/fixed-point.md, not from ctrl_params_t): psi_base = psi_pm, w_base =
// the rated electrical speed, v_base = psi_base w_base, l_base = Ld.
struct RefMachine {
    double ts, rs, lq, vdc; // pu (ld = psi_pm = 1 by the bases)
    RefMachine(const ctrl_machine_t &m, uint32_t fs)
    {
        const double wb = m.pole_pairs * m.speed_rated_rpm * 2 * kPi / 60.0;
        const double vb = m.psi_pm_wb * wb;
        const double ib = m.psi_pm_wb / m.ld_h;
        ts = wb / fs;
        rs = m.rs_ohm / (vb / ib);
        lq = m.lq_h / m.ld_h;
        vdc = m.vdc_v / vb;
    }
};

Matrix2d rot(double th) // e^{j th}
{
    Matrix2d r;
    r << std::cos(th), -std::sin(th), std::sin(th), std::cos(th);
    return r;
}

struct RefState {
    Vector2d i_ab, i_dq, psi_ab, psi_dq;
    double torque, amp;
    int sector;
    double theta;
};

// (3.9) and (3.10) from a current.
RefState ref_from_current(const RefMachine &m, const Vector2d &i_ab, double th)
{
    RefState s;
    s.i_ab = i_ab;
    s.i_dq = rot(-th) * i_ab;                               // (3.7)
    s.psi_dq = Vector2d(s.i_dq(0) + 1.0, m.lq * s.i_dq(1)); // (3.9)
    s.psi_ab = rot(th) * s.psi_dq;
    s.torque = s.psi_dq(0) * s.i_dq(1) - s.psi_dq(1) * s.i_dq(0); // (3.10)
    s.amp = s.psi_dq.norm();                                      // (4.3)
    s.theta = th;
    return s;
}

// (3.9) inverted, from a flux (6.12).
RefState ref_from_flux(const RefMachine &m, const Vector2d &psi_ab, double th)
{
    RefState s;
    s.psi_ab = psi_ab;
    s.psi_dq = rot(-th) * psi_ab;
    s.i_dq = Vector2d(s.psi_dq(0) - 1.0, s.psi_dq(1) / m.lq);
    s.i_ab = rot(th) * s.i_dq;
    s.torque = psi_ab(0) * s.i_ab(1) - psi_ab(1) * s.i_ab(0); // (3.6)
    s.amp = psi_ab.norm();
    s.theta = th;
    return s;
}

// Sector (4.5) by the definition, from the angle.
int ref_sector(const Vector2d &v)
{
    double t = std::atan2(v(1), v(0));
    if (t < 0)
        t += 2 * kPi;
    int x = static_cast<int>(std::ceil((t + kPi / 6.0) / (kPi / 3.0)));
    if (x > 6)
        x -= 6;
    return x < 1 ? 1 : x;
}

// Distance (rad) from the angle of v to the nearest sector boundary of (4.5).
double boundary_distance(const Vector2d &v)
{
    const double t = std::atan2(v(1), v(0));
    double best = 10.0;
    for (int x = -6; x <= 7; x++) {
        best = std::min(best, std::fabs(t - (2 * x - 1) * kPi / 6.0));
    }
    return best;
}

// (4.4) averaged over the plan.
Vector2d ref_plan_voltage(const ctrl_plan_t &p, double vdc)
{
    static const int legs[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                   {0, 1, 1}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}};
    Vector2d v(0, 0);
    for (unsigned k = 0; k < p.n_seg; k++) {
        const int *s = legs[p.vec[k]];
        const Vector2d vk =
            2.0 / 3.0 * vdc *
            Vector2d(s[0] - 0.5 * s[1] - 0.5 * s[2], std::sqrt(3.0) / 2.0 * (s[1] - s[2]));
        v += d(p.dur[k]) * vk;
    }
    return v;
}

struct Worst {
    const char *name;
    double err = 0.0;   // worst absolute error, pu
    double ratio = 0.0; // worst error / bound
    void add(double e, double bound)
    {
        err = std::max(err, e);
        ratio = std::max(ratio, e / bound);
        if (e > bound) {
            char msg[160];
            std::snprintf(msg, sizeof msg, "%s: error %.3g pu above bound %.3g pu", name, e, bound);
            TEST_FAIL_MESSAGE(msg);
        }
    }
};

Worst w_clarke{"clarke beta"}, w_idq{"i_dq (k)"}, w_psid{"psi_d (k)"}, w_psiq{"psi_q (k)"},
    w_psiab{"psi_ab (k)"}, w_t{"torque (k)"}, w_amp{"|psi| (k)"}, w_v{"plan voltage"},
    w_psi1{"psi_dq (k+1)"}, w_th1{"theta (k+1), rad"}, w_i1{"i_dq (k+1)"}, w_t1{"torque (k+1)"},
    w_amp1{"|psi| (k+1)"}, w_psiab1{"psi_ab (k+1)"}, w_iab1{"i_ab (k+1)"}, w_mtpa_s{"MTPA SPMSM"},
    w_mtpa_i{"MTPA IPMSM"};
long sector_mismatch = 0, sector_total = 0;
long quadrant_count[4] = {0, 0, 0, 0};

void check_sector(uint8_t got, const Vector2d &psi_ref, double e_psi)
{
    sector_total++;
    const int want = ref_sector(psi_ref);
    if (got == want)
        return;
    sector_mismatch++;
    // allowed only within the angular uncertainty of the flux near a boundary
    const double dist = boundary_distance(psi_ref);
    TEST_ASSERT_TRUE_MESSAGE(dist <= 2.0 * e_psi / psi_ref.norm() + 1e-12,
                             "sector differs away from a boundary");
}

void run_machine(const ctrl_machine_t &mach, uint32_t fs, int n, std::mt19937_64 &gen)
{
    ctrl_params_t p;
    ctrl_bases_t b;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&p, &b, &mach, fs));
    const RefMachine rm(mach, fs);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    const double imax = mach.current_max_a / (mach.psi_pm_wb / mach.ld_h);
    const double wmax = 1.2; // rated speed = 1 pu
    // parameter quantisation (0.5 LSB each, ld / inv_ld / psi_pm exact)
    const double lq_q = d(p.lq), inv_lq_q = d(p.inv_lq);
    TEST_ASSERT_TRUE(std::fabs(lq_q - rm.lq) <= 0.5 * L && std::fabs(d(p.ts) - rm.ts) <= 0.5 * L);

    ctrl_estimator_t e;
    ctrl_estimator_init(&e, &p);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_estimator_set_angle_src(&e, &p, &ctrl_angle_forced));
    for (int k = 0; k < n; k++) {
        // ---- inputs (identical for both sides) ----
        const double imag = imax * std::sqrt(u01(gen)); // uniform over the disc
        const double iang = 2 * kPi * u01(gen);
        const q24_t ia_q = q(imag * std::cos(iang));
        const q24_t ib_q = q(imag * (-0.5 * std::cos(iang) + std::sqrt(3.0) / 2 * std::sin(iang)));
        const fx_angle_t th_q = static_cast<fx_angle_t>(gen());
        const double th = th_q * (2 * kPi / 4294967296.0);
        const q24_t w_q = q(wmax * (2 * u01(gen) - 1));
        const q24_t vdc_q = q(rm.vdc * (0.9 + 0.2 * u01(gen)));
        ctrl_plan_t plan;
        const uint8_t vec = static_cast<uint8_t>(gen() % 8u);
        if (gen() % 2u) {
            ctrl_plan_active_zero(&plan, vec, q(u01(gen)));
        } else {
            const q24_t d1 = q(u01(gen));
            const q24_t d2 = static_cast<q24_t>((FX_ONE - d1) * u01(gen));
            plan.n_seg = 3u;
            plan.vec[0] = vec;
            plan.dur[0] = d1;
            plan.vec[1] = ctrl_vec_wrap(vec + 1);
            plan.dur[1] = d2;
            plan.vec[2] = ctrl_zero_after(vec);
            plan.dur[2] = FX_ONE - d1 - d2;
        }
        const double ia = d(ia_q), ib = d(ib_q), w = d(w_q), vdc = d(vdc_q);

        // ---- fixed point: the estimator, theta and omega from the forced source ----
        ctrl_angle_forced_set(ctrl_estimator_angle_state(&e), &p, th_q, w_q);
        const ctrl_meas_t meas{ia_q, ib_q, vdc_q, th_q};
        ctrl_legs_t legs;
        ctrl_plan_legs(&plan, &legs);
        ctrl_estimate_t est;
        ctrl_estimator_update(&e, &p, &meas, &legs, &est);
        const ctrl_mstate_t &now = est.now;
        const ctrl_mstate_t &next = est.next;
        q24_t va, vb;
        ctrl_legs_voltage(&legs, vdc_q, &va, &vb);

        // ---- reference ----
        const Vector2d i_ab(ia, (ia + 2 * ib) / std::sqrt(3.0)); // (3.3), i_c = -i_a - i_b
        const RefState r0 = ref_from_current(rm, i_ab, th);
        const Vector2d v = ref_plan_voltage(plan, vdc);
        const Vector2d psi1 = r0.psi_ab + rm.ts * (v - rm.rs * r0.i_ab); // (5.15)/(6.10)
        const double th1 = th + w * rm.ts;                               // (6.12)
        const RefState r1 = ref_from_flux(rm, psi1, th1);
        const int quad = (r0.torque >= 0 ? 0 : 1) + (w * r0.torque >= 0 ? 0 : 2);
        quadrant_count[quad]++;

        // ---- bounds (docs/error-budget.md) ----
        const double e_beta = 0.5 * L + std::ldexp(std::fabs(ia) + std::fabs(ib), -31);
        w_clarke.add(std::fabs(d(now.i_beta) - i_ab(1)) + std::fabs(d(now.i_alpha) - i_ab(0)),
                     e_beta);

        const double ai = std::fabs(i_ab(0)) + std::fabs(i_ab(1));
        const double e_i = 0.5 * L + S * ai + e_beta;
        const double id = std::fabs(r0.i_dq(0)), iq = std::fabs(r0.i_dq(1));
        const double pd = std::fabs(r0.psi_dq(0)), pq = std::fabs(r0.psi_dq(1));
        const double e_pd = e_i;
        const double e_pq = 0.5 * L + 0.5 * L * iq + lq_q * e_i;
        w_idq.add(std::max(std::fabs(d(now.i_d) - r0.i_dq(0)), std::fabs(d(now.i_q) - r0.i_dq(1))),
                  e_i);
        w_psid.add(std::fabs(d(now.psi_d) - r0.psi_dq(0)), e_pd);
        w_psiq.add(std::fabs(d(now.psi_q) - r0.psi_dq(1)), e_pq);
        const double e_T =
            0.5 * L + pd * e_i + iq * e_pd + pq * e_i + id * e_pq + (e_pd + e_pq) * e_i;
        w_t.add(std::fabs(d(now.torque) - r0.torque), e_T);
        w_amp.add(std::fabs(d(now.psi_amp) - r0.amp), 0.5 * L + e_pd + e_pq);
        const double e_pab = 0.5 * L + S * (pd + pq) + e_pd + e_pq;
        w_psiab.add(std::max(std::fabs(d(now.psi_alpha) - r0.psi_ab(0)),
                             std::fabs(d(now.psi_beta) - r0.psi_ab(1))),
                    e_pab);
        check_sector(now.sector, r0.psi_ab, e_pab);

        const double e_v = 0.5 * L + vdc * (0.5 * L + 1e-9);
        w_v.add(std::max(std::fabs(d(va) - v(0)), std::fabs(d(vb) - v(1))), e_v);

        // k+1 in the rotor frame: psi' = psi_dq + (Ts Vdc) Park(u) - Ts Rs i_dq
        // in the (table) frame at k, then turned by the quantised omega Ts.
        // u = the duties' voltage per unit of DC link (|u| <= 2/3, 0.5 LSB),
        // Park of u (0.5 LSB + S (|u_a| + |u_b|) + u's roundings), Ts Vdc
        // rounded (0.5 LSB) and its product (0.5 LSB); Ts Rs i (0.5 LSB +
        // Ts Rs e_i + the Q24 quantisation of Ts Rs).
        const Vector2d u = v / vdc;
        const double au = std::fabs(u(0)) + std::fabs(u(1));
        const double tsv = rm.ts * vdc;
        const double e_ud = 0.5 * L + S * au + 1.5 * L;
        const double e_inc = 0.5 * L + (2.0 / 3.0) * (0.5 * L + tsv * 1e-7) + tsv * e_ud;
        const double e_rsi = 0.5 * L + rm.ts * rm.rs * e_i + 0.5 * L * std::max(id, iq);
        const double e_h = std::max(e_pd, e_pq) + e_inc + e_rsi;
        const double ah = psi1.norm();
        // the frame turned by dtheta: fx_rot_q30 (EROT per cosine and sine, or
        // fx_sincos beyond pi/2), the angle quantised (e_th), one rounding
        const double e_th = 2 * kPi / 4294967296.0 * (0.5 + 0.5 * std::fabs(w));
        const double e_rot = std::fabs(w) * rm.ts <= kPi / 2 ? EROT : S;
        const double e_p1 = e_h + std::sqrt(2.0) * (e_rot + e_th) * ah + 0.5 * L;
        w_psi1.add(std::max(std::fabs(d(next.psi_d) - r1.psi_dq(0)),
                            std::fabs(d(next.psi_q) - r1.psi_dq(1))),
                   e_p1);
        double dth = next.theta_e * (2 * kPi / 4294967296.0) - std::fmod(th1, 2 * kPi);
        dth = std::remainder(dth, 2 * kPi);
        w_th1.add(std::fabs(dth), e_th + 1e-15);
        const double id1 = std::fabs(r1.i_dq(0)), iq1 = std::fabs(r1.i_dq(1));
        const double pd1 = std::fabs(r1.psi_dq(0)), pq1 = std::fabs(r1.psi_dq(1));
        const double e_id1 = 0.5 * L + e_p1;
        const double e_iq1 = 0.5 * L + 0.5 * L * pq1 + inv_lq_q * e_p1;
        w_i1.add(std::max(std::fabs(d(next.i_d) - r1.i_dq(0)), std::fabs(d(next.i_q) - r1.i_dq(1))),
                 std::max(e_id1, e_iq1));
        const double e_T1 = 0.5 * L + pd1 * e_iq1 + iq1 * e_p1 + pq1 * e_id1 + id1 * e_p1 +
                            2 * e_p1 * (e_id1 + e_iq1);
        w_t1.add(std::fabs(d(next.torque) - r1.torque), e_T1);
        // |psi(k+1)| from psi' (rotation-invariant), the stator-frame flux by the
        // inverse Park at k (table), the sector from it
        w_amp1.add(std::fabs(d(next.psi_amp) - r1.amp), 0.5 * L + 2 * e_h);
        const double e_pab1 = e_h + 0.5 * L + std::sqrt(2.0) * S * ah;
        w_psiab1.add(
            std::max(std::fabs(d(next.psi_alpha) - psi1(0)), std::fabs(d(next.psi_beta) - psi1(1))),
            e_pab1);
        check_sector(next.sector, psi1, e_pab1);
        // the current at k+1 in the stator frame: sine and cosine at k+1 by
        // turning those at k (S + e_rot + e_th + 1 LSB)
        const double e_sc1 = S + e_rot + e_th + L;
        const double e_iab1 = 0.5 * L + std::max(e_id1, e_iq1) * std::sqrt(2.0) +
                              std::sqrt(2.0) * e_sc1 * (id1 + iq1);
        w_iab1.add(std::max(std::fabs(d(next.i_alpha) - r1.i_ab(0)),
                            std::fabs(d(next.i_beta) - r1.i_ab(1))),
                   e_iab1);
    }

    // MTPA over the torque range up to the torque at current_max.
    for (int k = 0; k <= 400; k++) {
        const double i = imax * k / 400.0;
        if (!p.salient) {
            const q24_t t_q = q(i); // Te = i_q at MTPA (pu)
            const double t_si = d(t_q) * b.torque_nm;
            // (4.15) in SI
            const double psi_si = std::sqrt(
                mach.psi_pm_wb * mach.psi_pm_wb +
                std::pow(2 * mach.ld_h * t_si / (3 * mach.pole_pairs * mach.psi_pm_wb), 2));
            const double ref = psi_si / mach.psi_pm_wb;
            w_mtpa_s.add(std::fabs(d(ctrl_mtpa_psi(&p, t_q)) - ref),
                         1.0 * L + 0.5 * L * d(t_q) + 1e-12);
        } else {
            // exact MTPA by direct maximisation over the current angle (golden section)
            double a = -kPi / 2, cc = kPi / 2;
            const double g = (std::sqrt(5.0) - 1) / 2;
            auto torque = [&](double beta) {
                const double idv = -i * std::sin(beta), iqv = i * std::cos(beta);
                return iqv * (1 + (1 - rm.lq) * idv);
            };
            for (int it = 0; it < 200; it++) {
                const double x1 = cc - g * (cc - a), x2 = a + g * (cc - a);
                if (torque(x1) > torque(x2))
                    cc = x2;
                else
                    a = x1;
            }
            const double beta = 0.5 * (a + cc);
            const double idv = -i * std::sin(beta), iqv = i * std::cos(beta);
            const double t = torque(beta);
            const q24_t t_q = q(t);
            // reference at the quantised torque: psi(T) slope dpsi/dT < 2 -> 1 LSB
            const double psi = std::hypot(1 + idv, rm.lq * iqv);
            const double h = d(p.mtpa_t_max) / CTRL_MTPA_N;
            const double curv = (rm.lq - 1) * (rm.lq - 1) + 1;
            w_mtpa_i.add(std::fabs(d(ctrl_mtpa_psi(&p, t_q)) - psi), h * h / 8 * curv + 2.0 * L);
        }
    }
}

void test_reference_all_machines()
{
    std::mt19937_64 gen(20240601u);
    const ctrl_machine_t machines[] = {machine_thesis_spmsm(), machine_thesis_ipmsm80(),
                                       machine_chapter_ipmsm()};
    for (const ctrl_machine_t &m : machines) {
        run_machine(m, 10000u, 10000, gen);
        run_machine(m, 20000u, 10000, gen);
    }
    // corner cases of the range (machines.h), at the rates their rated speed allows
    const ctrl_machine_t s8 = machine_small_8v(), s60 = machine_small_60v(),
                         s10 = machine_small_10khz(), h = machine_spmsm_1000v();
    run_machine(s8, 20000u, 4000, gen);
    run_machine(s8, 40000u, 4000, gen);
    run_machine(s60, 20000u, 4000, gen);
    run_machine(s60, 40000u, 4000, gen);
    run_machine(s10, 10000u, 4000, gen);
    run_machine(s10, 40000u, 4000, gen);
    run_machine(h, 10000u, 4000, gen);
    // the random drive covered all four quadrants of Fig. 3.9
    for (long c : quadrant_count)
        TEST_ASSERT_TRUE(c > 5000);
    const Worst *all[] = {&w_clarke, &w_idq,    &w_psid, &w_psiq,   &w_psiab, &w_t,
                          &w_amp,    &w_v,      &w_psi1, &w_th1,    &w_i1,    &w_t1,
                          &w_amp1,   &w_psiab1, &w_iab1, &w_mtpa_s, &w_mtpa_i};
    std::printf("%-18s %14s %10s %10s\n", "quantity", "worst err (pu)", "(LSB)", "err/bound");
    for (const Worst *x : all) {
        std::printf("%-18s %14.3e %10.2f %10.3f\n", x->name, x->err, x->err / L, x->ratio);
    }
    std::printf("sector differences near boundaries: %ld of %ld\n", sector_mismatch, sector_total);
    std::printf("quadrants (fwd mot, fwd brake, bwd brake/mot): %ld %ld %ld %ld\n",
                quadrant_count[0], quadrant_count[1], quadrant_count[2], quadrant_count[3]);
}

} // namespace

int main()
{
    UNITY_BEGIN();
    RUN_TEST(test_reference_all_machines);
    return UNITY_END();
}
