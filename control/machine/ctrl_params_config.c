/*
 * Machine data (SI) -> per-unit bases and fixed-point parameters.
 * Configuration only: floating point is allowed here (and only in *_config.c).
 *
 * Bases (ctrl_params.h): psi_base = psi_pm, v_base = Vdc, w_base = v_base / psi_base,
 * t_base = 1 / w_base, i_base = psi_base / Ld, l_base = Ld, r_base = v_base / i_base,
 * T_base = 1.5 p psi_base i_base.
 */
#include <math.h>
#include <string.h>

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
    return (q24_t)llround(x); /* half away from zero */
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

static int pos_finite(double x, double lim)
{
    return isfinite(x) && x > 0.0 && x <= lim;
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
    const double k = 1.0 - exp(-CTRL_TWO_PI * fc_hz / (double)p->fs_hz);
    p->speed_lpf_k = ctrl_q24_from_double(k);
    return p->speed_lpf_k > 0 ? CTRL_OK : CTRL_EINVAL;
}

/* The one MTPA solver (pu, any Ld, Lq, psi_pm > 0): the current vector of
 * amplitude i maximising Te = i_q (psi_pm + (Ld - Lq) i_d) (3.10) on |i| = i,
 *   i_d = (psi_pm - sqrt(psi_pm^2 + 8 dL^2 i^2)) / (4 dL),  dL = Lq - Ld != 0,
 * i_d = 0 for dL = 0; returns i_d, i_q, Te and |psi_s|. */
static void mtpa_point(double ld, double lq, double psi_pm, double i, double *id, double *iq,
                       double *te, double *psi)
{
    const double dl = lq - ld;
    *id = dl == 0.0 ? 0.0 : (psi_pm - sqrt(psi_pm * psi_pm + 8.0 * dl * dl * i * i)) / (4.0 * dl);
    *iq = sqrt(fmax(i * i - *id * *id, 0.0));
    *te = *iq * (psi_pm - dl * *id);
    *psi = hypot(psi_pm + ld * *id, lq * *iq);
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
    p->mtpa_scale = (int32_t)llround(scale * 65536.0);
    return CTRL_OK;
}

static int params_compute(ctrl_params_t *p, ctrl_bases_t *b, const ctrl_machine_t *m,
                          uint32_t fs_hz)
{
    if (m->pole_pairs < 1 || m->pole_pairs > LIM_POLE_PAIRS || fs_hz == 0u || fs_hz > LIM_FS_HZ) {
        return CTRL_EINVAL;
    }
    /* Rs = 0 (an ideal, lossless machine) is accepted; negative is not. */
    if (!isfinite(m->rs_ohm) || m->rs_ohm < 0.0 || m->rs_ohm > LIM_R_OHM ||
        !pos_finite(m->ld_h, LIM_L_H) || !pos_finite(m->lq_h, LIM_L_H) ||
        !pos_finite(m->psi_pm_wb, LIM_PSI_WB) || !pos_finite(m->vdc_v, LIM_VDC_V) ||
        !pos_finite(m->inertia_kgm2, LIM_J) || !pos_finite(m->torque_rated_nm, LIM_TORQUE_NM) ||
        !pos_finite(m->speed_rated_rpm, LIM_SPEED_RPM) ||
        !pos_finite(m->current_rated_a, LIM_CURRENT_A) ||
        !pos_finite(m->current_max_a, LIM_CURRENT_A) || m->current_max_a < m->current_rated_a ||
        !isfinite(m->psi_ref_wb) || m->psi_ref_wb < 0.0 || m->psi_ref_wb > LIM_PSI_WB) {
        return CTRL_EINVAL;
    }

    b->psi_wb = m->psi_pm_wb;
    b->v_v = m->vdc_v;
    b->w_rad_s = b->v_v / b->psi_wb;
    b->t_s = 1.0 / b->w_rad_s;
    b->i_a = b->psi_wb / m->ld_h;
    b->l_h = m->ld_h;
    b->r_ohm = b->v_v / b->i_a;
    b->torque_nm = 1.5 * (double)m->pole_pairs * b->psi_wb * b->i_a;

    const double ts = 1.0 / ((double)fs_hz * b->t_s);
    const double rs = m->rs_ohm / b->r_ohm;
    const double lq = m->lq_h / b->l_h;
    const double w_rated = ctrl_rpm_to_elec(m->speed_rated_rpm, m->pole_pairs);
    const double vals[] = {
        ts,
        rs,
        ts * rs,
        lq,
        1.0 / lq,
        m->torque_rated_nm / b->torque_nm,
        w_rated / b->w_rad_s,
        m->current_rated_a / b->i_a,
        m->current_max_a / b->i_a,
        m->psi_ref_wb / b->psi_wb,
    };
    for (size_t i = 0; i < sizeof vals / sizeof vals[0]; i++) {
        if (!fits(vals[i])) {
            return CTRL_ERANGE;
        }
    }
    /* One period must turn at most one radian at 1 pu speed (Euler step of
     * (5.15) and omega_to_dangle < 2^31). */
    if (ts > 1.0) {
        return CTRL_ERANGE;
    }

    p->fs_hz = fs_hz;
    p->pole_pairs = m->pole_pairs;
    p->ts = ctrl_q24_from_double(ts);
    p->rs = ctrl_q24_from_double(rs);
    p->ts_rs = ctrl_q24_from_double(ts * rs);
    p->ld = FX_ONE;
    p->lq = ctrl_q24_from_double(lq);
    p->inv_ld = FX_ONE;
    p->inv_lq = ctrl_q24_from_double(1.0 / lq);
    p->psi_pm = FX_ONE;
    p->vdc_nom = FX_ONE;
    p->torque_rated = ctrl_q24_from_double(vals[5]);
    p->speed_rated_e = ctrl_q24_from_double(vals[6]);
    p->current_rated = ctrl_q24_from_double(vals[7]);
    p->current_max = ctrl_q24_from_double(vals[8]);
    p->psi_ref = ctrl_q24_from_double(vals[9]);
    /* Saliency below 1e-6 is numerical noise: treat as SPMSM (4.15). */
    p->salient = fabs(lq - 1.0) > 1.0e-6 ? 1u : 0u;

    /* Angle per period at 1 pu speed: Ts_pu rad = Ts_pu / (2 pi) turns. */
    const double k_ang = ts / CTRL_TWO_PI * 4294967296.0;
    p->omega_to_dangle = (int32_t)llround(k_ang);
    /* Inverse: omega_q24 = dtheta * 2^24 / k_ang, coefficient in Q28 (fixed
     * shift: cheap on the target). It must fit an int32_t (Ts_pu >= 0.0031)
     * and keep >= 20 significant bits (Ts_pu <= 1 gives >= 2^22). */
    const double inv = ldexp(16777216.0 / k_ang, (int)CTRL_DANGLE_SHIFT);
    if (!(inv < 2147483647.0) || inv < 1048576.0) {
        return CTRL_ERANGE;
    }
    p->dangle_to_omega = (int32_t)llround(inv);

    if (ctrl_params_set_speed_lpf(p, CTRL_SPEED_LPF_HZ_DEFAULT) != CTRL_OK &&
        ctrl_params_set_speed_lpf(p, 0.25 * (double)fs_hz) != CTRL_OK) {
        return CTRL_ERANGE;
    }

    p->mtpa_k = ctrl_q24_from_double(lq); /* Lq / psi_pm, psi_pm = 1 pu */
    p->inv_psi_pm = FX_ONE;               /* psi_pm = 1 pu */
    /* SPMSM: the same table from the closed forms (dL = 0), for tools. */
    return mtpa_table(p, 1.0, p->salient != 0u ? lq : 1.0, 1.0, vals[8]);
}

int ctrl_params_init(ctrl_params_t *p, ctrl_bases_t *bases, const ctrl_machine_t *m, uint32_t fs_hz)
{
    if (p == NULL || bases == NULL) {
        return CTRL_EINVAL;
    }
    memset(p, 0, sizeof *p);
    memset(bases, 0, sizeof *bases);
    if (m == NULL) {
        return CTRL_EINVAL;
    }
    const int rc = params_compute(p, bases, m, fs_hz);
    if (rc != CTRL_OK) {
        memset(p, 0, sizeof *p);
        memset(bases, 0, sizeof *bases);
    }
    return rc;
}
