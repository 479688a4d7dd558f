/*
 * Machine data (SI) -> per-unit bases and fixed-point parameters.
 * Configuration only: floating point is allowed here (and only in *_config.c).
 *
 * Bases (ctrl_params.h): psi_base = psi_pm, v_base = Vdc, w_base = v_base / psi_base,
 * t_base = 1 / w_base, i_base = psi_base / Ld, l_base = Ld, r_base = v_base / i_base,
 * T_base = 1.5 p psi_base i_base.
 */
#include <math.h>
#include <stdbool.h>
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

/*
 * The MTPA table in integer arithmetic (the same bits on every target: no
 * floating point, no library square root). Along the locus of amplitude i,
 * with dL = Lq - Ld (ctrl_mtpa_split, without its cancellation):
 *   i_d = -2 dL i^2 / (psi + sqrt(psi^2 + 8 dL^2 i^2)),  i_q = sqrt(i^2 - i_d^2),
 *   Te = i_q (psi - dL i_d) (3.10),  |psi_s| = |(psi + Ld i_d, Lq i_q)|.
 * Formats: i, i_d, i_q, psi Q24 pu, Ld and Lq Q27, |dL| Q29 (uint32_t
 * magnitudes, signs apart: the inductances' rounding kept below the
 * outputs' LSB); dL i, dL i^2 and the torque Q48 (uint64_t). Ranges
 * (params_compute's checks; psi = Ld = 1 by the bases): i <= 16,
 * Ld, Lq <= 8, max(Ld, Lq) i <= 31, so dL i^2 < 2^9 (Q48: < 2^57),
 * psi^2 + 8 (dL i)^2 < 2^62 (Q48), Te <= 100 (Q48: < 2^55), |psi_s| < 32.
 */
typedef struct {
    uint32_t psi;    /* Q24 */
    uint32_t ld, lq; /* Q27 */
    uint32_t adl;    /* |Lq - Ld|, Q29 */
    bool neg;        /* dL > 0: i_d <= 0 */
} mtpa_q_t;

/* a * b / 2^24, rounded, for a Q48 a < 2^60 and a Q24 b < 2^29 (< 2^61):
 * the two halves of a apart so that each product fits 64 bits. */
static uint64_t mul_q48_q24(uint64_t a, uint32_t b)
{
    return (a >> 24) * b + (((a & 0xFFFFFFu) * b + 0x800000u) >> 24);
}

/* 2 sqrt(2) in Q29 */
#define MTPA_2SQRT2_Q29 1518500250

/* The MTPA point of amplitude i (Q24): Te (Q48), |i_d|, i_q (Q24). */
static uint64_t mtpa_point_q(const mtpa_q_t *m, uint32_t i, uint32_t *aid, uint32_t *iq)
{
    const uint64_t a48 = ((uint64_t)m->adl * i + 16u) >> 5; /* |dL| i, Q48 */
    const q24_t a24 = (q24_t)((a48 + 0x800000u) >> 24);     /* < 31 pu */
    /* sqrt(psi^2 + 8 dL^2 i^2) = |(psi, 2 sqrt(2) |dL| i)| */
    const uint32_t s = (uint32_t)fx_mag((q24_t)m->psi, fx_mul_qn(a24, MTPA_2SQRT2_Q29, 29u));
    const uint64_t den = (uint64_t)m->psi + s;
    *aid = (uint32_t)((2u * mul_q48_q24(a48, i) + den / 2u) / den);
    /* round(sqrt(i^2 - i_d^2)): up exactly when the rest exceeds r (no
     * integer square is a half-integer's) */
    const uint64_t i2 = (uint64_t)i * i;
    const uint64_t d2 = (uint64_t)*aid * *aid;
    const uint64_t q2 = i2 > d2 ? i2 - d2 : 0u;
    const uint32_t r = fx_isqrt64(q2);
    *iq = q2 - (uint64_t)r * r > r ? r + 1u : r;
    /* psi - dL i_d = psi + |dL| |i_d| (opposite signs), Q48 */
    const uint64_t f48 = ((uint64_t)m->psi << 24) + (((uint64_t)m->adl * *aid + 16u) >> 5);
    return mul_q48_q24(f48, *iq);
}

/* |psi_s| = |(psi + Ld i_d, Lq i_q)| of an MTPA point, Q24 (the first
 * negative beyond the characteristic current). */
static uint32_t mtpa_psi_q(const mtpa_q_t *m, uint32_t aid, uint32_t iq)
{
    const q24_t d = fx_mul_qn((q24_t)aid, (int32_t)m->ld, 27u);
    const q24_t x = m->neg ? (q24_t)m->psi - d : (q24_t)m->psi + d;
    return (uint32_t)fx_mag(x, fx_mul_qn((q24_t)iq, (int32_t)m->lq, 27u));
}

/* The MTPA table: psi_s, i_d, i_q at CTRL_MTPA_N + 1 uniform torques up to
 * T(current_max). T(i) increases along the locus: each point's amplitude
 * is found by bisection on i in Q24 steps, the closer of the two last
 * points taken, so i is within half a step of the
 * exact one. Its error against the exact locus in double precision is
 * bounded in tests/core/test_params.c (test_mtpa_table_integer). */
static int mtpa_table(ctrl_params_t *p, double ld, double lq, double psi_pm, double i_max)
{
    const q24_t qpsi = ctrl_q24_from_double(psi_pm);
    const q24_t qi = ctrl_q24_from_double(i_max);
    /* the ranges the formats above rely on (params_compute's checks) */
    if (qpsi <= 0 || qi <= 0 || psi_pm > 1.0 || i_max > 16.0 || !(ld > 0.0) || !(lq > 0.0) ||
        fmax(ld, lq) > 8.0 || !(fabs(lq - ld) < 8.0) || fmax(ld, lq) * i_max > 31.0) {
        return CTRL_ERANGE;
    }
    const mtpa_q_t m = {(uint32_t)qpsi, (uint32_t)ctrl_cfg_llround(ld * 134217728.0),
                        (uint32_t)ctrl_cfg_llround(lq * 134217728.0),
                        (uint32_t)ctrl_cfg_llround(fabs(lq - ld) * 536870912.0), lq > ld};
    const uint32_t i_top = (uint32_t)qi;
    uint32_t aid;
    uint32_t iq;
    const uint64_t t_max48 = mtpa_point_q(&m, i_top, &aid, &iq);
    const uint32_t t_max = (uint32_t)((t_max48 + 0x800000u) >> 24);
    const double t_pu = ctrl_q24_to_double((q24_t)t_max);
    if (!fits(t_pu) || !(t_pu > 0.0) || !fits(ctrl_q24_to_double((q24_t)mtpa_psi_q(&m, aid, iq)))) {
        return CTRL_ERANGE;
    }
    /* T(lo) = t_lo <= t <= T(hi) = t_hi; lo from the row before (T increases
     * with k) */
    uint32_t lo = 0u;
    uint64_t t_lo = 0u;
    for (int k = 0; k <= CTRL_MTPA_N; k++) {
        const uint64_t t = t_max48 * (uint64_t)k / CTRL_MTPA_N; /* < 2^61 */
        uint32_t hi = i_top;
        uint64_t t_hi = t_max48;
        while (hi - lo > 1u) {
            const uint32_t mid = lo + (hi - lo) / 2u;
            const uint64_t tm = mtpa_point_q(&m, mid, &aid, &iq);
            if (tm < t) {
                lo = mid;
                t_lo = tm;
            } else {
                hi = mid;
                t_hi = tm;
            }
        }
        (void)mtpa_point_q(&m, t - t_lo <= t_hi - t ? lo : hi, &aid, &iq);
        p->mtpa_psi[k] = (q24_t)mtpa_psi_q(&m, aid, iq);
        p->mtpa_id[k] = m.neg ? -(q24_t)aid : (q24_t)aid;
        p->mtpa_iq[k] = (q24_t)iq;
    }
    /* CTRL_MTPA_N / T_max in Q16, rounded: < 2^31 */
    const uint64_t scale = (((uint64_t)CTRL_MTPA_N << 40) + t_max / 2u) / t_max;
    if (scale >= 0x80000000u) {
        return CTRL_ERANGE;
    }
    p->mtpa_t_max = (q24_t)t_max;
    p->mtpa_scale = (int32_t)scale;
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
#if CTRL_SL_HFI
    } else if (d->min > d->max) {
        /* not a range: a choice refused (the unit names its kind) */
        n = snprintf(buf, cap, "%s%s%s refused: %s", d->unit != NULL ? d->unit : "",
                     d->unit != NULL && d->unit[0] != '\0' ? " " : "", d->quantity,
                     d->depends != NULL ? d->depends : "not accepted");
#endif
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
