// Independent reference of the plant with an output filter (sim_host/
// plant_filter.h): Eigen's matrix exponential of the full linear system,
// assembled here from the circuit laws, not from the plant's matrix:
//
//  A. rotor frame, salient chapter IPMSM (S1 Table 2) at an imposed speed: the
//     state derivative is written as circuit evaluation (KCL node voltages,
//     element laws, j w terms of the rotating frame), and the system matrix of
//     z = (x, v_in, 1) is read from it column by column (it is linear);
//  B. stationary frame, the same machine made non-salient (Ld = Lq): filter and
//     machine in alpha-beta, the inverter voltage constant between switching
//     instants and the back-EMF j w psi e^{j theta} a rotating input (two more
//     states). No rotor-frame term at all: a different formulation;
//  C. free mechanics through plant_advance_period: the plant's step rule (the
//     speed held at the midpoint prediction over each period, updated with the
//     period's mean torque) replayed with the reference's own exponentials and
//     a 4-point Gauss-Legendre torque integral per piece.
// Both filters (S1 Tables 5 and 6); the active filter's half bridges switched
// at random instants by the test (plant_filter_set_switches), the reference
// exchanging the phase's capacitor voltage itself (abc, with the zero
// sequence). Random leg states over random intervals (1 ns .. 80 us), random
// speeds (both signs) and angles. Compared: machine current, motor-terminal
// voltage, inverter current and two inner quantities. Bound 1e-6 relative
// (an exact integration must be far below it); measured ~1e-10.
#include <Eigen/Dense>
#include <unsupported/Eigen/MatrixFunctions>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <cstring>
#include <random>
#include <vector>

#include "plant.h"
#include "unity.h"

void setUp(void)
{
}
void tearDown(void)
{
}

namespace
{

using cd = std::complex<double>;
using Mat = Eigen::MatrixXd;
using Vec = Eigen::VectorXd;

const double kPi = 3.14159265358979323846;

struct Motor {
    int p = 2;
    double rs = 5.8, ld = 44.8e-3, lq = 102.7e-3, psi = 0.533, vdc = 264.0;
};

plant_filter_cfg_t table5()
{
    plant_filter_cfg_t f;
    std::memset(&f, 0, sizeof f);
    f.type = PLANT_FILTER_PASSIVE;
    f.passive.l1_h = 20e-6;
    f.passive.c1_f = 52e-6;
    f.passive.r1_ohm = 56e3;
    f.passive.l2_h = 30e-3;
    f.passive.c2_f = 5.1e-6;
    f.passive.r2_ohm = 2.2;
    f.passive.l3_h = 30e-3;
    f.passive.c3_f = 12.5e-6;
    f.passive.r3_ohm = 128.0;
    f.passive.r3s_ohm = 2.0;
    return f;
}

plant_filter_cfg_t table6()
{
    plant_filter_cfg_t f;
    std::memset(&f, 0, sizeof f);
    f.type = PLANT_FILTER_ACTIVE;
    f.active.l1_h = 1e-6;
    f.active.c1_f = 2e-6;
    f.active.r1_ohm = 250.0;
    f.active.l2_h = 1.5e-6;
    f.active.c2_f = 2e-6;
    f.active.r2_ohm = 750.0;
    f.active.lf_h = 0.2;
    f.active.cf_f = 200e-6;
    f.active.cf_v0_v = 264.0;
    f.active.sample_hz = 100e3;
    f.active.band_v = 2.0;
    f.active.ref_cutoff_hz = 500.0;
    return f;
}

// ---------------------------------------------------------------- circuits
// Filter states as complex space vectors (frame-independent laws); the
// machine separately. Both filters: a list of named states and a function
// giving, for the state, input and back-EMF, the element voltages/currents.

// Passive: x = (i1, vC1, i2, vC2, i3, vC3) ; active: x = (u, iF, vC1, iT, vC2).
struct Circuit {
    plant_filter_cfg_t f;
    int nf() const
    {
        return f.type == PLANT_FILTER_PASSIVE ? 6 : 5;
    }
    // "Stationary-frame" derivative of the filter states (no j w terms) for
    // filter state xf, machine current im, inverter voltage v1; also the
    // motor-terminal voltage.
    void deriv(const cd *xf, cd im, cd v1, cd *dxf, cd *vmotor) const
    {
        if (f.type == PLANT_FILTER_PASSIVE) {
            const plant_filter_passive_t &q = f.passive;
            const cd i1 = xf[0], vc1 = xf[1], i2 = xf[2], vc2 = xf[3], i3 = xf[4], vc3 = xf[5];
            // KCL: node 2: i_C2 = i3 - i2; node X: i_R1 = i1 - i_C2
            const cd ic2 = i3 - i2;
            const cd vx = q.r1_ohm * (i1 - ic2);
            const cd v2 = vx - vc2;
            const cd ic3 = i3 - im;
            const cd v3 = q.r3_ohm * ic3 + vc3;
            dxf[0] = (v1 - vc1 - vx) / q.l1_h;
            dxf[1] = i1 / q.c1_f;
            dxf[2] = (v1 - v2 - q.r2_ohm * i2) / q.l2_h;
            dxf[3] = ic2 / q.c2_f;
            dxf[4] = (v2 - v3 - q.r3s_ohm * i3) / q.l3_h;
            dxf[5] = ic3 / q.c3_f;
            *vmotor = v3;
        } else {
            const plant_filter_active_t &q = f.active;
            const cd u = xf[0], iF = xf[1], vc1 = xf[2], iT = xf[3], vc2 = xf[4];
            const cd vp = q.r1_ohm * (iF - iT) + vc1; // primary node (transformer 1:1)
            const cd vm = q.r2_ohm * (iT - im) + vc2; // motor node
            dxf[0] = iF / q.cf_f;
            dxf[1] = (v1 - u - vp) / (q.lf_h + q.l1_h);
            dxf[2] = (iF - iT) / q.c1_f;
            dxf[3] = (vp - vm) / q.l2_h;
            dxf[4] = (iT - im) / q.c2_f;
            *vmotor = vm;
        }
    }
};

// --------------------------------------------------------- A: rotor frame
// z = (Re/Im of the filter states, id, iq, v_in d, v_in q, 1).
struct RefDq {
    Circuit c;
    Motor m;
    double w;  // electrical speed
    double th; // electrical angle
    Vec x;     // filter (2 nf) + machine (2)
    int nx() const
    {
        return 2 * c.nf() + 2;
    }
    Vec f(const Vec &z) const
    {
        const int nf = c.nf();
        std::vector<cd> xf(nf), dxf(nf);
        for (int k = 0; k < nf; ++k) {
            xf[k] = cd(z(2 * k), z(2 * k + 1));
        }
        const double id = z(2 * nf), iq = z(2 * nf + 1);
        const cd vin(z(nx()), z(nx() + 1));
        const double one = z(nx() + 2);
        cd vm;
        c.deriv(xf.data(), cd(id, iq), vin, dxf.data(), &vm);
        Vec dz = Vec::Zero(nx() + 3);
        const cd jw(0.0, w);
        for (int k = 0; k < nf; ++k) {
            const cd d = dxf[k] - jw * xf[k]; // rotating frame
            dz(2 * k) = d.real();
            dz(2 * k + 1) = d.imag();
        }
        // (3.8)-(3.9) at the motor-terminal voltage
        dz(2 * nf) = (vm.real() - m.rs * id + w * m.lq * iq) / m.ld;
        dz(2 * nf + 1) = (vm.imag() - m.rs * iq - w * (m.ld * id + m.psi * one)) / m.lq;
        // the constant alpha-beta inverter voltage rotates at -w in this frame
        dz(nx()) = w * vin.imag();
        dz(nx() + 1) = -w * vin.real();
        return dz;
    }
    Mat matrix() const
    {
        const int n = nx() + 3;
        Mat M(n, n);
        for (int j = 0; j < n; ++j) {
            Vec e = Vec::Zero(n);
            e(j) = 1.0;
            M.col(j) = f(e);
        }
        return M;
    }
    double torque() const
    {
        const int nf = c.nf();
        const double id = x(2 * nf), iq = x(2 * nf + 1);
        return 1.5 * m.p * ((m.ld * id + m.psi) * iq - m.lq * iq * id);
    }
    // hold the leg states s for dt; returns the torque integral (4-point
    // Gauss-Legendre) when with_torque
    double step(double dt, const int s[3], bool with_torque = false)
    {
        const double va = m.vdc / 3.0 * (2 * s[0] - s[1] - s[2]);
        const double vb = m.vdc / 3.0 * (s[1] - s[2]) * std::sqrt(3.0);
        const cd vdq = cd(va, vb) * std::exp(cd(0.0, -th));
        Vec z(nx() + 3);
        z << x, vdq.real(), vdq.imag(), 1.0;
        const Mat M = matrix();
        static const double gx[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563,
                                     0.8611363115940526};
        static const double gw[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461,
                                     0.3478548451374538};
        double te = 0.0;
        for (int k = 0; with_torque && k < 4; ++k) {
            const Vec zk = (M * (0.5 * dt * (1.0 + gx[k]))).exp() * z;
            RefDq tmp = *this;
            tmp.x = zk.head(nx());
            te += gw[k] * tmp.torque();
        }
        z = (M * dt).exp() * z;
        x = z.head(nx());
        th += w * dt;
        return 0.5 * dt * te;
    }
    // quantities in alpha-beta: motor current, motor voltage, inverter current,
    // node 2 / v_P and node X / u (as the plant's probes)
    void probes(cd out[5]) const
    {
        const int nf = c.nf();
        std::vector<cd> xf(nf), dxf(nf);
        for (int k = 0; k < nf; ++k) {
            xf[k] = cd(x(2 * k), x(2 * k + 1));
        }
        const cd im(x(2 * nf), x(2 * nf + 1));
        cd vm;
        c.deriv(xf.data(), im, cd(0.0, 0.0), dxf.data(), &vm);
        cd iinv, n2, nx_;
        if (c.f.type == PLANT_FILTER_PASSIVE) {
            const plant_filter_passive_t &q = c.f.passive;
            iinv = xf[0] + xf[2];
            nx_ = q.r1_ohm * (xf[0] + xf[2] - xf[4]);
            n2 = nx_ - xf[3];
        } else {
            const plant_filter_active_t &q = c.f.active;
            iinv = xf[1];
            n2 = q.r1_ohm * (xf[1] - xf[3]) + xf[2];
            nx_ = xf[0];
        }
        const cd r = std::exp(cd(0.0, th));
        out[0] = im * r;
        out[1] = vm * r;
        out[2] = iinv * r;
        out[3] = n2 * r;
        out[4] = nx_ * r;
    }
};

// AF capacitor exchange (the reference's own): u in the frame of angle th.
struct AfCaps {
    int sw[3] = {1, 1, 1};
    double up[3], lo[3], u0;
    explicit AfCaps(double v0) : up{v0, v0, v0}, lo{v0, v0, v0}, u0(v0)
    {
    }
    void exchange(cd &u_frame, double th, const int *sw_new)
    {
        const cd uab = u_frame * std::exp(cd(0.0, th));
        double u[3];
        for (int k = 0; k < 3; ++k) {
            const cd a = std::exp(cd(0.0, -2.0 * kPi * k / 3.0)); // phase k axis
            u[k] = (uab * a).real() + u0;
        }
        for (int k = 0; k < 3; ++k) {
            if (sw_new[k] == sw[k]) {
                continue;
            }
            if (sw[k]) {
                up[k] = u[k];
                u[k] = -lo[k];
            } else {
                lo[k] = -u[k];
                u[k] = up[k];
            }
            sw[k] = sw_new[k];
        }
        u0 = (u[0] + u[1] + u[2]) / 3.0;
        cd s(0.0, 0.0);
        for (int k = 0; k < 3; ++k) {
            s += 2.0 / 3.0 * u[k] * std::exp(cd(0.0, 2.0 * kPi * k / 3.0));
        }
        u_frame = s * std::exp(cd(0.0, -th));
    }
};

// ------------------------------------------------ B: stationary frame, Ld = Lq
struct RefAb {
    Circuit c;
    Motor m; // ld == lq
    double w, th;
    Vec x; // filter (2 nf) + machine alpha-beta current (2)
    int nx() const
    {
        return 2 * c.nf() + 2;
    }
    // z = (x, v_alpha, v_beta, e_alpha, e_beta): the inverter voltage is
    // constant, the back-EMF e = j w psi e^{j theta} rotates at +w.
    Vec f(const Vec &z) const
    {
        const int nf = c.nf();
        std::vector<cd> xf(nf), dxf(nf);
        for (int k = 0; k < nf; ++k) {
            xf[k] = cd(z(2 * k), z(2 * k + 1));
        }
        const cd im(z(2 * nf), z(2 * nf + 1));
        const cd v(z(nx()), z(nx() + 1));
        const cd e(z(nx() + 2), z(nx() + 3));
        cd vm;
        c.deriv(xf.data(), im, v, dxf.data(), &vm);
        Vec dz = Vec::Zero(nx() + 4);
        for (int k = 0; k < nf; ++k) {
            dz(2 * k) = dxf[k].real();
            dz(2 * k + 1) = dxf[k].imag();
        }
        const cd dim = (vm - m.rs * im - e) / m.ld;
        dz(2 * nf) = dim.real();
        dz(2 * nf + 1) = dim.imag();
        const cd de = cd(0.0, w) * e;
        dz(nx() + 2) = de.real();
        dz(nx() + 3) = de.imag();
        return dz;
    }
    void step(double dt, const int s[3])
    {
        const int n = nx() + 4;
        Mat M(n, n);
        for (int j = 0; j < n; ++j) {
            Vec ej = Vec::Zero(n);
            ej(j) = 1.0;
            M.col(j) = f(ej);
        }
        const double va = m.vdc / 3.0 * (2 * s[0] - s[1] - s[2]);
        const double vb = m.vdc / 3.0 * (s[1] - s[2]) * std::sqrt(3.0);
        const cd e = cd(0.0, w * m.psi) * std::exp(cd(0.0, th));
        Vec z(n);
        z << x, va, vb, e.real(), e.imag();
        z = (M * dt).exp() * z;
        x = z.head(nx());
        th += w * dt;
    }
};

// ----------------------------------------------------------------- runs

double g_worst = 0.0;

plant_config_t make_cfg(const Motor &m, const plant_filter_cfg_t &f, double rpm, double th0)
{
    plant_config_t c{};
    c.pole_pairs = m.p;
    c.rs_ohm = m.rs;
    c.ld_h = m.ld;
    c.lq_h = m.lq;
    c.psi_pm_wb = m.psi;
    c.vdc_v = m.vdc;
    c.mech = PLANT_MECH_IMPOSED;
    c.speed0_rpm = rpm;
    c.theta0_e_rad = th0;
    c.filter = f;
    return c;
}

// The test switches the half bridges itself: the hysteresis controller stops.
void hold_switches(plant_t *p, const plant_filter_cfg_t &f)
{
    if (f.type == PLANT_FILTER_ACTIVE) {
        const uint8_t hold[3] = {1, 1, 1};
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_filter_set_switches(p, hold));
    }
}

void plant_probes(const plant_t *p, cd out[5])
{
    static const int q[5] = {PLANT_FP_I_MOTOR, PLANT_FP_V_MOTOR, PLANT_FP_I_INV, PLANT_FP_V_NODE2,
                             PLANT_FP_V_NODEX};
    for (int k = 0; k < 5; ++k) {
        double ab[2];
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_filter_probe(p, q[k], ab));
        out[k] = cd(ab[0], ab[1]);
    }
}

struct Err {
    double worst[5] = {0, 0, 0, 0, 0};
    double scale[5] = {1e-9, 1e-9, 1e-9, 1e-9, 1e-9};
    void add(const cd a[5], const cd b[5])
    {
        for (int k = 0; k < 5; ++k) {
            worst[k] = std::max(worst[k], std::abs(a[k] - b[k]));
            scale[k] = std::max(scale[k], std::abs(b[k]));
        }
    }
    double rel() const
    {
        double r = 0.0;
        for (int k = 0; k < 5; ++k) {
            r = std::max(r, worst[k] / scale[k]);
        }
        return r;
    }
};

void report(const char *what, const Err &e)
{
    const double rel = e.rel();
    g_worst = std::max(g_worst, rel);
    char msg[260];
    std::snprintf(msg, sizeof msg,
                  "%s: rel. errors i_m %.2e, v_motor %.2e, i_inv %.2e, node2 %.2e, nodeX %.2e",
                  what, e.worst[0] / e.scale[0], e.worst[1] / e.scale[1], e.worst[2] / e.scale[2],
                  e.worst[3] / e.scale[3], e.worst[4] / e.scale[4]);
    TEST_MESSAGE(msg);
    TEST_ASSERT_TRUE_MESSAGE(rel < 1e-6, msg);
}

// A: random intervals, rotor frame, salient machine
void run_dq(const plant_filter_cfg_t &f, unsigned seed)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const Motor m;
    const double rpm = (2.0 * u(rng) - 1.0) * 1500.0;
    const double th0 = (2.0 * u(rng) - 1.0) * 3.0;
    plant_config_t c = make_cfg(m, f, rpm, th0);
    static plant_t p;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
    hold_switches(&p, f);
    RefDq r{Circuit{f}, m, rpm / 60.0 * 2.0 * kPi * m.p, th0, Vec::Zero(2 * Circuit{f}.nf() + 2)};
    AfCaps caps(f.active.cf_v0_v);
    if (f.type == PLANT_FILTER_ACTIVE) {
        r.x(0) = 0.0; // all upper capacitors: pure zero sequence, u = 0
        r.x(1) = 0.0;
    }
    Err e;
    for (int k = 0; k < 200; ++k) {
        const double dt = 1e-9 * std::pow(8e4, u(rng));
        const int s[3] = {(int)(u(rng) < 0.5), (int)(u(rng) < 0.5), (int)(u(rng) < 0.5)};
        const uint8_t s8[3] = {(uint8_t)s[0], (uint8_t)s[1], (uint8_t)s[2]};
        if (f.type == PLANT_FILTER_ACTIVE && u(rng) < 0.2) {
            const int sw[3] = {(int)(u(rng) < 0.5), (int)(u(rng) < 0.5), (int)(u(rng) < 0.5)};
            const uint8_t sw8[3] = {(uint8_t)sw[0], (uint8_t)sw[1], (uint8_t)sw[2]};
            TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_filter_set_switches(&p, sw8));
            cd uf(r.x(0), r.x(1));
            caps.exchange(uf, r.th, sw);
            r.x(0) = uf.real();
            r.x(1) = uf.imag();
        }
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance(&p, dt, s8));
        r.step(dt, s);
        cd a[5], b[5];
        plant_probes(&p, a);
        r.probes(b);
        e.add(a, b);
    }
    char what[120];
    std::snprintf(what, sizeof what, "A %s filter, rotor frame, %.0f r/min, 200 random intervals",
                  f.type == PLANT_FILTER_PASSIVE ? "passive" : "active", rpm);
    report(what, e);
}

// B: random intervals, stationary frame, Ld = Lq
void run_ab(const plant_filter_cfg_t &f, unsigned seed)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    Motor m;
    m.lq = m.ld;
    const double rpm = (2.0 * u(rng) - 1.0) * 1500.0;
    const double th0 = (2.0 * u(rng) - 1.0) * 3.0;
    plant_config_t c = make_cfg(m, f, rpm, th0);
    static plant_t p;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
    hold_switches(&p, f);
    const int nf = Circuit{f}.nf();
    RefAb r{Circuit{f}, m, rpm / 60.0 * 2.0 * kPi * m.p, th0, Vec::Zero(2 * nf + 2)};
    AfCaps caps(f.active.cf_v0_v);
    Err e;
    for (int k = 0; k < 200; ++k) {
        const double dt = 1e-9 * std::pow(8e4, u(rng));
        const int s[3] = {(int)(u(rng) < 0.5), (int)(u(rng) < 0.5), (int)(u(rng) < 0.5)};
        const uint8_t s8[3] = {(uint8_t)s[0], (uint8_t)s[1], (uint8_t)s[2]};
        if (f.type == PLANT_FILTER_ACTIVE && u(rng) < 0.2) {
            const int sw[3] = {(int)(u(rng) < 0.5), (int)(u(rng) < 0.5), (int)(u(rng) < 0.5)};
            const uint8_t sw8[3] = {(uint8_t)sw[0], (uint8_t)sw[1], (uint8_t)sw[2]};
            TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_filter_set_switches(&p, sw8));
            cd uab(r.x(0), r.x(1));
            caps.exchange(uab, 0.0, sw); // stationary frame: angle 0
            r.x(0) = uab.real();
            r.x(1) = uab.imag();
        }
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance(&p, dt, s8));
        r.step(dt, s);
        // compare in alpha-beta
        cd a[5], b[5];
        plant_probes(&p, a);
        std::vector<cd> xf(nf), dxf(nf);
        for (int j = 0; j < nf; ++j) {
            xf[j] = cd(r.x(2 * j), r.x(2 * j + 1));
        }
        const cd im(r.x(2 * nf), r.x(2 * nf + 1));
        cd vm;
        r.c.deriv(xf.data(), im, cd(0.0, 0.0), dxf.data(), &vm);
        b[0] = im;
        b[1] = vm;
        if (f.type == PLANT_FILTER_PASSIVE) {
            const plant_filter_passive_t &q = f.passive;
            b[2] = xf[0] + xf[2];
            b[4] = q.r1_ohm * (xf[0] + xf[2] - xf[4]);
            b[3] = b[4] - xf[3];
        } else {
            const plant_filter_active_t &q = f.active;
            b[2] = xf[1];
            b[3] = q.r1_ohm * (xf[1] - xf[3]) + xf[2];
            b[4] = xf[0];
        }
        e.add(a, b);
    }
    char what[120];
    std::snprintf(what, sizeof what,
                  "B %s filter, stationary frame (Ld = Lq), %.0f r/min, 200 random intervals",
                  f.type == PLANT_FILTER_PASSIVE ? "passive" : "active", rpm);
    report(what, e);
}

// C: free mechanics, centre-aligned periods through plant_advance_period
void run_free(const plant_filter_cfg_t &f, unsigned seed)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const Motor m;
    const double J = 3.29e-4, tl = 1.0, T = 1e-4;
    plant_config_t c = make_cfg(m, f, 300.0, 0.4);
    c.mech = PLANT_MECH_FREE;
    c.inertia_kgm2 = J;
    c.load_torque_nm = tl;
    static plant_t p;
    TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_init(&p, &c));
    hold_switches(&p, f);
    double wm = 300.0 / 60.0 * 2.0 * kPi;
    RefDq r{Circuit{f}, m, 0.0, 0.4, Vec::Zero(2 * Circuit{f}.nf() + 2)};
    Err e;
    double werr = 0.0;
    for (int k = 0; k < 60; ++k) {
        double d[3];
        for (double &x : d) {
            const double v = u(rng);
            x = v < 0.1 ? 0.0 : (v > 0.9 ? 1.0 : u(rng));
        }
        TEST_ASSERT_EQUAL_INT(PLANT_OK, plant_advance_period(&p, T, d));
        // the step rule: speed held at the midpoint prediction
        const double wmid = wm + 0.5 * T * (r.torque() - tl) / J;
        r.w = wmid * m.p;
        double inst[8] = {0.0, T};
        for (int x = 0; x < 3; ++x) {
            inst[2 + x] = 0.5 * T * (1.0 - d[x]);
            inst[5 + x] = 0.5 * T * (1.0 + d[x]);
        }
        std::sort(inst, inst + 8);
        double te_int = 0.0;
        for (int j = 0; j < 7; ++j) {
            const double a = inst[j], b = inst[j + 1];
            if (b <= a) {
                continue;
            }
            const double mid = 0.5 * (a + b);
            int s[3];
            for (int x = 0; x < 3; ++x) {
                s[x] = (mid >= 0.5 * T * (1.0 - d[x]) && mid < 0.5 * T * (1.0 + d[x])) ? 1 : 0;
            }
            te_int += r.step(b - a, s, true);
        }
        wm += (te_int / T - tl) * T / J;
        cd a[5], b[5];
        plant_probes(&p, a);
        r.probes(b);
        e.add(a, b);
        werr = std::max(werr, std::fabs(plant_omega_m(&p) - wm) / std::fabs(wm));
    }
    char what[160];
    std::snprintf(what, sizeof what,
                  "C %s filter, free mechanics, 60 periods: speed %.2f r/min, rel. speed error "
                  "%.2e",
                  f.type == PLANT_FILTER_PASSIVE ? "passive" : "active", wm * 60.0 / (2.0 * kPi),
                  werr);
    report(what, e);
    TEST_ASSERT_TRUE_MESSAGE(werr < 1e-6, what);
}

void test_rotor_frame(void)
{
    for (unsigned s = 1; s <= 2; ++s) {
        run_dq(table5(), 7919u * s);
        run_dq(table6(), 104729u * s);
    }
}

void test_stationary_frame(void)
{
    run_ab(table5(), 31u);
    run_ab(table6(), 37u);
}

void test_free_mechanics(void)
{
    run_free(table5(), 41u);
    run_free(table6(), 43u);
    char msg[80];
    std::snprintf(msg, sizeof msg, "worst relative error over all runs: %.3g", g_worst);
    TEST_MESSAGE(msg);
}

} // namespace

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_rotor_frame);
    RUN_TEST(test_stationary_frame);
    RUN_TEST(test_free_mechanics);
    return UNITY_END();
}
