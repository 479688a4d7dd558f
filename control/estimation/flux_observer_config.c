/* Stator-flux observer: SI configuration -> fixed-point gains (configuration). */
#include <math.h>
#include <string.h>

#include "ctrl_cfg_math.h"
#include "ctrl_units.h"
#include "flux_observer.h"
#include "flux_observer_config.h"

void ctrl_fobs_config_default(ctrl_fobs_config_t *c, const ctrl_machine_t *m)
{
    memset(c, 0, sizeof *c);
    c->mode = CTRL_FOBS_SENSORLESS;
    c->k0_rad_s = 0.01 * ctrl_rpm_to_elec(m->speed_rated_rpm, m->pole_pairs);
    c->kappa = 0.5;
    c->kenc_rad_s = 0.05 * ctrl_rpm_to_elec(m->speed_rated_rpm, m->pole_pairs);
    c->pll_hz = 300.0;
    c->band_a = 0.05 * m->current_rated_a;
    c->psi_tau_s = 0.0;
    c->psi_speed_min = 0.2;
}

int ctrl_fobs_init(ctrl_fobs_t *o, const ctrl_params_t *p, const ctrl_bases_t *b,
                   const ctrl_fobs_config_t *c, ctrl_diag_t *why)
{
    if (o == NULL || p == NULL || b == NULL || c == NULL || p->fs_hz == 0u) {
        return CTRL_EINVAL;
    }
    const double fs = (double)p->fs_hz;
    const double ts = 1.0 / fs;
    /* Per-period gains k Ts up to CTRL_FOBS_KTS_MAX (0.5); the PLL's
     * 2 w_n Ts up to 0.5 as well (discrete loop well inside its stability
     * limit); the dead time below a quarter period. */
    const double k_max = 0.5 * fs;
    const double pll_max = 0.5 * fs / (4.0 * CTRL_PI);
    const double w_rated = (double)p->speed_rated_e * b->w_rad_s / (double)FX_ONE;
    const double kappa_max = w_rated > 0.0 ? 0.5 / (w_rated * ts) : 0.0;
    const double i_rated = (double)p->current_rated * b->i_a / (double)FX_ONE;
    if (!ctrl_diag_in_range(why, "mode", "", (double)c->mode, 0.0, 1.0) ||
        !ctrl_diag_in_range(why, "k0_rad_s", "rad/s", c->k0_rad_s, 0.0, k_max) ||
        !ctrl_diag_in_range(why, "kappa", "", c->kappa, 0.0, fmin(2.0, kappa_max)) ||
        !ctrl_diag_in_range(why, "kenc_rad_s", "rad/s", c->kenc_rad_s, 0.0, k_max) ||
        !ctrl_diag_in_range(why, "pll_hz", "Hz", c->pll_hz, 0.1, pll_max) ||
        !ctrl_diag_in_range(why, "dead_time_s", "s", c->dead_time_s, 0.0, 0.25 * ts) ||
        !ctrl_diag_in_range(why, "v_fwd_v", "V", c->v_fwd_v, 0.0,
                            0.1 * b->v_v * (double)p->vdc_nom / (double)FX_ONE) ||
        !ctrl_diag_in_range(why, "band_a", "A", c->band_a, 1e-3 * i_rated, 10.0 * i_rated) ||
        !ctrl_diag_in_range(why, "psi_speed_min", "", c->psi_speed_min, 0.0, 2.0) ||
        !(c->psi_tau_s == 0.0 ||
          ctrl_diag_in_range(why, "psi_tau_s", "s", c->psi_tau_s, 10.0 * ts, 100.0))) {
        return CTRL_EINVAL;
    }
    const double wn = CTRL_TWO_PI * c->pll_hz;
    const double band_pu = c->band_a / b->i_a;
    ctrl_fobs_t n;
    memset(&n, 0, sizeof n);
    n.mode = (uint8_t)c->mode;
    n.k0_ts = ctrl_q24_from_double(c->k0_rad_s * ts);
    n.kappa_ts = ctrl_q24_from_double(c->kappa * b->w_rad_s * ts);
    n.kenc_ts = ctrl_q24_from_double(c->kenc_rad_s * ts);
    n.dl = fx_sub(p->ld, p->lq);
    n.pll_kp = ctrl_q24_from_double(2.0 * wn * ts);
    /* omega [pu] += w_n^2 Ts e [rad] / w_base, e = e_units 2 pi / 2^32, in Q48. */
    const double ki = wn * wn * ts * CTRL_TWO_PI * 65536.0 / b->w_rad_s;
    if (!ctrl_diag_in_range(why, "pll_hz", "Hz", ki, 0.5, 2147483647.0)) {
        if (why != NULL) { /* report the frequency, with the range the Q format allows */
            why->value = c->pll_hz;
            why->min = sqrt(0.5 * b->w_rad_s / (ts * CTRL_TWO_PI * 65536.0)) / CTRL_TWO_PI;
            why->max =
                fmin(pll_max,
                     sqrt(2147483647.0 * b->w_rad_s / (ts * CTRL_TWO_PI * 65536.0)) / CTRL_TWO_PI);
        }
        return CTRL_EINVAL;
    }
    n.pll_ki = (int32_t)ctrl_cfg_llround(ki);
    n.dt_frac = ctrl_q24_from_double(c->dead_time_s * fs);
    n.v_fwd = ctrl_q24_from_double(c->v_fwd_v / b->v_v);
    n.inv_band = (int32_t)ctrl_cfg_llround(65536.0 / band_pu < 2147483647.0 ? 65536.0 / band_pu
                                                                            : 2147483647.0);
    n.psi_k = c->psi_tau_s > 0.0 ? ctrl_q24_from_double(1.0 - ctrl_cfg_exp(-ts / c->psi_tau_s)) : 0;
    n.psi_speed_min =
        ctrl_q24_from_double(c->psi_speed_min * (double)p->speed_rated_e / (double)FX_ONE);
    n.primed = 0u;
    *o = n;
    return CTRL_OK;
}
