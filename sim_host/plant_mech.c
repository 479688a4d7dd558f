/*
 * Non-ideal mechanics over one sub-interval: friction with stiction, cogging,
 * active and passive loads (plant_mech.h). Stick and slip are events located
 * inside the sub-interval; between them the right side is smooth and RK4
 * integrates it with steps bounded by what makes it vary.
 */
#include "plant_mech.h"

#include <math.h>
#include <string.h>

/* RK4 step bounds: phase of the highest cogging harmonic per step, and
 * (natural frequency x step) of the stiffest linear part (cogging detent,
 * viscous J/B, speed profile slope). RK4's local error per step is ~x^5/120
 * of the quantity: 0.25 gives < 1e-5 relative per step and, the error
 * being of fifth order, < 1e-6 over one cogging period (tests/plant's
 * reference agreement). */
#define MECH_DPHI_MAX 0.25
/* Events per sub-interval before the integration gives up (chatter). */
#define MECH_EVENTS_MAX 100000
/* Event location: bracket width relative to the step. */
#define MECH_LOC_TOL 1e-14

#define TWO_PI (2.0 * PLANT_PI)

/* -------------------------------------------------------------- inputs */

void mech_setup(const plant_t *p, mech_in_t *in)
{
    const plant_config_t *c = &p->cfg;
    memset(in, 0, sizeof *in);
    in->j = c->inertia_kgm2;
    in->b = c->friction_nms;
    in->tc = c->coulomb_nm;
    in->tp = p->load_passive_nm;
    in->tbrk = c->stiction_nm + p->load_passive_nm;
    in->tl = p->load_torque_nm;
    in->prof =
        (p->profile_on && c->load_profile.kind != PLANT_PROFILE_NONE) ? &c->load_profile : NULL;
    in->cog_n = c->cog_n;
    in->cog_per_rev = (double)c->cog_per_rev;
    in->cog_amp = c->cog_amp_nm;
    for (int k = 0; k < c->cog_n; ++k) {
        in->cog_c[k] = p->cog_c[k];
        in->cog_s[k] = p->cog_s[k];
    }
    /* the speed-independent parts of step_max: the bound of |dw/dt| but Te
     * and B w, and the steps of the linear parts (cogging detent
     * J theta'' = -N sum k A_k theta linearised, J/B, the speed profile's
     * slope) */
    double prof_max = 0.0, prof_slope = 0.0, cog_sum = 0.0, cog_k = 0.0;
    if (in->prof != NULL) {
        for (int i = 0; i < in->prof->n; ++i) {
            prof_max = fmax(prof_max, fabs(in->prof->y[i]));
            if (i + 1 < in->prof->n && in->prof->kind == PLANT_PROFILE_SPEED) {
                prof_slope = fmax(prof_slope, fabs((in->prof->y[i + 1] - in->prof->y[i]) /
                                                   (in->prof->x[i + 1] - in->prof->x[i])));
            }
        }
    }
    for (int k = 0; k < c->cog_n; ++k) {
        cog_sum += c->cog_amp_nm[k];
        cog_k += (double)(k + 1) * c->cog_amp_nm[k];
    }
    in->acc_rest = (fabs(in->tl) + prof_max + in->tc + in->tp + cog_sum) / in->j;
    in->h_lin = INFINITY;
    if (cog_k > 0.0) {
        in->h_lin = MECH_DPHI_MAX / sqrt(in->cog_per_rev * cog_k / in->j);
    }
    if (in->b > 0.0) {
        in->h_lin = fmin(in->h_lin, MECH_DPHI_MAX * in->j / in->b);
    }
    if (prof_slope > 0.0) {
        in->h_lin = fmin(in->h_lin, MECH_DPHI_MAX * in->j / prof_slope);
    }
    if (c->cog_n > 0) {
        double ph = fmod(in->cog_per_rev * p->theta_m, TWO_PI);
        in->cog_phase0 = ph < 0.0 ? ph + TWO_PI : ph;
        in->cog_s0 = sin(in->cog_phase0);
        in->cog_c0 = cos(in->cog_phase0);
    }
}

/* sin and cos of the cogging phase phase0 + d: for |d| <= 0.5 (a sub-interval
 * rarely travels more) the rotation of the start's sin and cos by d, with d's
 * own sin and cos from their Taylor series to degree 15 and 16 (remainder
 * < 0.5^17/17! = 2e-20), a fraction of the cost of sin() and cos(). */
static void cog_sincos(const mech_in_t *in, double d, double *s, double *c)
{
    if (fabs(d) > 0.5) {
        *s = sin(in->cog_phase0 + d);
        *c = cos(in->cog_phase0 + d);
        return;
    }
    const double d2 = d * d;
    const double sd =
        d * (1.0 -
             d2 / 6.0 *
                 (1.0 -
                  d2 / 20.0 *
                      (1.0 - d2 / 42.0 *
                                 (1.0 - d2 / 72.0 *
                                            (1.0 - d2 / 110.0 *
                                                       (1.0 - d2 / 156.0 * (1.0 - d2 / 210.0)))))));
    const double cd =
        1.0 -
        d2 / 2.0 *
            (1.0 -
             d2 / 12.0 *
                 (1.0 -
                  d2 / 30.0 *
                      (1.0 - d2 / 56.0 *
                                 (1.0 - d2 / 90.0 *
                                            (1.0 - d2 / 132.0 *
                                                       (1.0 - d2 / 182.0 * (1.0 - d2 / 240.0)))))));
    *s = in->cog_s0 * cd + in->cog_c0 * sd;
    *c = in->cog_c0 * cd - in->cog_s0 * sd;
}

/* sum_k A_k sin(k phi + phi_k), phi = phase0 + N dth, by the angle-addition
 * recurrence over k. */
double mech_cogging(const mech_in_t *in, double dth)
{
    if (in->cog_n == 0) {
        return 0.0;
    }
    double s1, c1;
    cog_sincos(in, in->cog_per_rev * dth, &s1, &c1);
    double sk = s1, ck = c1, t = 0.0;
    for (int k = 0; k < in->cog_n; ++k) {
        t += in->cog_amp[k] * (sk * in->cog_c[k] + ck * in->cog_s[k]);
        const double sn = sk * c1 + ck * s1;
        ck = ck * c1 - sk * s1;
        sk = sn;
    }
    return t;
}

double mech_cogging_energy(const mech_in_t *in, double dth)
{
    const double phi = in->cog_phase0 + in->cog_per_rev * dth;
    double w = 0.0;
    for (int k = 0; k < in->cog_n; ++k) {
        const double a = (double)(k + 1) * phi;
        /* cos(k phi + phi_k) */
        w += in->cog_amp[k] / ((double)(k + 1) * in->cog_per_rev) *
             (cos(a) * in->cog_c[k] - sin(a) * in->cog_s[k]);
    }
    return w;
}

/* Profile value at x (held outside the points) and the index i of the
 * segment [x_i, x_i+1] holding x (-1 before the first point, n-1 after the
 * last). */
static double prof_eval(const plant_profile_t *pr, double x, int *seg)
{
    const int n = pr->n;
    if (!(x > pr->x[0])) {
        *seg = -1;
        return pr->y[0];
    }
    if (x >= pr->x[n - 1]) {
        *seg = n - 1;
        return pr->y[n - 1];
    }
    int lo = 0, hi = n - 1; /* x[lo] < x < x[hi] ... x in [x[lo], x[hi]) */
    while (hi - lo > 1) {
        const int mid = (lo + hi) / 2;
        if (pr->x[mid] <= x) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    *seg = lo;
    return pr->y[lo] + (pr->y[lo + 1] - pr->y[lo]) * (x - pr->x[lo]) / (pr->x[lo + 1] - pr->x[lo]);
}

double mech_load(const mech_in_t *in, double t, double w)
{
    double tl = in->tl;
    if (in->prof != NULL) {
        int seg;
        const double x = in->prof->kind == PLANT_PROFILE_TIME ? in->prof_x0 + t : w;
        tl += prof_eval(in->prof, x, &seg);
    }
    return tl;
}

static double te_at(const mech_in_t *in, double t)
{
    return in->te[0] + t * (in->te[1] + t * in->te[2]);
}

/* Net driving torque Te + T_cog - T_La at time t, angle dth from the start, speed w.
 * The stuck test and the acceleration at rest use this same expression, so
 * a break-away found by it starts with an acceleration of the right sign. */
static double net_torque(const mech_in_t *in, double t, double dth, double w)
{
    return (te_at(in, t) + mech_cogging(in, dth)) - mech_load(in, t, w);
}

/* ----------------------------------------------------------- turning */

/* State integrated while turning: angle travelled, speed, e_drive,
 * e_friction, e_load, integral |w| (direction fixed). */
#define NY 6

static void deriv(const mech_in_t *in, int dir, double t, const double y[NY], double dy[NY])
{
    const double w = y[1];
    const double tla = mech_load(in, t, w);
    const double net = (te_at(in, t) + mech_cogging(in, y[0])) - tla;
    const double d = (double)dir;
    dy[0] = w;
    dy[1] = ((net - in->b * w) - (in->tc + in->tp) * d) / in->j;
    dy[2] = te_at(in, t) * w;
    dy[3] = (in->b * w + in->tc * d) * w;
    dy[4] = (tla + in->tp * d) * w;
    dy[5] = d * w;
}

/* One RK4 step of length hs from (t, y) with k1 = f(t, y) given. */
static void rk4(const mech_in_t *in, int dir, double t, const double y[NY], const double k1[NY],
                double hs, double out[NY])
{
    double k2[NY], k3[NY], k4[NY], yt[NY];
    for (int i = 0; i < NY; ++i) {
        yt[i] = y[i] + 0.5 * hs * k1[i];
    }
    deriv(in, dir, t + 0.5 * hs, yt, k2);
    for (int i = 0; i < NY; ++i) {
        yt[i] = y[i] + 0.5 * hs * k2[i];
    }
    deriv(in, dir, t + 0.5 * hs, yt, k3);
    for (int i = 0; i < NY; ++i) {
        yt[i] = y[i] + hs * k3[i];
    }
    deriv(in, dir, t + hs, yt, k4);
    for (int i = 0; i < NY; ++i) {
        out[i] = y[i] + hs / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
}

/* Largest RK4 step for this sub-interval (see MECH_DPHI_MAX); *a_bound: a
 * bound of |dw/dt| over it. */
static double step_max(const mech_in_t *in, double h, double w0, double *a_bound)
{
    const double te_max = fabs(in->te[0]) + fabs(in->te[1]) * h + fabs(in->te[2]) * h * h;
    const double a_max = (te_max + in->b * fabs(w0)) / in->j + in->acc_rest;
    *a_bound = a_max;
    double hmax = fmin(h, in->h_lin);
    if (in->cog_n > 0) {
        const double rate = (fabs(w0) + a_max * h) * in->cog_per_rev * (double)in->cog_n;
        if (rate * hmax > MECH_DPHI_MAX) { /* the highest harmonic's phase per step */
            hmax = MECH_DPHI_MAX / rate;
        }
    }
    return hmax;
}

/* g(tau) = dir * w after one RK4 step of length tau. */
static double g_at(const mech_in_t *in, int dir, double t, const double y[NY], const double k1[NY],
                   double tau, double yo[NY])
{
    rk4(in, dir, t, y, k1, tau, yo);
    return (double)dir * yo[1];
}

/* The first zero of dir * w in (0, hs] given g(hs) < 0 or a dip below zero
 * at s_dip * hs (s_dip > 0); the state there in yo. Returns 0 if there is
 * no crossing after all (a dip of the interpolant only). */
static int locate_zero(const mech_in_t *in, int dir, double t, const double y[NY],
                       const double k1[NY], double hs, double s_dip, double yo[NY], double *tau)
{
    double hi = s_dip > 0.0 ? s_dip * hs : hs;
    double ghi = g_at(in, dir, t, y, k1, hi, yo);
    if (!(ghi <= 0.0)) {
        return 0;
    }
    double lo = 0.0, glo = (double)dir * y[1];
    if (!(glo > 0.0)) {
        /* starting at rest (break-away or reversal): the acceleration has
         * the sign of dir, so dir * w > 0 just after the start */
        lo = hi;
        glo = ghi;
        for (int i = 0; i < 200 && !(glo > 0.0); ++i) {
            lo *= 0.5;
            glo = g_at(in, dir, t, y, k1, lo, yo);
        }
        if (!(glo > 0.0)) {
            *tau = 0.0; /* it never turned that way */
            memcpy(yo, y, sizeof(double) * NY);
            return 1;
        }
    }
    const double tol = MECH_LOC_TOL * hs;
    int side = 0;
    for (int it = 0; it < 200 && hi - lo > tol; ++it) {
        double m = (lo * ghi - hi * glo) / (ghi - glo);
        if (!(m > lo && m < hi)) {
            m = 0.5 * (lo + hi);
        }
        const double gm = g_at(in, dir, t, y, k1, m, yo);
        if (gm > 0.0) {
            lo = m;
            glo = gm;
            if (side == 1) {
                ghi *= 0.5;
            }
            side = 1;
        } else {
            hi = m;
            ghi = gm;
            if (side == -1) {
                glo *= 0.5;
            }
            side = -1;
            if (gm == 0.0) {
                break;
            }
        }
    }
    (void)g_at(in, dir, t, y, k1, hi, yo);
    *tau = hi;
    return 1;
}

/* A dip of the cubic Hermite interpolant of g = dir * w over the step
 * (values g0 >= 0, g1 >= 0, slopes m0, m1 per unit s): the s in (0, 1) of
 * its lowest point if that is below zero, else 0. */
static double hermite_dip(double g0, double g1, double m0, double m1)
{
    const double c1 = m0;
    const double c2 = -3.0 * g0 - 2.0 * m0 + 3.0 * g1 - m1;
    const double c3 = 2.0 * g0 + m0 - 2.0 * g1 + m1;
    /* P'(s) = c1 + 2 c2 s + 3 c3 s^2 */
    double r[2];
    int n = 0;
    const double a = 3.0 * c3, b = 2.0 * c2, c = c1;
    if (a == 0.0) {
        if (b != 0.0) {
            r[n++] = -c / b;
        }
    } else {
        const double disc = b * b - 4.0 * a * c;
        if (disc >= 0.0) {
            const double q = -0.5 * (b + copysign(sqrt(disc), b));
            if (q != 0.0) {
                r[n++] = q / a;
                r[n++] = c / q;
            }
        }
    }
    double best = 0.0, s_best = 0.0;
    for (int i = 0; i < n; ++i) {
        const double s = r[i];
        if (s > 0.0 && s < 1.0) {
            const double v = g0 + s * (c1 + s * (c2 + s * c3));
            if (v < best) {
                best = v;
                s_best = s;
            }
        }
    }
    return s_best;
}

/* ----------------------------------------------------------- at rest */

/* Real roots of a t^2 + b t + c = 0 (stable form); returns their number. */
static int quad_roots(double a, double b, double c, double r[2])
{
    if (a == 0.0) {
        if (b == 0.0) {
            return 0;
        }
        r[0] = -c / b;
        return 1;
    }
    const double disc = b * b - 4.0 * a * c;
    if (disc < 0.0) {
        return 0;
    }
    const double q = -0.5 * (b + copysign(sqrt(disc), b));
    if (q == 0.0) {
        r[0] = 0.0;
        return 1;
    }
    r[0] = q / a;
    r[1] = c / q;
    return 2;
}

/* First instant in [t0, t1] at which the rotor at rest (at dth)
 * breaks away, |net| > tbrk; +inf if none. Between t0 and t1 the active load
 * is linear in t (t1 is at most the next time-profile point). */
static double breakaway(const mech_in_t *in, double t0, double t1, double dth)
{
    if (fabs(net_torque(in, t0, dth, 0.0)) > in->tbrk) {
        return t0;
    }
    /* net(t) = A + B t + C t^2 on [t0, t1]: from three evaluations of the load
     * (exact for the linear load) and the quadratic Te. */
    const double tm = 0.5 * (t0 + t1);
    const double l0 = mech_load(in, t0, 0.0), l1 = mech_load(in, t1, 0.0);
    const double ls = t1 > t0 ? (l1 - l0) / (t1 - t0) : 0.0;
    (void)tm;
    const double cog = mech_cogging(in, dth);
    const double C = in->te[2];
    const double B = in->te[1] - ls;
    const double A = in->te[0] + cog - (l0 - ls * t0);
    double cand[4];
    int n = 0;
    for (int sgn = -1; sgn <= 1; sgn += 2) {
        double r[2];
        const int k = quad_roots(C, B, A - (double)sgn * in->tbrk, r);
        for (int i = 0; i < k; ++i) {
            if (r[i] >= t0 - 1e-12 * (t1 - t0) && r[i] <= t1) {
                cand[n++] = r[i] < t0 ? t0 : r[i];
            }
        }
    }
    /* ascending */
    for (int i = 1; i < n; ++i) {
        const double v = cand[i];
        int j = i - 1;
        while (j >= 0 && cand[j] > v) {
            cand[j + 1] = cand[j];
            --j;
        }
        cand[j + 1] = v;
    }
    const double reach = 1e-9 * (t1 - t0) + 1e-18;
    for (int i = 0; i < n; ++i) {
        /* polish: the first representable instant at or after the root
         * where the evaluated torque exceeds (a tangency never does) */
        double t = cand[i], step = fmax(fabs(t), 1e-300) * 2.2e-16;
        while (t <= t1 && t - cand[i] <= reach) {
            if (fabs(net_torque(in, t, dth, 0.0)) > in->tbrk) {
                return t;
            }
            t = cand[i] + step;
            step *= 2.0;
        }
    }
    /* Rounding hid a crossing that the end value shows: bisect for it. */
    if (fabs(net_torque(in, t1, dth, 0.0)) > in->tbrk) {
        double lo = t0, hi = t1;
        for (int it = 0; it < 200 && hi - lo > MECH_LOC_TOL * (t1 - t0); ++it) {
            const double m = 0.5 * (lo + hi);
            if (fabs(net_torque(in, m, dth, 0.0)) > in->tbrk) {
                hi = m;
            } else {
                lo = m;
            }
        }
        return hi;
    }
    return INFINITY;
}

/* ----------------------------------------------------------- driver */

/* Next time-profile point strictly after t (sub-interval time), or h. */
static double next_break(const mech_in_t *in, double t, double h)
{
    if (in->prof == NULL || in->prof->kind != PLANT_PROFILE_TIME) {
        return h;
    }
    for (int i = 0; i < in->prof->n; ++i) {
        const double tb = in->prof->x[i] - in->prof_x0;
        if (tb > t && tb < h) {
            return tb;
        }
    }
    return h;
}

int mech_mean_speed(const mech_in_t *in, double h, double w0, int dir, double *wh)
{
    double a_max;
    (void)step_max(in, h, w0, &a_max);
    if (dir != 0 && fabs(w0) > a_max * h) {
        /* no stop and no break-away possible: the midpoint prediction */
        const double y[NY] = {0.0, w0, 0.0, 0.0, 0.0, 0.0};
        double dy[NY];
        deriv(in, dir, 0.0, y, dy);
        *wh = w0 + 0.5 * h * dy[1];
        return PLANT_OK;
    }
    mech_out_t o;
    const int rc = mech_solve(in, h, w0, dir, &o);
    *wh = o.dtheta / h;
    return rc;
}

int mech_solve(const mech_in_t *in, double h, double w0, int dir0, mech_out_t *out)
{
    memset(out, 0, sizeof *out);
    out->t_event = INFINITY;
    double y[NY] = {0.0, w0, 0.0, 0.0, 0.0, 0.0};
    int dir = dir0;
    if (w0 != 0.0) {
        dir = w0 > 0.0 ? 1 : -1;
    }
    double a_max;
    double hmax = step_max(in, h, w0, &a_max);
    if (in->coarse) {
        hmax = h;
    }
    double t = 0.0;
    long events = 0;
    while (t < h) {
        const double t_end = next_break(in, t, h);
        if (dir == 0) {
            const double tb = breakaway(in, t, t_end, y[0]);
            if (!(tb <= t_end)) {
                out->d.stuck_s += t_end - t;
                t = t_end;
                continue;
            }
            out->d.stuck_s += tb - t;
            t = tb;
            out->t_event = fmin(out->t_event, t);
            dir = net_torque(in, t, y[0], 0.0) > 0.0 ? 1 : -1;
            out->d.breakaways++;
            if (++events > MECH_EVENTS_MAX) {
                return PLANT_ERANGE;
            }
            continue;
        }
        /* turning: RK4 steps to t_end or to the speed's zero */
        const double span = t_end - t;
        long n = (long)ceil(span / hmax - 1e-9);
        if (n < 1) {
            n = 1;
        }
        const double hs = span / (double)n;
        const double t_seg = t;
        double k1[NY];
        deriv(in, dir, t, y, k1);
        int event = 0;
        for (long i = 0; i < n; ++i) {
            const double ts = t_seg + (double)i * hs;
            const double len = (i == n - 1) ? t_end - ts : hs;
            double y1[NY], k1n[NY];
            rk4(in, dir, ts, y, k1, len, y1);
            const double g0 = (double)dir * y[1], g1 = (double)dir * y1[1];
            double s_dip = 0.0;
            int cross = !(g1 > 0.0) && !(g0 == 0.0 && g1 == 0.0 && k1[1] == 0.0);
            /* a dip below zero inside the step needs the speed to fall by
             * min(g0, g1) within it */
            const int dip_possible = fmin(g0, g1) <= a_max * len;
            if (!cross && (dip_possible || i + 1 < n)) {
                deriv(in, dir, ts + len, y1, k1n);
            }
            if (!cross && dip_possible) {
                s_dip = hermite_dip(g0, g1, (double)dir * k1[1] * len, (double)dir * k1n[1] * len);
                cross = s_dip > 0.0;
            }
            double tau = 0.0, ye[NY];
            if (cross && locate_zero(in, dir, ts, y, k1, len, s_dip, ye, &tau)) {
                memcpy(y, ye, sizeof y);
                y[1] = 0.0;
                out->d.moving_s += ts + tau - t;
                t = ts + tau;
                out->t_event = fmin(out->t_event, t);
                const double net = net_torque(in, t, y[0], 0.0);
                if (fabs(net) <= in->tbrk) {
                    dir = 0;
                    out->d.stops++;
                } else {
                    dir = net > 0.0 ? 1 : -1;
                    out->d.reversals++;
                }
                if (++events > MECH_EVENTS_MAX) {
                    return PLANT_ERANGE;
                }
                event = 1;
                break;
            }
            memcpy(y, y1, sizeof y); /* (a dip of the interpolant only: go on) */
            if (i + 1 < n) {
                memcpy(k1, k1n, sizeof k1);
            }
        }
        if (!event) {
            out->d.moving_s += t_end - t;
            t = t_end;
        }
        if (!isfinite(y[0]) || !isfinite(y[1])) {
            return PLANT_ERANGE;
        }
    }
    out->dtheta = y[0];
    out->omega = y[1];
    out->dir = dir;
    out->d.e_drive_j = y[2];
    out->d.e_friction_j = y[3];
    out->d.e_load_j = y[4];
    out->d.abs_angle_rad = y[5];
    return PLANT_OK;
}
