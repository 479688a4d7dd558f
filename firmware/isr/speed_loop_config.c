/* Speed-PI sizing from the machine (speed_loop.h); configuration time only. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>

#include "ctrl_cfg_math.h"
#include "ctrl_units.h"
#include "field_weak_config.h"
#include "speed_loop.h"

#define FW_SL_DEG (CTRL_PI / 180.0)

static int fw_sl_fail(char *why, size_t len, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static int fw_sl_fail(char *why, size_t len, const char *fmt, ...)
{
    if (why != NULL && len > 0u) {
        va_list ap;
        va_start(ap, fmt);
        (void)vsnprintf(why, len, fmt, ap);
        va_end(ap);
    }
    return CTRL_EINVAL;
}

int fw_speed_loop_design(fw_speed_design_t *d, const ctrl_machine_t *m, double loop_hz,
                         double lpf_hz, char *why, size_t why_len)
{
    if (d == NULL || m == NULL) {
        return fw_sl_fail(why, why_len, "speed loop: no machine");
    }
    if (!(m->inertia_kgm2 > 0.0) || !isfinite(m->inertia_kgm2)) {
        return fw_sl_fail(why, why_len, "speed loop: inertia %g kg*m^2 must be > 0",
                          m->inertia_kgm2);
    }
    if (!(loop_hz > 0.0) || !(lpf_hz > 0.0)) {
        return fw_sl_fail(why, why_len, "speed loop: rate %g Hz and filter %g Hz must be > 0",
                          loop_hz, lpf_hz);
    }
    const double pm = d->phase_margin_deg > 0.0 ? d->phase_margin_deg : FW_SPEED_PM_DEFAULT_DEG;
    if (!(pm >= 20.0 && pm <= 80.0)) {
        return fw_sl_fail(why, why_len,
                          "speed loop: phase margin %g deg is out of range [%g, %g] deg", pm, 20.0,
                          80.0);
    }
    const double td = 1.0 / loop_hz + 1.0 / (2.0 * CTRL_PI * lpf_hz) + FW_SPEED_TORQUE_DELAY_S;
    /* The phase budget left for the dead time: 90 deg - PM (with wz -> 0). */
    const double wc_max = (90.0 - pm) * FW_SL_DEG / td;
    double wc;
    if (d->bandwidth_hz > 0.0) {
        wc = 2.0 * CTRL_PI * d->bandwidth_hz;
        if (!(wc < wc_max) || !isfinite(wc)) {
            return fw_sl_fail(why, why_len,
                              "speed loop: bandwidth %g Hz is out of range (0, %.4g) Hz: with "
                              "phase margin %g deg the loop's dead time allows no more",
                              d->bandwidth_hz, wc_max / (2.0 * CTRL_PI), pm);
        }
    } else {
        wc = (90.0 - atan(FW_SPEED_ZERO_RATIO) / FW_SL_DEG - pm) * FW_SL_DEG / td;
        if (!(wc > 0.0)) {
            return fw_sl_fail(why, why_len,
                              "speed loop: phase margin %g deg leaves no bandwidth "
                              "(at most %g deg)",
                              pm, 90.0 - atan(FW_SPEED_ZERO_RATIO) / FW_SL_DEG);
        }
    }
    /* tan as sin / cos: libm's tan would add 1 KB to the board's image */
    const double phi = (90.0 - pm) * FW_SL_DEG - wc * td;
    const double wz = wc * ctrl_cfg_sin(phi) / ctrl_cfg_cos(phi);
    const double kp = m->inertia_kgm2 * wc / sqrt(1.0 + (wz / wc) * (wz / wc));
    d->bandwidth_hz = wc / (2.0 * CTRL_PI);
    d->phase_margin_deg = pm;
    d->kp_nm_s_rad = kp;
    d->ki_nm_rad = kp * wz;
    d->zero_hz = wz / (2.0 * CTRL_PI);
    d->dead_time_s = td;
    return CTRL_OK;
}

/* Torque on the flux circle |psi| = psi at i_d ((3.9), (3.10)); 0 off it. */
static double fw_torque_on_flux(const ctrl_machine_t *m, double psi, double id)
{
    const double pd = m->psi_pm_wb + m->ld_h * id;
    const double r = psi * psi - pd * pd;
    if (!(r > 0.0)) {
        return 0.0;
    }
    const double iq = sqrt(r) / m->lq_h;
    return 1.5 * (double)m->pole_pairs * iq * (m->psi_pm_wb + (m->ld_h - m->lq_h) * id);
}

/* fw_torque_limit_nm with the flux margin given. */
static double fw_torque_limit_at(const ctrl_machine_t *m, const ctrl_desc_t *ctrl,
                                 double *t_flux_max, double margin)
{
    if (t_flux_max != NULL) {
        *t_flux_max = 0.0;
    }
    if (m == NULL) {
        return 0.0;
    }
    double lim = m->torque_rated_nm;
    /* a controller without a fixed flux holds MTPA's limits (field_weak.h) */
    const double psi = ctrl != NULL && ctrl->flux_free != 0u ? 0.0 : m->psi_ref_wb;
    if (psi > 0.0 && m->ld_h > 0.0 && m->lq_h > 0.0) {
        /* Scan the circle's i_d span, then refine around the best point. */
        const double lo = (-psi - m->psi_pm_wb) / m->ld_h;
        const double hi = (psi - m->psi_pm_wb) / m->ld_h;
        double best = 0.0;
        double best_id = lo;
        const int n = 4000;
        for (int k = 0; k <= n; k++) {
            const double id = lo + (hi - lo) * (double)k / (double)n;
            const double t = fw_torque_on_flux(m, psi, id);
            if (t > best) {
                best = t;
                best_id = id;
            }
        }
        double a = best_id - (hi - lo) / (double)n;
        double b = best_id + (hi - lo) / (double)n;
        for (int it = 0; it < 60; it++) { /* ternary search, unimodal near the peak */
            const double m1 = a + (b - a) / 3.0;
            const double m2 = b - (b - a) / 3.0;
            if (fw_torque_on_flux(m, psi, m1) < fw_torque_on_flux(m, psi, m2)) {
                a = m1;
            } else {
                b = m2;
            }
        }
        const double tmax = fmax(best, fw_torque_on_flux(m, psi, 0.5 * (a + b)));
        if (t_flux_max != NULL) {
            *t_flux_max = tmax;
        }
        if (margin * tmax < lim) {
            lim = margin * tmax;
        }
    }
    return lim;
}

double fw_torque_limit_nm(const ctrl_machine_t *m, const ctrl_desc_t *ctrl, double *t_flux_max)
{
    return fw_torque_limit_at(m, ctrl, t_flux_max, FW_TORQUE_FLUX_MARGIN);
}

double fw_torque_limit_brake_nm(const ctrl_machine_t *m, const ctrl_desc_t *ctrl,
                                double *t_flux_max)
{
    return fw_torque_limit_at(m, ctrl, t_flux_max, CTRL_FIELDWEAK_TORQUE_MARGIN_BRAKE_DEFAULT);
}
