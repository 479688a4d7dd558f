/* Sensorless angle: SI configuration -> fixed point (configuration only). */
#include <math.h>
#include <string.h>

#include "ctrl_cfg_math.h"
#include "ctrl_units.h"
#include "fx.h"
#include "sensorless.h"
#include "sensorless_config.h"

void ctrl_sl_config_default(ctrl_sl_config_t *c, const ctrl_machine_t *m)
{
    memset(c, 0, sizeof *c);
    ctrl_fobs_config_default(&c->obs, m);
    c->t_start_nm = 0.5 * m->torque_rated_nm;
    c->ramp_rad_s2 = 0.25 * c->t_start_nm * (double)m->pole_pairs / m->inertia_kgm2;
    c->w_on_frac = 0.05;
    c->w_off_frac = 0.025;
    c->low_s = 0.05;
    const double w_on = c->w_on_frac * ctrl_rpm_to_elec(m->speed_rated_rpm, m->pole_pairs);
    c->settle_s = 6.0 / w_on;
    c->kappa_start = 2.0;
    c->theta0_rad = 0.0;
    c->damp_zeta = 0.7;
    c->inertia_kgm2 = m->inertia_kgm2;
    c->ia_saliency_min = 0.1;
    c->ia_i_frac = 0.1;
    c->ia_rounds = 2.0;
    c->pol_deg = 10.0;
    c->pol_min_frac = 0.25;
#if CTRL_SL_HFI
    c->hfi = 0u;
    ctrl_hfi_config_default(&c->hfi_cfg, m);
    c->hfi_low_s = 5e-3;
#endif
}

/* The initial angle's settings (sensorless.h): the pulse amplitude that
 * changes the current by ia_i_frac of the rated current in one period
 * through the mean inverse inductance S = (1/Ld + 1/Lq) / 2 (within 0.45
 * Vdc, inside the modulator's circle Vdc / sqrt 3), the polarity pulse's
 * halves t with (t_start p / J) t^2 = pol (accelerated for t, braked for t). */
static int sl_ia_init(ctrl_sl_t *n, const ctrl_params_t *p, const ctrl_bases_t *b,
                      const ctrl_sl_config_t *c, ctrl_diag_t *why)
{
    if (!ctrl_diag_in_range(why, "ia_saliency_min", "", c->ia_saliency_min, 0.0, 1e3) ||
        !ctrl_diag_in_range(why, "ia_i_frac", "", c->ia_i_frac, 0.005, 0.5) ||
        !ctrl_diag_in_range(why, "ia_rounds", "", c->ia_rounds, 1.0, (double)CTRL_IA_ROUNDS_MAX) ||
        !ctrl_diag_in_range(why, "pol_deg", "deg", c->pol_deg, 0.5, 90.0) ||
        !ctrl_diag_in_range(why, "pol_min_frac", "", c->pol_min_frac, 0.0, 1.0)) {
        return CTRL_EINVAL;
    }
#if !CTRL_SL_INITIAL_ANGLE
    (void)p;
    (void)b;
    n->ia_on = 0u;
    return CTRL_OK;
#else
    const double ld = (double)p->ld * b->l_h / (double)FX_ONE;
    const double lq = (double)p->lq * b->l_h / (double)FX_ONE;
    const double sal = 2.0 * fabs(lq - ld) / (lq + ld);
    /* the injection's start measures the axis with the pulses too, at the
     * saliency it accepts (ctrl_hfi_init) */
#if CTRL_SL_HFI
    const int want = sal >= c->ia_saliency_min || c->hfi != 0u;
#else
    const int want = sal >= c->ia_saliency_min;
#endif
    n->ia_on = (c->inertia_kgm2 > 0.0 && want) ? 1u : 0u;
    if (n->ia_on == 0u) {
        return CTRL_OK;
    }
    const double fs = (double)p->fs_hz;
    const double i_rated = (double)p->current_rated * b->i_a / (double)FX_ONE;
    const double l_mean = 2.0 * ld * lq / (ld + lq);
    const double vdc = (double)p->vdc_nom * b->v_v / (double)FX_ONE;
    const double v = fmin(c->ia_i_frac * i_rated * l_mean * fs, 0.45 * vdc);
    const q24_t v_q = ctrl_q24_from_double(v / b->v_v);
    if (ctrl_ia_init(&n->ia, v_q, (uint32_t)ctrl_cfg_llround(c->ia_rounds), lq > ld ? 1 : -1) !=
        0) {
        (void)ctrl_diag_in_range(why, "ia_i_frac", "", c->ia_i_frac, 1.0, 0.0);
        return CTRL_EINVAL;
    }
    const double pol = c->pol_deg * CTRL_TWO_PI / 360.0;
    const double t = sqrt(pol * c->inertia_kgm2 / (c->t_start_nm * (double)p->pole_pairs));
    if (!ctrl_diag_in_range(why, "polarity pulse half (from pol_deg, t_start_nm, inertia_kgm2)",
                            "s", t, 1.0 / fs, 1.0)) {
        return CTRL_EINVAL;
    }
    n->pol_n = (uint32_t)ceil(t * fs);
    {
        /* The controller puts t_start's MTPA current (i_d, i_q) in the frame
         * it is given; that frame turned back by the current's angle beta
         * from the q axis puts the current on the measured q axis, so the
         * pulse's torque is the magnet's alone and changes sign with the
         * polarity (the reluctance torque, the same for both, could
         * outweigh it at large currents). */
        const double tq = fmin(c->t_start_nm / b->torque_nm, (double)p->mtpa_t_max / FX_ONE);
        const double pos = tq * ((double)p->mtpa_scale / 65536.0) * (double)FX_ONE;
        const int k = (int)fmin(floor(pos), (double)CTRL_MTPA_N - 1.0);
        const double f = pos - (double)k;
        const double id = (1.0 - f) * p->mtpa_id[k] + f * p->mtpa_id[k + 1];
        const double iq = (1.0 - f) * p->mtpa_iq[k] + f * p->mtpa_iq[k + 1];
        /* beta = atan2(-i_d, i_q) by the core's own fx_atan2 (|i| < 2^31 in
         * Q24: the table's values), not libm's: host and target alike */
        n->pol_shift = fx_atan2((int32_t)ctrl_cfg_llround(-id), (int32_t)ctrl_cfg_llround(iq));
    }
    n->zero_n = (uint32_t)ceil(1e-3 * fs); /* the current back to zero: 1 ms */
    n->pol_min =
        (fx_angle_t)(uint32_t)ctrl_cfg_llround(c->pol_min_frac * c->pol_deg / 360.0 * 4294967296.0);
    return CTRL_OK;
#endif
}

#if CTRL_SL_HFI
/* The injection (c->hfi): its gains (ctrl_hfi_init: refused on a machine
 * with too little saliency), the hand-over speeds, LOCK's length (8 / w_o:
 * the tracking's error from the pulses' angle, (1 + w t + (w t)^2 / 2)
 * e^(-w t) at its triple pole, down to 1.4 %), the time above the upper
 * speed before the hand-over. */
static int sl_hfi_init(ctrl_sl_t *n, const ctrl_params_t *p, const ctrl_bases_t *b,
                       const ctrl_sl_config_t *c, ctrl_diag_t *why)
{
    if (c->hfi == 0u) {
        return CTRL_OK;
    }
    if (!ctrl_diag_in_range(why, "hfi", "0/1", (double)c->hfi, 0.0, 1.0)) {
        return CTRL_EINVAL;
    }
    if (!CTRL_SL_INITIAL_ANGLE || n->ia_on == 0u) {
        /* the start measures the axis with the initial angle's pulses and
         * sizes the motion's polarity pulse from the inertia */
        (void)ctrl_diag_in_range(why, "inertia_kgm2 (the injection's start needs it)", "kg*m^2",
                                 c->inertia_kgm2, 1e-12, 1e6);
        return CTRL_EINVAL;
    }
    if (ctrl_hfi_init(&n->hfi, p, b, &c->hfi_cfg, why) != CTRL_OK) {
        return CTRL_EINVAL;
    }
    const double fs = (double)p->fs_hz;
    if (!ctrl_diag_in_range(why, "hfi_low_s", "s", c->hfi_low_s, 1.0 / fs, 10.0)) {
        return CTRL_EINVAL;
    }
    const double w_rated = (double)p->speed_rated_e / (double)FX_ONE;
    n->hfi_on = 1u;
    n->hfi_w_hi = ctrl_q24_from_double(c->hfi_cfg.w_hi_frac * w_rated);
    n->hfi_w_lo = ctrl_q24_from_double(c->hfi_cfg.w_lo_frac * w_rated);
    const double wo = (double)n->hfi.l1 / (double)FX_ONE * fs / 3.0;
    n->lock_n = (uint32_t)ceil(8.0 * fs / wo);
    n->hfi_low_n = (uint32_t)ceil(c->hfi_low_s * fs);
    (void)b;
    return CTRL_OK;
}
#endif

int ctrl_sl_init(ctrl_sl_t *s, const ctrl_params_t *p, const ctrl_bases_t *b,
                 const ctrl_sl_config_t *c, ctrl_diag_t *why)
{
    if (s == NULL || p == NULL || b == NULL || c == NULL || p->fs_hz == 0u) {
        return CTRL_EINVAL;
    }
    const double fs = (double)p->fs_hz;
    const double t_max = (double)p->torque_rated * b->torque_nm / (double)FX_ONE * 2.0;
    const double w_rated = (double)p->speed_rated_e * b->w_rad_s / (double)FX_ONE;
    /* The ramp reaches the handover speed in at least 10 periods. */
    const double w_on = c->w_on_frac * w_rated;
    if (!ctrl_diag_in_range(why, "t_start_nm", "N*m", c->t_start_nm, 1e-6 * t_max, t_max) ||
        !ctrl_diag_in_range(why, "w_on_frac", "", c->w_on_frac, 0.005, 0.5) ||
        !ctrl_diag_in_range(why, "w_off_frac", "", c->w_off_frac, 0.0, c->w_on_frac) ||
        !ctrl_diag_in_range(why, "ramp_rad_s2", "rad/s^2", c->ramp_rad_s2, 1e-3 * w_on,
                            0.1 * w_on * fs) ||
        !ctrl_diag_in_range(why, "low_s", "s", c->low_s, 1.0 / fs, 100.0) ||
        !ctrl_diag_in_range(why, "settle_s", "s", c->settle_s, 1.0 / fs, 100.0) ||
        !ctrl_diag_in_range(why, "kappa_start", "", c->kappa_start, 0.0, 4.0) ||
        !ctrl_diag_in_range(why, "theta0_rad", "rad", c->theta0_rad, -1e3, 1e3) ||
        !ctrl_diag_in_range(why, "damp_zeta", "", c->damp_zeta, 0.0, 2.0) ||
        !ctrl_diag_in_range(why, "inertia_kgm2", "kg*m^2", c->inertia_kgm2, 0.0, 1e6)) {
        return CTRL_EINVAL;
    }
    ctrl_sl_t n;
    memset(&n, 0, sizeof n);
    ctrl_fobs_config_t oc = c->obs;
    oc.mode = CTRL_FOBS_SENSORLESS;
    /* kappa_start within what the observer accepts for kappa */
    ctrl_fobs_config_t ks = oc;
    ks.kappa = c->kappa_start;
    ctrl_fobs_t tmp;
    if (ctrl_fobs_init(&tmp, p, b, &ks, why) != CTRL_OK) {
        if (why != NULL && why->quantity != NULL && strcmp(why->quantity, "kappa") == 0) {
            why->quantity = "kappa_start";
        }
        return CTRL_EINVAL;
    }
    if (ctrl_fobs_init(&n.obs, p, b, &oc, why) != CTRL_OK) {
        return CTRL_EINVAL;
    }
    n.kappa_ts = n.obs.kappa_ts;
    n.kappa_start = tmp.kappa_ts;
    n.t_start = ctrl_q24_from_double(c->t_start_nm / b->torque_nm);
    n.ramp_dw = ctrl_q24_from_double(c->ramp_rad_s2 / fs / b->w_rad_s);
    n.w_on = ctrl_q24_from_double(w_on / b->w_rad_s);
    n.w_off = ctrl_q24_from_double(c->w_off_frac * w_rated / b->w_rad_s);
    n.settle_n = (uint32_t)ceil(c->settle_s * fs);
    n.low_n = (uint32_t)ceil(c->low_s * fs);
    {
        /* The rotor about the forced current: J theta_m'' = -t_start p
         * theta_m (small swings about the unloaded equilibrium), w_n =
         * sqrt(t_start p / J); the shift -kd dw gives the torque -t_start kd dw_e,
         * damping ratio zeta for kd = 2 zeta / w_n (s, per electrical rad/s). */
        const double pp = (double)p->pole_pairs;
        const double j = c->inertia_kgm2;
        const double kd_s = j > 0.0 ? 2.0 * c->damp_zeta * sqrt(j / (c->t_start_nm * pp)) : 0.0;
        const double kd = kd_s * b->w_rad_s * 4294967296.0 / CTRL_TWO_PI;
        if (!ctrl_diag_in_range(why, "damp_zeta", "", kd, 0.0, (double)CTRL_SL_KD_MAX)) {
            return CTRL_EINVAL;
        }
        n.kd = (int64_t)ctrl_cfg_llround(kd);
    }
    if (sl_ia_init(&n, p, b, c, why) != CTRL_OK) {
        return CTRL_EINVAL;
    }
#if CTRL_SL_HFI
    if (sl_hfi_init(&n, p, b, c, why) != CTRL_OK) {
        return CTRL_EINVAL;
    }
#endif
    /* into [0, 2 pi) by floor (not fmod: its 0.75 KB do not fit the board's image) */
    double th = c->theta0_rad - CTRL_TWO_PI * floor(c->theta0_rad / CTRL_TWO_PI);
    if (th >= CTRL_TWO_PI) {
        th -= CTRL_TWO_PI;
    }
    n.theta0 =
        (fx_angle_t)(uint32_t)fmin(floor(th / CTRL_TWO_PI * 4294967296.0 + 0.5), 4294967295.0);
    if (n.t_start <= 0 || n.ramp_dw <= 0 || n.w_on <= 0) {
        (void)ctrl_diag_in_range(why, n.t_start <= 0 ? "t_start_nm" : "ramp_rad_s2", "", -1.0, 0.0,
                                 0.0);
        return CTRL_EINVAL;
    }
    *s = n;
    ctrl_sl_reset(s);
    return CTRL_OK;
}
