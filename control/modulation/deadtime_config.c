/* Dead-time and device-drop compensation: SI -> fixed point (configuration). */
#include <math.h>

#include "ctrl_cfg_math.h"
#include "deadtime.h"

/* A leg against the motor's neutral, the other two legs' mean following it:
 * the phase sees (2/3) Vdc for d Ts and the current ripple is
 * (2/3) Vdc d (1 - d) / (L fs) peak to peak, largest at d = 1/2:
 * Vdc / (6 L fs); the smaller inductance is the one the ripple follows. */
#if CTRL_DEAD_COMP
double ctrl_deadtime_band_default(const ctrl_machine_t *m, double fs_hz)
{
    const double l = fmin(m->ld_h, m->lq_h);
    const double half_pp = m->vdc_v / (12.0 * l * fs_hz);
    return fmax(half_pp, 0.02 * m->current_rated_a);
}

int ctrl_deadtime_init(ctrl_deadtime_t *d, const ctrl_deadtime_config_t *c, const ctrl_params_t *p,
                       const ctrl_bases_t *b, ctrl_diag_t *why)
{
    if (d == NULL || c == NULL || p == NULL || b == NULL || p->fs_hz == 0u) {
        return CTRL_EINVAL;
    }
    const double fs = (double)p->fs_hz;
    const double vdc_v = b->v_v * (double)p->vdc_nom / (double)FX_ONE;
    const double i_rated = b->i_a * (double)p->current_rated / (double)FX_ONE;
    if (!ctrl_diag_in_range(why, "dead_time_s", "s", c->dead_time_s, 0.0, 0.25 / fs) ||
        !ctrl_diag_in_range(why, "v_fwd_v", "V", c->v_fwd_v, 0.0, 0.1 * vdc_v) ||
        !ctrl_diag_in_range(why, "band_a", "A", c->band_a, 1e-3 * i_rated, 10.0 * i_rated)) {
        return CTRL_EINVAL;
    }
    const double band_pu = c->band_a / b->i_a;
    ctrl_deadtime_t n;
    n.dd = ctrl_q24_from_double(c->dead_time_s * fs + c->v_fwd_v / vdc_v);
    n.dt = ctrl_q24_from_double(c->dead_time_s * fs);
    n.high_prev = 0u;
    n.inv_band =
        (int32_t)ctrl_cfg_llround(fmin((double)(1u << CTRL_DT_BAND_SHIFT) / band_pu, 2147483647.0));
    *d = n;
    return CTRL_OK;
}
#else
double ctrl_deadtime_band_default(const ctrl_machine_t *m, double fs_hz)
{
    (void)m;
    (void)fs_hz;
    return 0.0;
}

int ctrl_deadtime_init(ctrl_deadtime_t *d, const ctrl_deadtime_config_t *c, const ctrl_params_t *p,
                       const ctrl_bases_t *b, ctrl_diag_t *why)
{
    (void)c;
    (void)p;
    (void)b;
    (void)why;
    if (d == NULL) {
        return CTRL_EINVAL;
    }
    d->dd = 0;
    d->dt = 0;
    d->inv_band = 0;
    d->high_prev = 0u;
    return CTRL_OK;
}
#endif /* CTRL_DEAD_COMP */
