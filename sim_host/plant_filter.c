/*
 * Output filters of the book chapter (S1 §6) in the plant: state equations in
 * the rotor frame, exact piecewise integration, the active filter's
 * controller, statistics. Topologies and the integration: plant_filter.h.
 *
 * Every element is written for space vectors: a stationary-frame relation
 * L di/dt = v becomes, in the frame rotating at w, L (di/dt + j w i) = v, and
 * C dv/dt = i likewise; resistors are unchanged. As real pairs, j = J =
 * [0 -1; 1 0]. The machine is (3.8)-(3.9) with the stator voltage taken at
 * the filter's output node.
 *
 * State x (dq pairs, in this order):
 *   passive: i1 (L1-C1 branch), vC1, i2 (R2-L2 branch), vC2, i3 (L3-r3),
 *            vC3, i_m (machine)
 *   active:  u (AF capacitor voltage in the line), iF (L_F and L1), vC1,
 *            iT (transformer and L2), vC2, i_m
 * Algebraic node voltages (KCL at X, 2, 3; at P, M):
 *   passive: vX = R1 (i1 + i2 - i3), v2 = vX - vC2, v3 = R3 (i3 - i_m) + vC3
 *   active:  vP = R1 (iF - iT) + vC1, vM = R2 (iT - i_m) + vC2
 * Augmented z = (x, v_in_d, v_in_q, 1): the input rotates, v_in' = wu J v_in,
 * and the constant carries the back-EMF -w psi_pm / Lq of the q row.
 *
 * Active filter, one half bridge per phase with two capacitors C_F: with the
 * upper switch on the upper capacitor is in the line (u_x = +v_up, it charges
 * with a positive line current), with the lower one the lower capacitor
 * (u_x = -v_lo, it discharges); in both cases du_x/dt = i_x / C_F. Between
 * switching instants the AF is therefore a series capacitor per phase, whose
 * zero-sequence part carries no current; at a switching instant the phase's
 * u_x is exchanged with the idle capacitor's voltage.
 */
#include <math.h>
#include <string.h>

#include "plant.h"
#include "plant_expm.h"

#define PF_SQRT3 1.73205080756887729353
#define PF_R_OPEN_DEFAULT 1.0e6
/* exp(M h) of the cache is reused for a duration within this of h (s): the
 * rounding of instants of the global time grid, far below any time constant
 * that survives a piece. */
#define PF_H_EPS 1e-15

/* passive state indices */
enum {
    PS_I1 = 0,
    PS_VC1 = 2,
    PS_I2 = 4,
    PS_VC2 = 6,
    PS_I3 = 8,
    PS_VC3 = 10,
    PS_IM = 12,
    PS_N = 14
};
/* active state indices */
enum { AS_U = 0, AS_IF = 2, AS_VC1 = 4, AS_IT = 6, AS_VC2 = 8, AS_IM = 10, AS_N = 12 };

static int pos_finite(double x)
{
    return isfinite(x) && x > 0.0;
}

/* --------------------------------------------------------- assembly */

typedef struct {
    double *m;
    int na;
} mat_t;

/* M[r..r+1][c..c+1] += a I */
static void add_s(mat_t *mt, int r, int c, double a)
{
    mt->m[r * mt->na + c] += a;
    mt->m[(r + 1) * mt->na + c + 1] += a;
}

/* M[r..r+1][c..c+1] += a J, J = [0 -1; 1 0] */
static void add_j(mat_t *mt, int r, int c, double a)
{
    mt->m[r * mt->na + c + 1] -= a;
    mt->m[(r + 1) * mt->na + c] += a;
}

/* Machine rows at index im with stator voltage vs = ks_i * i_k + vC_k + ...:
 * Ld id' = vd - Rs id + w Lq iq, Lq iq' = vq - Rs iq - w Ld id - w psi. The
 * caller adds the voltage terms scaled by 1/Ld, 1/Lq. */
static void machine_rows(const plant_t *p, mat_t *mt, int im, double w, double r_extra)
{
    const double ld = p->cfg.ld_h, lq = p->cfg.lq_h, rs = p->cfg.rs_ohm + r_extra;
    const int na = mt->na, one = na - 1;
    mt->m[im * na + im] += -rs / ld;
    mt->m[im * na + im + 1] += w * lq / ld;
    mt->m[(im + 1) * na + im] += -w * ld / lq;
    mt->m[(im + 1) * na + im + 1] += -rs / lq;
    mt->m[(im + 1) * na + one] += -w * p->cfg.psi_pm_wb / lq;
}

/* Voltage term a * v (a pair) into the machine rows (scaled by 1/Ld, 1/Lq). */
static void machine_in(const plant_t *p, mat_t *mt, int im, int c, double a)
{
    mt->m[im * mt->na + c] += a / p->cfg.ld_h;
    mt->m[(im + 1) * mt->na + c + 1] += a / p->cfg.lq_h;
}

static void build_passive(const plant_t *p, double w, double wu, int open, mat_t *mt)
{
    const plant_filter_passive_t *f = &p->cfg.filter.passive;
    const int in = PS_N;
    const double ro = p->cfg.filter.r_open_ohm > 0.0 ? p->cfg.filter.r_open_ohm : PF_R_OPEN_DEFAULT;
    const double r1 = f->r1_ohm;
    /* i1' = (v1 - R1 i1 - R1 i2 + R1 i3 - vC1) / L1 */
    const double g1 = 1.0 / f->l1_h;
    add_s(mt, PS_I1, PS_I1, -r1 * g1);
    add_s(mt, PS_I1, PS_I2, -r1 * g1);
    add_s(mt, PS_I1, PS_I3, r1 * g1);
    add_s(mt, PS_I1, PS_VC1, -g1);
    /* vC1' = i1 / C1 */
    add_s(mt, PS_VC1, PS_I1, 1.0 / f->c1_f);
    /* i2' = (v1 - R1 i1 - (R1 + R2) i2 + R1 i3 + vC2) / L2 */
    const double g2 = 1.0 / f->l2_h;
    add_s(mt, PS_I2, PS_I1, -r1 * g2);
    add_s(mt, PS_I2, PS_I2, -(r1 + f->r2_ohm) * g2);
    add_s(mt, PS_I2, PS_I3, r1 * g2);
    add_s(mt, PS_I2, PS_VC2, g2);
    /* vC2' = (i3 - i2) / C2 */
    add_s(mt, PS_VC2, PS_I3, 1.0 / f->c2_f);
    add_s(mt, PS_VC2, PS_I2, -1.0 / f->c2_f);
    /* i3' = (R1 i1 + R1 i2 - (R1 + R3 + r3) i3 - vC2 + R3 i_m - vC3) / L3 */
    const double g3 = 1.0 / f->l3_h;
    add_s(mt, PS_I3, PS_I1, r1 * g3);
    add_s(mt, PS_I3, PS_I2, r1 * g3);
    add_s(mt, PS_I3, PS_I3, -(r1 + f->r3_ohm + f->r3s_ohm) * g3);
    add_s(mt, PS_I3, PS_VC2, -g3);
    add_s(mt, PS_I3, PS_IM, f->r3_ohm * g3);
    add_s(mt, PS_I3, PS_VC3, -g3);
    /* vC3' = (i3 - i_m) / C3 */
    add_s(mt, PS_VC3, PS_I3, 1.0 / f->c3_f);
    add_s(mt, PS_VC3, PS_IM, -1.0 / f->c3_f);
    /* machine at v3 = R3 i3 - R3 i_m + vC3 */
    machine_rows(p, mt, PS_IM, w, f->r3_ohm);
    machine_in(p, mt, PS_IM, PS_I3, f->r3_ohm);
    machine_in(p, mt, PS_IM, PS_VC3, 1.0);
    /* rotor-frame terms of the filter elements */
    for (int k = 0; k < PS_IM; k += 2) {
        add_j(mt, k, k, -w);
    }
    /* inverter terminal voltage v1: the input, or -R_open (i1 + i2) */
    if (open) {
        add_s(mt, PS_I1, PS_I1, -ro * g1);
        add_s(mt, PS_I1, PS_I2, -ro * g1);
        add_s(mt, PS_I2, PS_I1, -ro * g2);
        add_s(mt, PS_I2, PS_I2, -ro * g2);
    } else {
        add_s(mt, PS_I1, in, g1);
        add_s(mt, PS_I2, in, g2);
    }
    add_j(mt, in, in, wu);
}

static void build_active(const plant_t *p, double w, double wu, int open, mat_t *mt)
{
    const plant_filter_active_t *f = &p->cfg.filter.active;
    const int in = AS_N;
    const double ro = p->cfg.filter.r_open_ohm > 0.0 ? p->cfg.filter.r_open_ohm : PF_R_OPEN_DEFAULT;
    const double r1 = f->r1_ohm, r2 = f->r2_ohm;
    /* u' = iF / C_F */
    add_s(mt, AS_U, AS_IF, 1.0 / f->cf_f);
    /* iF' = (vI - u - R1 iF + R1 iT - vC1) / (L_F + L1) */
    const double gf = 1.0 / (f->lf_h + f->l1_h);
    add_s(mt, AS_IF, AS_U, -gf);
    add_s(mt, AS_IF, AS_IF, -r1 * gf);
    add_s(mt, AS_IF, AS_IT, r1 * gf);
    add_s(mt, AS_IF, AS_VC1, -gf);
    /* vC1' = (iF - iT) / C1 */
    add_s(mt, AS_VC1, AS_IF, 1.0 / f->c1_f);
    add_s(mt, AS_VC1, AS_IT, -1.0 / f->c1_f);
    /* iT' = (R1 iF - (R1 + R2) iT + vC1 + R2 i_m - vC2) / L2 */
    const double g2 = 1.0 / f->l2_h;
    add_s(mt, AS_IT, AS_IF, r1 * g2);
    add_s(mt, AS_IT, AS_IT, -(r1 + r2) * g2);
    add_s(mt, AS_IT, AS_VC1, g2);
    add_s(mt, AS_IT, AS_IM, r2 * g2);
    add_s(mt, AS_IT, AS_VC2, -g2);
    /* vC2' = (iT - i_m) / C2 */
    add_s(mt, AS_VC2, AS_IT, 1.0 / f->c2_f);
    add_s(mt, AS_VC2, AS_IM, -1.0 / f->c2_f);
    /* machine at vM = R2 iT - R2 i_m + vC2 */
    machine_rows(p, mt, AS_IM, w, r2);
    machine_in(p, mt, AS_IM, AS_IT, r2);
    machine_in(p, mt, AS_IM, AS_VC2, 1.0);
    for (int k = 0; k < AS_IM; k += 2) {
        add_j(mt, k, k, -w);
    }
    if (open) {
        add_s(mt, AS_IF, AS_IF, -ro * gf);
    } else {
        add_s(mt, AS_IF, in, gf);
    }
    add_j(mt, in, in, wu);
}

static int n_aug(const plant_filter_t *f)
{
    return f->n + 3;
}

static void ensure_matrix(plant_t *p, double w, double wu, int open)
{
    plant_filter_t *f = &p->flt;
    if (f->m_valid && f->m_w == w && f->m_wu == wu && f->m_open == open) {
        return;
    }
    const int na = n_aug(f);
    memset(f->m, 0, sizeof f->m);
    mat_t mt = {f->m, na};
    if (f->type == PLANT_FILTER_PASSIVE) {
        build_passive(p, w, wu, open, &mt);
    } else {
        build_active(p, w, wu, open, &mt);
    }
    f->m_valid = 1;
    f->m_w = w;
    f->m_wu = wu;
    f->m_open = open;
    for (int k = 0; k < PLANT_FILTER_CACHE; ++k) {
        f->cache[k].valid = 0;
    }
}

/* exp(M h) from the cache or computed (never into slot `keep`, which holds a
 * matrix the caller still uses); *slot receives its slot; NULL on failure. */
static const double *expm_h(plant_t *p, double h, int keep, int *slot)
{
    plant_filter_t *f = &p->flt;
    const double tol = PF_H_EPS * (1.0 + fabs(p->t));
    for (int k = 0; k < PLANT_FILTER_CACHE; ++k) {
        if (f->cache[k].valid && fabs(f->cache[k].h - h) <= tol) {
            *slot = k;
            return f->cache[k].e;
        }
    }
    int k = f->cache_next;
    if (k == keep) {
        k = (k + 1) % PLANT_FILTER_CACHE;
    }
    f->cache_next = (k + 1) % PLANT_FILTER_CACHE;
    *slot = k;
    const int na = n_aug(f);
    double *e = f->cache[k].e;
    if (plant_expm(f->m, (size_t)na, h, e) != 0) {
        f->cache[k].valid = 0;
        return NULL;
    }
    /* exact input rows: v_in rotates by wu h, the constant stays 1 */
    const int in = f->n;
    for (int r = in; r < na; ++r) {
        for (int c = 0; c < na; ++c) {
            e[r * na + c] = 0.0;
        }
    }
    const double wu = f->m_open ? 0.0 : f->m_wu;
    e[in * na + in] = cos(wu * h);
    e[in * na + in + 1] = -sin(wu * h);
    e[(in + 1) * na + in] = sin(wu * h);
    e[(in + 1) * na + in + 1] = cos(wu * h);
    e[(na - 1) * na + na - 1] = 1.0;
    f->cache[k].valid = 1;
    f->cache[k].h = h;
    return f->cache[k].e;
}

/* ------------------------------------------------------- quantities */

/* Quantities of one augmented state z (dq). */
typedef struct {
    double im[2];              /* machine current */
    double vm[2];              /* motor terminal voltage */
    double vin[2], iin[2];     /* inverter terminal voltage and current */
    double br[PLANT_FB_N][2];  /* branch currents */
    double loss;               /* resistor losses, W (three phases) */
    double node2[2], nodex[2]; /* see PLANT_FP_V_NODE2 / _NODEX */
} quant_t;

static double ro_of(const plant_t *p)
{
    return p->cfg.filter.r_open_ohm > 0.0 ? p->cfg.filter.r_open_ohm : PF_R_OPEN_DEFAULT;
}

static double sq2(const double v[2])
{
    return v[0] * v[0] + v[1] * v[1];
}

static void quantities(const plant_t *p, const double *z, int open, quant_t *q)
{
    const plant_filter_t *f = &p->flt;
    memset(q, 0, sizeof *q);
    for (int c = 0; c < 2; ++c) {
        if (f->type == PLANT_FILTER_PASSIVE) {
            const plant_filter_passive_t *ps = &p->cfg.filter.passive;
            const double i1 = z[PS_I1 + c], i2 = z[PS_I2 + c], i3 = z[PS_I3 + c];
            const double im = z[PS_IM + c];
            q->im[c] = im;
            q->iin[c] = i1 + i2;
            q->vin[c] = open ? -ro_of(p) * (i1 + i2) : z[PS_N + c];
            q->vm[c] = ps->r3_ohm * (i3 - im) + z[PS_VC3 + c];
            q->nodex[c] = ps->r1_ohm * (i1 + i2 - i3);
            q->node2[c] = q->nodex[c] - z[PS_VC2 + c];
            q->br[PLANT_FB_INVERTER][c] = i1 + i2;
            q->br[PLANT_FB_MOTOR][c] = im;
            q->br[PLANT_FB_TRAP_L1C1][c] = i1;
            q->br[PLANT_FB_TRAP_L2][c] = i2;
            q->br[PLANT_FB_TRAP_C2][c] = i3 - i2;
            q->br[PLANT_FB_TRAP_R1][c] = i1 + i2 - i3;
            q->br[PLANT_FB_RLC_L3][c] = i3;
            q->br[PLANT_FB_RLC_SHUNT][c] = i3 - im;
        } else {
            const plant_filter_active_t *as = &p->cfg.filter.active;
            const double iF = z[AS_IF + c], iT = z[AS_IT + c], im = z[AS_IM + c];
            q->im[c] = im;
            q->iin[c] = iF;
            q->vin[c] = open ? -ro_of(p) * iF : z[AS_N + c];
            q->vm[c] = as->r2_ohm * (iT - im) + z[AS_VC2 + c];
            q->node2[c] = as->r1_ohm * (iF - iT) + z[AS_VC1 + c];
            q->nodex[c] = z[AS_U + c];
            q->br[PLANT_FB_INVERTER][c] = iF;
            q->br[PLANT_FB_MOTOR][c] = im;
            q->br[PLANT_FB_PRI_SHUNT][c] = iF - iT;
            q->br[PLANT_FB_TRANSF][c] = iT;
            q->br[PLANT_FB_SEC_SHUNT][c] = iT - im;
        }
    }
    if (f->type == PLANT_FILTER_PASSIVE) {
        const plant_filter_passive_t *ps = &p->cfg.filter.passive;
        q->loss = 1.5 * (ps->r1_ohm * sq2(q->br[PLANT_FB_TRAP_R1]) +
                         ps->r2_ohm * sq2(q->br[PLANT_FB_TRAP_L2]) +
                         ps->r3s_ohm * sq2(q->br[PLANT_FB_RLC_L3]) +
                         ps->r3_ohm * sq2(q->br[PLANT_FB_RLC_SHUNT]));
    } else {
        const plant_filter_active_t *as = &p->cfg.filter.active;
        q->loss = 1.5 * (as->r1_ohm * sq2(q->br[PLANT_FB_PRI_SHUNT]) +
                         as->r2_ohm * sq2(q->br[PLANT_FB_SEC_SHUNT]));
    }
    if (open) {
        q->loss += 1.5 * ro_of(p) * sq2(q->iin);
    }
}

static double torque_of(const plant_t *p, const double im[2])
{
    const double id = im[0], iq = im[1];
    return 1.5 * (double)p->cfg.pole_pairs *
           ((p->cfg.ld_h * id + p->cfg.psi_pm_wb) * iq - p->cfg.lq_h * iq * id);
}

static void rot(double c, double s, const double dq[2], double ab[2])
{
    ab[0] = dq[0] * c - dq[1] * s;
    ab[1] = dq[0] * s + dq[1] * c;
}

/* Energy stored in the filter's L and C (three phases), J. */
static double stored_energy(const plant_t *p)
{
    const plant_filter_t *f = &p->flt;
    const double *x = f->x;
    double e = 0.0;
    if (f->type == PLANT_FILTER_PASSIVE) {
        const plant_filter_passive_t *ps = &p->cfg.filter.passive;
        e = 0.75 *
            (ps->l1_h * sq2(x + PS_I1) + ps->c1_f * sq2(x + PS_VC1) + ps->l2_h * sq2(x + PS_I2) +
             ps->c2_f * sq2(x + PS_VC2) + ps->l3_h * sq2(x + PS_I3) + ps->c3_f * sq2(x + PS_VC3));
    } else {
        const plant_filter_active_t *as = &p->cfg.filter.active;
        e = 0.75 * ((as->lf_h + as->l1_h) * sq2(x + AS_IF) + as->c1_f * sq2(x + AS_VC1) +
                    as->l2_h * sq2(x + AS_IT) + as->c2_f * sq2(x + AS_VC2));
        /* storage capacitors: the three in the line (u_abc) and the idle ones */
        const double c = cos(p->theta_e), s = sin(p->theta_e);
        double ab[2];
        rot(c, s, x + AS_U, ab);
        const double ua[3] = {ab[0] + f->u0, -0.5 * ab[0] + 0.5 * PF_SQRT3 * ab[1] + f->u0,
                              -0.5 * ab[0] - 0.5 * PF_SQRT3 * ab[1] + f->u0};
        for (int k = 0; k < 3; ++k) {
            const double idle = f->sw[k] ? f->v_lo[k] : f->v_up[k];
            e += 0.5 * as->cf_f * (ua[k] * ua[k] + idle * idle);
        }
    }
    return e;
}

/* ------------------------------------------------------------ setup */

static int passive_ok(const plant_filter_passive_t *f)
{
    return pos_finite(f->l1_h) && pos_finite(f->c1_f) && pos_finite(f->r1_ohm) &&
           pos_finite(f->l2_h) && isfinite(f->r2_ohm) && f->r2_ohm >= 0.0 && pos_finite(f->c2_f) &&
           pos_finite(f->l3_h) && isfinite(f->r3s_ohm) && f->r3s_ohm >= 0.0 &&
           pos_finite(f->r3_ohm) && pos_finite(f->c3_f);
}

static int active_ok(const plant_filter_active_t *f)
{
    return pos_finite(f->l1_h) && pos_finite(f->r1_ohm) && pos_finite(f->c1_f) &&
           pos_finite(f->l2_h) && pos_finite(f->r2_ohm) && pos_finite(f->c2_f) &&
           pos_finite(f->lf_h) && pos_finite(f->cf_f) && pos_finite(f->cf_v0_v) &&
           pos_finite(f->sample_hz) && isfinite(f->band_v) && f->band_v >= 0.0 &&
           pos_finite(f->ref_cutoff_hz) && isfinite(f->dc_bw_hz) && f->dc_bw_hz >= 0.0 &&
           f->dc_bw_hz < 0.1 * f->sample_hz && (f->dc_bw_hz == 0.0 || pos_finite(f->dc_re_max_ohm));
}

int plant_filter_setup(plant_t *p)
{
    plant_filter_t *f = &p->flt;
    const plant_filter_cfg_t *c = &p->cfg.filter;
    memset(f, 0, sizeof *f);
    f->type = c->type;
    if (c->type == PLANT_FILTER_NONE) {
        return PLANT_OK;
    }
    if (!(isfinite(c->r_open_ohm) && c->r_open_ohm >= 0.0)) {
        return PLANT_EINVAL;
    }
    if (c->type == PLANT_FILTER_PASSIVE) {
        if (!passive_ok(&c->passive)) {
            return PLANT_EINVAL;
        }
        f->n = PS_N;
    } else if (c->type == PLANT_FILTER_ACTIVE) {
        if (!active_ok(&c->active)) {
            return PLANT_EINVAL;
        }
        f->n = AS_N;
        for (int k = 0; k < 3; ++k) {
            f->sw[k] = 1u;
            f->v_up[k] = c->active.cf_v0_v;
            f->v_lo[k] = c->active.cf_v0_v;
        }
        f->u0 = c->active.cf_v0_v; /* all three upper capacitors: pure zero sequence */
        f->af_next = (int64_t)floor(p->t * c->active.sample_hz + 1e-9) + 1;
        f->st.cf_min_v = c->active.cf_v0_v;
        f->st.cf_max_v = c->active.cf_v0_v;
    } else {
        return PLANT_EINVAL;
    }
    f->x[f->n - 2] = p->id;
    f->x[f->n - 1] = p->iq;
    f->st.type = c->type;
    f->st.n_branches = c->type == PLANT_FILTER_PASSIVE ? 8 : 5;
    return PLANT_OK;
}

void plant_filter_motor_current(const plant_t *p, double *id, double *iq)
{
    *id = p->flt.x[p->flt.n - 2];
    *iq = p->flt.x[p->flt.n - 1];
}

/* -------------------------------------------------------- one piece */

static void matvec(const double *e, const double *z, int na, double *out)
{
    for (int i = 0; i < na; ++i) {
        double s = 0.0;
        for (int j = 0; j < na; ++j) {
            s += e[i * na + j] * z[j];
        }
        out[i] = s;
    }
}

/* Largest ||M h||_1 of one half piece: scaling and squaring needs s =
 * log2(||M h|| / theta_13) squarings, and each doubles the rounding error of
 * the undamped (rotating) modes, so s is kept <= 24 (2^24 eps ~ 2e-9); longer
 * pieces are cut into equal parts. The input's own rows (a rotation and the
 * constant) are then set exactly, so that the drive does not drift over
 * many parts. */
#define PF_MH_MAX (5.37 * 16777216.0)

static double norm1_m(const plant_filter_t *f)
{
    const int na = n_aug(f);
    double m = 0.0;
    for (int j = 0; j < na; ++j) {
        double s = 0.0;
        for (int i = 0; i < na; ++i) {
            s += fabs(f->m[i * na + j]);
        }
        m = s > m ? s : m;
    }
    return m;
}

static int piece_part(plant_t *p, const plant_filter_input_t *in, double w, double dt,
                      double *te_int, double vint[2]);

int plant_filter_piece(plant_t *p, const plant_filter_input_t *in, double w, double dt,
                       double *te_int, double vint[2])
{
    plant_filter_t *f = &p->flt;
    ensure_matrix(p, w, in->open ? 0.0 : in->wu, in->open);
    const double parts = ceil(0.5 * dt * norm1_m(f) / PF_MH_MAX);
    if (!(parts > 1.0)) {
        return piece_part(p, in, w, dt, te_int, vint);
    }
    if (parts > 1e9) {
        return PLANT_ERANGE;
    }
    const long n = (long)parts;
    const double h = dt / parts;
    plant_filter_input_t sub = *in;
    const double th0 = p->theta_e;
    for (long k = 0; k < n; ++k) {
        /* the input phasor and the angle at the part's start */
        const double a = in->wu * h * (double)k, ca = cos(a), sa = sin(a);
        sub.w_d = in->w_d * ca - in->w_q * sa;
        sub.w_q = in->w_d * sa + in->w_q * ca;
        p->theta_e = th0 + w * h * (double)k;
        const int rc = piece_part(p, &sub, w, h, te_int, vint);
        if (rc != PLANT_OK) {
            p->theta_e = th0;
            return rc;
        }
    }
    p->theta_e = th0;
    return PLANT_OK;
}

/* One part: the state at k h/6 (k = 1..6) by E = exp(M h/6), one matrix per
 * duration; the integrals (torque, losses, |i|^2, power, motor voltage) by
 * the open Newton-Cotes rule on the five inner nodes,
 * h/20 (11 f1 - 14 f2 + 26 f3 - 14 f4 + 11 f5), exact for quintics. Its nodes
 * are inside the piece: the nanosecond transients of the stiff branches
 * (L1-R1 of the trap, L2 of the active filter) right after a switching
 * instant, which an end-point rule such as Simpson's would weight with a
 * finite share of the piece, carry negligible energy (1/2 L di^2). */
#define PF_NODES 5
static int piece_part(plant_t *p, const plant_filter_input_t *in, double w, double dt,
                      double *te_int, double vint[2])
{
    static const double wk[PF_NODES] = {11.0 / 20.0, -14.0 / 20.0, 26.0 / 20.0, -14.0 / 20.0,
                                        11.0 / 20.0};
    plant_filter_t *f = &p->flt;
    int slot = -1;
    const double *e = expm_h(p, dt / 6.0, -1, &slot);
    if (e == NULL) {
        return PLANT_ERANGE;
    }
    const int n = f->n, na = n + 3;
    double z[PF_NODES + 2][PLANT_FILTER_NA];
    memcpy(z[0], f->x, (size_t)n * sizeof(double));
    z[0][n] = in->open ? 0.0 : in->w_d;
    z[0][n + 1] = in->open ? 0.0 : in->w_q;
    z[0][n + 2] = 1.0;
    for (int k = 1; k <= PF_NODES + 1; ++k) {
        matvec(e, z[k - 1], na, z[k]);
    }
    const double *z1 = z[PF_NODES + 1];
    for (int j = 0; j < na; ++j) {
        if (!isfinite(z1[j])) {
            return PLANT_ERANGE;
        }
    }
    double te = 0.0, loss = 0.0, pin = 0.0, pcu = 0.0;
    double i2[PLANT_FB_N] = {0.0};
    for (int k = 1; k <= PF_NODES + 1; ++k) {
        quant_t q;
        quantities(p, z[k], in->open, &q);
        const double wt = k <= PF_NODES ? wk[k - 1] : 0.0;
        for (int b = 0; b < f->st.n_branches; ++b) {
            const double m2 = sq2(q.br[b]);
            i2[b] += wt * m2;
            const double mag = sqrt(m2);
            if (mag > f->st.i_peak[b]) {
                f->st.i_peak[b] = mag;
            }
        }
        if (k > PF_NODES) {
            break;
        }
        te += wt * torque_of(p, q.im);
        loss += wt * q.loss;
        pin += wt * 1.5 * (q.vin[0] * q.iin[0] + q.vin[1] * q.iin[1]);
        pcu += wt * 1.5 * p->cfg.rs_ohm * sq2(q.im);
        const double th = p->theta_e + w * dt * (double)k / 6.0;
        double ab[2];
        rot(cos(th), sin(th), q.vm, ab);
        vint[0] += wt * dt * ab[0];
        vint[1] += wt * dt * ab[1];
        if (in->open) {
            /* the open inverter's resistance is no filter element */
            loss -= wt * 1.5 * ro_of(p) * sq2(q.iin);
        }
    }
    *te_int += te * dt;
    for (int b = 0; b < f->st.n_branches; ++b) {
        f->st.i2_int[b] += i2[b] * dt;
    }
    f->st.e_loss_j += loss * dt;
    if (p->cfg.track_energy) {
        const double wm = w / (double)p->cfg.pole_pairs;
        p->e_in_j += pin * dt;
        p->e_src_j += pin * dt;
        p->e_cu_j += pcu * dt;
        p->e_mech_j += te * dt * wm;
    }
    memcpy(f->x, z1, (size_t)n * sizeof(double));
    return PLANT_OK;
}

/* ---------------------------------------------- active filter control */

double plant_filter_next_event(const plant_t *p)
{
    const plant_filter_t *f = &p->flt;
    if (f->type != PLANT_FILTER_ACTIVE || f->af_manual) {
        return INFINITY; /* tests holding the switches: no controller */
    }
    return (double)f->af_next / p->cfg.filter.active.sample_hz;
}

static void ab_to_abc(const double ab[2], double abc[3])
{
    abc[0] = ab[0];
    abc[1] = -0.5 * ab[0] + 0.5 * PF_SQRT3 * ab[1];
    abc[2] = -0.5 * ab[0] - 0.5 * PF_SQRT3 * ab[1];
}

/* Put the capacitor chosen by sw_new[] of each phase into the line. */
static void af_switch(plant_t *p, const uint8_t sw_new[3])
{
    plant_filter_t *f = &p->flt;
    const double c = cos(p->theta_e), s = sin(p->theta_e);
    double ab[2], u[3];
    rot(c, s, f->x + AS_U, ab);
    ab_to_abc(ab, u);
    int changed = 0;
    for (int k = 0; k < 3; ++k) {
        u[k] += f->u0;
        if (sw_new[k] == f->sw[k]) {
            continue;
        }
        if (f->sw[k]) { /* upper out, lower in */
            f->v_up[k] = u[k];
            u[k] = -f->v_lo[k];
        } else {
            f->v_lo[k] = -u[k];
            u[k] = f->v_up[k];
        }
        f->sw[k] = sw_new[k];
        f->st.af_transitions++;
        changed = 1;
    }
    if (!changed) {
        return;
    }
    f->u0 = (u[0] + u[1] + u[2]) / 3.0;
    ab[0] = (2.0 * u[0] - u[1] - u[2]) / 3.0; /* (3.3) */
    ab[1] = (u[1] - u[2]) / PF_SQRT3;
    /* back to the rotor frame: dq = ab e^{-j theta} */
    f->x[AS_U] = ab[0] * c + ab[1] * s;
    f->x[AS_U + 1] = -ab[0] * s + ab[1] * c;
}

/* The six storage capacitors' voltages, upper and lower per phase (the ones
 * in the line from u_abc), into the statistics and up[], lo[]. */
static void af_track_cf(plant_t *p, double up[3], double lo[3])
{
    plant_filter_t *f = &p->flt;
    double ab[2], u[3];
    rot(cos(p->theta_e), sin(p->theta_e), f->x + AS_U, ab);
    ab_to_abc(ab, u);
    for (int k = 0; k < 3; ++k) {
        up[k] = f->sw[k] ? u[k] + f->u0 : f->v_up[k];
        lo[k] = f->sw[k] ? f->v_lo[k] : -(u[k] + f->u0);
        f->st.cf_min_v = fmin(f->st.cf_min_v, fmin(up[k], lo[k]));
        f->st.cf_max_v = fmax(f->st.cf_max_v, fmax(up[k], lo[k]));
    }
}

/* Storage regulation (plant_filter_active_t.dc_bw_hz): the energy error of
 * the six capacitors against their pre-charge, E* - E (J), through a PI with
 * both poles at -2 pi bw (dE/dt = P: Kp = 2 w, Ki = w^2) gives the power P
 * to draw; the AF draws it as the series resistance r_e = P / (1.5 |i|^2)
 * (amplitude-invariant space vector: three-phase power 1.5 r_e |i|^2), with
 * |i|^2 low-passed at 10 bw. r_e is limited; the integrator stops while the
 * limit holds it (clamping anti-windup). Returns r_e for this sample. */
static double af_storage_re(plant_t *p, const double up[3], const double lo[3], const double iin[2],
                            double h)
{
    plant_filter_t *f = &p->flt;
    const plant_filter_active_t *as = &p->cfg.filter.active;
    if (as->dc_bw_hz <= 0.0) {
        return 0.0;
    }
    double e_err = 0.0;
    const double v0sq = as->cf_v0_v * as->cf_v0_v;
    for (int k = 0; k < 3; ++k) {
        e_err += 0.5 * as->cf_f * ((v0sq - up[k] * up[k]) + (v0sq - lo[k] * lo[k]));
    }
    const double w = 2.0 * PLANT_PI * as->dc_bw_hz;
    f->dc_i2 += (iin[0] * iin[0] + iin[1] * iin[1] - f->dc_i2) * (1.0 - exp(-h * 10.0 * w));
    const double i2 = fmax(f->dc_i2, 1e-6);
    const double p_cmd = 2.0 * w * e_err + f->dc_int;
    double re = p_cmd / (1.5 * i2);
    const double lim = as->dc_re_max_ohm;
    const int held = re > lim || re < -lim;
    re = fmin(lim, fmax(-lim, re));
    if (!held || (re > 0.0) != (e_err > 0.0)) {
        f->dc_int += w * w * e_err * h;
    }
    f->dc_re = re;
    return re;
}

/* Sampled hysteresis voltage control (S1 §6.2.1, Fig. 57): the AF injects
 * v_sig = v_inv - v* so that the motor sees v*; comparing its output v_AF =
 * v_inv - v_M with v_sig is comparing the motor phase voltage v_M with v*.
 * v_M above v* + band: the upper capacitor (+v_CF) into the line, which
 * lowers di/dt through L_F and hence v_M; below v* - band: the lower one.
 * v* from S1 (50)-(53) with i_sd = 0, i_sq from the torque command. */
void plant_filter_event(plant_t *p)
{
    plant_filter_t *f = &p->flt;
    if (f->type != PLANT_FILTER_ACTIVE) {
        return;
    }
    const plant_filter_active_t *as = &p->cfg.filter.active;
    const double h = 1.0 / as->sample_hz;
    f->af_next++;
    /* i_sq = T / (1.5 p psi_F), S1 (50), low-passed (exact for a command
     * held over the sample) so that p L_sq i_sq of S1 (52) exists */
    const double tau = 1.0 / (2.0 * PLANT_PI * as->ref_cutoff_hz);
    const double i_cmd = f->tq_cmd_nm / (1.5 * (double)p->cfg.pole_pairs * p->cfg.psi_pm_wb);
    f->isq_f += (i_cmd - f->isq_f) * (1.0 - exp(-h / tau));
    const double disq = (i_cmd - f->isq_f) / tau;
    double cf_up[3], cf_lo[3];
    af_track_cf(p, cf_up, cf_lo);
    if (f->af_manual || (p->s_valid && p->s[0] == PLANT_LEG_OFF && p->s[1] == PLANT_LEG_OFF &&
                         p->s[2] == PLANT_LEG_OFF)) {
        return; /* tests hold the switches; gates off: the AF idles too */
    }
    const double w = p->step_on ? p->step_wm * (double)p->cfg.pole_pairs
                                : p->omega_m * (double)p->cfg.pole_pairs;
    quant_t q;
    double z[PLANT_FILTER_NA] = {0.0};
    memcpy(z, f->x, (size_t)f->n * sizeof(double));
    quantities(p, z, 0, &q);
    /* S1 (51), (52); less the storage regulation's drop r_e i_inv */
    const double re = af_storage_re(p, cf_up, cf_lo, q.iin, h);
    const double vref_dq[2] = {-w * p->cfg.lq_h * f->isq_f - re * q.iin[0],
                               p->cfg.rs_ohm * f->isq_f + p->cfg.lq_h * disq +
                                   w * p->cfg.psi_pm_wb - re * q.iin[1]};
    /* S1 (53), K = 1 for the amplitude-invariant transform (3.3) */
    const double c = cos(p->theta_e), s = sin(p->theta_e);
    double ab[2], vref[3], vm[3];
    rot(c, s, vref_dq, ab);
    ab_to_abc(ab, vref);
    rot(c, s, q.vm, ab);
    ab_to_abc(ab, vm);
    uint8_t sw[3];
    for (int k = 0; k < 3; ++k) {
        const double err = vm[k] - vref[k];
        sw[k] = err > as->band_v ? 1u : (err < -as->band_v ? 0u : f->sw[k]);
    }
    af_switch(p, sw);
}

/* ------------------------------------------------------- public API */

const char *plant_filter_branch_name(int type, int branch)
{
    static const char *const passive[] = {"inverter", "motor",   "trap_l1c1", "trap_l2",
                                          "trap_c2",  "trap_r1", "rlc_l3",    "rlc_shunt"};
    static const char *const active[] = {"inverter", "motor", "pri_shunt", "transformer",
                                         "sec_shunt"};
    if (type == PLANT_FILTER_PASSIVE && branch >= 0 && branch < 8) {
        return passive[branch];
    }
    if (type == PLANT_FILTER_ACTIVE && branch >= 0 && branch < 5) {
        return active[branch];
    }
    return NULL;
}

int plant_filter_stats(const plant_t *p, plant_filter_stats_t *st)
{
    if (p == NULL || st == NULL || p->flt.type == PLANT_FILTER_NONE) {
        return PLANT_EINVAL;
    }
    *st = p->flt.st;
    st->e_stored_j = stored_energy(p);
    return PLANT_OK;
}

int plant_filter_reset_peaks(plant_t *p)
{
    if (p == NULL || p->flt.type == PLANT_FILTER_NONE) {
        return PLANT_EINVAL;
    }
    for (int b = 0; b < PLANT_FB_N; ++b) {
        p->flt.st.i_peak[b] = 0.0;
    }
    if (p->flt.type == PLANT_FILTER_ACTIVE) {
        p->flt.st.cf_min_v = INFINITY;
        p->flt.st.cf_max_v = -INFINITY;
        double up[3], lo[3];
        af_track_cf(p, up, lo);
    }
    return PLANT_OK;
}

int plant_filter_probe(const plant_t *p, int quantity, double ab[2])
{
    if (p == NULL || ab == NULL || p->flt.type == PLANT_FILTER_NONE || quantity < 0 ||
        quantity >= PLANT_FP_BRANCH0 + p->flt.st.n_branches) {
        return PLANT_EINVAL;
    }
    const plant_filter_t *f = &p->flt;
    double z[PLANT_FILTER_NA] = {0.0};
    memcpy(z, f->x, (size_t)f->n * sizeof(double));
    /* the inverter input of the present leg states */
    const int open = p->s_valid && p->s[0] > 1u;
    if (!open) {
        const double vdc = p->vdc;
        double sa[3];
        for (int k = 0; k < 3; ++k) {
            sa[k] = p->s[k] == PLANT_LEG_HIGH ? vdc : 0.0;
        }
        const double va = (2.0 * sa[0] - sa[1] - sa[2]) / 3.0, vb = (sa[1] - sa[2]) / PF_SQRT3;
        const double c = cos(p->theta_e), s = sin(p->theta_e);
        z[f->n] = va * c + vb * s;
        z[f->n + 1] = -va * s + vb * c;
    }
    quant_t q;
    quantities(p, z, open, &q);
    const double *dq = NULL;
    switch (quantity) {
    case PLANT_FP_V_INV:
        dq = q.vin;
        break;
    case PLANT_FP_V_MOTOR:
        dq = q.vm;
        break;
    case PLANT_FP_I_INV:
        dq = q.iin;
        break;
    case PLANT_FP_I_MOTOR:
        dq = q.im;
        break;
    case PLANT_FP_V_NODE2:
        dq = q.node2;
        break;
    case PLANT_FP_V_NODEX:
        dq = q.nodex;
        break;
    default:
        dq = q.br[quantity - PLANT_FP_BRANCH0];
        break;
    }
    rot(cos(p->theta_e), sin(p->theta_e), dq, ab);
    return PLANT_OK;
}

int plant_filter_set_torque_cmd(plant_t *p, double torque_nm)
{
    if (p == NULL || p->flt.type == PLANT_FILTER_NONE || !isfinite(torque_nm)) {
        return PLANT_EINVAL;
    }
    p->flt.tq_cmd_nm = torque_nm;
    return PLANT_OK;
}

int plant_filter_set_switches(plant_t *p, const uint8_t *sw)
{
    if (p == NULL || p->flt.type != PLANT_FILTER_ACTIVE) {
        return PLANT_EINVAL;
    }
    if (sw == NULL) {
        p->flt.af_manual = 0;
        p->flt.af_next = (int64_t)floor(p->t * p->cfg.filter.active.sample_hz + 1e-9) + 1;
        return PLANT_OK;
    }
    if (sw[0] > 1u || sw[1] > 1u || sw[2] > 1u) {
        return PLANT_EINVAL;
    }
    p->flt.af_manual = 1;
    af_switch(p, sw);
    return PLANT_OK;
}
