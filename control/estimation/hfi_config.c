/* High-frequency injection: SI configuration -> fixed point (configuration only). */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "ctrl_cfg_math.h"
#include "ctrl_units.h"
#include "fx.h"
#include "help_text.h"
#include "hfi.h"
#include "hfi_config.h"

/* The settings by name ("hfi.<field>"; 0: the machine's default), as a
 * controller's tunables (controller.h): ctrl_tunable_set(&ctrl_hfi_desc, ...). */
#define HFI_T(f, unit, lo, hi, text)                                                               \
    {                                                                                              \
        "hfi." #f, unit, HELP_TEXT(text), offsetof(ctrl_hfi_config_t, f), lo, hi                   \
    }
static const ctrl_tunable_t hfi_tunables[] = {
    HFI_T(ripple_frac, "", 0.0, 0.5, "injection: current step per period along d, share of rated"),
    HFI_T(v_inj_v, "V", 0.0, 1e5, "injection amplitude instead of ripple_frac (<= Vdc / 4)"),
    HFI_T(track_hz, "Hz", 0.0, 1e5, "tracking observer's bandwidth (10 Hz .. fs / 100)"),
    HFI_T(j_kgm2, "kg*m^2", 0.0, 1e6, "its mechanics' inertia (torque feed-forward)"),
    HFI_T(h_tau_s, "s", 0.0, 1.0, "time constant of the ripple model (its removal)"),
    HFI_T(sal_min, "", 0.0, 10.0, "smallest max(Lq/Ld, Ld/Lq) accepted"),
    HFI_T(w_hi_frac, "", 0.0, 0.5, "hand-over to the flux observer above, share of rated speed"),
    HFI_T(w_lo_frac, "", 0.0, 0.5, "back to the injection below, share of rated speed"),
    HFI_T(pol_i_frac, "", 0.0, 2.0, "polarity pulses' peak current, share of rated"),
    HFI_T(pol_rounds, "", 0.0, 16.0, "polarity pulse pairs per direction"),
    HFI_T(pol_min, "", 0.0, 0.5, "smallest pulse asymmetry that tells the polarity"),
};
_Static_assert(sizeof hfi_tunables / sizeof hfi_tunables[0] * sizeof(double) ==
                   sizeof(ctrl_hfi_config_t),
               "a tunable for every field of ctrl_hfi_config_t");

const ctrl_desc_t ctrl_hfi_desc = {
    .name = "hfi",
    .title = "high-frequency injection (docs/algorithms.md)",
    .cfg_size = sizeof(ctrl_hfi_config_t),
    .tunables = hfi_tunables,
    .n_tunables = sizeof hfi_tunables / sizeof hfi_tunables[0],
};

void ctrl_hfi_config_default(ctrl_hfi_config_t *c, const ctrl_machine_t *m)
{
    memset(c, 0, sizeof *c);
    c->ripple_frac = 0.03;
    c->v_inj_v = 0.0;
    c->track_hz = 0.0; /* from the inertia and fs (ctrl_hfi_init) */
    c->j_kgm2 = m->inertia_kgm2 > 0.0 ? m->inertia_kgm2 : 0.0;
    c->h_tau_s = 2e-3;
    c->sal_min = 1.1;
    /* The observer's angle error from a resistance error dR at speed w is
     * about kappa dR i / (w psi_pm) (docs/algorithms.md, "Stator-flux
     * observer", kappa = 0.5): 2 deg for dR = 10 % at rated current at w_2. */
    const double w_rated = ctrl_rpm_to_elec(m->speed_rated_rpm, m->pole_pairs);
    const double w2 = m->psi_pm_wb > 0.0 ? 0.5 * 0.1 * m->rs_ohm * m->current_rated_a /
                                               (m->psi_pm_wb * ctrl_deg_to_rad(2.0))
                                         : 0.0;
    const double lo = w_rated > 0.0 ? fmin(fmax(w2 / w_rated, 0.02), 0.05) : 0.02;
    c->w_lo_frac = lo;
    c->w_hi_frac = 2.0 * lo;
    c->pol_i_frac = 1.0;
    c->pol_rounds = 2.0;
    c->pol_min = 0.02;
}

double ctrl_hfi_saliency(const ctrl_params_t *p)
{
    if (p->ld <= 0 || p->lq <= 0) {
        return 0.0;
    }
    const double r = (double)p->lq / (double)p->ld;
    return r >= 1.0 ? r : 1.0 / r;
}

int ctrl_hfi_init(ctrl_hfi_t *h, const ctrl_params_t *p, const ctrl_bases_t *b,
                  const ctrl_hfi_config_t *c, ctrl_diag_t *why)
{
    if (h == NULL || p == NULL || b == NULL || c == NULL || p->fs_hz == 0u) {
        return CTRL_EINVAL;
    }
    const double fs = (double)p->fs_hz;
    const double ts = 1.0 / fs;
    const double ld = (double)p->ld * b->l_h / (double)FX_ONE;
    const double lq = (double)p->lq * b->l_h / (double)FX_ONE;
    const double vdc = (double)p->vdc_nom * b->v_v / (double)FX_ONE;
    const double i_rated = (double)p->current_rated * b->i_a / (double)FX_ONE;
    const double sal = ctrl_hfi_saliency(p);
    if (!ctrl_diag_in_range(why, "sal_min", "", c->sal_min, 1.01, 10.0) ||
        !ctrl_diag_in_range(why, "saliency max(Lq/Ld, Ld/Lq)", "", sal, c->sal_min, HUGE_VAL) ||
        !ctrl_diag_in_range(why, "ripple_frac", "", c->ripple_frac, 1e-3, 0.5) ||
        !ctrl_diag_in_range(why, "v_inj_v", "V", c->v_inj_v, 0.0, 0.25 * vdc) ||
        !ctrl_diag_in_range(why, "h_tau_s", "s", c->h_tau_s, 2.0 * ts, 1.0) ||
        !ctrl_diag_in_range(why, "w_lo_frac", "", c->w_lo_frac, 0.0, 0.5) ||
        !ctrl_diag_in_range(why, "w_hi_frac", "", c->w_hi_frac, c->w_lo_frac, 0.5) ||
        !ctrl_diag_in_range(why, "pol_i_frac", "", c->pol_i_frac, 0.05, 2.0) ||
        !ctrl_diag_in_range(why, "pol_rounds", "", c->pol_rounds, 1.0, 16.0) ||
        !ctrl_diag_in_range(why, "pol_min", "", c->pol_min, 0.0, 0.5)) {
        return CTRL_EINVAL;
    }
    /* The tracking observer's range: above 10 Hz (the ripple model and the
     * speed filter are faster), at most fs / 100 (the two periods from an
     * injection to its demodulated sample are a delay the loop must not
     * see). track_hz 0: a load step of the rated torque unknown to it,
     * a = p T / J, peaks at 0.271 a / w_o^2 (error (a/2) t^2 e^(-w_o t) at
     * t = 2 / w_o): 5 deg; without an inertia the slowest. */
    const double tr_lo = 10.0;
    const double tr_hi = 0.01 * fs;
    const double torque_rated = (double)p->torque_rated * b->torque_nm / (double)FX_ONE;
    if (!ctrl_diag_in_range(why, "j_kgm2", "kg*m^2", c->j_kgm2, 0.0, 1e6)) {
        return CTRL_EINVAL;
    }
    double tr = c->track_hz;
    if (tr == 0.0) {
        const double a = c->j_kgm2 > 0.0 ? torque_rated * (double)p->pole_pairs / c->j_kgm2 : 0.0;
        tr = fmin(fmax(sqrt(0.271 * a / ctrl_deg_to_rad(5.0)) / CTRL_TWO_PI, tr_lo), tr_hi);
    }
    if (!ctrl_diag_in_range(why, "track_hz", "Hz", tr, tr_lo, tr_hi)) {
        return CTRL_EINVAL;
    }
    ctrl_hfi_t n;
    memset(&n, 0, sizeof n);
    /* Amplitude: one period changes the current along d by ripple_frac of
     * the rated current (Ts V / Ld), within a quarter of the DC link. */
    const double v =
        c->v_inj_v > 0.0 ? c->v_inj_v : fmin(c->ripple_frac * i_rated * ld * fs, 0.25 * vdc);
    n.u_h = ctrl_q24_from_double(v / vdc);
    /* y_q = -Ts V D sin 2e (hfi.h): the error e = y_q / (2 Ts V D) for small e */
    const double dd = 0.5 * (1.0 / ld - 1.0 / lq);
    const double hd_pu = ts * v * dd / b->i_a; /* signed */
    /* fx_angle_t units per Q24 count of y_q */
    const double k0 = 4294967296.0 / CTRL_TWO_PI / (2.0 * hd_pu * (double)FX_ONE);
    int shift = 1;
    while (shift < 40 && fabs(k0) * ctrl_cfg_ldexp(1.0, shift + 1) < 1073741824.0) {
        shift++;
    }
    const double kq = k0 * ctrl_cfg_ldexp(1.0, shift);
    if (!ctrl_diag_in_range(why, "angle error gain (from the amplitude and Ld, Lq)", "", fabs(kq),
                            1.0, 1073741824.0)) {
        return CTRL_EINVAL;
    }
    n.k_err = (int32_t)ctrl_cfg_llround(kq);
    n.k_err_shift = (uint8_t)shift;
    n.h0 = ctrl_q24_from_double(ts * v / ld / b->i_a);
    n.inv_2vh = ctrl_q24_from_double(b->v_v / (2.0 * v));
    n.v_nom = p->vdc_nom;
    n.ts_inv_ld = fx_mul(p->ts, p->inv_ld);
    n.ts_inv_lq = fx_mul(p->ts, p->inv_lq);
    n.h_k = ctrl_q24_from_double(1.0 - ctrl_cfg_exp(-ts / c->h_tau_s));
    /* triple pole at -w_o: l1 = 3 w_o, l2 = 3 w_o^2, l3 = w_o^3 per period;
     * angle units e 2 pi / 2^32 rad, speeds in Q48 pu */
    const double wo = CTRL_TWO_PI * tr;
    const double unit = CTRL_TWO_PI / 4294967296.0 / b->w_rad_s * 281474976710656.0;
    n.l1 = ctrl_q24_from_double(3.0 * wo * ts);
    const double l2 = 3.0 * wo * wo * ts * unit;
    const double l3 = wo * wo * wo * ts * ts * unit * 65536.0;
    if (!ctrl_diag_in_range(why, "track_hz (its gains in Q48)", "", fmin(l2, l3), 0.5,
                            2147483647.0) ||
        !ctrl_diag_in_range(why, "track_hz (its gains in Q48)", "", fmax(l2, l3), 0.5,
                            2147483647.0)) {
        return CTRL_EINVAL;
    }
    n.l2 = (int32_t)ctrl_cfg_llround(l2);
    n.l3 = (int32_t)ctrl_cfg_llround(l3);
    /* speed change per period per pu of torque: Ts p T_base / (J w_base) */
    n.k_acc = c->j_kgm2 > 0.0 ? ctrl_q24_from_double(ts * (double)p->pole_pairs * b->torque_nm /
                                                     (c->j_kgm2 * b->w_rad_s))
                              : 0;
    n.err_max = (int32_t)1 << 29; /* 45 deg */
    /* Polarity pulses: the rated current (pol_i_frac) along d in n_pol
     * periods of at most 0.45 Vdc (inside the modulator's circle). */
    const double ip = c->pol_i_frac * i_rated;
    const double np = ceil(ip * ld * fs / (0.45 * vdc));
    if (!ctrl_diag_in_range(why, "polarity pulse periods (from pol_i_frac, Ld, Vdc)", "", np, 1.0,
                            2000.0)) {
        return CTRL_EINVAL;
    }
    n.n_pol = (uint16_t)np;
    n.v_pol = ctrl_q24_from_double(ip * ld * fs / np / b->v_v);
    n.pol_rounds = (uint8_t)ctrl_cfg_llround(c->pol_rounds);
    n.pol_min = ctrl_q24_from_double(c->pol_min);
    n.pol_result = CTRL_HFI_POL_NONE;
    n.cs[0][0] = n.cs[1][0] = FX_ONE;
    *h = n;
    return CTRL_OK;
}
