/*
 * Double-precision reference of the field-weakening limits
 * (control/regulators/field_weak.h), C++17: the same equations from the SI
 * machine data and the SI bases (no base value assumed), driven with the
 * fixed-point code's random inputs: three machines (thesis SPMSM, 80 kW IPMSM
 * in MTPA mode and with its fixed 0.1837 Wb, chapter IPMSM) at 10 and 20 kHz;
 * DC link 0.6..1.2 x nominal, electrical speed up to +-3x rated, torque
 * requests up to +-1.5x the MTPA torque at the current limit (motoring and
 * braking), commanded flux amplitudes or none.
 *
 * Checked per sample, each against the bound its Q formats predict
 * (docs/error-budget.md, "Field weakening"):
 *   psi_max   = sqrt(V^2 - (Rs I)^2 - 2 Rs w T_prev) / |w|, capped, with
 *               T_prev the low-passed torque, I = min(|T_prev| / psi_pm, I_max);
 *   T_lim(psi) at the fixed-point psi (the flux-circle part alone);
 *   the limit kind away from the decision boundaries;
 *   torque = clamp(request) and psi_ref = min(own reference, psi_max), exactly;
 *   the FOC currents on the flux circle after convergence.
 * The worst errors and error/bound ratios are printed.
 */
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>

extern "C" {
#include "ctrl_params.h"
#include "field_weak.h"
#include "field_weak_config.h"
#include "fx.h"
#include "mtpa.h"
#include "unity.h"

#include "../plant/ini_machines.h"
}

void setUp(void)
{
}
void tearDown(void)
{
}

namespace
{

constexpr double L = 1.0 / 16777216.0; // 1 LSB of Q24

double d(q24_t x)
{
    return static_cast<double>(x) * L;
}
q24_t q(double x)
{
    return ctrl_q24_from_double(x);
}

struct Worst {
    const char *name;
    double err = 0.0, ratio = 0.0;
    long n = 0;
    void add(double e, double bound)
    {
        n++;
        err = std::max(err, e);
        ratio = std::max(ratio, e / bound);
        if (!(e <= bound)) {
            char msg[200];
            std::snprintf(msg, sizeof msg, "%s: error %.3g pu above bound %.3g pu", name, e, bound);
            TEST_FAIL_MESSAGE(msg);
        }
    }
    void print() const
    {
        std::printf("  %-28s n %7ld  worst %.3g pu  worst/bound %.3f\n", name, n, err, ratio);
    }
};

Worst w_psi{"psi_max"}, w_t{"torque limit at psi"}, w_cur_t{"FOC currents: torque"},
    w_cur_p{"FOC currents: flux"};
long kind_checked = 0, kind_skipped = 0;

// Exact pu model of one machine from the SI data and the SI bases.
struct Ref {
    double psi, ld, lq, rs, i, vf, ceil, t_mtpa, psi_mtpa, margin, margin_brake, c1, c2;
    bool salient;
    Ref(const ctrl_machine_t &m, const ctrl_bases_t &b, const ctrl_fieldweak_cfg_t &c)
    {
        psi = m.psi_pm_wb / b.psi_wb;
        ld = m.ld_h / b.l_h;
        lq = m.lq_h / b.l_h;
        rs = m.rs_ohm / b.r_ohm;
        i = m.current_rated_a / b.i_a;
        vf = c.v_frac / std::sqrt(3.0);
        ceil = psi + lq * i;
        margin = c.torque_margin;
        margin_brake = c.torque_margin_brake;
        salient = lq > ld;
        double md, mq;
        ctrl_mtpa_split(psi, ld, lq, i, &md, &mq);
        t_mtpa = psi * mq + (ld - lq) * md * mq;
        psi_mtpa = std::hypot(ld * md + psi, lq * mq);
        c1 = psi / ld;
        c2 = 1.0 / ld - 1.0 / lq;
    }
    double torque(double id, double iq) const
    {
        return (psi + (ld - lq) * id) * iq;
    }
    // MTPV on the flux circle p: (T, i_d).
    void mtpv(double p, double &t, double &id) const
    {
        const double pd = -2.0 * c2 * p * p / (c1 + std::sqrt(c1 * c1 + 8.0 * c2 * c2 * p * p));
        const double pq = std::sqrt(std::max(p * p - pd * pd, 0.0));
        t = pq * (c1 - c2 * pd);
        id = (pd - psi) / ld;
    }
    // Torque limit on the flux circle p (field_weak.h) at most marg of its
    // MTPV torque, its kind, and the distance of p from the decisions (for
    // the kind check).
    double t_at_flux(double p, double marg, int &kind, double &margin_dist) const
    {
        double tv, idv;
        mtpv(p, tv, idv);
        const double id_r = (p - psi) / ld, id_l = -(p + psi) / ld;
        // least |i| on the ellipse: at Ld psi / (Lq^2 - Ld^2) or the right end
        const double id_m = lq > ld ? std::min(id_r, ld * psi / (lq * lq - ld * ld)) : id_r;
        const double pdm = ld * id_m + psi;
        const double i_min =
            std::sqrt(std::max(id_m * id_m + (p * p - pdm * pdm) / (lq * lq), 0.0));
        double t = tv;
        kind = CTRL_FIELDWEAK_LIMIT_MTPV;
        margin_dist = std::min(std::fabs(i_min - i), std::fabs(std::fabs(id_l) - i));
        if (i_min > i) {
            t = 0.0;
            kind = CTRL_FIELDWEAK_LIMIT_VOLTAGE;
        } else if (std::fabs(id_l) > i) {
            const double c = psi * psi + lq * lq * i * i - p * p;
            const double b = 2.0 * ld * psi;
            const double idx = -2.0 * c / (b + std::sqrt(b * b + 4.0 * (lq * lq - ld * ld) * c));
            margin_dist = std::min(margin_dist, std::fabs(idv - idx));
            if (idv < idx) {
                t = torque(idx, std::sqrt(std::max(i * i - idx * idx, 0.0)));
                kind = CTRL_FIELDWEAK_LIMIT_VOLTAGE;
            }
        }
        return std::min(std::max(t, 0.0), marg * tv);
    }
    // Bound of the fixed-point torque limit at p (pu): the MTPV part rounds c1,
    // c2, psi^2 and forms two roots and a division (a few LSB on quantities of
    // size c1 + c2 psi), psi_q = sqrt(psi^2 - psi_d^2) loses E/(2 psi_q) (at
    // most sqrt(E)); the intersection rounds c (size c0), its root and the
    // division (E_id, relative to 1 + |i_d|), and i_q = sqrt(I^2 - i_d^2)
    // loses E_iq2/(2 i_q) with E_iq2 = 2 I E_id + 2 LSB (at most sqrt(E_iq2)).
    double t_bound(double p) const
    {
        double tv, idv;
        mtpv(p, tv, idv);
        const double k = c1 + c2 * p + 1.0;
        const double pd = (idv * ld + psi);
        const double pq = std::sqrt(std::max(p * p - pd * pd, 0.0));
        const double e_pd = 16 * L * (1.0 + std::fabs(pd)) * (1.0 + c2);
        const double e_p2 = 2.0 * std::fabs(pd) * e_pd + 4 * L * (1.0 + p);
        const double e_pq = pq > 0 ? std::min(e_p2 / (2.0 * pq), std::sqrt(e_p2)) : std::sqrt(e_p2);
        const double e_tv = e_pq * k + pq * c2 * e_pd + 4 * L * (1.0 + pq);
        const double c = psi * psi + lq * lq * i * i - p * p;
        const double b = 2.0 * ld * psi;
        const double e_id = 16 * L * (1.0 + std::fabs(c) + lq * lq) / b * (1.0 + 1.0 / ld);
        const double idx = -2.0 * c / (b + std::sqrt(b * b + 4.0 * (lq * lq - ld * ld) * c));
        const double iq2 = std::max(i * i - idx * idx, 0.0);
        const double iq = std::sqrt(iq2);
        const double e_iq2 = 2.0 * i * e_id + 2 * L;
        const double e_iq =
            iq > 0 ? std::min(e_iq2 / (2.0 * iq), std::sqrt(e_iq2)) : std::sqrt(e_iq2);
        const double e_tx =
            (lq - ld) * e_id * iq + (psi + (lq - ld) * std::fabs(idx)) * e_iq + 4 * L * (1.0 + iq);
        return std::max(e_tv, e_tx) + 4 * L;
    }
};

// The limit kind is compared only away from its decisions: 64 LSB of i_d.
constexpr double kKindGuard = 64 * L;

void run(const ctrl_machine_t &m, bool mtpa_mode, uint32_t fs, int n, std::mt19937_64 &gen)
{
    ctrl_params_t p;
    ctrl_bases_t b;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&p, &b, &m, fs));
    if (mtpa_mode) {
        p.psi_ref = 0;
    }
    ctrl_fieldweak_cfg_t cfg;
    ctrl_fieldweak_cfg_default(&cfg);
    ctrl_fieldweak_t s;
    char why[160];
    TEST_ASSERT_EQUAL_INT_MESSAGE(CTRL_OK,
                                  ctrl_fieldweak_init(&s, &cfg, &m, &b, &p, why, sizeof why), why);
    const Ref r(m, b, cfg);
    const double vdc_nom = m.vdc_v / b.v_v;
    const double w_rated =
        m.speed_rated_rpm * 2.0 * 3.14159265358979323846 / 60.0 * m.pole_pairs / b.w_rad_s;
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    for (int k = 0; k < n; k++) {
        const double vdc = vdc_nom * (0.6 + 0.6 * u01(gen));
        const double w = w_rated * 3.0 * (2.0 * u01(gen) - 1.0) * (u01(gen) < 0.05 ? 0.0 : 1.0);
        const double t0 = r.t_mtpa * 1.5 * (2.0 * u01(gen) - 1.0);
        const double t1 = r.t_mtpa * 1.5 * (2.0 * u01(gen) - 1.0);
        const double pc = u01(gen) < 0.3 ? r.psi * (0.5 + u01(gen)) : 0.0;
        ctrl_fieldweak_reset(&s);
        ctrl_fieldweak_out_t o0, o;
        // First period primes the filter (vdc exactly) and sets T_prev.
        ctrl_fieldweak_step(&s, &p, q(vdc), q(w), q(t0), q(pc), &o0);
        const double tp = d(s.t_prev); // the low-passed torque the second period uses
        ctrl_fieldweak_step(&s, &p, q(vdc), q(w), q(t1), q(pc), &o);
        TEST_ASSERT_EQUAL_INT32(q(vdc), o.vdc);
        // psi_max
        const double wq = d(q(w));
        const double v = r.vf * d(q(vdc));
        const double ri = std::min(r.rs * std::fabs(tp) / r.psi, r.rs * r.i);
        const double x = v * v - ri * ri - 2.0 * r.rs * wq * tp;
        const double aw = std::fabs(wq);
        double pm = r.ceil;
        double e_psi = 1.0 * L;
        if (aw > 0.0) {
            pm = std::min(std::sqrt(std::max(x, 0.0)) / aw, r.ceil);
            // V: 0.5 LSB + vdc 2^-31 (v_frac in Q30); X: 2 V dV, the product
            // w T rounded (0.5 LSB) times 2 Rs, 2 Rs rounded times |w T|.
            const double dv = 0.5 * L + d(q(vdc)) * std::ldexp(1.0, -31);
            // Rs I: Rs/psi_pm and the product rounded (0.5 LSB each, times |T|
            // and 1), Rs I_max rounded: 2 Rs I dI on its square.
            const double e_x = 2.0 * v * dv + 2.0 * r.rs * 0.5 * L + std::fabs(wq * tp) * 0.5 * L +
                               2.0 * ri * (1.0 + std::fabs(tp)) * L + std::ldexp(1.0, -47);
            const double sx = std::sqrt(std::max(x, 0.0));
            const double e_sx =
                (sx > 0 ? std::min(e_x / (2.0 * sx), std::sqrt(e_x)) : std::sqrt(e_x)) + L;
            e_psi = e_sx / aw + 1.0 * L;
        }
        w_psi.add(std::fabs(d(o.psi_max) - pm), e_psi);
        // torque limit at the flux the fixed-point code used
        const q24_t fix = pc > 0 ? q(pc) : p.psi_ref;
        if (fix <= 0 && o.psi_max >= s.psi_mtpa) {
            TEST_ASSERT_EQUAL_INT32(s.t_mtpa, o.torque_max);
            TEST_ASSERT_EQUAL_UINT8(CTRL_FIELDWEAK_LIMIT_CURRENT, o.limit);
            TEST_ASSERT_DOUBLE_WITHIN(0.5 * L, r.t_mtpa, d(o.torque_max));
        } else {
            const double pl = d(fix > 0 ? std::min(fix, o.psi_max) : o.psi_max);
            int kind;
            double dist;
            // braking (w T < 0) on a fixed flux: the braking margin
            const bool brake = fix > 0 && ((q(w) > 0 && q(t1) < 0) || (q(w) < 0 && q(t1) > 0));
            const double tl = r.t_at_flux(pl, brake ? r.margin_brake : r.margin, kind, dist);
            w_t.add(std::fabs(d(o.torque_max) - tl), r.t_bound(pl));
            if (fix > 0 && q(pl) < o.psi_max) {
                kind = CTRL_FIELDWEAK_LIMIT_FLUX;
            }
            if (dist > kKindGuard) {
                kind_checked++;
                TEST_ASSERT_EQUAL_UINT8(kind, o.limit);
            } else {
                kind_skipped++;
            }
        }
        // clamp and flux reference (exact)
        const q24_t tr = q(t1);
        TEST_ASSERT_EQUAL_INT32(fx_clamp(tr, fx_neg(o.torque_max), o.torque_max), o.torque);
        TEST_ASSERT_EQUAL_INT32(std::min(ctrl_flux_ref(&p, q(pc), o.torque), o.psi_max), o.psi_ref);
        TEST_ASSERT_EQUAL_UINT8(tr != o.torque, o.clipped);
        // FOC currents on the flux circle (MTPA mode only, where FOC uses them)
        if (mtpa_mode && pc == 0.0 && o.weakening && o.torque != 0) {
            q24_t id = 0, iq = 0;
            for (int j = 0; j < 12; j++) {
                ctrl_fieldweak_currents(&s, &p, o.torque, o.psi_ref, &id, &iq);
            }
            // The MTPA currents (of the table) when their flux is within psi_ref.
            q24_t md, mq;
            ctrl_mtpa_current(&p, o.torque, &md, &mq);
            if (fx_mag(fx_add(fx_mul(p.ld, md), p.psi_pm), fx_mul(p.lq, mq)) <= o.psi_ref) {
                TEST_ASSERT_EQUAL_INT32(md, id);
                TEST_ASSERT_EQUAL_INT32(mq, iq);
                continue;
            }
            const double tt = r.torque(d(id), d(iq));
            const double pp = std::hypot(r.ld * d(id) + r.psi, r.lq * d(iq));
            // Converged: i_q = T / (psi_pm + (Ld - Lq) i_d) rounds twice (the
            // division, Ld - Lq and the product: 2 LSB relative to 1 + |T|);
            // the flux residual of psi_d after the bracketed steps (the Newton
            // step rounds: a few LSB) plus i_q's rounding times Lq.
            const double e_t = 4 * L * (1.0 + std::fabs(tt)) * (1.0 + (r.lq - r.ld));
            const double e_p = 8 * L * (1.0 + r.lq) + 4 * L * r.ld * (1.0 + 1.0 / r.ld);
            w_cur_t.add(std::fabs(tt - d(o.torque)), e_t);
            w_cur_p.add(std::fabs(pp - d(o.psi_ref)), e_p);
        }
    }
}

void test_reference(void)
{
    std::mt19937_64 gen(16);
    ctrl_machine_t ipm_mtpa = ini_thesis_ipmsm80;
    for (uint32_t fs : {10000u, 20000u}) {
        run(ini_thesis_spmsm, true, fs, 20000, gen);
        run(ipm_mtpa, true, fs, 20000, gen);
        run(ini_thesis_ipmsm80, false, fs, 20000, gen);
        run(ini_chapter_ipmsm, true, fs, 20000, gen);
    }
    std::printf("field weakening, fixed point against double:\n");
    w_psi.print();
    w_t.print();
    w_cur_t.print();
    w_cur_p.print();
    std::printf("  limit kind: %ld compared, %ld near a decision skipped\n", kind_checked,
                kind_skipped);
    TEST_ASSERT_TRUE(w_cur_t.n > 1000);
    TEST_ASSERT_TRUE(kind_checked > 10000);
}

} // namespace

int main()
{
    UNITY_BEGIN();
    RUN_TEST(test_reference);
    return UNITY_END();
}
