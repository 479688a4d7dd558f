/* Dead-time and device-drop compensation: SI -> fixed point (configuration). */
#include <math.h>

#include "ctrl_cfg_math.h"
#include "deadtime.h"

#if CTRL_DEAD_COMP
/* The inductance the phase ripple follows: the mean of the inverse
 * inductances (a ripple vector at any angle to d over a turn). */
static double dt_l_ripple(const ctrl_machine_t *m)
{
    return 2.0 / (1.0 / m->ld_h + 1.0 / m->lq_h);
}

/* The current at an edge is known to w: the ripple's change over the t_d / 2
 * by which the compensation moves the edge, at most (2/3) Vdc / L (a phase
 * against the other two) times t_d / 2, and the sensing the prediction
 * starts from, 4 counts (the third phase is the sum of two samples, each
 * quantised to half a count and with about a count of noise). */
double ctrl_deadtime_band_default(const ctrl_machine_t *m, double dead_time_s, double i_a_per_count)
{
    return m->vdc_v * dead_time_s / (3.0 * dt_l_ripple(m)) + 4.0 * i_a_per_count;
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
    const double l_h =
        b->l_h * 2.0 / ((double)FX_ONE / (double)p->ld + (double)FX_ONE / (double)p->lq);
    /* the edge ripple per unit of bracket and of DC link: Ts V_base / (6 L),
     * A; in pu (the bases' L_base = Ld, V_base / I_base = w_base Ld) it is
     * Ts_pu (Ld / L) / 6, at most 1 x 4.5 / 6 = 0.75 within ctrl_params'
     * ranges (Ts_pu <= 1, Lq / Ld >= 1/8): always in Q24, no check. */
    const double k_rip_a = b->v_v / (6.0 * l_h * fs);
    if (!ctrl_diag_in_range(why, "dead_time_s", "s", c->dead_time_s, 0.0, 0.25 / fs) ||
        !ctrl_diag_in_range(why, "v_fwd_v", "V", c->v_fwd_v, 0.0, 0.1 * vdc_v)) {
        return CTRL_EINVAL;
    }
    ctrl_deadtime_t n = {0, 0, 0, 0, 0u};
    if (c->dead_time_s > 0.0 || c->v_fwd_v > 0.0) {
        /* the band and the ripple only with the compensation on: off,
         * nothing uses them */
        if (!ctrl_diag_in_range(why, "band_a", "A", c->band_a, 1e-3 * i_rated, 10.0 * i_rated)) {
            return CTRL_EINVAL;
        }
        const double band_pu = c->band_a / b->i_a;
        n.dd = ctrl_q24_from_double(c->dead_time_s * fs + c->v_fwd_v / vdc_v);
        n.dt = ctrl_q24_from_double(c->dead_time_s * fs);
        n.inv_w = (int32_t)ctrl_cfg_llround(
            fmin((double)(1u << CTRL_DT_BAND_SHIFT) / band_pu, 2147483647.0));
        n.k_rip = ctrl_q24_from_double(k_rip_a / b->i_a);
    }
    *d = n;
    return CTRL_OK;
}
#else
double ctrl_deadtime_band_default(const ctrl_machine_t *m, double dead_time_s, double i_a_per_count)
{
    (void)m;
    (void)dead_time_s;
    (void)i_a_per_count;
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
    d->inv_w = 0;
    d->high_prev = 0u;
    return CTRL_OK;
}
#endif /* CTRL_DEAD_COMP */
