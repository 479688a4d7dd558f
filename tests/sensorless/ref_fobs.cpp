/*
 * Double-precision reference of the stator-flux observer (flux_observer.h) and
 * fx_atan2 (C++17, Eigen 3), driven with the same randomised inputs as the
 * fixed-point code: three machines (thesis SPMSM, 80 kW IPMSM, chapter IPMSM)
 * at 10 and 20 kHz, both modes, random observer states (flux, PLL) and
 * inputs (voltage up to the DC link, currents up to current_max in any
 * direction, speeds up to 1.2 rated both ways, any angle), and the voltage
 * reconstruction with random duties, previous duties, currents in and out
 * of the soft-sign band, dead time and forward drop.
 *
 * The reference computes one period (ctrl_fobs_voltage; ctrl_fobs_update) in
 * double with the parameters from the SI data (the bases ctrl_params_init
 * reports), starting from the fixed-point state. Each quantity carries the
 * first-order bound of the fixed-point error (docs/error-budget.md, "Flux
 * observer"): every product rounded once (0.5 LSB), every Q24 parameter
 * rounded (0.5 LSB), fx_sincos S, fx_atan2 A, propagated through the
 * operations as |a| e_b + |b| e_a. Asserted per sample; the worst errors and
 * the worst error/bound ratio are printed.
 */
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <random>

extern "C" {
#include "../core/machines.h"
#include "ctrl_params.h"
#include "flux_observer.h"
#include "flux_observer_config.h"
#include "fx.h"
#include "angle_source.h"
#include "unity.h"
}

void setUp(void)
{
}
void tearDown(void)
{
}

namespace
{

using Eigen::Vector2d;

constexpr double kPi = 3.14159265358979323846;
constexpr double L = 1.0 / 16777216.0;                          // 1 LSB of Q24
constexpr double S = (kPi / 1024.0) * (kPi / 1024.0) / 8.0 + L; // fx_sincos
constexpr double A = 1.0 / 65536.0 / 8.0 * 0.649519052838329 +  // fx_atan2, rad
                     1.5 / 8388608.0 + 2.0 * kPi / 4294967296.0;
constexpr double kTurn = 4294967296.0;

double d(q24_t x)
{
    return static_cast<double>(x) * L;
}

// A value and the bound of the fixed-point error on it.
struct V {
    double v, e;
};
V exact(double v)
{
    return {v, 0.0};
}
V param(double v) // a Q24 parameter rounded from its exact value
{
    return {v, 0.5 * L};
}
V add(V a, V b)
{
    return {a.v + b.v, a.e + b.e};
}
V sub(V a, V b)
{
    return {a.v - b.v, a.e + b.e};
}
V mul(V a, V b) // fx_mul: one rounding
{
    return {a.v * b.v, std::fabs(a.v) * b.e + std::fabs(b.v) * a.e + a.e * b.e + 0.5 * L};
}
V dot(V a1, V a2, V b1, V b2) // fx_dot: a1 b1 + a2 b2, one rounding
{
    return {a1.v * b1.v + a2.v * b2.v, std::fabs(a1.v) * b1.e + std::fabs(b1.v) * a1.e +
                                           std::fabs(a2.v) * b2.e + std::fabs(b2.v) * a2.e +
                                           a1.e * b1.e + a2.e * b2.e + 0.5 * L};
}
V cross(V a1, V a2, V b1, V b2) // fx_cross: a1 b2 - a2 b1, one rounding
{
    V r = dot(a1, a2, b2, b1);
    r.v = a1.v * b2.v - a2.v * b1.v;
    return r;
}

double wrap(double x)
{
    while (x >= kPi)
        x -= 2 * kPi;
    while (x < -kPi)
        x += 2 * kPi;
    return x;
}
double ang(fx_angle_t a)
{
    return static_cast<double>(a) * 2.0 * kPi / kTurn;
}

struct Worst {
    const char *name;
    double err = 0.0, ratio = 0.0;
    void add(double e, double bound)
    {
        err = std::max(err, e);
        ratio = std::max(ratio, e / bound);
        if (e > bound) {
            char msg[200];
            std::snprintf(msg, sizeof msg, "%s: error %.3g above bound %.3g", name, e, bound);
            TEST_FAIL_MESSAGE(msg);
        }
    }
};

Worst w_atan{"fx_atan2, rad"}, w_v{"voltage (dead time, drop)"}, w_psi{"psi_ab (k)"},
    w_eta{"eta_ab (k)"}, w_th{"theta (k), rad"}, w_acc{"psi_ab after correction"},
    w_w{"omega (PLL frequency)"}, w_wi{"omega (PLL integrator)"}, w_thp{"theta_pll, rad"},
    w_psipm{"psi_pm estimate"};

// Exact per-unit parameters from the SI data and the bases.
struct Ref {
    double ts, rs, ld, lq, psi_pm, vdc, w_rated, i_rated, i_max;
    double k0ts, kappats, kencts, kp, ki, dt, vfwd, band, psik, psi_wmin;
    double dangle_to_omega_ex, omega_to_dangle_ex;
};

Ref make_ref(const ctrl_machine_t &m, const ctrl_bases_t &b, uint32_t fs,
             const ctrl_fobs_config_t &c)
{
    Ref r;
    const double ts_s = 1.0 / fs;
    r.ts = ts_s * b.w_rad_s;
    r.rs = m.rs_ohm / b.r_ohm;
    r.ld = m.ld_h / b.l_h;
    r.lq = m.lq_h / b.l_h;
    r.psi_pm = m.psi_pm_wb / b.psi_wb;
    r.vdc = m.vdc_v / b.v_v;
    r.w_rated = m.speed_rated_rpm * 2.0 * kPi / 60.0 * m.pole_pairs / b.w_rad_s;
    r.i_rated = m.current_rated_a / b.i_a;
    r.i_max = m.current_max_a / b.i_a;
    r.k0ts = c.k0_rad_s * ts_s;
    r.kappats = c.kappa * b.w_rad_s * ts_s;
    r.kencts = c.kenc_rad_s * ts_s;
    const double wn = 2.0 * kPi * c.pll_hz;
    r.kp = 2.0 * wn * ts_s;
    r.ki = wn * wn * ts_s * 2.0 * kPi * 65536.0 / b.w_rad_s; // Q48 per angle unit
    r.dt = c.dead_time_s * fs;
    r.vfwd = c.v_fwd_v / b.v_v;
    r.band = c.band_a / b.i_a;
    r.psik = c.psi_tau_s > 0.0 ? 1.0 - std::exp(-ts_s / c.psi_tau_s) : 0.0;
    r.psi_wmin = c.psi_speed_min * r.w_rated;
    r.omega_to_dangle_ex = r.ts / (2.0 * kPi) * kTurn;
    r.dangle_to_omega_ex = 1.0 / r.omega_to_dangle_ex;
    return r;
}

// ---------------------------------------------------------------- fx_atan2

void check_atan(std::mt19937_64 &gen)
{
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::uniform_int_distribution<int> sh(0, 31);
    for (int n = 0; n < 100000; n++) {
        const double scale = std::ldexp(1.0, 31 - sh(gen));
        const int32_t x =
            static_cast<int32_t>(std::max(-2147483648.0, std::min(2147483647.0, u(gen) * scale)));
        const int32_t y =
            static_cast<int32_t>(std::max(-2147483648.0, std::min(2147483647.0, u(gen) * scale)));
        if (x == 0 && y == 0)
            continue;
        w_atan.add(std::fabs(wrap(ang(fx_atan2(y, x)) - std::atan2(y, x))), A);
    }
}

// ------------------------------------------------- voltage reconstruction

// Soft sign as the fixed point forms it: i inv_band / 2^16, inv_band an
// integer (relative rounding 0.5 / inv_band), clamped.
V soft_sign(const ctrl_fobs_t &o, double band, V i)
{
    const double s = i.v / band;
    if (s >= 1.0 + 1e-9 || s <= -1.0 - 1e-9) {
        return {s > 0 ? 1.0 : -1.0, 0.0}; // the clamp is exact away from the corner
    }
    const double e = i.e / band + std::fabs(i.v) * 0.5 / 65536.0 + 0.5 * L;
    return {std::max(-1.0, std::min(1.0, s)), e};
}

V duty_eff(double dp, double dd, V s, V td)
{
    const bool hp = dp >= 1.0, h = dd >= 1.0, inside = dd > 0 && !h;
    V rise = exact(0), fall = exact(0);
    if (h && !hp)
        rise = td;
    else if (!h && hp)
        fall = td;
    if (inside) {
        rise = add(rise, td.v <= dd ? td : exact(dd));
        fall = add(fall, td.v <= 1.0 - dd ? td : exact(1.0 - dd));
    }
    if (s.v > 0 || (s.v == 0 && s.e == 0))
        return sub(exact(dd), mul(s, rise));
    return add(exact(dd), mul({-s.v, s.e}, fall));
}

void check_voltage(const ctrl_params_t &p, const Ref &r, std::mt19937_64 &gen)
{
    std::uniform_real_distribution<double> u(0.0, 1.0);
    ctrl_fobs_t o;
    std::memset(&o, 0, sizeof o);
    for (int n = 0; n < 20000; n++) {
        // dead time up to 2 % of the period, drop up to 2 % of the DC link
        o.dt_frac = ctrl_q24_from_double(0.02 * u(gen));
        o.v_fwd = ctrl_q24_from_double(0.02 * r.vdc * u(gen));
        const double band = r.i_rated * (0.01 + 0.1 * u(gen));
        o.inv_band = static_cast<int32_t>(std::lround(65536.0 / band));
        const double band_fx = 65536.0 / o.inv_band;
        ctrl_legs_t prev, legs;
        for (int x = 0; x < 3; x++) {
            const double a = u(gen), b = u(gen);
            prev.duty[x] = a < 0.2 ? 0 : (a > 0.8 ? FX_ONE : ctrl_q24_from_double(u(gen)));
            legs.duty[x] = b < 0.2 ? 0 : (b > 0.8 ? FX_ONE : ctrl_q24_from_double(u(gen)));
        }
        o.legs_prev = prev;
        const double vdc = r.vdc * (0.9 + 0.2 * u(gen));
        const q24_t vdc_q = ctrl_q24_from_double(vdc);
        // currents in and out of the band
        const double ia = (u(gen) - 0.5) * 2.0 * (u(gen) < 0.5 ? 2.0 * band : r.i_max);
        const double ib = (u(gen) - 0.5) * 2.0 * (u(gen) < 0.5 ? 2.0 * band : r.i_max);
        const q24_t ia_q = ctrl_q24_from_double(ia), ib_q = ctrl_q24_from_double(ib);
        q24_t va, vb;
        ctrl_fobs_voltage(&o, &legs, vdc_q, ia_q, ib_q, &va, &vb);

        const V td = exact(d(o.dt_frac)); // the configured value (its rounding is configuration)
        const V sa = soft_sign(o, band_fx, exact(d(ia_q)));
        const V sb = soft_sign(o, band_fx, exact(d(ib_q)));
        const V sc = soft_sign(o, band_fx, {-(d(ia_q) + d(ib_q)), 0.5 * L});
        V e[3] = {duty_eff(d(prev.duty[0]), d(legs.duty[0]), sa, td),
                  duty_eff(d(prev.duty[1]), d(legs.duty[1]), sb, td),
                  duty_eff(d(prev.duty[2]), d(legs.duty[2]), sc, td)};
        const double vd = d(vdc_q);
        double ra = vd * (2.0 * e[0].v - e[1].v - e[2].v) / 3.0;
        double rb = vd * (e[1].v - e[2].v) / std::sqrt(3.0);
        // ctrl_legs_voltage on the effective duties (docs: 0.5 L + Vdc (0.5 L + 1e-9))
        double ea = 0.5 * L + vd * (0.5 * L + 1e-9) + vd * (2.0 * e[0].e + e[1].e + e[2].e) / 3.0;
        double eb = 0.5 * L + vd * (0.5 * L + 1e-9) + vd * (e[1].e + e[2].e) / std::sqrt(3.0);
        if (o.v_fwd != 0) {
            const double vf = d(o.v_fwd);
            const double fa = (2.0 * sa.v - sb.v - sc.v) / 3.0;
            const double fb = (sb.v - sc.v) / std::sqrt(3.0);
            ra -= vf * fa;
            rb -= vf * fb;
            ea += 0.5 * L + vf * (0.5 * L + 1e-9 + (2.0 * sa.e + sb.e + sc.e) / 3.0) + 0.5 * L;
            eb += 0.5 * L + vf * (0.5 * L + 1e-9 + (sb.e + sc.e) / std::sqrt(3.0)) + 0.5 * L;
        }
        w_v.add(std::fabs(d(va) - ra), ea);
        w_v.add(std::fabs(d(vb) - rb), eb);
        (void)p;
    }
}

// ------------------------------------------------------ one observer period

void check_observer(const ctrl_machine_t &mach, uint32_t fs, unsigned mode, int n,
                    std::mt19937_64 &gen)
{
    ctrl_params_t p;
    ctrl_bases_t b;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&p, &b, &mach, fs));
    ctrl_fobs_config_t c;
    ctrl_fobs_config_default(&c, &mach);
    c.mode = mode;
    c.psi_tau_s = 0.02; // the PM-flux estimate on, so that it is checked too
    ctrl_fobs_t o0;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_fobs_init(&o0, &p, &b, &c, nullptr));
    const Ref r = make_ref(mach, b, fs, c);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    check_voltage(p, r, gen);

    for (int k = 0; k < n; k++) {
        ctrl_fobs_t o = o0;
        // Random state: rotor angle, active flux of 0.5..1.5 psi_pm on it
        // (plus a random error), currents, PLL near the speed.
        const double th = 2.0 * kPi * u(gen);
        const double w = (2.0 * u(gen) - 1.0) * 1.2 * r.w_rated;
        auto rnd_i = [&]() {
            const double a = 2.0 * kPi * u(gen), m = r.i_max * u(gen);
            return Vector2d(m * std::cos(a), m * std::sin(a));
        };
        const Vector2d ip = rnd_i();
        const Vector2d i1 = ip + 0.1 * rnd_i();
        const double mag = r.psi_pm * (0.5 + u(gen)) + 0.1 * r.psi_pm * (2.0 * u(gen) - 1.0);
        const double tho = th + 0.2 * (2.0 * u(gen) - 1.0);
        const Vector2d psi0 = Vector2d(mag * std::cos(tho), mag * std::sin(tho)) + r.lq * ip;
        o.psi_alpha_acc = static_cast<int64_t>(std::llround(psi0(0) * 16777216.0)) * FX_ONE +
                          static_cast<int64_t>(u(gen) * 16777216.0);
        o.psi_beta_acc = static_cast<int64_t>(std::llround(psi0(1) * 16777216.0)) * FX_ONE +
                         static_cast<int64_t>(u(gen) * 16777216.0);
        o.i_alpha_prev = ctrl_q24_from_double(ip(0));
        o.i_beta_prev = ctrl_q24_from_double(ip(1));
        o.pll_theta = static_cast<fx_angle_t>(static_cast<int64_t>(std::llround(
            std::fmod(th + 0.05 * (2 * u(gen) - 1) + 4 * kPi, 2 * kPi) / (2 * kPi) * kTurn)));
        o.pll_omega_acc = static_cast<int64_t>(std::llround(w * 16777216.0)) * FX_ONE;
        o.omega = ctrl_q24_from_double(w);
        o.psi_pm_acc =
            static_cast<int64_t>(std::llround(r.psi_pm * (0.8 + 0.4 * u(gen)) * 16777216.0)) *
            FX_ONE;
        o.primed = 1u;
        // inputs: voltage up to the DC link, current i(k), encoder angle
        const double va = r.vdc * (2.0 * u(gen) - 1.0), vb = r.vdc * (2.0 * u(gen) - 1.0);
        const q24_t va_q = ctrl_q24_from_double(va), vb_q = ctrl_q24_from_double(vb);
        const q24_t ia_q = ctrl_q24_from_double(i1(0)), ib_q = ctrl_q24_from_double(i1(1));
        const fx_angle_t enc = static_cast<fx_angle_t>(
            static_cast<int64_t>(std::llround(std::fmod(th, 2 * kPi) / (2 * kPi) * kTurn)));

        // ---- reference, from the fixed-point state (exact) ----
        const V ipa = exact(d(o.i_alpha_prev)), ipb = exact(d(o.i_beta_prev));
        const V ia = exact(d(ia_q)), ib = exact(d(ib_q));
        const double acc_a = static_cast<double>(o.psi_alpha_acc) / 281474976710656.0;
        const double acc_b = static_cast<double>(o.psi_beta_acc) / 281474976710656.0;
        // integrate: ts v - ts rs (i_p + i)/2 (Q48 exact but for the parameters
        // and the /2 rounding), then the Q24 view
        auto integ = [&](double acc, double v, V i_p, V i) {
            const double val = acc + r.ts * v - r.ts * r.rs * 0.5 * (i_p.v + i.v);
            const double e = 0.5 * L * std::fabs(v) + 0.5 * L * 0.5 * std::fabs(i_p.v + i.v) +
                             0.5 / 281474976710656.0;
            return V{val, e};
        };
        const V accA = integ(acc_a, d(va_q), ipa, ia), accB = integ(acc_b, d(vb_q), ipb, ib);
        const V psa{accA.v, accA.e + 0.5 * L}, psb{accB.v, accB.e + 0.5 * L};
        const V lq = param(r.lq);
        const V eta_a = sub(psa, mul(lq, ia)), eta_b = sub(psb, mul(lq, ib));
        const double eta_n = std::hypot(eta_a.v, eta_b.v);
        const V th_hat{std::atan2(eta_b.v, eta_a.v),
                       A + std::max(eta_a.e, eta_b.e) * std::sqrt(2.0) / eta_n};

        // ---- fixed point ----
        const fx_angle_t pll_theta0 = o.pll_theta;
        const int64_t o0_pll_acc = o.pll_omega_acc;
        const int64_t o0_psi_acc = o.psi_pm_acc;
        const q24_t omega0 = o.omega;
        const fx_angle_t th_fx = ctrl_fobs_update(&o, &p, va_q, vb_q, ia_q, ib_q, enc);
        w_psi.add(std::fabs(d(o.psi_alpha) - psa.v), psa.e);
        w_psi.add(std::fabs(d(o.psi_beta) - psb.v), psb.e);
        w_eta.add(std::fabs(d(o.eta_alpha) - eta_a.v), eta_a.e);
        w_eta.add(std::fabs(d(o.eta_beta) - eta_b.v), eta_b.e);
        w_th.add(std::fabs(wrap(ang(th_fx) - th_hat.v)), th_hat.e);

        // ---- reference correction in the frame of the reference angle ----
        const V thr = mode == CTRL_FOBS_ENCODER ? exact(ang(enc)) : th_hat;
        const V s{std::sin(thr.v), S + thr.e}, cth{std::cos(thr.v), S + thr.e};
        const V id = dot(cth, s, ia, ib), iq = cross(cth, s, ia, ib); // ctrl_park
        const V psi_d = dot(cth, s, psa, psb);
        V cd, cq;
        if (mode == CTRL_FOBS_ENCODER) {
            const V psi_q = cross(cth, s, psa, psb);
            const V ed = sub(add(mul(param(r.ld), id), param(r.psi_pm)), psi_d);
            const V eq = sub(mul(lq, iq), psi_q);
            cd = mul(param(r.kencts), ed);
            cq = mul(param(r.kencts), eq);
        } else {
            const V eta_d = dot(cth, s, eta_a, eta_b);
            const V dl = add(param(r.ld), param(r.lq)); // Ld - Lq: two roundings
            const V dlv{r.ld - r.lq, dl.e};
            const V psi_a = add(param(r.psi_pm), mul(dlv, id));
            // the gain uses the speed of the previous period (the state)
            const V wprev = exact(std::fabs(d(omega0)));
            V kts = add(param(r.k0ts), mul(param(r.kappats), wprev));
            if (kts.v > 0.5)
                kts = exact(0.5);
            const V g = mul(mul(kts, sub(psi_a, eta_d)), param(1.0 / r.psi_pm));
            cd = mul(g, psi_a);
            cq = mul(g, mul(dlv, iq));
            cq.v = -cq.v;
        }
        // ctrl_inv_park: alpha = c d - s q, beta = s d + c q
        const V ca = cross(cth, s, cq, cd);
        const V cb = dot(s, cth, cd, cq);
        const V na{accA.v + ca.v, accA.e + ca.e}, nb{accB.v + cb.v, accB.e + cb.e};
        w_acc.add(std::fabs(static_cast<double>(o.psi_alpha_acc) / 281474976710656.0 - na.v),
                  na.e + 1e-15);
        w_acc.add(std::fabs(static_cast<double>(o.psi_beta_acc) / 281474976710656.0 - nb.v),
                  nb.e + 1e-15);

        // ---- PLL (angle units of 2^-32 turn; Q48 integrator) ----
        const double ku = kTurn / (2.0 * kPi); // angle units per rad
        const double e_fx =
            static_cast<double>(fx_u2i((mode == CTRL_FOBS_ENCODER ? enc : th_fx) - pll_theta0));
        const double e_ref = mode == CTRL_FOBS_ENCODER ? e_fx : wrap(thr.v - ang(pll_theta0)) * ku;
        const double e_e = mode == CTRL_FOBS_ENCODER ? 0.0 : thr.e * ku;
        const double q48 = 281474976710656.0;
        const double acc_ref = static_cast<double>(o0_pll_acc) + r.ki * e_ref;
        const double acc_e =
            std::fabs(static_cast<double>(o.pll_ki) - r.ki) * std::fabs(e_ref) + r.ki * e_e;
        const V wi{acc_ref / q48, acc_e / q48 + 0.5 * L};
        w_wi.add(std::fabs(static_cast<double>(o.pll_omega_acc) / q48 - acc_ref / q48),
                 acc_e / q48 + 1e-15);
        // kp e, rounded to an angle unit; kp a Q24 parameter
        const V kpe{r.kp * e_ref, std::fabs(e_ref) * 0.5 * L + r.kp * e_e + 0.5};
        // conversions angle units <-> pu speed: K = omega_to_dangle and
        // m = dangle_to_omega rounded (relative 0.5/K + 0.5/m)
        const double rel = 0.5 / static_cast<double>(p.omega_to_dangle) +
                           0.5 / static_cast<double>(p.dangle_to_omega);
        const double dg = r.dangle_to_omega_ex;
        const V wout{wi.v + kpe.v * dg, wi.e + std::fabs(kpe.v) * dg * rel + kpe.e * dg + 0.5 * L};
        w_w.add(std::fabs(d(o.omega) - wout.v), wout.e);
        const double k_ex = r.omega_to_dangle_ex;
        const double thp_ref = static_cast<double>(pll_theta0) + wi.v * k_ex + kpe.v;
        const double thp_e = wi.e * k_ex + std::fabs(wi.v) * k_ex * rel + 0.5 + kpe.e;
        const double thp_diff = wrap((static_cast<double>(o.pll_theta) - thp_ref) / ku) * ku;
        w_thp.add(std::fabs(thp_diff) / ku, thp_e / ku);

        // ---- PM-flux estimate: psi_d - Ld i_d, EMA, above the speed threshold ----
        if (std::fabs(std::fabs(wout.v) - r.psi_wmin) > wout.e + L) {
            const bool on = std::fabs(wout.v) >= r.psi_wmin;
            const double out0 = d(fx_round_sat(o0_psi_acc, FX_QBITS));
            double acc = static_cast<double>(o0_psi_acc) / q48;
            double e = 0.0;
            if (on) {
                const V raw = sub(psi_d, mul(param(r.ld), id));
                acc += (raw.v - out0) * r.psik;
                e = r.psik * raw.e + std::fabs(raw.v - out0) * 0.5 * L + raw.e * 0.5 * L;
            }
            w_psipm.add(std::fabs(static_cast<double>(o.psi_pm_acc) / q48 - acc), e + 1e-15);
        }
    }
}

} // namespace

static void test_reference(void)
{
    std::mt19937_64 gen(12345);
    check_atan(gen);
    const ctrl_machine_t ms[3] = {machine_thesis_spmsm(), machine_thesis_ipmsm80(),
                                  machine_chapter_ipmsm()};
    const uint32_t fss[2] = {10000u, 20000u};
    for (const auto &m : ms)
        for (uint32_t fs : fss)
            for (unsigned mode = 0; mode < 2; mode++)
                check_observer(m, fs, mode, 5000, gen);
    const Worst *all[] = {&w_atan, &w_v,  &w_psi, &w_eta, &w_th,
                          &w_acc,  &w_wi, &w_w,   &w_thp, &w_psipm};
    std::printf("%-28s %-12s %-10s %s\n", "quantity", "worst error", "LSB", "worst err/bound");
    for (const Worst *w : all)
        std::printf("%-28s %-12.3g %-10.2f %.3f\n", w->name, w->err, w->err / L, w->ratio);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_reference);
    return UNITY_END();
}
