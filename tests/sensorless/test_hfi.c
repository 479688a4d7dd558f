/*
 * High-frequency injection (hfi.h) against a salient machine integrated in
 * double (rotor frame, 8 midpoint steps per period), the injection asked
 * for at k applied in [k+1, k+2) (the pipeline's delay), the currents
 * quantised to Q24 as the firmware measures them:
 *   - tracking from start errors of -80 .. +80 deg at standstill: within
 *     0.05 deg after 0.1 s (and to the d axis, not its opposite); from
 *     100 deg it locks on the opposite axis (the saliency's pi ambiguity,
 *     which the polarity resolves);
 *   - noise on the samples: the steady error's rms within the bound of the
 *     demodulated noise through the loop's noise bandwidth;
 *   - a rotor turning at 5 % of rated speed: the mean error within 0.2 deg
 *     (each change demodulated in its own injection's frame);
 *   - a free rotor accelerated by its torque: the observer's torque
 *     feed-forward follows it without lag;
 *   - the fundamental current: the injection's ripple removed to within
 *     2 % of its step, the mean the machine's current;
 *   - the polarity pulses: north and south told on a machine whose d axis
 *     saturates with the magnet's flux, none on the linear one (asymmetry
 *     below 0.1 %);
 *   - the injection added to leg duties: the (4.4) voltage is the asked one,
 *     the common mode moved to fit, a clamp reported;
 *   - the configuration: a machine with too little saliency refused with its
 *     ratio and the minimum.
 * Runs on the host and in QEMU (integer core).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../core/machines.h"
#include "ctrl_units.h"
#include "hfi.h"
#include "hfi_config.h"
#include "plan.h"
#include "unity.h"

void setUp(void)
{
}
void tearDown(void)
{
}

#define TURN 4294967296.0
#define SUB 8

static ctrl_params_t P;
static ctrl_bases_t B;

static double d(q24_t x)
{
    return ctrl_q24_to_double(x);
}

/* The machine in pu, rotor frame: psi_d = psi_pm + ld (i_d - sat i_d^2 / 2)
 * (the d axis saturating with the magnet's flux for sat > 0: the incremental
 * inductance ld (1 - sat i_d) falls towards north), psi_q = lq i_q. */
typedef struct {
    double ld, lq, psi, r, sat;
    double theta, omega; /* rotor angle (rad), electrical speed (pu) */
    double id, iq;
    double k_acc; /* free rotor: d omega / dt = k_acc torque (pu per pu time); 0: imposed */
} mach_t;

static void mach_init(mach_t *m, double theta, double omega)
{
    memset(m, 0, sizeof *m);
    m->ld = d(P.ld);
    m->lq = d(P.lq);
    m->psi = d(P.psi_pm);
    m->r = d(P.rs);
    m->theta = theta;
    m->omega = omega;
}

static void mach_deriv(const mach_t *m, double c, double s, double va, double vb, double id,
                       double iq, double *did, double *diq)
{
    const double vd = c * va + s * vb;
    const double vq = -s * va + c * vb;
    const double psd = m->psi + m->ld * (id - 0.5 * m->sat * id * id);
    const double lid = m->ld * (1.0 - m->sat * id);
    *did = (vd - m->r * id + m->omega * m->lq * iq) / lid;
    *diq = (vq - m->r * iq - m->omega * psd) / m->lq;
}

/* One period with the stator voltage (va, vb) pu: midpoint steps (the
 * angle's sine and cosine formed only where it turns: soft double in QEMU). */
static void mach_period(mach_t *m, double va, double vb)
{
    const double dt = d(P.ts) / SUB;
    double c0 = cos(m->theta);
    double s0 = sin(m->theta);
    for (int k = 0; k < SUB; k++) {
        double a1;
        double b1;
        mach_deriv(m, c0, s0, va, vb, m->id, m->iq, &a1, &b1);
        const double thm = m->theta + 0.5 * dt * m->omega;
        const double cm = m->omega != 0.0 ? cos(thm) : c0;
        const double sm = m->omega != 0.0 ? sin(thm) : s0;
        double a2;
        double b2;
        mach_deriv(m, cm, sm, va, vb, m->id + 0.5 * dt * a1, m->iq + 0.5 * dt * b1, &a2, &b2);
        m->id += dt * a2;
        m->iq += dt * b2;
        m->theta += dt * m->omega;
        if (m->omega != 0.0 || m->k_acc > 0.0) {
            c0 = cos(m->theta);
            s0 = sin(m->theta);
        }
        if (m->k_acc > 0.0) {
            const double psd = m->psi + m->ld * (m->id - 0.5 * m->sat * m->id * m->id);
            m->omega += dt * m->k_acc * (psd * m->iq - m->lq * m->iq * m->id);
        }
    }
}

static void mach_current(const mach_t *m, double *ia, double *ib)
{
    const double c = cos(m->theta);
    const double s = sin(m->theta);
    *ia = c * m->id - s * m->iq;
    *ib = s * m->id + c * m->iq;
}

/* The fundamental voltage that holds the rotor-frame current (id, iq) at
 * speed omega (steady state of the linear machine), stator frame. */
static void mach_hold(const mach_t *m, double id, double iq, double *va, double *vb)
{
    const double vd = m->r * id - m->omega * m->lq * iq;
    const double vq = m->r * iq + m->omega * (m->psi + m->ld * id);
    const double c = cos(m->theta);
    const double s = sin(m->theta);
    *va = c * vd - s * vq;
    *vb = s * vd + c * vq;
}

/* the machine's torque (3.10), pu: the observer's feed-forward */
static q24_t torque_of(const mach_t *m)
{
    const double psd = m->psi + m->ld * (m->id - 0.5 * m->sat * m->id * m->id);
    return ctrl_q24_from_double(psd * m->iq - m->lq * m->iq * m->id);
}

static uint32_t rng = 777u;
static double noise(double a)
{
    rng = rng * 1664525u + 1013904223u;
    return a * (2.0 * (double)(rng >> 8) / 16777216.0 - 1.0);
}

static double wrap(double e)
{
    return e - CTRL_TWO_PI * floor((e + CTRL_PI) / CTRL_TWO_PI);
}

/* tracked minus rotor angle, rad within +-pi */
static double err_of(const ctrl_hfi_t *h, const mach_t *m)
{
    return wrap((double)h->theta * CTRL_TWO_PI / TURN - m->theta);
}

typedef struct {
    double e_rms, e_mean, e_last;
    double if_ripple, if_a_mean, if_b_mean, ia_mean, ib_mean;
} run_t;

/* n periods of the machine holding (id, iq) with the injection; statistics
 * over the last n_stat periods. a: uniform noise on each sample, pu. */
static void run(ctrl_hfi_t *h, mach_t *m, double id, double iq, uint32_t n, uint32_t n_stat,
                double a, run_t *out)
{
    m->id = id; /* the fundamental in its steady state */
    m->iq = iq;
    q24_t v_prev_a = 0; /* the fundamental voltage of [k-1, k) */
    q24_t v_prev_b = 0;
    q24_t u_prev_a = 0; /* asked at k-1: acts in [k, k+1) */
    q24_t u_prev_b = 0;
    double s2 = 0.0;
    double s1 = 0.0;
    double ifa_s = 0.0;
    double ifb_s = 0.0;
    double ia_s = 0.0;
    double ib_s = 0.0;
    double ifa_min = 1e9;
    double ifa_max = -1e9;
    double ifb_min = 1e9;
    double ifb_max = -1e9;
    const double vdc = d(P.vdc_nom);
    for (uint32_t k = 0; k < n; k++) {
        double ia;
        double ib;
        mach_current(m, &ia, &ib);
        const q24_t qa = ctrl_q24_from_double(ia + noise(a));
        const q24_t qb = ctrl_q24_from_double(ib + noise(a));
        q24_t fa;
        q24_t fb;
        ctrl_hfi_update(h, &P, v_prev_a, v_prev_b, qa, qb, torque_of(m), &fa, &fb);
        if (k >= n - n_stat) {
            const double e = err_of(h, m);
            s1 += e;
            s2 += e * e;
            ifa_s += d(fa);
            ifb_s += d(fb);
            ia_s += ia;
            ib_s += ib;
            ifa_min = fmin(ifa_min, d(fa));
            ifa_max = fmax(ifa_max, d(fa));
            ifb_min = fmin(ifb_min, d(fb));
            ifb_max = fmax(ifb_max, d(fb));
        }
        double va;
        double vb;
        mach_hold(m, id, iq, &va, &vb);
        v_prev_a = ctrl_q24_from_double(va);
        v_prev_b = ctrl_q24_from_double(vb);
        va += vdc * d(u_prev_a);
        vb += vdc * d(u_prev_b);
        u_prev_a = h->u_alpha;
        u_prev_b = h->u_beta;
        mach_period(m, va, vb);
    }
    const double ns = (double)n_stat;
    out->e_mean = s1 / ns;
    out->e_rms = sqrt(s2 / ns);
    out->e_last = err_of(h, m);
    out->if_a_mean = ifa_s / ns;
    out->if_b_mean = ifb_s / ns;
    out->ia_mean = ia_s / ns;
    out->ib_mean = ib_s / ns;
    out->if_ripple = fmax(ifa_max - ifa_min, ifb_max - ifb_min);
}

/* The 80 kW IPMSM; the rotor's speed imposed (a dynamometer): the
 * observer without the torque feed-forward (inertia 0), at 40 Hz. */
static void setup(ctrl_hfi_t *h, uint32_t fs)
{
    const ctrl_machine_t m = machine_thesis_ipmsm80();
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&P, &B, &m, fs));
    ctrl_hfi_config_t c;
    ctrl_hfi_config_default(&c, &m);
    c.j_kgm2 = 0.0;
    c.track_hz = 40.0;
    ctrl_diag_t why;
    memset(&why, 0, sizeof why);
    TEST_ASSERT_EQUAL_INT_MESSAGE(CTRL_OK, ctrl_hfi_init(h, &P, &B, &c, &why), why.quantity);
}

static double deg(double rad)
{
    return rad * 180.0 / CTRL_PI;
}

static void test_lock_from_start_errors(void)
{
    static ctrl_hfi_t h;
    setup(&h, 20000u);
    double worst = 0.0;
    for (int e0 = -80; e0 <= 80; e0 += 20) {
        mach_t m;
        mach_init(&m, 0.7, 0.0);
        const double th0 = m.theta + ctrl_deg_to_rad((double)e0);
        ctrl_hfi_start(&h,
                       (fx_angle_t)(uint32_t)llround(fmod(th0 + 4.0 * CTRL_PI, CTRL_TWO_PI) /
                                                     CTRL_TWO_PI * TURN),
                       0, 0, 0, 0);
        run_t r;
        run(&h, &m, 0.0, 0.0, 2000u, 200u, 0.0, &r);
        worst = fmax(worst, fabs(r.e_last));
    }
    printf("start errors -80..80 deg: worst error after 0.1 s %.4f deg\n", deg(worst));
    TEST_ASSERT_TRUE(worst <= ctrl_deg_to_rad(0.05));
    /* beyond 90 deg the opposite axis (pi ambiguity of the saliency) */
    mach_t m;
    mach_init(&m, 0.7, 0.0);
    const double th0 = m.theta + ctrl_deg_to_rad(100.0);
    ctrl_hfi_start(&h, (fx_angle_t)(uint32_t)llround(th0 / CTRL_TWO_PI * TURN), 0, 0, 0, 0);
    run_t r;
    run(&h, &m, 0.0, 0.0, 2000u, 200u, 0.0, &r);
    printf("start error 100 deg: error after 0.1 s %.3f deg\n", deg(r.e_last));
    TEST_ASSERT_TRUE(fabs(fabs(r.e_last) - CTRL_PI) <= ctrl_deg_to_rad(0.05));
}

static void test_noise(void)
{
    static ctrl_hfi_t h;
    setup(&h, 20000u);
    mach_t m;
    mach_init(&m, 2.0, 0.0);
    ctrl_hfi_start(&h, (fx_angle_t)(uint32_t)llround(2.0 / CTRL_TWO_PI * TURN), 0, 0, 0, 0);
    /* +-0.25 % of the rated current on every sample (1 A, sigma 0.58 A:
     * about the simulated 12-bit ADC's noise and quantisation, 0.34 A) */
    const double a = 0.0025 * d(P.current_rated);
    run_t r;
    run(&h, &m, 0.3, 0.8, 6000u, 4000u, a, &r);
    /* bound: the demodulated error is sgn(k) (n(k) - 2 n(k-1) + n(k-2)) / 2
     * over 2 Ts V |D|, sgn alternating: near 0 Hz, where the loop passes it,
     * its density is that of white noise of 2 sigma_i (the second
     * difference's at fs/2, moved there by the alternating sign); through
     * the tracking observer's noise bandwidth, its triple pole at w_o:
     * B = 1.031 w_o; 30 % for the discrete loop with its two periods of
     * delay (less damped than the continuous one) */
    const double ts_s = 1.0 / (double)P.fs_hz;
    const double wo = d(h.l1) / (3.0 * ts_s);
    const double hd = fabs(0.5 * (d(P.inv_ld) - d(P.inv_lq)) * d(P.ts) * d(h.u_h) * d(P.vdc_nom));
    const double sig_e = 2.0 * (a / sqrt(3.0)) / (2.0 * hd);
    const double bound = 1.3 * sig_e * sqrt(2.0 * 1.031 * wo * ts_s);
    printf("noise +-%.4f pu: error rms %.3f deg (bound %.3f deg), mean %.3f deg\n", a, deg(r.e_rms),
           deg(bound), deg(r.e_mean));
    TEST_ASSERT_TRUE(r.e_rms <= bound);
    TEST_ASSERT_TRUE(r.e_rms > 0.0);
}

static void test_turning(void)
{
    static ctrl_hfi_t h;
    setup(&h, 20000u);
    const double w = 0.05 * d(P.speed_rated_e);
    double worst = 0.0;
    for (int sgn = -1; sgn <= 1; sgn += 2) {
        mach_t m;
        mach_init(&m, 1.0, sgn * w);
        ctrl_hfi_start(&h, (fx_angle_t)(uint32_t)llround(1.0 / CTRL_TWO_PI * TURN),
                       ctrl_q24_from_double(sgn * w), 0, 0, 0);
        run_t r;
        run(&h, &m, -0.2, 0.6 * sgn, 4000u, 2000u, 0.0, &r);
        printf("speed %+.3f pu: mean error %.4f deg, rms %.4f deg\n", sgn * w, deg(r.e_mean),
               deg(r.e_rms));
        worst = fmax(worst, fabs(r.e_mean));
    }
    TEST_ASSERT_TRUE(worst <= ctrl_deg_to_rad(0.2));
}

/* A free rotor accelerated by the rated current's torque from standstill
 * for 0.1 s (to a third of rated speed): with the torque feed-forward the
 * observer follows the acceleration without lag (mean error within 0.1 deg);
 * without it the tracking lags (the feed-forward is what the bound tests). */
static double accel_error(double inertia, double *mean)
{
    const ctrl_machine_t mm = machine_thesis_ipmsm80();
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&P, &B, &mm, 20000u));
    ctrl_hfi_config_t c;
    ctrl_hfi_config_default(&c, &mm);
    c.j_kgm2 = inertia;
    c.track_hz = 20.0;
    static ctrl_hfi_t h;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_hfi_init(&h, &P, &B, &c, NULL));
    mach_t m;
    mach_init(&m, 0.5, 0.0);
    /* d omega_pu / dt_pu = p T_base / (J w_base^2) T_pu */
    m.k_acc = (double)mm.pole_pairs * B.torque_nm / (mm.inertia_kgm2 * B.w_rad_s * B.w_rad_s);
    ctrl_hfi_start(&h, (fx_angle_t)(uint32_t)llround(0.5 / CTRL_TWO_PI * TURN), 0, 0, 0, 0);
    run_t r;
    run(&h, &m, 0.0, 0.5, 2000u, 1000u, 0.0, &r);
    printf("inertia %.4f: accelerated to %.1f %% of rated speed, mean error %.4f deg, rms %.4f\n",
           inertia, 100.0 * m.omega / d(P.speed_rated_e), deg(r.e_mean), deg(r.e_rms));
    *mean = r.e_mean;
    return r.e_rms;
}

static void test_accel(void)
{
    double mean_ff;
    double mean_no;
    (void)accel_error(machine_thesis_ipmsm80().inertia_kgm2, &mean_ff);
    (void)accel_error(0.0, &mean_no);
    TEST_ASSERT_TRUE(fabs(mean_ff) <= ctrl_deg_to_rad(0.1));
    TEST_ASSERT_TRUE(fabs(mean_no) > 5.0 * fabs(mean_ff));
}

static void test_fundamental(void)
{
    static ctrl_hfi_t h;
    setup(&h, 20000u);
    mach_t m;
    mach_init(&m, 4.0, 0.0);
    ctrl_hfi_start(&h, (fx_angle_t)(uint32_t)llround(4.0 / CTRL_TWO_PI * TURN), 0, 0, 0, 0);
    run_t r;
    run(&h, &m, -0.4, 1.0, 2000u, 400u, 0.0, &r);
    const double step = d(h.h0);
    printf("fundamental: ripple %.5f pu of a step %.5f pu (%.2f %%), mean off by %.2e, %.2e pu\n",
           r.if_ripple, step, 100.0 * r.if_ripple / step, r.if_a_mean - r.ia_mean,
           r.if_b_mean - r.ib_mean);
    TEST_ASSERT_TRUE(r.if_ripple <= 0.02 * step);
    TEST_ASSERT_TRUE(fabs(r.if_a_mean - r.ia_mean) <= 0.02 * step);
    TEST_ASSERT_TRUE(fabs(r.if_b_mean - r.ib_mean) <= 0.02 * step);
}

/* The polarity pulses on the axis at offset (rad) from the rotor's d axis. */
static uint8_t polarity(ctrl_hfi_t *h, double sat, double offset, double *asym)
{
    mach_t m;
    mach_init(&m, 0.3, 0.0);
    m.sat = sat;
    const double th = m.theta + offset;
    ctrl_hfi_pol_start(h,
                       (fx_angle_t)(uint32_t)llround(fmod(th, CTRL_TWO_PI) / CTRL_TWO_PI * TURN));
    q24_t v_prev_a = 0;
    q24_t v_prev_b = 0;
    uint32_t n = 0u;
    uint8_t running = 1u;
    while (running != 0u && n < 100000u) {
        double ia;
        double ib;
        mach_current(&m, &ia, &ib);
        q24_t va;
        q24_t vb;
        running =
            ctrl_hfi_pol_step(h, ctrl_q24_from_double(ia), ctrl_q24_from_double(ib), &va, &vb);
        mach_period(&m, d(v_prev_a), d(v_prev_b));
        v_prev_a = va;
        v_prev_b = vb;
        n++;
    }
    TEST_ASSERT_EQUAL_UINT32(ctrl_hfi_pol_periods(h), n);
    *asym = d(h->pol_asym);
    return h->pol_result;
}

static void test_polarity(void)
{
    static ctrl_hfi_t h;
    setup(&h, 20000u);
    /* incremental Ld 20 % lower at the rated current towards north */
    const double sat = 0.2 / d(P.current_rated);
    double a;
    TEST_ASSERT_EQUAL_UINT8(CTRL_HFI_POL_NORTH, polarity(&h, sat, 0.0, &a));
    printf("saturating d axis: north asymmetry %+.4f\n", a);
    TEST_ASSERT_TRUE(a > 0.05);
    TEST_ASSERT_EQUAL_UINT8(CTRL_HFI_POL_NORTH, polarity(&h, sat, ctrl_deg_to_rad(5.0), &a));
    TEST_ASSERT_EQUAL_UINT8(CTRL_HFI_POL_SOUTH, polarity(&h, sat, CTRL_PI, &a));
    printf("saturating d axis: south asymmetry %+.4f\n", a);
    TEST_ASSERT_TRUE(a < -0.05);
    TEST_ASSERT_EQUAL_UINT8(CTRL_HFI_POL_SOUTH, polarity(&h, sat, CTRL_PI - 0.1, &a));
    /* linear machine: nothing to read */
    TEST_ASSERT_EQUAL_UINT8(CTRL_HFI_POL_NONE, polarity(&h, 0.0, 0.0, &a));
    printf("linear machine: asymmetry %+.2e\n", a);
    TEST_ASSERT_TRUE(fabs(a) < 1e-3);
}

static void test_legs(void)
{
    static ctrl_hfi_t h;
    setup(&h, 20000u);
    ctrl_hfi_start(&h, 0x12345678u, 0, 0, 0, 0);
    q24_t fa;
    q24_t fb;
    for (int k = 0; k < 3; k++) {
        ctrl_hfi_update(&h, &P, 0, 0, 0, 0, 0, &fa, &fb);
    }
    TEST_ASSERT_TRUE(h.u_alpha != 0 || h.u_beta != 0);
    const q24_t base[3] = {ctrl_q24_from_double(0.5), ctrl_q24_from_double(0.45),
                           ctrl_q24_from_double(0.55)};
    q24_t legs[3] = {base[0], base[1], base[2]};
    TEST_ASSERT_EQUAL_UINT8(0u, ctrl_hfi_add_to_legs(&h, legs, FX_ONE));
    /* (4.4) of the difference is the injection */
    const double da = d(legs[0]) - d(base[0]);
    const double db = d(legs[1]) - d(base[1]);
    const double dc = d(legs[2]) - d(base[2]);
    const double ua = (2.0 * da - db - dc) / 3.0;
    const double ub = (db - dc) / CTRL_SQRT3;
    TEST_ASSERT_DOUBLE_WITHIN(3e-7, d(h.u_alpha), ua);
    TEST_ASSERT_DOUBLE_WITHIN(3e-7, d(h.u_beta), ub);
    /* at the top: the common mode moved down, the injection whole */
    q24_t top[3] = {FX_ONE, ctrl_q24_from_double(0.9), ctrl_q24_from_double(0.95)};
    const q24_t top0[3] = {top[0], top[1], top[2]};
    TEST_ASSERT_EQUAL_UINT8(0u, ctrl_hfi_add_to_legs(&h, top, FX_ONE));
    const double ta =
        (2.0 * (d(top[0]) - d(top0[0])) - (d(top[1]) - d(top0[1])) - (d(top[2]) - d(top0[2]))) /
        3.0;
    TEST_ASSERT_DOUBLE_WITHIN(3e-7, d(h.u_alpha), ta);
    for (int x = 0; x < 3; x++) {
        TEST_ASSERT_TRUE(top[x] >= 0 && top[x] <= FX_ONE);
    }
    /* a spread of the whole DC link: clamped, reported */
    q24_t full[3] = {FX_ONE, 0, 0};
    const uint8_t clipped = ctrl_hfi_add_to_legs(&h, full, FX_ONE);
    const double fa2 = (2.0 * d(full[0]) - d(full[1]) - d(full[2])) / 3.0 - 2.0 / 3.0;
    /* either the injection fitted whole or the clamp was reported */
    TEST_ASSERT_TRUE(clipped == 1u || fabs(fa2 - d(h.u_alpha)) <= 3e-7);
    TEST_ASSERT_TRUE(clipped == 1u);
}

static void test_config(void)
{
    ctrl_hfi_t h;
    ctrl_hfi_config_t c;
    ctrl_diag_t why;
    /* the thesis SPMSM: Ld = Lq, nothing to read */
    const ctrl_machine_t sp = machine_thesis_spmsm();
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&P, &B, &sp, 10000u));
    ctrl_hfi_config_default(&c, &sp);
    memset(&why, 0, sizeof why);
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_hfi_init(&h, &P, &B, &c, &why));
    char text[200];
    ctrl_diag_format(&why, text, sizeof text);
    printf("thesis SPMSM: %s\n", text);
    TEST_ASSERT_NOT_NULL(strstr(text, "saliency"));
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 1.0, why.value);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 1.1, why.min);
    /* Lq/Ld = 1.05 below 1.1 */
    ctrl_machine_t m = machine_thesis_ipmsm80();
    m.lq_h = 1.05 * m.ld_h;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&P, &B, &m, 10000u));
    ctrl_hfi_config_default(&c, &m);
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_hfi_init(&h, &P, &B, &c, &why));
    TEST_ASSERT_DOUBLE_WITHIN(1e-4, 1.05, why.value);
    /* accepted with the minimum lowered */
    c.sal_min = 1.04;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_hfi_init(&h, &P, &B, &c, &why));
    /* a bad field is named */
    m = machine_thesis_ipmsm80();
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&P, &B, &m, 10000u));
    ctrl_hfi_config_default(&c, &m);
    c.w_hi_frac = 0.5 * c.w_lo_frac;
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_hfi_init(&h, &P, &B, &c, &why));
    TEST_ASSERT_EQUAL_STRING("w_hi_frac", why.quantity);
    ctrl_hfi_config_default(&c, &m);
    c.track_hz = 1000.0; /* above fs / 100 */
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, ctrl_hfi_init(&h, &P, &B, &c, &why));
    TEST_ASSERT_EQUAL_STRING("track_hz", why.quantity);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_lock_from_start_errors);
    RUN_TEST(test_noise);
    RUN_TEST(test_turning);
    RUN_TEST(test_accel);
    RUN_TEST(test_fundamental);
    RUN_TEST(test_polarity);
    RUN_TEST(test_legs);
    RUN_TEST(test_config);
    return UNITY_END();
}
