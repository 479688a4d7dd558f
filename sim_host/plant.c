/*
 * Plant model: 2L-VSI (3.1) + PMSM (3.8)-(3.10) / flux maps (3.11)-(3.14) +
 * mechanics (3.15). See plant.h for the interface and the integration methods.
 *
 * Exact path (linear machine, ideal stiff inverter, all legs driven).
 * In the rotor frame, with omega = omega_e held constant over a sub-interval:
 *   Ld id' = vd - Rs id + omega Lq iq
 *   Lq iq' = vq - Rs iq - omega (Ld id + psi_pm)                      (3.8)-(3.9)
 * i.e. x' = A x + B u(t) + c, x = (id, iq), B = diag(1/Ld, 1/Lq),
 *   A = [-Rs/Ld, omega Lq/Ld; -omega Ld/Lq, -Rs/Lq], c = (0, -omega psi_pm/Lq).
 * The leg states fix v_ab (constant), so vd + j vq = W e^{-j omega t} with
 * W = v_ab e^{-j theta_0}: u = Re{P e^{s t}}, s = -j omega, P = (W, -jW).
 * Particular solutions: xp(t) = Re{X e^{st}}, X = (sI - A)^{-1} B P, and the
 * constant xc = -A^{-1} c. Then x(t) = e^{At}(x0 - xp(0) - xc) + xp(t) + xc.
 * With Rs > 0, A is Hurwitz (trace < 0, det > 0), so A and sI - A are
 * invertible. e^{At} of the 2x2 matrix in closed form:
 *   e^{At} = e^{tau t} [C(q) I + t S(q) (A - tau I)], tau = tr(A)/2,
 *   q = t^2 ((a-d)^2/4 + b c), C = cosh(sqrt q), S = sinh(sqrt q)/sqrt q
 * (cos / sin for q < 0; Taylor series for |q| < 1e-2).
 */
#include "plant.h"

#include <math.h>
#include <string.h>

#include "plant_mech.h"

#define PLANT_SQRT3 1.73205080756887729353
#define PLANT_RK4_STEP_DEFAULT 0.5e-6
/* Time comparisons: instants closer than this are the same instant. */
#define PLANT_T_EPS 1e-15

/* ---------------------------------------------------------------- helpers */

static int finite_pos(double x)
{
    return isfinite(x) && x > 0.0;
}
static int finite_nonneg(double x)
{
    return isfinite(x) && x >= 0.0;
}

static double wrap_pi(double a)
{
    if (a >= -PLANT_PI && a < PLANT_PI) {
        return a;
    }
    a = fmod(a + PLANT_PI, 2.0 * PLANT_PI);
    if (a < 0.0) {
        a += 2.0 * PLANT_PI;
    }
    return a - PLANT_PI;
}

static double omega_e(const plant_t *p)
{
    return p->omega_m * (double)p->cfg.pole_pairs;
}

/* psi from i (linear (3.9) or flux map (3.11)). */
static void flux_from_current(const plant_t *p, double id, double iq, double *pd, double *pq)
{
    if (p->cfg.fluxmap != NULL) {
        plant_fluxmap_psi(p->cfg.fluxmap, id, iq, pd, pq);
    } else {
        *pd = p->cfg.ld_h * id + p->cfg.psi_pm_wb;
        *pq = p->cfg.lq_h * iq;
    }
}

/* i from psi ((3.14) or the linear inverse). */
static int current_from_flux(const plant_t *p, double pd, double pq, double *id, double *iq)
{
    if (p->cfg.fluxmap != NULL) {
        *id = p->id; /* warm start of Newton */
        *iq = p->iq;
        return plant_fluxmap_current(p->cfg.fluxmap, pd, pq, id, iq);
    }
    *id = (pd - p->cfg.psi_pm_wb) / p->cfg.ld_h;
    *iq = pq / p->cfg.lq_h;
    return PLANT_OK;
}

static double torque_dq(const plant_t *p, double id, double iq, double pd, double pq)
{
    return 1.5 * (double)p->cfg.pole_pairs * (pd * iq - pq * id); /* (3.10) */
}

static void dq_to_abc(double id, double iq, double th, double i_abc[3])
{
    const double c = cos(th), s = sin(th);
    const double ia = id * c - iq * s;
    const double ib = id * s + iq * c;
    i_abc[0] = ia;
    i_abc[1] = -0.5 * ia + 0.5 * PLANT_SQRT3 * ib;
    i_abc[2] = -0.5 * ia - 0.5 * PLANT_SQRT3 * ib;
}

/* Effective state of leg x at the current time (dead time forces OFF). */
typedef struct {
    uint8_t s[3];
} legs_t;

/* ------------------------------------------------------------ exact path */

/* C(q) = cosh(sqrt q), S(q) = sinh(sqrt q)/sqrt q, analytic in q. */
static void ch_sh(double q, double *c, double *s)
{
    if (fabs(q) < 1e-2) {
        *c = 1.0 + q * (1.0 / 2.0 + q * (1.0 / 24.0 + q * (1.0 / 720.0 + q * (1.0 / 40320.0))));
        *s = 1.0 + q * (1.0 / 6.0 + q * (1.0 / 120.0 + q * (1.0 / 5040.0 + q * (1.0 / 362880.0))));
    } else if (q > 0.0) {
        const double r = sqrt(q);
        *c = cosh(r);
        *s = sinh(r) / r;
    } else {
        const double r = sqrt(-q);
        *c = cos(r);
        *s = sin(r) / r;
    }
}

/* Constants of the exact solution for one speed and one voltage vector. */
typedef struct {
    double a, b, c, d;   /* A */
    double tau, disc;    /* tr(A)/2, (a-d)^2/4 + bc */
    double w;            /* omega_e */
    double wu;           /* angular frequency of the input in the rotor frame */
    double Wr, Wi;       /* v_dq at the start of the sub-interval */
    int iso;             /* Ld == Lq and wu == -w: e^{At} is a damped
                            rotation by the same angle as the input */
    double xr[2], xi[2]; /* X = xr + j xi */
    double xc[2];        /* constant particular solution */
} exact_t;

/* Input v_d + j v_q = W e^{j wu t}, W = v_ab(0) e^{-j th0}. The inverter case
 * (constant v_ab) is wu = -w; a synchronously rotating stator voltage is wu = 0. */
static void exact_setup(const plant_t *p, double w, double wu, double v_al, double v_be, double ct,
                        double st, exact_t *e)
{
    const double ld = p->cfg.ld_h, lq = p->cfg.lq_h, rs = p->cfg.rs_ohm;
    e->w = w;
    e->wu = wu;
    e->a = -rs / ld;
    e->b = w * lq / ld;
    e->c = -w * ld / lq;
    e->d = -rs / lq;
    e->tau = 0.5 * (e->a + e->d);
    e->disc = 0.25 * (e->a - e->d) * (e->a - e->d) + e->b * e->c;
    e->iso = (ld == lq) && (wu == -w);
    /* W = v_ab e^{-j th0} */
    const double wr = v_al * ct + v_be * st;
    const double wi = -v_al * st + v_be * ct;
    e->Wr = wr;
    e->Wi = wi;
    /* B P = (W/Ld, -jW/Lq) */
    const double p0r = wr / ld, p0i = wi / ld;
    const double p1r = wi / lq, p1i = -wr / lq;
    /* M = sI - A, s = j wu: [[-a + j wu, -b], [-c, -d + j wu]] */
    const double m00r = -e->a, m00i = wu, m01r = -e->b;
    const double m10r = -e->c, m11r = -e->d, m11i = wu;
    /* det = m00 m11 - m01 m10 */
    const double detr = m00r * m11r - m00i * m11i - m01r * m10r;
    const double deti = m00r * m11i + m00i * m11r;
    const double dd = detr * detr + deti * deti;
    /* X = adj(M) BP / det; adj = [[m11, -m01], [-m10, m00]] */
    const double n0r = (m11r * p0r - m11i * p0i) - m01r * p1r;
    const double n0i = (m11r * p0i + m11i * p0r) - m01r * p1i;
    const double n1r = -m10r * p0r + (m00r * p1r - m00i * p1i);
    const double n1i = -m10r * p0i + (m00r * p1i + m00i * p1r);
    e->xr[0] = (n0r * detr + n0i * deti) / dd;
    e->xi[0] = (n0i * detr - n0r * deti) / dd;
    e->xr[1] = (n1r * detr + n1i * deti) / dd;
    e->xi[1] = (n1i * detr - n1r * deti) / dd;
    /* xc = -A^{-1} c, c = (0, c1) */
    const double c1 = -w * p->cfg.psi_pm_wb / lq;
    const double detA = e->a * e->d - e->b * e->c;
    e->xc[0] = (e->b * c1) / detA;
    e->xc[1] = -(e->a * c1) / detA;
}

/* State at time t into the sub-interval from x0; *cw_out, *sw_out (may be
 * NULL) receive cos, sin of wu t. */
static void exact_eval(const exact_t *e, const double x0[2], double t, double x[2], double *cw_out,
                       double *sw_out)
{
    const double g = exp(e->tau * t);
    double e00, e01, e10, e11, cw, sw;
    if (e->iso) {
        /* A = -R/L I + w J: e^{At} = e^{-Rt/L} [cos wt, sin wt; -sin wt, cos wt] */
        const double c = cos(e->w * t), s = sin(e->w * t);
        e00 = g * c;
        e01 = g * s;
        e10 = -g * s;
        e11 = g * c;
        cw = c;
        sw = -s;
    } else {
        double ch, sh;
        ch_sh(e->disc * t * t, &ch, &sh);
        e00 = g * (ch + t * sh * (e->a - e->tau));
        e01 = g * (t * sh * e->b);
        e10 = g * (t * sh * e->c);
        e11 = g * (ch + t * sh * (e->d - e->tau));
        cw = cos(e->wu * t);
        sw = sin(e->wu * t);
    }
    if (cw_out != NULL) {
        *cw_out = cw;
        *sw_out = sw;
    }
    /* xp(0) = Re X */
    const double z0 = x0[0] - e->xr[0] - e->xc[0];
    const double z1 = x0[1] - e->xr[1] - e->xc[1];
    /* xp(t) = Re{X e^{j wu t}} = xr cos - xi sin */
    x[0] = e00 * z0 + e01 * z1 + e->xr[0] * cw - e->xi[0] * sw + e->xc[0];
    x[1] = e10 * z0 + e11 * z1 + e->xr[1] * cw - e->xi[1] * sw + e->xc[1];
}

/* ------------------------------------------------------------- voltages */

/* Leg voltages (to the DC negative rail) for the leg states and phase currents. */
static void leg_voltages(const plant_t *p, const legs_t *l, double vdc, const double i_abc[3],
                         double v_leg[3], double *i_dc)
{
    const double vf = p->cfg.v_fwd_v;
    double idc = 0.0;
    for (int x = 0; x < 3; ++x) {
        const double i = i_abc[x];
        const double sg = (i > 0.0) ? 1.0 : ((i < 0.0) ? -1.0 : 0.0);
        if (l->s[x] == PLANT_LEG_HIGH) {
            v_leg[x] = vdc - vf * sg;
            idc += i;
        } else if (l->s[x] == PLANT_LEG_LOW) {
            v_leg[x] = -vf * sg;
        } else if (i > 0.0) { /* off: lower diode */
            v_leg[x] = -vf;
        } else if (i < 0.0) { /* off: upper diode, current back into the link */
            v_leg[x] = vdc + vf;
            idc += i;
        } else { /* off, no current: the leg floats; take the phase's own
                    neutral-point voltage so that it drives no current */
            v_leg[x] = NAN;
        }
    }
    /* A floating leg (off, zero current) takes the mean of the others so that
     * it adds nothing to the neutral shift (first-order approximation). */
    int nf = 0;
    double sum = 0.0;
    for (int x = 0; x < 3; ++x) {
        if (isnan(v_leg[x])) {
            ++nf;
        } else {
            sum += v_leg[x];
        }
    }
    for (int x = 0; x < 3; ++x) {
        if (isnan(v_leg[x])) {
            v_leg[x] = (nf < 3) ? sum / (double)(3 - nf) : 0.5 * vdc;
        }
    }
    *i_dc = idc;
}

/* alpha-beta voltage of the leg voltages, (3.1) with (3.3). */
static void leg_to_ab(const double v_leg[3], double *v_al, double *v_be)
{
    *v_al = (2.0 * v_leg[0] - v_leg[1] - v_leg[2]) / 3.0;
    *v_be = (v_leg[1] - v_leg[2]) / PLANT_SQRT3;
}

/* --------------------------------------------------------------- RK4 path */

/* y = (psi_d, psi_q, vdc, e_src, e_in, e_cu, e_mech) */
#define RK_N 7

static int rk_deriv(const plant_t *p, const legs_t *l, double th, double w, const double y[RK_N],
                    double dy[RK_N], double v_ab[2])
{
    double id, iq;
    const int rc = current_from_flux(p, y[0], y[1], &id, &iq);
    if (rc != PLANT_OK) {
        return rc;
    }
    double i_abc[3], v_leg[3], idc, v_al, v_be;
    dq_to_abc(id, iq, th, i_abc);
    const double vdc = y[2];
    leg_voltages(p, l, vdc, i_abc, v_leg, &idc);
    leg_to_ab(v_leg, &v_al, &v_be);
    if (v_ab != NULL) {
        v_ab[0] = v_al;
        v_ab[1] = v_be;
    }
    const double c = cos(th), s = sin(th);
    const double vd = v_al * c + v_be * s;
    const double vq = -v_al * s + v_be * c;
    const double rs = p->cfg.rs_ohm;
    dy[0] = vd - rs * id + w * y[1]; /* (3.13) */
    dy[1] = vq - rs * iq - w * y[0];
    double p_src = 0.0;
    if (p->cfg.dc_cap_f > 0.0) {
        const double i_src = (p->cfg.vdc_v - vdc) / p->cfg.dc_src_r_ohm;
        dy[2] = (i_src - idc) / p->cfg.dc_cap_f;
        p_src = p->cfg.vdc_v * i_src;
    } else {
        dy[2] = 0.0;
        p_src = vdc * idc;
    }
    dy[3] = p_src;
    dy[4] = v_leg[0] * i_abc[0] + v_leg[1] * i_abc[1] + v_leg[2] * i_abc[2];
    dy[5] = 1.5 * rs * (id * id + iq * iq);
    dy[6] = torque_dq(p, id, iq, y[0], y[1]) * w / (double)p->cfg.pole_pairs;
    return PLANT_OK;
}

/* Integrate dt with fixed RK4 sub-steps (the last one shortened); omega
 * constant; leg states fixed, current signs re-evaluated at every stage. */
static int rk4_interval(plant_t *p, const legs_t *l, double w, double dt)
{
    const double hmax = p->cfg.rk4_step_s;
    long n = (long)ceil(dt / hmax - 1e-9);
    if (n < 1) {
        n = 1;
    }
    const double h = dt / (double)n;
    double y[RK_N] = {p->psi_d, p->psi_q, p->vdc, p->e_src_j, p->e_in_j, p->e_cu_j, p->e_mech_j};
    double th = p->theta_e;
    for (long k = 0; k < n; ++k) {
        double k1[RK_N], k2[RK_N], k3[RK_N], k4[RK_N], yt[RK_N], v_ab[2];
        int rc = rk_deriv(p, l, th, w, y, k1, v_ab);
        /* motor voltage integral: leg voltages of the sub-step's start */
        p->v_int[0] += h * v_ab[0];
        p->v_int[1] += h * v_ab[1];
        for (int j = 0; j < RK_N; ++j) {
            yt[j] = y[j] + 0.5 * h * k1[j];
        }
        rc |= rk_deriv(p, l, th + 0.5 * h * w, w, yt, k2, NULL);
        for (int j = 0; j < RK_N; ++j) {
            yt[j] = y[j] + 0.5 * h * k2[j];
        }
        rc |= rk_deriv(p, l, th + 0.5 * h * w, w, yt, k3, NULL);
        for (int j = 0; j < RK_N; ++j) {
            yt[j] = y[j] + h * k3[j];
        }
        rc |= rk_deriv(p, l, th + h * w, w, yt, k4, NULL);
        if (rc != PLANT_OK) {
            return PLANT_ERANGE;
        }
        for (int j = 0; j < RK_N; ++j) {
            y[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
        }
        th += h * w;
    }
    p->psi_d = y[0];
    p->psi_q = y[1];
    p->vdc = y[2];
    if (p->cfg.track_energy) {
        p->e_src_j = y[3];
        p->e_in_j = y[4];
        p->e_cu_j = y[5];
        p->e_mech_j = y[6];
    }
    if (current_from_flux(p, p->psi_d, p->psi_q, &p->id, &p->iq) != PLANT_OK) {
        return PLANT_ERANGE;
    }
    if (!(p->vdc >= 0.0) || !isfinite(p->id) || !isfinite(p->iq)) {
        return PLANT_ERANGE;
    }
    return PLANT_OK;
}

/* ------------------------------------------------------------ one piece */

static int legs_driven(const legs_t *l)
{
    return l->s[0] <= 1u && l->s[1] <= 1u && l->s[2] <= 1u;
}

static int use_exact(const plant_t *p, const legs_t *l)
{
    return p->linear_exact && legs_driven(l);
}

/* Exact integration over dt from the current state for the input of e;
 * energies by 4-point Gauss-Legendre (integrands smooth inside the piece). */
static int exact_interval(plant_t *p, const exact_t *e, double dt)
{
    const double x0[2] = {p->id, p->iq};
    if (p->cfg.track_energy) {
        static const double gx[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563,
                                     0.8611363115940526};
        static const double gw[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461,
                                     0.3478548451374538};
        const double p_pairs = (double)p->cfg.pole_pairs;
        double ein = 0.0, ecu = 0.0, emech = 0.0;
        for (int k = 0; k < 4; ++k) {
            const double tk = 0.5 * dt * (1.0 + gx[k]);
            double x[2];
            exact_eval(e, x0, tk, x, NULL, NULL);
            const double c = cos(e->wu * tk), s = sin(e->wu * tk);
            const double vd = e->Wr * c - e->Wi * s, vq = e->Wr * s + e->Wi * c;
            const double pd = p->cfg.ld_h * x[0] + p->cfg.psi_pm_wb;
            const double pq = p->cfg.lq_h * x[1];
            ein += gw[k] * 1.5 * (vd * x[0] + vq * x[1]);
            ecu += gw[k] * 1.5 * p->cfg.rs_ohm * (x[0] * x[0] + x[1] * x[1]);
            emech += gw[k] * torque_dq(p, x[0], x[1], pd, pq) * e->w / p_pairs;
        }
        p->e_in_j += 0.5 * dt * ein;
        p->e_src_j += 0.5 * dt * ein;
        p->e_cu_j += 0.5 * dt * ecu;
        p->e_mech_j += 0.5 * dt * emech;
    }
    double x[2], cw, sw;
    exact_eval(e, x0, dt, x, &cw, &sw);
    if (!isfinite(x[0]) || !isfinite(x[1])) {
        return PLANT_ERANGE;
    }
    if (e->wu == -e->w) {
        /* cos, sin of the angle at the end: rotate the cached ones by w dt
         * (cos w dt = cw, sin w dt = -sw); keyed on the exact end angle as
         * advance_piece computes it; refreshed every 32 rotations. */
        const double c0 = p->trig_c, s0 = p->trig_s;
        p->trig_c = c0 * cw + s0 * sw;
        p->trig_s = s0 * cw - c0 * sw;
        p->trig_key = wrap_pi(p->theta_e + e->w * dt);
        p->trig_n++;
    } else {
        p->trig_n = 0;
    }
    p->id = x[0];
    p->iq = x[1];
    flux_from_current(p, p->id, p->iq, &p->psi_d, &p->psi_q);
    return PLANT_OK;
}

/* Ideal sinusoidal stator voltage (test input), see plant_advance_voltage_ab. */
typedef struct {
    int active;
    double amp, omega_v, phase;
} sine_in_t;

/* Integral of the test source amp e^{j (omega_v t + phase)} over [t0, t0 + dt]. */
static void sine_vint(plant_t *p, const sine_in_t *sine, double t0, double dt)
{
    const double a0 = sine->omega_v * t0 + sine->phase;
    if (fabs(sine->omega_v * dt) < 1e-9) {
        p->v_int[0] += sine->amp * cos(a0) * dt;
        p->v_int[1] += sine->amp * sin(a0) * dt;
        return;
    }
    const double a1 = a0 + sine->omega_v * dt;
    /* integral e^{j a} dt = (e^{j a1} - e^{j a0}) / (j omega_v) */
    p->v_int[0] += sine->amp * (sin(a1) - sin(a0)) / sine->omega_v;
    p->v_int[1] += sine->amp * (cos(a0) - cos(a1)) / sine->omega_v;
}

/* Filter path: one piece at the step's held speed (the machine and the filter
 * together, plant_filter.c); theta, t and the torque integral advance here,
 * the speed at the step's end (step_end). */
static int filter_piece(plant_t *p, const legs_t *l, const sine_in_t *sine, double dt)
{
    const double pp = (double)p->cfg.pole_pairs;
    const double w = p->step_wm * pp;
    plant_filter_input_t in = {0, -w, 0.0, 0.0};
    const double c = cos(p->theta_e), s = sin(p->theta_e);
    if (sine != NULL && sine->active) {
        const double ang = sine->omega_v * p->t + sine->phase;
        const double va = sine->amp * cos(ang), vb = sine->amp * sin(ang);
        in.wu = sine->omega_v - w;
        in.w_d = va * c + vb * s;
        in.w_q = -va * s + vb * c;
    } else if (legs_driven(l)) {
        const double vdc = p->vdc;
        const double v_leg[3] = {l->s[0] ? vdc : 0.0, l->s[1] ? vdc : 0.0, l->s[2] ? vdc : 0.0};
        double va, vb;
        leg_to_ab(v_leg, &va, &vb);
        in.w_d = va * c + vb * s;
        in.w_q = -va * s + vb * c;
    } else if (l->s[0] == PLANT_LEG_OFF && l->s[1] == PLANT_LEG_OFF && l->s[2] == PLANT_LEG_OFF) {
        in.open = 1;
    } else {
        return PLANT_EINVAL; /* some legs off: only with dead time, refused with a filter */
    }
    double te_int = 0.0;
    const int rc = plant_filter_piece(p, &in, w, dt, &te_int, p->v_int);
    if (rc != PLANT_OK) {
        return rc;
    }
    p->step_te_int += te_int;
    plant_filter_motor_current(p, &p->id, &p->iq);
    flux_from_current(p, p->id, p->iq, &p->psi_d, &p->psi_q);
    p->theta_e = wrap_pi(p->theta_e + w * dt);
    p->theta_m += p->step_wm * dt;
    p->t += dt;
    p->trig_n = 0;
    return PLANT_OK;
}

/* Electrical integration over dt at constant omega_e = w (theta not advanced). */
static int electrical_piece(plant_t *p, const legs_t *l, const sine_in_t *sine, double w,
                            double t_off, double dt)
{
    exact_t e;
    if (sine != NULL && sine->active) {
        const double ang = sine->omega_v * (p->t + t_off) + sine->phase;
        exact_setup(p, w, sine->omega_v - w, sine->amp * cos(ang), sine->amp * sin(ang),
                    cos(p->theta_e), sin(p->theta_e), &e);
        sine_vint(p, sine, p->t + t_off, dt);
        return exact_interval(p, &e, dt);
    }
    if (use_exact(p, l)) {
        const double vdc = p->vdc;
        double v_leg[3] = {l->s[0] ? vdc : 0.0, l->s[1] ? vdc : 0.0, l->s[2] ? vdc : 0.0};
        double v_al, v_be;
        leg_to_ab(v_leg, &v_al, &v_be);
        p->v_int[0] += v_al * dt;
        p->v_int[1] += v_be * dt;
        if (p->trig_n == 0 || p->trig_n > 32 || p->trig_key != p->theta_e) {
            p->trig_c = cos(p->theta_e);
            p->trig_s = sin(p->theta_e);
            p->trig_n = 1;
        }
        exact_setup(p, w, -w, v_al, v_be, p->trig_c, p->trig_s, &e);
        return exact_interval(p, &e, dt);
    }
    if (l->s[0] == PLANT_LEG_OFF && l->s[1] == PLANT_LEG_OFF && l->s[2] == PLANT_LEG_OFF &&
        p->id == 0.0 && p->iq == 0.0 && w == 0.0 && p->cfg.fluxmap == NULL &&
        p->cfg.dc_cap_f == 0.0) {
        /* Switches open, no current, rotor at rest (linear machine, stiff
         * link): every derivative of the RK4 path is zero, so it would leave
         * the state exactly as it is; skip its 0.5 us steps (the boot and
         * calibration of a free rotor in the QEMU images spent millions of
         * instructions per period on them). */
        return PLANT_OK;
    }
    return rk4_interval(p, l, w, dt);
}

/* The electrical state electrical_piece changes, for a second pass. */
typedef struct {
    double id, iq, psi_d, psi_q, theta_e, vdc;
    double e_in_j, e_cu_j, e_mech_j, e_src_j, v_int[2];
    double trig_c, trig_s, trig_key;
    int trig_n;
} elec_state_t;

static void elec_save(const plant_t *p, elec_state_t *e)
{
    *e = (elec_state_t){p->id,
                        p->iq,
                        p->psi_d,
                        p->psi_q,
                        p->theta_e,
                        p->vdc,
                        p->e_in_j,
                        p->e_cu_j,
                        p->e_mech_j,
                        p->e_src_j,
                        {p->v_int[0], p->v_int[1]},
                        p->trig_c,
                        p->trig_s,
                        p->trig_key,
                        p->trig_n};
}

static void elec_restore(plant_t *p, const elec_state_t *e)
{
    p->id = e->id;
    p->iq = e->iq;
    p->psi_d = e->psi_d;
    p->psi_q = e->psi_q;
    p->theta_e = e->theta_e;
    p->vdc = e->vdc;
    p->e_in_j = e->e_in_j;
    p->e_cu_j = e->e_cu_j;
    p->e_mech_j = e->e_mech_j;
    p->e_src_j = e->e_src_j;
    p->v_int[0] = e->v_int[0];
    p->v_int[1] = e->v_int[1];
    p->trig_c = e->trig_c;
    p->trig_s = e->trig_s;
    p->trig_key = e->trig_key;
    p->trig_n = e->trig_n;
}

/* Splits of one piece at stick and slip events, at most (then the rest is
 * integrated whole, the events still located by the mechanics). */
#define PLANT_MECH_SPLITS 8

/* Free mechanics with friction, stiction, cogging or a load profile
 * (plant_mech.h) over the sub-piece [t_off, t_off + *h] of the piece (p->t is
 * the piece's start): two passes, each the electrical part at a held speed
 * (first the predicted mean speed, mech_mean_speed; then the mean speed the
 * first pass's mechanics found), Te at 0, h/2, h, and the mechanics against
 * the quadratic through them. If the first pass finds a stick or slip event
 * inside and split is set, the sub-piece ends there (*h shortened): a held
 * speed over a piece in which the rotor was at rest for a part would be
 * wrong (a locked rotor's break-away 0.5 us late). The second pass removes
 * the held speed's first-order error (100 x smaller angle error against
 * tests/plant/ref_plant_mech.cpp); a third gains nothing (what remains is the
 * speed's variation inside the piece). theta_e follows theta_m. */
static int mech_subpiece(plant_t *p, const legs_t *l, const sine_in_t *sine, double t_off,
                         double *h, int split)
{
    const double pp = (double)p->cfg.pole_pairs;
    mech_in_t in;
    mech_setup(p, &in);
    in.prof_x0 = p->t + t_off - p->profile_t0;
    const double te0 = plant_torque(p);
    in.te[0] = te0;
    in.coarse = 1;
    double dt = *h, wh;
    int rc = mech_mean_speed(&in, dt, p->omega_m, p->mech_dir, &wh);
    if (rc != PLANT_OK) {
        return rc;
    }
    elec_state_t e0;
    elec_save(p, &e0);
    const double th0 = p->theta_e;
    mech_out_t mo;
    for (int pass = 0; pass < 2; ++pass) {
        in.coarse = pass == 0;
        if (pass == 1) {
            const double wh2 = mo.dtheta / dt;
            if (fabs(wh2 - wh) * pp * dt <= 1e-15) {
                /* the same held speed (a rotor at rest): the first pass's
                 * electrical part stands, the mechanics once more exactly */
                rc = mech_solve(&in, dt, p->omega_m, p->mech_dir, &mo);
                if (rc != PLANT_OK) {
                    return rc;
                }
                break;
            }
            elec_restore(p, &e0);
            wh = wh2;
        }
        rc = electrical_piece(p, l, sine, wh * pp, t_off, 0.5 * dt);
        if (rc != PLANT_OK) {
            return rc;
        }
        p->theta_e = th0 + wh * pp * 0.5 * dt;
        const double tem = plant_torque(p);
        rc = electrical_piece(p, l, sine, wh * pp, t_off + 0.5 * dt, 0.5 * dt);
        if (rc != PLANT_OK) {
            return rc;
        }
        const double te1 = plant_torque(p);
        in.te[1] = (-3.0 * te0 + 4.0 * tem - te1) / dt;
        in.te[2] = (2.0 * te0 - 4.0 * tem + 2.0 * te1) / (dt * dt);
        rc = mech_solve(&in, dt, p->omega_m, p->mech_dir, &mo);
        if (rc != PLANT_OK) {
            return rc;
        }
        if (pass == 0 && split && mo.t_event > 1e-9 * dt && mo.t_event < (1.0 - 1e-9) * dt) {
            /* end the sub-piece at the event: the first pass again, shorter */
            elec_restore(p, &e0);
            dt = mo.t_event;
            split = 0;
            pass = -1;
            in.coarse = 1;
            in.te[1] = in.te[2] = 0.0;
            rc = mech_mean_speed(&in, dt, p->omega_m, p->mech_dir, &wh);
            if (rc != PLANT_OK) {
                return rc;
            }
        }
    }
    *h = dt;
    p->omega_m = mo.omega;
    p->mech_dir = mo.dir;
    p->theta_m += mo.dtheta;
    p->theta_e = wrap_pi(th0 + pp * mo.dtheta);
    plant_mech_stats_t *s = &p->ms;
    s->stuck_s += mo.d.stuck_s;
    s->moving_s += mo.d.moving_s;
    s->breakaways += mo.d.breakaways;
    s->stops += mo.d.stops;
    s->reversals += mo.d.reversals;
    s->e_drive_j += mo.d.e_drive_j;
    s->e_friction_j += mo.d.e_friction_j;
    s->e_load_j += mo.d.e_load_j;
    s->abs_angle_rad += mo.d.abs_angle_rad;
    return PLANT_OK;
}

/* A piece of free non-ideal mechanics: sub-pieces ended at the events. */
static int mech_piece(plant_t *p, const legs_t *l, const sine_in_t *sine, double dt)
{
    double done = 0.0;
    for (int k = 0; done < dt; ++k) {
        double h = dt - done;
        const int rc = mech_subpiece(p, l, sine, done, &h, k < PLANT_MECH_SPLITS);
        if (rc != PLANT_OK) {
            return rc;
        }
        done = (h == dt - done) ? dt : done + h;
    }
    return PLANT_OK;
}

/* Advance dt with fixed effective leg states: electrical + mechanical. */
static int advance_piece(plant_t *p, const legs_t *l, const sine_in_t *sine, double dt)
{
    if (dt <= 0.0) {
        return PLANT_OK;
    }
    if (p->flt.type != PLANT_FILTER_NONE) {
        return filter_piece(p, l, sine, dt);
    }
    const double pp = (double)p->cfg.pole_pairs;
    int rc;
    if (p->cfg.mech == PLANT_MECH_FREE && p->mech_events) {
        rc = mech_piece(p, l, sine, dt);
        if (rc != PLANT_OK) {
            return rc;
        }
    } else if (p->cfg.mech == PLANT_MECH_FREE) {
        /* omega held at the midpoint prediction; Te averaged by Simpson. */
        const double J = p->cfg.inertia_kgm2, B = p->cfg.friction_nms;
        const double te0 = plant_torque(p);
        const double wm0 = p->omega_m;
        /* Passive load: its sign follows the motion at the piece start (at
         * rest: the direction the net torque would start it, none when the
         * load can hold it). */
        const double tp = p->load_passive_nm;
        double dir = (wm0 > 0.0) - (wm0 < 0.0);
        if (dir == 0.0 && fabs(te0 - p->load_torque_nm) > tp) {
            dir = te0 - p->load_torque_nm > 0.0 ? 1.0 : -1.0;
        }
        const double tl = p->load_torque_nm + tp * dir;
        const int held = tp > 0.0 && dir == 0.0;
        const double wm_mid = held ? 0.0 : wm0 + 0.5 * dt * (te0 - tl - B * wm0) / J;
        const double th0 = p->theta_e;
        rc = electrical_piece(p, l, sine, wm_mid * pp, 0.0, 0.5 * dt);
        if (rc != PLANT_OK) {
            return rc;
        }
        p->theta_e = th0 + wm_mid * pp * 0.5 * dt;
        const double te_mid = plant_torque(p);
        rc = electrical_piece(p, l, sine, wm_mid * pp, 0.5 * dt, 0.5 * dt);
        if (rc != PLANT_OK) {
            return rc;
        }
        p->theta_e = wrap_pi(th0 + wm_mid * pp * dt);
        const double te1 = plant_torque(p);
        const double te_av = (te0 + 4.0 * te_mid + te1) / 6.0;
        const double f = te_av - tl;
        if (held) {
            p->omega_m = 0.0;
        } else if (B > 0.0) {
            const double a = exp(-B * dt / J);
            p->omega_m = wm0 * a + f / B * (1.0 - a);
        } else {
            p->omega_m = wm0 + f * dt / J;
        }
        if (tp > 0.0 && dir != 0.0 && p->omega_m * dir < 0.0) {
            /* A passive load stops the rotor, it cannot reverse it: the
             * speed crossed zero inside the piece; the next piece starts at
             * rest and decides from the torque then (error: one piece). */
            p->omega_m = 0.0;
        }
        p->theta_m += wm_mid * dt;
    } else {
        const double w = p->omega_m * pp;
        rc = electrical_piece(p, l, sine, w, 0.0, dt);
        if (rc != PLANT_OK) {
            return rc;
        }
        p->theta_e = wrap_pi(p->theta_e + w * dt);
        p->theta_m += p->omega_m * dt;
    }
    p->t += dt;
    return PLANT_OK;
}

/* ------------------------------------------------------------------ API */

/* The non-ideal mechanics' part of a configuration: clears *ok if a value is
 * out of range; returns 1 if any term is present (the event path). */
static int mech_config_ok(const plant_config_t *c, int *ok)
{
    int good = finite_nonneg(c->coulomb_nm) && isfinite(c->stiction_nm) &&
               c->stiction_nm >= c->coulomb_nm && c->cog_n >= 0 && c->cog_n <= PLANT_COG_MAX;
    int any_cog = 0;
    for (int k = 0; good && k < c->cog_n; ++k) {
        good = finite_nonneg(c->cog_amp_nm[k]) && isfinite(c->cog_phase_rad[k]);
        any_cog |= c->cog_amp_nm[k] > 0.0;
    }
    if (good && c->cog_n > 0) {
        good = c->cog_per_rev >= 1;
    }
    const plant_profile_t *pr = &c->load_profile;
    if (good && pr->kind != PLANT_PROFILE_NONE) {
        good = (pr->kind == PLANT_PROFILE_TIME || pr->kind == PLANT_PROFILE_SPEED) && pr->n >= 2 &&
               pr->n <= PLANT_PROFILE_MAX;
        for (int i = 0; good && i < pr->n; ++i) {
            good = isfinite(pr->x[i]) && isfinite(pr->y[i]) && (i == 0 || pr->x[i] > pr->x[i - 1]);
        }
    }
    if (!good) {
        *ok = 0;
        return 0;
    }
    return c->coulomb_nm > 0.0 || c->stiction_nm > 0.0 || any_cog || pr->kind != PLANT_PROFILE_NONE;
}

int plant_init(plant_t *p, const plant_config_t *cfg)
{
    if (p == NULL) {
        return PLANT_EINVAL;
    }
    memset(p, 0, sizeof(*p));
    if (cfg == NULL) {
        return PLANT_EINVAL;
    }
    const plant_config_t *c = cfg;
    int ok = c->pole_pairs >= 1 && c->pole_pairs <= 100 && finite_pos(c->rs_ohm) &&
             finite_pos(c->ld_h) && finite_pos(c->lq_h) && finite_nonneg(c->psi_pm_wb) &&
             finite_pos(c->vdc_v) && finite_nonneg(c->dc_cap_f) && finite_nonneg(c->dead_time_s) &&
             finite_nonneg(c->v_fwd_v) && finite_nonneg(c->friction_nms) &&
             isfinite(c->load_torque_nm) && finite_nonneg(c->load_passive_nm) &&
             isfinite(c->theta0_e_rad) && isfinite(c->id0_a) && isfinite(c->iq0_a) &&
             isfinite(c->speed0_rpm) && finite_nonneg(c->rk4_step_s) &&
             (c->mech == PLANT_MECH_IMPOSED || c->mech == PLANT_MECH_FREE);
    if (ok && c->dc_cap_f > 0.0) {
        ok = finite_pos(c->dc_src_r_ohm);
    }
    if (ok && c->mech == PLANT_MECH_FREE) {
        ok = finite_pos(c->inertia_kgm2);
    }
    if (ok && c->fluxmap != NULL) {
        ok = c->fluxmap->n_d >= 2 && c->fluxmap->n_q >= 2 && c->fluxmap->psi_d != NULL &&
             c->fluxmap->psi_q != NULL;
    }
    if (ok && c->filter.type != PLANT_FILTER_NONE) {
        /* the filter path integrates the linear model exactly (plant_filter.h) */
        ok = c->fluxmap == NULL && c->dc_cap_f == 0.0 && c->dead_time_s == 0.0 && c->v_fwd_v == 0.0;
    }
    const int events = mech_config_ok(c, &ok);
    if (ok && events && c->filter.type != PLANT_FILTER_NONE) {
        /* the filter path holds the speed over a whole PWM period */
        ok = 0;
    }
    if (!ok) {
        return PLANT_EINVAL;
    }
    p->cfg = *c;
    if (p->cfg.rk4_step_s <= 0.0) {
        p->cfg.rk4_step_s = PLANT_RK4_STEP_DEFAULT;
    }
    p->linear_exact = (c->fluxmap == NULL && c->dc_cap_f == 0.0 && c->v_fwd_v == 0.0);
    p->theta_e = wrap_pi(c->theta0_e_rad);
    p->theta_m = c->theta0_e_rad / (double)c->pole_pairs;
    p->omega_m = c->speed0_rpm * 2.0 * PLANT_PI / 60.0;
    p->vdc = c->vdc_v;
    p->load_torque_nm = c->load_torque_nm;
    p->load_passive_nm = c->load_passive_nm;
    p->mech_events = events;
    p->mech_dir = (p->omega_m > 0.0) - (p->omega_m < 0.0);
    p->profile_on = 1;
    p->profile_t0 = 0.0;
    for (int k = 0; k < c->cog_n; ++k) {
        p->cog_c[k] = cos(c->cog_phase_rad[k]);
        p->cog_s[k] = sin(c->cog_phase_rad[k]);
    }
    p->id = c->id0_a;
    p->iq = c->iq0_a;
    flux_from_current(p, p->id, p->iq, &p->psi_d, &p->psi_q);
    for (int x = 0; x < 3; ++x) {
        p->dead_end[x] = -1.0;
    }
    if (plant_filter_setup(p) != PLANT_OK) {
        memset(p, 0, sizeof(*p));
        return PLANT_EINVAL;
    }
    return PLANT_OK;
}

void plant_set_observer(plant_t *p, plant_observer_fn fn, void *ctx, double obs_dt)
{
    if (p == NULL) {
        return;
    }
    if (fn == NULL || !(obs_dt > 0.0) || !isfinite(obs_dt)) {
        p->obs = NULL;
        p->obs_ctx = NULL;
        p->obs_dt = 0.0;
        return;
    }
    p->obs = fn;
    p->obs_ctx = ctx;
    p->obs_dt = obs_dt;
    p->v_int[0] = p->v_int[1] = 0.0;
    p->v_int_t0 = p->t;
    p->obs_next = (int64_t)floor(p->t / obs_dt + 1e-9) + 1;
}

void plant_set_load_torque(plant_t *p, double t_load_nm)
{
    if (p != NULL && isfinite(t_load_nm)) {
        p->load_torque_nm = t_load_nm;
    }
}

void plant_set_load_passive(plant_t *p, double t_passive_nm)
{
    if (p != NULL && isfinite(t_passive_nm) && t_passive_nm >= 0.0) {
        p->load_passive_nm = t_passive_nm;
    }
}

/* The mechanics' inputs now (sub-interval time 0, the torque now). */
static void mech_now(const plant_t *p, mech_in_t *in)
{
    mech_setup(p, in);
    in->prof_x0 = p->t - p->profile_t0;
    in->te[0] = plant_torque(p);
}

double plant_load_torque(const plant_t *p)
{
    if (p == NULL) {
        return NAN;
    }
    const double tp = p->load_passive_nm;
    if (p->mech_events) {
        mech_in_t in;
        mech_now(p, &in);
        const double tla = mech_load(&in, 0.0, p->omega_m);
        if (p->mech_dir != 0) {
            return tla + tp * (double)p->mech_dir;
        }
        /* At rest the bearings hold up to T_s of the net torque, the passive
         * load the rest (at most T_p). */
        const double net = in.te[0] + plant_cogging_torque(p) - tla;
        const double ts = p->cfg.stiction_nm;
        const double bearing = net > ts ? ts : (net < -ts ? -ts : net);
        return tla + (net - bearing);
    }
    if (p->omega_m != 0.0) {
        return p->load_torque_nm + (p->omega_m > 0.0 ? tp : -tp);
    }
    /* At rest the passive load holds up to tp of the net torque. */
    const double net = plant_torque(p) - p->load_torque_nm;
    return p->load_torque_nm + (net > tp ? tp : (net < -tp ? -tp : net));
}

void plant_set_speed_rpm(plant_t *p, double rpm)
{
    if (p != NULL && isfinite(rpm)) {
        p->omega_m = rpm * 2.0 * PLANT_PI / 60.0;
        p->mech_dir = (p->omega_m > 0.0) - (p->omega_m < 0.0);
    }
}

void plant_load_profile_enable(plant_t *p, int on)
{
    if (p != NULL) {
        p->profile_on = on != 0;
        p->profile_t0 = p->t;
    }
}

double plant_cogging_torque(const plant_t *p)
{
    if (p == NULL || p->cfg.cog_n == 0) {
        return 0.0;
    }
    mech_in_t in;
    mech_setup(p, &in);
    return mech_cogging(&in, 0.0);
}

double plant_cogging_energy(const plant_t *p)
{
    if (p == NULL || p->cfg.cog_n == 0) {
        return 0.0;
    }
    mech_in_t in;
    mech_setup(p, &in);
    return mech_cogging_energy(&in, 0.0);
}

double plant_friction_torque(const plant_t *p)
{
    if (p == NULL) {
        return NAN;
    }
    if (!p->mech_events || p->mech_dir != 0) {
        const double d = p->mech_events ? (double)p->mech_dir
                                        : (double)((p->omega_m > 0.0) - (p->omega_m < 0.0));
        return p->cfg.friction_nms * p->omega_m + p->cfg.coulomb_nm * d;
    }
    mech_in_t in;
    mech_now(p, &in);
    const double net = in.te[0] + mech_cogging(&in, 0.0) - mech_load(&in, 0.0, 0.0);
    const double ts = p->cfg.stiction_nm;
    return net > ts ? ts : (net < -ts ? -ts : net);
}

int plant_stuck(const plant_t *p)
{
    return p != NULL && p->mech_events && p->mech_dir == 0;
}

void plant_mech_stats(const plant_t *p, plant_mech_stats_t *st)
{
    *st = p->ms;
}

/* Effective leg states at the current time (dead time). */
static void effective_legs(const plant_t *p, legs_t *l)
{
    for (int x = 0; x < 3; ++x) {
        l->s[x] = (p->t < p->dead_end[x] - PLANT_T_EPS) ? PLANT_LEG_OFF : p->s[x];
    }
}

static int advance_common(plant_t *p, double dt, const uint8_t s[3], const sine_in_t *sine);

/* Filter path: one plant step of planned length len holds the electrical
 * speed at the midpoint prediction (free mechanics) or the imposed speed, so
 * that the combined linear system is time invariant over the step. Returns
 * 1 if this call opened the step. */
static int step_begin(plant_t *p, double len)
{
    if (p->flt.type == PLANT_FILTER_NONE || p->step_on) {
        return 0;
    }
    p->step_on = 1;
    p->step_t0 = p->t;
    p->step_len = len;
    p->step_wm0 = p->omega_m;
    p->step_te_int = 0.0;
    p->step_wm = p->omega_m;
    if (p->cfg.mech == PLANT_MECH_FREE) {
        const double J = p->cfg.inertia_kgm2, B = p->cfg.friction_nms;
        p->step_wm += 0.5 * len * (plant_torque(p) - p->load_torque_nm - B * p->omega_m) / J;
    }
    return 1;
}

/* Close the step: the speed follows (3.15) with the step's mean torque. */
static void step_end(plant_t *p, int opened)
{
    if (!opened) {
        return;
    }
    p->step_on = 0;
    const double dt = p->t - p->step_t0;
    if (p->cfg.mech != PLANT_MECH_FREE || !(dt > 0.0)) {
        return;
    }
    const double J = p->cfg.inertia_kgm2, B = p->cfg.friction_nms;
    const double f = p->step_te_int / dt - p->load_torque_nm;
    if (B > 0.0) {
        const double a = exp(-B * dt / J);
        p->omega_m = p->step_wm0 * a + f / B * (1.0 - a);
    } else {
        p->omega_m = p->step_wm0 + f * dt / J;
    }
}

int plant_advance(plant_t *p, double dt, const uint8_t s[3])
{
    if (p == NULL || s == NULL || !finite_nonneg(dt) || s[0] > 2u || s[1] > 2u || s[2] > 2u) {
        return PLANT_EINVAL;
    }
    const int opened = step_begin(p, dt);
    const int rc = advance_common(p, dt, s, NULL);
    step_end(p, opened);
    return rc;
}

int plant_advance_voltage_ab(plant_t *p, double dt, double v_amp, double omega_v, double phase)
{
    if (p == NULL || !finite_nonneg(dt) || !isfinite(v_amp) || !isfinite(omega_v) ||
        !isfinite(phase) || !p->linear_exact) {
        return PLANT_EINVAL;
    }
    const sine_in_t sine = {1, v_amp, omega_v, phase};
    const uint8_t s[3] = {p->s[0], p->s[1], p->s[2]};
    const int opened = step_begin(p, dt);
    const int rc = advance_common(p, dt, s, &sine);
    step_end(p, opened);
    return rc;
}

/* Observer call at a grid instant; the motor-voltage integral restarts. */
static void observe(plant_t *p)
{
    p->obs(p->obs_ctx, p);
    p->obs_next++;
    p->v_int[0] = p->v_int[1] = 0.0;
    p->v_int_t0 = p->t;
}

/*
 * The observer instants strictly inside the piece [p->t, t_next) with legs l:
 * a copy of the plant is advanced from the piece's start to each of them and
 * observed, the plant itself is not touched, so its integration (the pieces
 * between switching, dead-time and filter instants) is the same with and
 * without an observer, bit for bit. The motor-voltage integral carries the
 * part of the piece after the last instant into the plant's (the copy's
 * integral is the running one: its last part is the piece's remainder).
 * Returns PLANT_OK or the copy's error.
 */
static int observe_inside(plant_t *p, const legs_t *l, const sine_in_t *sine, double t_next,
                          double eps)
{
    if (p->obs == NULL || (double)p->obs_next * p->obs_dt >= t_next - eps) {
        return PLANT_OK;
    }
    plant_t sh;
    if (p->flt.type == PLANT_FILTER_NONE) {
        /* Without a filter a piece reads nothing past the filter's type:
         * the state before it (640 bytes on the host), not the filter's
         * 16 kB of cached exponentials, once per observed piece. */
        memcpy(&sh, p, offsetof(plant_t, flt));
        sh.flt.type = PLANT_FILTER_NONE;
    } else {
        sh = *p;
    }
    double before[2] = {0.0, 0.0}; /* the piece's share of the integral up to the last instant */
    while ((double)p->obs_next * p->obs_dt < t_next - eps) {
        const double t_obs = (double)p->obs_next * p->obs_dt;
        if (t_obs > sh.t) {
            const double v0[2] = {sh.v_int[0], sh.v_int[1]};
            const int rc = advance_piece(&sh, l, sine, t_obs - sh.t);
            if (rc != PLANT_OK) {
                return rc;
            }
            before[0] += sh.v_int[0] - v0[0];
            before[1] += sh.v_int[1] - v0[1];
            sh.t = t_obs;
        }
        p->obs(p->obs_ctx, &sh);
        p->obs_next++;
        sh.v_int[0] = sh.v_int[1] = 0.0;
        sh.v_int_t0 = sh.t;
        p->v_int_t0 = sh.t;
    }
    /* The plant's integral restarts at the last instant: the piece's whole
     * share is added by advance_piece, so the part before it goes out now. */
    p->v_int[0] = -before[0];
    p->v_int[1] = -before[1];
    return PLANT_OK;
}

static int advance_common(plant_t *p, double dt, const uint8_t s[3], const sine_in_t *sine)
{
    /* Commanded transitions: count them, start the dead time. */
    for (int x = 0; x < 3 && sine == NULL; ++x) {
        if (p->s_valid && s[x] <= 1u && p->s[x] <= 1u && s[x] != p->s[x]) {
            p->transitions[x]++;
            if (p->cfg.dead_time_s > 0.0) {
                p->dead_end[x] = p->t + p->cfg.dead_time_s;
            }
        }
        p->s[x] = s[x];
    }
    if (sine == NULL) {
        p->s_valid = 1;
    }
    const double t_end = p->t + dt;
    const double eps_end = PLANT_T_EPS * (1.0 + fabs(t_end));
    int guard = 0;
    while (p->t < t_end - eps_end) {
        /* The pieces end at the period's end, the active filter's sampling
         * instants and the dead times' ends: never at an observer instant. */
        double t_next = t_end;
        /* the active filter's controller samples on its own grid */
        const double t_flt = plant_filter_next_event(p);
        int hit_flt = 0;
        if (t_flt <= t_next + eps_end) {
            t_next = (t_flt < t_next) ? t_flt : t_next;
            hit_flt = 1;
        }
        for (int x = 0; x < 3; ++x) {
            if (p->dead_end[x] > p->t + PLANT_T_EPS && p->dead_end[x] < t_next) {
                t_next = p->dead_end[x];
                hit_flt = 0;
            }
        }
        legs_t l;
        effective_legs(p, &l);
        int rc = observe_inside(p, &l, sine, t_next, eps_end);
        if (rc != PLANT_OK) {
            return rc;
        }
        rc = advance_piece(p, &l, sine, t_next - p->t);
        if (rc != PLANT_OK) {
            return rc;
        }
        p->t = t_next; /* avoid drift of repeated sums */
        /* An observer instant at the piece's end (within rounding): the plant's state. */
        while (p->obs != NULL && (double)p->obs_next * p->obs_dt <= p->t + eps_end) {
            observe(p);
        }
        if (hit_flt) {
            plant_filter_event(p);
        }
        if (++guard > 100000000) {
            return PLANT_ERANGE;
        }
    }
    p->t = t_end; /* the loop stops within rounding of t_end */
    /* Observer and filter instants that coincide with t_end within rounding. */
    const double eps_t = PLANT_T_EPS * (1.0 + fabs(p->t));
    while (p->obs != NULL && (double)p->obs_next * p->obs_dt <= p->t + eps_t) {
        observe(p);
    }
    while (plant_filter_next_event(p) <= p->t + eps_t) {
        plant_filter_event(p);
    }
    return PLANT_OK;
}

int plant_advance_period(plant_t *p, double T, const double duty[3])
{
    if (p == NULL || duty == NULL || !finite_pos(T)) {
        return PLANT_EINVAL;
    }
    double on[3], off[3];
    for (int x = 0; x < 3; ++x) {
        double d = duty[x];
        if (!isfinite(d)) {
            return PLANT_EINVAL;
        }
        d = (d < 0.0) ? 0.0 : ((d > 1.0) ? 1.0 : d);
        on[x] = 0.5 * T * (1.0 - d);
        off[x] = 0.5 * T * (1.0 + d);
    }
    /* Sorted switching instants (insertion sort of 8 values incl. 0 and T). */
    double inst[8] = {0.0, T, on[0], on[1], on[2], off[0], off[1], off[2]};
    for (int i = 1; i < 8; ++i) {
        const double v = inst[i];
        int j = i - 1;
        while (j >= 0 && inst[j] > v) {
            inst[j + 1] = inst[j];
            --j;
        }
        inst[j + 1] = v;
    }
    const double t0 = p->t;
    const int opened = step_begin(p, T);
    for (int i = 0; i < 7; ++i) {
        const double a = inst[i], b = inst[i + 1];
        if (b - a <= 0.0) {
            continue;
        }
        const double mid = 0.5 * (a + b);
        uint8_t s[3];
        for (int x = 0; x < 3; ++x) {
            s[x] = (mid >= on[x] && mid < off[x]) ? PLANT_LEG_HIGH : PLANT_LEG_LOW;
        }
        /* Integrate to the absolute instant t0 + b (no accumulated rounding). */
        const int rc = plant_advance(p, (t0 + b) - p->t, s);
        if (rc != PLANT_OK) {
            step_end(p, opened);
            return rc;
        }
    }
    step_end(p, opened);
    return PLANT_OK;
}

/* -------------------------------------------------------------- getters */

double plant_time(const plant_t *p)
{
    return p->t;
}

void plant_i_abc(const plant_t *p, double i_abc[3])
{
    dq_to_abc(p->id, p->iq, p->theta_e, i_abc);
}

void plant_i_dq(const plant_t *p, double *id, double *iq)
{
    *id = p->id;
    *iq = p->iq;
}

void plant_i_ab(const plant_t *p, double *i_alpha, double *i_beta)
{
    const double c = cos(p->theta_e), s = sin(p->theta_e);
    *i_alpha = p->id * c - p->iq * s;
    *i_beta = p->id * s + p->iq * c;
}

void plant_psi_ab(const plant_t *p, double *psi_alpha, double *psi_beta)
{
    const double c = cos(p->theta_e), s = sin(p->theta_e);
    *psi_alpha = p->psi_d * c - p->psi_q * s;
    *psi_beta = p->psi_d * s + p->psi_q * c;
}

double plant_psi_amp(const plant_t *p)
{
    return hypot(p->psi_d, p->psi_q);
}

double plant_torque(const plant_t *p)
{
    return torque_dq(p, p->id, p->iq, p->psi_d, p->psi_q);
}

double plant_theta_e(const plant_t *p)
{
    return p->theta_e;
}
double plant_omega_e(const plant_t *p)
{
    return omega_e(p);
}
double plant_theta_m(const plant_t *p)
{
    return p->theta_m;
}
double plant_omega_m(const plant_t *p)
{
    return p->omega_m;
}
double plant_vdc(const plant_t *p)
{
    return p->vdc;
}

static void ab_to_abc(double a, double b, double abc[3])
{
    abc[0] = a;
    abc[1] = -0.5 * a + 0.5 * PLANT_SQRT3 * b;
    abc[2] = -0.5 * a - 0.5 * PLANT_SQRT3 * b;
}

void plant_v_motor_abc(const plant_t *p, double v_abc[3])
{
    double ab[2];
    if (p->flt.type != PLANT_FILTER_NONE) {
        (void)plant_filter_probe(p, PLANT_FP_V_MOTOR, ab);
    } else {
        const double v_leg[3] = {p->s[0] == PLANT_LEG_HIGH ? p->vdc : 0.0,
                                 p->s[1] == PLANT_LEG_HIGH ? p->vdc : 0.0,
                                 p->s[2] == PLANT_LEG_HIGH ? p->vdc : 0.0};
        leg_to_ab(v_leg, &ab[0], &ab[1]);
    }
    ab_to_abc(ab[0], ab[1], v_abc);
}

void plant_v_motor_mean_abc(const plant_t *p, double v_abc[3])
{
    const double dt = p->t - p->v_int_t0;
    if (!(dt > 0.0)) {
        plant_v_motor_abc(p, v_abc);
        return;
    }
    ab_to_abc(p->v_int[0] / dt, p->v_int[1] / dt, v_abc);
}

void plant_i_inverter_abc(const plant_t *p, double i_abc[3])
{
    if (p->flt.type == PLANT_FILTER_NONE) {
        plant_i_abc(p, i_abc);
        return;
    }
    double ab[2];
    (void)plant_filter_probe(p, PLANT_FP_I_INV, ab);
    ab_to_abc(ab[0], ab[1], i_abc);
}

uint64_t plant_transitions(const plant_t *p)
{
    return p->transitions[0] + p->transitions[1] + p->transitions[2];
}

double plant_magnetic_energy(const plant_t *p)
{
    if (p->cfg.fluxmap != NULL) {
        return NAN;
    }
    return 0.75 * (p->cfg.ld_h * p->id * p->id + p->cfg.lq_h * p->iq * p->iq);
}

void plant_energy(const plant_t *p, double *e_src_j, double *e_in_j, double *e_cu_j,
                  double *e_mech_j)
{
    *e_src_j = p->e_src_j;
    *e_in_j = p->e_in_j;
    *e_cu_j = p->e_cu_j;
    *e_mech_j = p->e_mech_j;
}
