/*
 * Machine data (SI) -> per-unit bases and fixed-point parameters.
 * Configuration only: floating point is allowed here (and only in *_config.c).
 *
 * Bases (ctrl_params.h): psi_base = psi_pm, v_base = Vdc, w_base = v_base / psi_base,
 * t_base = 1 / w_base, i_base = psi_base / Ld, l_base = Ld, r_base = v_base / i_base,
 * T_base = 1.5 p psi_base i_base.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "ctrl_cfg_math.h"
#include "ctrl_params.h"
#include "ctrl_units.h"

/* Plausibility limits of the SI data (CTRL_EINVAL outside): generous, they
 * only catch unit mistakes (mH typed as H, r/min as rad/s, ...). */
#define LIM_POLE_PAIRS 64
#define LIM_R_OHM 1.0e3
#define LIM_L_H 10.0
#define LIM_PSI_WB 100.0
#define LIM_VDC_V 1.0e5
#define LIM_J 1.0e4
#define LIM_TORQUE_NM 1.0e6
#define LIM_SPEED_RPM 1.0e6
#define LIM_CURRENT_A 1.0e6
#define LIM_FS_HZ 1000000u

/* Q24 fit: |x| <= 100 pu (headroom below 128 for sums), and a non-zero value
 * is >= 2^-16 pu so that its Q24 relative resolution is better than 2^-8. */
#define FIT_MAX 100.0
#define FIT_MIN_NONZERO (1.0 / 65536.0)

q24_t ctrl_q24_from_double(double pu)
{
    if (isnan(pu)) {
        return 0;
    }
    const double x = pu * (double)FX_ONE;
    if (x >= 2147483647.0) {
        return FX_MAX;
    }
    if (x <= -2147483648.0) {
        return FX_MIN;
    }
    return (q24_t)ctrl_cfg_llround(x); /* half away from zero */
}

double ctrl_q24_to_double(q24_t x)
{
    return (double)x / (double)FX_ONE;
}

int ctrl_q24_from_si(double si, double base, double lo_pu, double hi_pu, q24_t *out)
{
    const double pu = si / base;
    if (out == NULL || !isfinite(pu) || !(pu >= lo_pu) || !(pu <= hi_pu)) {
        return CTRL_ERANGE;
    }
    *out = ctrl_q24_from_double(pu);
    return CTRL_OK;
}

static int fits(double pu)
{
    const double a = fabs(pu);
    return isfinite(pu) && a <= FIT_MAX && (a == 0.0 || a >= FIT_MIN_NONZERO);
}

int ctrl_params_set_speed_lpf(ctrl_params_t *p, double fc_hz)
{
    if (p == NULL || p->fs_hz == 0u || !isfinite(fc_hz) || fc_hz <= 0.0 ||
        fc_hz >= 0.5 * (double)p->fs_hz) {
        return CTRL_EINVAL;
    }
    /* EMA y += k (x - y): pole exp(-2 pi fc Ts) matched (impulse invariance). */
    const double k = 1.0 - ctrl_cfg_exp(-CTRL_TWO_PI * fc_hz / (double)p->fs_hz);
    p->speed_lpf_k = ctrl_q24_from_double(k);
    return p->speed_lpf_k > 0 ? CTRL_OK : CTRL_EINVAL;
}

void ctrl_mtpa_split(double psi_pm, double ld, double lq, double i, double *i_d, double *i_q)
{
    const double dl = lq - ld;
    const double d =
        dl == 0.0 ? 0.0 : (psi_pm - sqrt(psi_pm * psi_pm + 8.0 * dl * dl * i * i)) / (4.0 * dl);
    *i_d = d;
    *i_q = sqrt(fmax(i * i - d * d, 0.0));
}

/* The MTPA point of amplitude i (pu, ctrl_mtpa_split): i_d, i_q, Te (3.10)
 * and |psi_s|. */
static void mtpa_point(double ld, double lq, double psi_pm, double i, double *id, double *iq,
                       double *te, double *psi)
{
    ctrl_mtpa_split(psi_pm, ld, lq, i, id, iq);
    *te = *iq * (psi_pm - (lq - ld) * *id);
    *psi = ctrl_cfg_hypot(psi_pm + ld * *id, lq * *iq);
}

/* The MTPA table: psi_s, i_d, i_q at CTRL_MTPA_N + 1 uniform torques up to
 * T(current_max); T(i) increases along the locus, so each point is found by
 * bisection on the current amplitude. */
static int mtpa_table(ctrl_params_t *p, double ld, double lq, double psi_pm, double i_max)
{
    double id;
    double iq;
    double t_max;
    double psi;
    mtpa_point(ld, lq, psi_pm, i_max, &id, &iq, &t_max, &psi);
    if (!fits(t_max) || !(t_max > 0.0) || !fits(psi)) {
        return CTRL_ERANGE;
    }
    for (int k = 0; k <= CTRL_MTPA_N; k++) {
        const double t = t_max * (double)k / (double)CTRL_MTPA_N;
        double lo = 0.0;
        double hi = i_max;
        double tm;
        for (int it = 0; it < 80; it++) {
            const double mid = 0.5 * (lo + hi);
            mtpa_point(ld, lq, psi_pm, mid, &id, &iq, &tm, &psi);
            if (tm < t) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        mtpa_point(ld, lq, psi_pm, 0.5 * (lo + hi), &id, &iq, &tm, &psi);
        p->mtpa_psi[k] = ctrl_q24_from_double(psi);
        p->mtpa_id[k] = ctrl_q24_from_double(id);
        p->mtpa_iq[k] = ctrl_q24_from_double(iq);
    }
    const double scale = (double)CTRL_MTPA_N / t_max; /* Q16 */
    if (!(scale * 65536.0 < 2147483647.0)) {
        return CTRL_ERANGE;
    }
    p->mtpa_t_max = ctrl_q24_from_double(t_max);
    p->mtpa_scale = (int32_t)ctrl_cfg_llround(scale * 65536.0);
    return CTRL_OK;
}

int ctrl_diag_refuse(ctrl_diag_t *d, int code, const char *quantity, const char *unit, double value,
                     double lo, double hi, const char *depends)
{
    if (d != NULL) {
        *d = (ctrl_diag_t){code, quantity, unit, value, lo, hi, depends};
    }
    return code;
}

int ctrl_diag_in_range(ctrl_diag_t *d, const char *quantity, const char *unit, double value,
                       double lo, double hi)
{
    if (isfinite(value) && value >= lo && value <= hi) {
        return 1;
    }
    (void)ctrl_diag_refuse(d, CTRL_EINVAL, quantity, unit, value, lo, hi, NULL);
    return 0;
}

/* An SI datum: finite and inside [lo, hi] (lo itself excluded when open). */
static int si_ok(double x, double lo, double hi, int open)
{
    return isfinite(x) && (open ? x > lo : x >= lo) && x <= hi;
}

static int params_compute(ctrl_params_t *p, ctrl_bases_t *b, const ctrl_machine_t *m,
                          uint32_t fs_hz, ctrl_diag_t *d)
{
    /* ---- SI data: finite, positive, below limits that only catch unit mistakes ---- */
    if (m->pole_pairs < 1 || m->pole_pairs > LIM_POLE_PAIRS) {
        return ctrl_diag_refuse(d, CTRL_EINVAL, "pole_pairs", "", (double)m->pole_pairs, 1.0,
                                (double)LIM_POLE_PAIRS, NULL);
    }
    if (fs_hz == 0u || fs_hz > LIM_FS_HZ) {
        return ctrl_diag_refuse(d, CTRL_EINVAL, "fs_hz", "Hz", (double)fs_hz, 1.0,
                                (double)LIM_FS_HZ, NULL);
    }
    const struct {
        const char *name, *unit;
        double value, lo, hi;
        int open;
    } si[] = {
        /* Rs = 0 (an ideal, lossless machine) is accepted. */
        {"rs_ohm", "ohm", m->rs_ohm, 0.0, LIM_R_OHM, 0},
        {"ld_h", "H", m->ld_h, 0.0, LIM_L_H, 1},
        {"lq_h", "H", m->lq_h, 0.0, LIM_L_H, 1},
        {"psi_pm_wb", "Wb", m->psi_pm_wb, 0.0, LIM_PSI_WB, 1},
        {"vdc_v", "V", m->vdc_v, 0.0, LIM_VDC_V, 1},
        {"inertia_kgm2", "kg*m^2", m->inertia_kgm2, 0.0, LIM_J, 1},
        {"torque_rated_nm", "N*m", m->torque_rated_nm, 0.0, LIM_TORQUE_NM, 1},
        {"speed_rated_rpm", "r/min", m->speed_rated_rpm, 0.0, LIM_SPEED_RPM, 1},
        {"current_rated_a", "A", m->current_rated_a, 0.0, LIM_CURRENT_A, 1},
        {"current_max_a", "A", m->current_max_a, m->current_rated_a, LIM_CURRENT_A, 0},
        {"psi_ref_wb", "Wb", m->psi_ref_wb, 0.0, LIM_PSI_WB, 0},
    };
    for (size_t k = 0; k < sizeof si / sizeof si[0]; k++) {
        if (!si_ok(si[k].value, si[k].lo, si[k].hi, si[k].open)) {
            return ctrl_diag_refuse(d, CTRL_EINVAL, si[k].name, si[k].unit, si[k].value, si[k].lo,
                                    si[k].hi, NULL);
        }
    }

    /* ---- bases (ctrl_params.h) ---- */
    const double w_rated = ctrl_rpm_to_elec(m->speed_rated_rpm, m->pole_pairs);
    b->psi_wb = m->psi_pm_wb;
    b->w_rad_s = w_rated;
    b->t_s = 1.0 / b->w_rad_s;
    b->v_v = b->psi_wb * b->w_rad_s;
    b->l_h = m->ld_h;
    b->i_a = b->psi_wb / b->l_h;
    b->r_ohm = b->w_rad_s * b->l_h;
    b->torque_nm = 1.5 * (double)m->pole_pairs * b->psi_wb * b->i_a;

    /* ---- the per-unit values and the ranges the core's formats take ---- */
    const double ts = 1.0 / ((double)fs_hz * b->t_s);
    const double ld = m->ld_h / b->l_h;
    const double lq = m->lq_h / b->l_h;
    const double psi_pm = m->psi_pm_wb / b->psi_wb;
    const double rs = m->rs_ohm / b->r_ohm;
    const double vdc = m->vdc_v / b->v_v;
    const double i_max = m->current_max_a / b->i_a;
    const double psi_at_imax = (psi_pm + fmax(ld, lq) * i_max) / psi_pm;
    const struct {
        const char *name, *unit;
        double value, lo, hi;
        const char *depends;
    } pu[] = {
        /* One period turns the rotor by at most one radian at rated speed; at
         * least CTRL_TS_PU_MIN keeps dangle_to_omega in its Q26 format. */
        {"rated electrical speed x Ts", "rad per period", ts, CTRL_TS_PU_MIN, CTRL_TS_PU_MAX,
         "speed_rated_rpm, pole_pairs, fs_hz"},
        /* Forward Euler of the resistive drop in the prediction (5.15). */
        {"Ts Rs / Ld", "", ts * rs, 0.0, 1.0, "rs_ohm, ld_h, fs_hz"},
        {"Lq / Ld", "", lq / ld, 0.125, 8.0, "ld_h, lq_h"},
        {"vdc_v / rated back-EMF (psi_pm x rated electrical speed)", "", vdc, 1.0 / 64.0, 32.0,
         "vdc_v, psi_pm_wb, speed_rated_rpm, pole_pairs"},
        {"current_max_a / (psi_pm_wb / ld_h)", "", i_max, 1.0 / 256.0, 16.0,
         "current_max_a, psi_pm_wb, ld_h"},
        {"flux linkage at current_max / psi_pm", "", psi_at_imax, 1.0, 32.0,
         "psi_pm_wb, ld_h, lq_h, current_max_a"},
        {"Rs / (rated electrical speed x Ld)", "", rs, 0.0, FIT_MAX,
         "rs_ohm, ld_h, speed_rated_rpm, pole_pairs"},
        {"torque_rated_nm / torque base", "", m->torque_rated_nm / b->torque_nm, FIT_MIN_NONZERO,
         FIT_MAX, "torque_rated_nm, pole_pairs, psi_pm_wb, ld_h"},
        {"current_rated_a / (psi_pm_wb / ld_h)", "", m->current_rated_a / b->i_a, FIT_MIN_NONZERO,
         FIT_MAX, "current_rated_a, psi_pm_wb, ld_h"},
        {"psi_ref_wb / psi_pm_wb", "", m->psi_ref_wb / b->psi_wb, 0.0, FIT_MAX,
         "psi_ref_wb, psi_pm_wb"},
    };
    for (size_t k = 0; k < sizeof pu / sizeof pu[0]; k++) {
        if (!(pu[k].value >= pu[k].lo && pu[k].value <= pu[k].hi)) {
            return ctrl_diag_refuse(d, CTRL_ERANGE, pu[k].name, pu[k].unit, pu[k].value, pu[k].lo,
                                    pu[k].hi, pu[k].depends);
        }
    }

    p->fs_hz = fs_hz;
    p->pole_pairs = m->pole_pairs;
    p->ts = ctrl_q24_from_double(ts);
    p->rs = ctrl_q24_from_double(rs);
    p->ts_rs = ctrl_q24_from_double(ts * rs);
    p->ld = ctrl_q24_from_double(ld);
    p->lq = ctrl_q24_from_double(lq);
    p->inv_ld = ctrl_q24_from_double(1.0 / ld);
    p->inv_lq = ctrl_q24_from_double(1.0 / lq);
    p->psi_pm = ctrl_q24_from_double(psi_pm);
    p->inv_psi_pm = ctrl_q24_from_double(1.0 / psi_pm);
    p->vdc_nom = ctrl_q24_from_double(vdc);
    p->torque_rated = ctrl_q24_from_double(m->torque_rated_nm / b->torque_nm);
    p->speed_rated_e = ctrl_q24_from_double(w_rated / b->w_rad_s);
    p->current_rated = ctrl_q24_from_double(m->current_rated_a / b->i_a);
    p->current_max = ctrl_q24_from_double(i_max);
    p->psi_ref = ctrl_q24_from_double(m->psi_ref_wb / b->psi_wb);
    /* Saliency below 1e-6 is numerical noise: treat as SPMSM (4.15). */
    p->salient = fabs(lq / ld - 1.0) > 1.0e-6 ? 1u : 0u;

    /* Angle per period at 1 pu speed: Ts_pu rad = Ts_pu / (2 pi) turns, and
     * the inverse coefficient in Q26 (CTRL_DANGLE_SHIFT): an int32_t for
     * Ts_pu >= CTRL_TS_PU_MIN, >= 2^20 significant for Ts_pu <= 1.5. */
    const double k_ang = ts / CTRL_TWO_PI * 4294967296.0;
    p->omega_to_dangle = (int32_t)ctrl_cfg_llround(k_ang);
    p->dangle_to_omega =
        (int32_t)ctrl_cfg_llround(ctrl_cfg_ldexp(16777216.0 / k_ang, (int)CTRL_DANGLE_SHIFT));

    if (ctrl_params_set_speed_lpf(p, CTRL_SPEED_LPF_HZ_DEFAULT) != CTRL_OK &&
        ctrl_params_set_speed_lpf(p, 0.25 * (double)fs_hz) != CTRL_OK) {
        return ctrl_diag_refuse(d, CTRL_ERANGE, "speed filter coefficient", "", 0.0, 0.0, 1.0,
                                "fs_hz");
    }

    p->mtpa_k = ctrl_q24_from_double(lq / psi_pm); /* (4.15): Lq / psi_pm */
    /* The MTPA table (for the SPMSM from the closed forms, dL = 0, for tools). */
    const int rc = mtpa_table(p, ld, p->salient != 0u ? lq : ld, psi_pm, i_max);
    if (rc != CTRL_OK) {
        return ctrl_diag_refuse(d, rc, "MTPA torque at current_max", "pu", 0.0, 0.002, FIT_MAX,
                                "current_max_a, psi_pm_wb, ld_h, lq_h");
    }
    return CTRL_OK;
}

int ctrl_params_init_diag(ctrl_params_t *p, ctrl_bases_t *bases, const ctrl_machine_t *m,
                          uint32_t fs_hz, ctrl_diag_t *why)
{
    if (why != NULL) {
        memset(why, 0, sizeof *why);
    }
    if (p == NULL || bases == NULL) {
        return ctrl_diag_refuse(why, CTRL_EINVAL, "output pointer", "", 0.0, 0.0, 0.0, NULL);
    }
    memset(p, 0, sizeof *p);
    memset(bases, 0, sizeof *bases);
    if (m == NULL) {
        return ctrl_diag_refuse(why, CTRL_EINVAL, "machine", "", 0.0, 0.0, 0.0, NULL);
    }
    const int rc = params_compute(p, bases, m, fs_hz, why);
    if (rc != CTRL_OK) {
        memset(p, 0, sizeof *p);
        memset(bases, 0, sizeof *bases);
    }
    return rc;
}

int ctrl_params_init(ctrl_params_t *p, ctrl_bases_t *bases, const ctrl_machine_t *m, uint32_t fs_hz)
{
    return ctrl_params_init_diag(p, bases, m, fs_hz, NULL);
}

size_t ctrl_diag_format(const ctrl_diag_t *d, char *buf, size_t cap)
{
    if (buf == NULL || cap == 0u) {
        return 0u;
    }
    int n;
    if (d == NULL || d->code == CTRL_OK || d->quantity == NULL) {
        n = snprintf(buf, cap, "ok");
    } else if (d->min == 0.0 && d->max == 0.0) {
        n = snprintf(buf, cap, "%s missing", d->quantity);
    } else {
        const char *u = d->unit != NULL && d->unit[0] != '\0' ? " " : "";
        const char *un = d->unit != NULL ? d->unit : "";
        n = snprintf(buf, cap,
                     "%s = %.6g%s%s is outside the range the core takes, [%.6g, %.6g]%s%s",
                     d->quantity, d->value, u, un, d->min, d->max, u, un);
        if (n >= 0 && (size_t)n < cap && d->depends != NULL) {
            const int k = snprintf(buf + n, cap - (size_t)n, " (from %s)", d->depends);
            n = k < 0 ? n : n + k;
        }
    }
    return n < 0 ? 0u : ((size_t)n < cap ? (size_t)n : cap - 1u);
}
