/*
 * Protection thresholds from SI data (configuration time only: double is
 * allowed here, never in the per-period path). Derivations in protect.h.
 */
#include <float.h>
#include <math.h>
#include <stddef.h>

#include "ctrl_units.h"
#include "protect.h"

/* DC-link window around the nominal voltage. */
#define FW_VDC_MAX_REL 1.25
#define FW_VDC_MIN_REL 0.70
/* Watchdog: the main loop must kick at least every 100 ms. */
#define FW_WDG_SECONDS 0.1
/* Least number of periods for the stuck check (noise immunity at high rates). */
#define FW_ENC_STUCK_MIN_PERIODS 8.0

double fw_speed_max_rpm(const ctrl_machine_t *m)
{
    if (m == NULL || !isfinite(m->speed_rated_rpm) || !(m->speed_rated_rpm > 0.0)) {
        return 0.0;
    }
    if (m->speed_max_rpm != 0.0) {
        return isfinite(m->speed_max_rpm) && m->speed_max_rpm >= m->speed_rated_rpm
                   ? m->speed_max_rpm
                   : 0.0;
    }
    double n = m->speed_rated_rpm;
    if (m->psi_pm_wb > 0.0 && m->vdc_v > 0.0 && m->pole_pairs > 0) {
        /* sqrt(3) w_e psi_pm = Vdc */
        const double w_e = m->vdc_v / (sqrt(3.0) * m->psi_pm_wb);
        n = fmax(n, w_e / (double)m->pole_pairs * 60.0 / (2.0 * CTRL_PI));
    }
    return n;
}

int fw_protect_config(fw_protect_cfg_t *cfg, const ctrl_machine_t *m, const ctrl_bases_t *b,
                      uint32_t fs_hz, uint32_t enc_counts_per_rev, uint32_t cycle_clock_hz,
                      double overspeed_rpm, ctrl_diag_t *why)
{
    if (cfg == NULL || m == NULL || b == NULL || fs_hz == 0u || enc_counts_per_rev == 0u ||
        !(b->i_a > 0.0) || !(b->v_v > 0.0) || !(b->w_rad_s > 0.0) || m->pole_pairs <= 0) {
        return CTRL_EINVAL; /* no bases: the machine's own check refused it first */
    }
    /* The machine's own check (ctrl_params_init) has named these before. */
    if (!(m->current_max_a > 0.0) || !(m->vdc_v > 0.0) || !(m->inertia_kgm2 > 0.0) ||
        !(m->torque_rated_nm >= 0.0) || !isfinite(m->current_max_a) || !isfinite(m->inertia_kgm2)) {
        return CTRL_EINVAL;
    }
    /* Overspeed in Q24 pu electrical speed; must fit below 2^31 (< 128 pu):
     * a maximum speed far above the rated one (the speed base) is refused. */
    const double w_max_pu = ctrl_rpm_to_elec(overspeed_rpm, m->pole_pairs) / b->w_rad_s;
    if (!(overspeed_rpm > 0.0) || !(w_max_pu < 127.0)) {
        return ctrl_diag_refuse(why, CTRL_EINVAL, "overspeed level", "r/min", overspeed_rpm, 0.0,
                                ctrl_elec_to_rpm(127.0 * b->w_rad_s, m->pole_pairs),
                                "127 x the speed base: speed_rated_rpm, speed_max_rpm");
    }
    cfg->omega_max = ctrl_q24_from_double(w_max_pu);
    cfg->follow_periods = fs_hz / 20u; /* speed following: 50 ms */
    const double fs = (double)fs_hz;
    const double i_lim_pu = ctrl_q24_to_double(FW_PROTECT_I_MAX_LIM);
    if (ctrl_q24_from_si(m->current_max_a, b->i_a, 0.0, i_lim_pu, &cfg->i_max) != CTRL_OK) {
        /* the trip level must fit the check (protect.h) */
        return ctrl_diag_refuse(why, CTRL_ERANGE, "current_max_a", "A", m->current_max_a, 0.0,
                                i_lim_pu * b->i_a, "64 x the current base");
    }
    cfg->vdc_max = ctrl_q24_from_double(FW_VDC_MAX_REL * m->vdc_v / b->v_v);
    cfg->vdc_min = ctrl_q24_from_double(FW_VDC_MIN_REL * m->vdc_v / b->v_v);

    /* Largest torque at i_max (3.10), an upper bound for an IPMSM as well. */
    const double dl = fabs(m->ld_h - m->lq_h);
    const double t_imax =
        1.5 * (double)m->pole_pairs * (m->psi_pm_wb + dl * m->current_max_a) * m->current_max_a;
    const double a_mech = (t_imax + m->torque_rated_nm) / m->inertia_kgm2; /* rad/s^2 */
    const double a_cpp2 = a_mech * (double)enc_counts_per_rev / CTRL_TWO_PI / (fs * fs);
    /* Quantisation moves each difference by +-1 count, the second difference
     * by +-2. A limit beyond int32_t (a tiny inertia) admits every second
     * difference the check can form, as the physics does: saturated there. */
    cfg->enc_jump_max = (int32_t)fmin(4.0 + ceil(a_cpp2), (double)INT32_MAX);
    const double rate_min = sqrt(4.0 * a_cpp2); /* r^2 / (2 a) >= 2 counts */
    cfg->enc_rate_min_q16 = (int32_t)fmin(ceil(rate_min * 65536.0), (double)INT32_MAX);
    const double n_stuck = fmax(FW_ENC_STUCK_MIN_PERIODS, ceil(2.0 / sqrt(a_cpp2)));
    cfg->enc_stuck_periods = (uint32_t)fmin(n_stuck, 1.0e6);
    cfg->deadline_cycles = cycle_clock_hz / fs_hz;
    cfg->wdg_periods = (uint32_t)ceil(FW_WDG_SECONDS * fs);
    return CTRL_OK;
}
