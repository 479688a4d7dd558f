/*
 * Start-up of the pipeline: SI configuration -> fixed point (double allowed
 * here: configuration time only, never called from the ISR).
 */
#include <math.h>
#include <string.h>

#include "ctrl_cfg_math.h"
#include "ctrl_foc_config.h"
#include "ctrl_units.h"
#include "field_weak_config.h"
#include "pipeline.h"

#include "flux_observer_config.h"
#include "plan.h"
#include "sensorless_config.h"
#include "speed_loop.h"
#include "speed_pi_config.h"

#define FW_CALIB_DEFAULT 256u

void fw_config_default(fw_config_t *c, const ctrl_machine_t *machine, const ctrl_desc_t *ctrl)
{
    if (c == NULL) {
        return;
    }
    memset(c, 0, sizeof *c);
    c->machine = machine;
    c->ctrl = ctrl;
    c->ctrl_cfg = NULL;
    c->calib_samples = FW_CALIB_DEFAULT;
    c->adc_gain_corr[0] = c->adc_gain_corr[1] = c->adc_gain_corr[2] = 1.0;
    c->enc_offset = 0u;
    c->enc_direction = 1;
    c->enc_cpr = 0u;
    cm_config_default(&c->cm);
    /* Speed PI sized at fw_init from the machine's inertia (speed_loop.h). */
    c->speed_bw_hz = 0.0;
    c->speed_pm_deg = 0.0;
    c->speed_kp = 0.0;
    c->speed_ki = 0.0;
    c->speed_unit = CTRL_SPEED_UNIT_RAD_S_MECH;
    c->speed_out_max_nm = fw_torque_limit_nm(machine, ctrl, NULL);
    c->speed_loop_hz = 1000u;
    c->overspeed_rpm = 0.0;
    c->psi_adapt = true;
    c->dead_time_s = 0.0;
    c->v_fwd_v = 0.0;
    c->dead_comp = true;
    c->dead_comp_band_a = 0.0;
    c->sensorless = false;
    c->hfi = false;                      /* hfi_cfg 0: the machine's defaults */
    c->torque_follow_fault_windows = 0u; /* warning only */
}

size_t fw_explain(const fw_t *fw, char *buf, size_t cap)
{
    if (fw == NULL || fw->why.code == CTRL_OK) {
        return ctrl_diag_format(NULL, buf, cap);
    }
    return ctrl_diag_format(&fw->why, buf, cap);
}

const char *fw_strerror(int code)
{
    switch (code) {
    case FW_OK:
        return "ok";
    case FW_EINVAL:
        return "invalid machine, HAL or pipeline configuration";
    case FW_ECTRL:
        return "controller rejected its configuration (or state/config too large)";
    case FW_ERANGE:
        return "a gain or limit does not fit its fixed-point format";
    case FW_EBUSY:
        return "not allowed while running";
    case FW_ENOENT:
        return "unknown name";
    default:
        return "unknown error";
    }
}

#if CTRL_SL_HFI
/* The injection's settings: each non-zero field of set replaces the
 * machine's default in c (fw_config_t.hfi_cfg). */
static void fw_hfi_overlay(ctrl_hfi_config_t *c, const ctrl_hfi_config_t *set)
{
    double *const dst[] = {&c->ripple_frac, &c->v_inj_v,    &c->track_hz,  &c->j_kgm2,
                           &c->h_tau_s,     &c->sal_min,    &c->w_hi_frac, &c->w_lo_frac,
                           &c->pol_i_frac,  &c->pol_rounds, &c->pol_min};
    const double src[] = {set->ripple_frac, set->v_inj_v,    set->track_hz,  set->j_kgm2,
                          set->h_tau_s,     set->sal_min,    set->w_hi_frac, set->w_lo_frac,
                          set->pol_i_frac,  set->pol_rounds, set->pol_min};
    _Static_assert(sizeof src == sizeof(ctrl_hfi_config_t), "every field of ctrl_hfi_config_t");
    for (size_t k = 0; k < sizeof src / sizeof src[0]; k++) {
        if (src[k] != 0.0) {
            *dst[k] = src[k];
        }
    }
}

/* The controllers the injection works with: its voltage is added to their
 * modulated output (leg duties of a continuous voltage); a switching table's
 * or a hysteresis controller's single vector has no room for it. */
static bool fw_hfi_controller_ok(const ctrl_desc_t *d)
{
    static const char *const ok[] = {"foc", "m2ptfc", "drr"};
    for (size_t k = 0; k < sizeof ok / sizeof ok[0]; k++) {
        if (strcmp(d->name, ok[k]) == 0) {
            return true;
        }
    }
    return false;
}
#endif

/* x in [0, 2) -> Q30, or -1 when it does not fit. */
static int32_t fw_q30(double x)
{
    if (!(x >= 0.0) || !(x < 2.0)) {
        return -1;
    }
    return (int32_t)floor(x * 1073741824.0 + 0.5);
}

/* The speed PI's gains for cfg into *pi (integrator cleared) and what they
 * are into *si's gain and design fields: cfg's explicit gains (speed_kp or
 * speed_ki > 0, in speed_unit), else designed from the machine's inertia with
 * cfg's bandwidth and phase margin for the medium task's rate (speed_loop.h).
 * FW_OK, or FW_EINVAL (the design refused: bandwidth or phase margin) /
 * FW_ERANGE (fw->why). fw_init and a live change (fw_speed_retune) share it. */
#if PMSM_LIVE_PARAMS
#define FW_SPEED_GAINS_INLINE /* two callers: one copy */
#elif defined(__GNUC__)
/* one caller: in it, as before it had a name (measured: 300 B less on the
 * B-G431B-ESC1 than a call) */
#define FW_SPEED_GAINS_INLINE __attribute__((always_inline)) inline
#else
#define FW_SPEED_GAINS_INLINE inline
#endif
static FW_SPEED_GAINS_INLINE int fw_speed_gains(fw_t *fw, const fw_config_t *cfg,
                                                ctrl_speed_pi_t *pi, fw_speed_info_t *si)
{
    const hal_info_t *in = &fw->info;
    double kp = cfg->speed_kp;
    double ki = cfg->speed_ki;
    ctrl_speed_unit_t unit = cfg->speed_unit;
    si->bandwidth_hz = 0.0;
    si->phase_margin_deg = 0.0;
    si->zero_hz = 0.0;
    if (!(kp > 0.0) && !(ki > 0.0)) {
        fw_speed_design_t d = {cfg->speed_bw_hz, cfg->speed_pm_deg, 0.0, 0.0, 0.0, 0.0};
        const double loop_rate = (double)in->pwm_freq_hz / (double)fw->mid_div;
        const double lpf_hz = CTRL_SPEED_LPF_HZ_DEFAULT < 0.45 * (double)in->pwm_freq_hz
                                  ? CTRL_SPEED_LPF_HZ_DEFAULT
                                  : 0.45 * (double)in->pwm_freq_hz;
        if (fw_speed_loop_design(&d, fw->machine, loop_rate, lpf_hz, NULL, 0u) != CTRL_OK) {
            return FW_EINVAL;
        }
        kp = d.kp_nm_s_rad;
        ki = d.ki_nm_rad;
        unit = CTRL_SPEED_UNIT_RAD_S_MECH;
        si->bandwidth_hz = d.bandwidth_hz;
        si->phase_margin_deg = d.phase_margin_deg;
        si->zero_hz = d.zero_hz;
    }
    /* The gains in SI per mechanical rad/s for reports. */
    const double per_rad = unit == CTRL_SPEED_UNIT_RPM          ? 60.0 / CTRL_TWO_PI
                           : unit == CTRL_SPEED_UNIT_RAD_S_ELEC ? (double)fw->machine->pole_pairs
                                                                : 1.0;
    si->kp_nm_s_rad = kp * per_rad;
    si->ki_nm_rad = ki * per_rad;
    if (!(cfg->speed_out_max_nm > 0.0) ||
        ctrl_speed_pi_config_diag(pi, &fw->bases, fw->machine->pole_pairs, kp, ki, unit,
                                  cfg->speed_out_max_nm, in->pwm_freq_hz / fw->mid_div,
                                  &fw->why) != CTRL_OK) {
        return FW_ERANGE;
    }
    return FW_OK;
}

/* Everything that follows from the machine: per-unit parameters, estimator,
 * controller, conversion gains, encoder scaling, protections, speed loop and
 * the commissioning limits. fw_init (with the caller's controller
 * configuration) and fw_commission_apply (cfg_default of the new machine)
 * share it. */
static int fw_setup_machine(fw_t *fw, const fw_config_t *cfg, const ctrl_desc_t *ctrl,
                            const void *ctrl_cfg)
{
#if PMSM_LIVE_PARAMS
    fw_request_withdraw(fw, FW_REQ_SPEED_TUNE); /* superseded by the gains set here */
#endif
    const hal_info_t *in = &fw->info;
    if (ctrl_params_init_diag(&fw->params, &fw->bases, fw->machine, in->pwm_freq_hz, &fw->why) !=
        CTRL_OK) {
        return FW_EINVAL;
    }
    fw->psi_ref_cfg = fw->params.psi_ref;
    if ((uint64_t)fw->enc_cpr * (uint64_t)fw->params.pole_pairs > (uint64_t)INT32_MAX) {
        return FW_ERANGE;
    }
    /* Field weakening and the torque limit: rated current, 92 % of Vdc/sqrt(3)
     * (field_weak_config.h defaults). */
    ctrl_fieldweak_cfg_t fieldweak_cfg;
    ctrl_fieldweak_cfg_default(&fieldweak_cfg);
    const int fwrc = ctrl_fieldweak_init(&fw->fieldweak, &fieldweak_cfg, fw->machine, &fw->bases,
                                         &fw->params, NULL, 0u);
    if (fwrc != CTRL_OK) {
        const ctrl_diag_t d = {
            fwrc, "field-weakening constants (Lq < Ld, or beyond 100 pu)", "", 0.0, 0.0,
            0.0,  "psi_pm_wb, ld_h, lq_h, rs_ohm, current_rated_a"};
        fw->why = d;
        return fwrc == CTRL_ERANGE ? FW_ERANGE : FW_EINVAL;
    }
#if CTRL_SL_HFI
    /* at standstill the injection's speed estimate scatters about 0: below 1 %
     * of rated speed the field weakening takes standstill (medium.c) */
    fw->hfi_w_still = cfg->hfi ? fw->params.speed_rated_e / 100 : 0;
#endif
    fw->torque_max = 0;
    fw->trim_k = ctrl_q24_from_double(
        1.0 - ctrl_cfg_exp(-CTRL_TWO_PI * FW_TRIM_HZ / (double)in->pwm_freq_hz));
    /* Dead-time and device-drop compensation of the written duties; the
     * observers then take the duties before it as the applied voltage
     * (without it, CTRL_DEAD_COMP 0 or dead_comp off, they remove the
     * inverter's error themselves). */
    const bool comp = cfg->dead_comp && CTRL_DEAD_COMP != 0;
    {
        const double dt = comp ? cfg->dead_time_s : 0.0;
        const double vf = comp ? cfg->v_fwd_v : 0.0;
        const ctrl_deadtime_config_t dc = {
            dt, vf,
            cfg->dead_comp_band_a > 0.0 ? cfg->dead_comp_band_a
                                        : ctrl_deadtime_band_default(fw->machine, cfg->dead_time_s,
                                                                     in->adc_current_a_per_count)};
        if (ctrl_deadtime_init(&fw->deadtime, &dc, &fw->params, &fw->bases, &fw->why) != CTRL_OK) {
            return FW_EINVAL;
        }
    }
    const double obs_dead_time_s = comp ? 0.0 : cfg->dead_time_s;
    const double obs_v_fwd_v = comp ? 0.0 : cfg->v_fwd_v;
    /* Before the controller: installing it narrows the estimator's outputs. */
    ctrl_estimator_init(&fw->est, &fw->params);
    /* PM-flux tracking: the encoder-mode observer, its estimate adopted above
     * 10 % of rated speed with a 20 ms time constant (docs/algorithms.md,
     * "PM flux from the voltage model"), corrected every N periods
     * (psi_track.h). */
    {
        ctrl_fobs_config_t oc;
        ctrl_fobs_config_default(&oc, fw->machine);
        oc.mode = CTRL_FOBS_ENCODER;
        oc.psi_tau_s = 0.02;
        oc.psi_speed_min = 0.1;
        /* its PLL does not run (psi_track.h); within the discrete loop's range */
        oc.pll_hz = fmin(oc.pll_hz, 0.4 * (double)in->pwm_freq_hz / (4.0 * CTRL_PI));
        oc.dead_time_s = obs_dead_time_s;
        oc.v_fwd_v = obs_v_fwd_v;
        if (ctrl_fobs_init(&fw->psi_track.obs, &fw->params, &fw->bases, &oc, &fw->why) != CTRL_OK ||
            ctrl_psi_track_setup(&fw->psi_track, &fw->params) != CTRL_OK) {
            return FW_EINVAL;
        }
        /* The configured value stays while the estimate agrees with it within
         * 2 %: about its own uncertainty (a 10 % resistance error moves it by
         * dR i / (w psi_pm), 1.3 % on the thesis SPMSM at 750 r/min and rated
         * current), and a 2 % torque error at most. */
        fw->psi_pm_cfg = fw->params.psi_pm;
        fw->psi_band = fx_mul(fw->params.psi_pm, ctrl_q24_from_double(0.02));
        fw->psi_engaged = false;
    }
#if CTRL_SL_HFI
    if (cfg->hfi && !cfg->sensorless) {
        const ctrl_diag_t d = {CTRL_EINVAL,
                               "sensorless",
                               "",
                               0.0,
                               1.0,
                               1.0,
                               "the injection (hfi) is a sensorless angle"};
        fw->why = d;
        return FW_EINVAL;
    }
#else
    if (cfg->hfi) {
        /* not built into this image (CMake option PMSM_SL_HFI): the setting
         * that asks for it named with its range here (a range [0, 0] would
         * read "missing", ctrl_diag_format) */
        (void)ctrl_diag_in_range(&fw->why, "est.sensorless", "", 2.0, 0.0, 1.0);
        return FW_EINVAL;
    }
#endif
    if (cfg->sensorless) {
        /* The sensorless angle source with its defaults (sensorless_config.h)
         * and the inverter's dead time and drop; its PLL within the discrete
         * loop's range at any fs, as above. */
        if (ctrl_estimator_set_angle_src(&fw->est, &fw->params, &ctrl_angle_sensorless) !=
            CTRL_OK) {
            return FW_EINVAL;
        }
        ctrl_sl_config_t sc;
        ctrl_sl_config_default(&sc, fw->machine);
        sc.obs.pll_hz = fmin(sc.obs.pll_hz, 0.4 * (double)in->pwm_freq_hz / (4.0 * CTRL_PI));
        {
            /* the observer's gains within what one period takes at rated
             * speed (k Ts <= 0.5, flux_observer_config.c): fast motors at
             * low fs */
            const double w_rated =
                ctrl_rpm_to_elec(fw->machine->speed_rated_rpm, fw->machine->pole_pairs);
            const double k_max = 0.45 * (double)in->pwm_freq_hz / w_rated;
            sc.kappa_start = fmin(sc.kappa_start, k_max);
            sc.obs.kappa = fmin(sc.obs.kappa, k_max);
        }
        sc.obs.dead_time_s = obs_dead_time_s;
        sc.obs.v_fwd_v = obs_v_fwd_v;
#if CTRL_SL_HFI
        sc.hfi = cfg->hfi ? 1u : 0u;
        fw_hfi_overlay(&sc.hfi_cfg, &cfg->hfi_cfg);
#endif
        ctrl_angle_sl_t *const sl = ctrl_estimator_angle_state(&fw->est);
        if (ctrl_sl_init(&sl->sl, &fw->params, &fw->bases, &sc, &fw->why) != CTRL_OK) {
            return FW_EINVAL;
        }
#if CTRL_SL_START_CHECK
        /* The start's own time: the ramp to the handover speed, the settling
         * at it and a salient machine's polarity pulses; three times that
         * and 0.25 s before the start counts as failed (FW_FAULT_SL_START). */
        const ctrl_sl_t *s = &sl->sl;
        const double ramp_n = s->ramp_dw > 0 ? (double)s->w_on / (double)s->ramp_dw : 0.0;
        const double n =
            3.0 * (ramp_n + (double)s->settle_n + 2.0 * (double)s->pol_n + (double)s->zero_n) +
            0.25 * (double)in->pwm_freq_hz;
        fw->sl_forced_max = n < 4.0e9 ? (uint32_t)n : 4000000000u;
#endif
    }
    const int sel = fw_select_controller(fw, ctrl, ctrl_cfg);
    if (sel != FW_OK) {
        return sel;
    }

    /* Conversion gains (formats in pipeline.h). */
    for (int x = 0; x < 3; x++) {
        const double corr = cfg->adc_gain_corr[x];
        if (!(corr > 0.5) || !(corr < 1.5)) {
            return FW_EINVAL;
        }
        fw->gain_q30[x] = fw_q30(corr * in->adc_current_a_per_count / fw->bases.i_a);
        if (fw->gain_q30[x] <= 0) {
            return FW_ERANGE;
        }
    }
    fw->vdc_gain_q30 = fw_q30(in->adc_vdc_v_per_count / fw->bases.v_v);
    if (fw->vdc_gain_q30 <= 0) {
        return FW_ERANGE;
    }
    {
        const uint64_t num = (uint64_t)(uint32_t)fw->params.pole_pairs << 32;
        fw->enc_q32 = (uint32_t)((num / fw->enc_cpr) & 0xFFFFFFFFu);
        fw->enc_r = (uint32_t)(num % fw->enc_cpr);
    }

    fw_protect_cfg_t pc;
    /* Overspeed: FW_OVERSPEED_REL above the machine's maximum speed unless
     * configured; the speed reference is limited to the trip level /
     * FW_OVERSPEED_REL. */
    const double n_max = fw_speed_max_rpm(fw->machine);
    if (!(n_max > 0.0)) {
        /* a declared maximum speed below the rated one: named, as every
         * refusal (the link's fuzzer found it answered with no reason) */
        const ctrl_diag_t d = {CTRL_EINVAL,
                               "maximum speed",
                               "r/min",
                               fw->machine->speed_max_rpm,
                               fw->machine->speed_rated_rpm,
                               HUGE_VAL,
                               "speed_max_rpm, speed_rated_rpm"};
        fw->why = d;
        return FW_EINVAL;
    }
    fw->speed_info.overspeed_rpm =
        cfg->overspeed_rpm > 0.0 ? cfg->overspeed_rpm : FW_OVERSPEED_REL * n_max;
    fw->speed_info.speed_ref_max_rpm = fw->speed_info.overspeed_rpm / FW_OVERSPEED_REL;
    if (fw_protect_config(&pc, fw->machine, &fw->bases, in->pwm_freq_hz, fw->enc_cpr,
                          in->cycle_clock_hz, fw->speed_info.overspeed_rpm, &fw->why) != CTRL_OK) {
        return FW_EINVAL;
    }
    /* The medium-rate task's rate: fs / mid_div, mid_div >= 1 rounded to the
     * nearest; speed following counts its runs (the same 50 ms, rounded up). */
    const uint32_t loop_hz = cfg->speed_loop_hz == 0u || cfg->speed_loop_hz > in->pwm_freq_hz
                                 ? in->pwm_freq_hz
                                 : cfg->speed_loop_hz;
    fw->mid_div = (in->pwm_freq_hz + loop_hz / 2u) / loop_hz;
    fw->mid_count = 1u;
    pc.follow_periods = (pc.follow_periods + fw->mid_div - 1u) / fw->mid_div;
    /* Field weakening runs in the medium task on the DC link's mean over a
     * run: its filter's coefficient per run, for the same corner. Its first
     * run starts its state anew. */
    fw->fieldweak.vdc_k =
        ctrl_q24_from_double(1.0 - ctrl_cfg_exp(-CTRL_TWO_PI * fieldweak_cfg.vdc_lpf_hz *
                                                (double)fw->mid_div / (double)in->pwm_freq_hz));
    fw->mid_reset = 1u;
    fw->mid_fresh = 0u;
#if PMSM_LIVE_PARAMS
    fw->mid_retune = 0u; /* a change taken for the old configuration */
#endif
    if (fw_protect_init(&fw->prot, &pc) != CTRL_OK) {
        return FW_ERANGE;
    }
    fw_torque_follow_cfg_t tfc;
    if (fw_torque_follow_config(&tfc, in->pwm_freq_hz, fw->params.torque_rated,
                                cfg->torque_follow_fault_windows) != CTRL_OK) {
        return FW_EINVAL;
    }
    fw_torque_follow_init(&fw->tqf, &tfc);

    /* Speed loop: one update per run of the medium task. */
    const int src = fw_speed_gains(fw, cfg, &fw->speed_pi, &fw->speed_info);
    if (src != FW_OK) {
        return src;
    }

    fw->torque_ref_max = ctrl_q24_from_double(cfg->speed_out_max_nm / fw->bases.torque_nm);
    fw->torque_ref_min = fx_neg(fw->torque_ref_max);
    /* Commissioning limits: a machine the steps cannot represent only
     * disables commissioning (fw_commission_start names the quantity). */
    fw->cm_what = NULL;
    cm_config_t cmc = cfg->cm;
    cmc.dead_time_s = (float)cfg->dead_time_s; /* the drive's, for the mechanics */
    if (cm_configure(&fw->cm, &cmc, &fw->params, &fw->bases, fw->machine, in, fw->enc_cpr,
                     &fw->cm_what) != 0 &&
        fw->cm_what == NULL) {
        fw->cm_what = "commissioning configuration";
    }
#if CTRL_COGGING
    /* The table stays across a new machine (it is against the encoder's
     * counts), not across a new encoder direction. A loop that does not fit
     * leaves the step to say so (cog_config). */
    fw->cm.cog = &fw->cog;
    (void)cm_cogging_configure(&fw->cog, &cfg->cog, fw->machine, &fw->params, &fw->bases,
                               in->pwm_freq_hz, fw->enc_cpr);
    if (fw->cog.enc_neg != fw->enc_neg) {
        fw->cog_on = 0u;
        fw->cog.valid = 0u;
        fw->cog.enc_neg = fw->enc_neg;
    }
#endif
    return FW_OK;
}

int fw_init(fw_t *fw, hal_t *hal, const fw_config_t *cfg)
{
    if (fw == NULL || hal == NULL || cfg == NULL || cfg->machine == NULL || cfg->ctrl == NULL ||
        cfg->ctrl->step == NULL || cfg->ctrl->init == NULL || cfg->ctrl->reset == NULL) {
        return FW_EINVAL;
    }
    memset(fw, 0, sizeof *fw);
    fw->tm_last = &fw->tm_ring[0];
    fw->tm_slot = &fw->tm_ring[0];
    fw->hal = hal;
    hal_gate_enable(hal, false);
    hal_info_get(hal, &fw->info);
    const hal_info_t *in = &fw->info;
    if (in->pwm_freq_hz == 0u || in->period_counts == 0u || in->adc_bits < 2u ||
        in->adc_bits > 16u || !(in->adc_current_a_per_count > 0.0) ||
        !(in->adc_vdc_v_per_count > 0.0) || in->encoder_counts_per_rev == 0u ||
        cfg->calib_samples == 0u || cfg->calib_samples > 65536u ||
        (cfg->enc_direction != 1 && cfg->enc_direction != -1) ||
        in->pwm_cmp_max > in->period_counts ||
        (in->adc_current_zero_tol != 0u &&
         (in->adc_current_zero < in->adc_current_zero_tol ||
          (uint32_t)in->adc_current_zero + in->adc_current_zero_tol >= (1u << in->adc_bits)))) {
        return FW_EINVAL;
    }
    fw->machine_own = *cfg->machine;
    fw->machine = &fw->machine_own;
    fw->cfg = *cfg;
    fw->cfg.machine = NULL;
    fw->cfg.ctrl_cfg = NULL;
    fw->enc_cpr = cfg->enc_cpr != 0u ? cfg->enc_cpr : in->encoder_counts_per_rev;
    fw->enc_offset = cfg->enc_offset;
    fw->enc_neg = cfg->enc_direction < 0 ? 0xFFFFFFFFu : 0u;
    const int rc = fw_setup_machine(fw, cfg, cfg->ctrl, cfg->ctrl_cfg);
    if (rc != FW_OK) {
        return rc;
    }
    /* Offsets accepted by the calibration: the back-end's expected code and
     * tolerance (its board data), else mid-scale +- 1/32 of full scale. */
    const uint16_t mid = (uint16_t)(1u << (in->adc_bits - 1u));
    const bool known = in->adc_current_zero_tol != 0u;
    fw->adc_zero = known ? in->adc_current_zero : mid;
    fw->adc_zero_tol = known ? in->adc_current_zero_tol : (uint16_t)(mid >> 4);
    fw->pwm_n8 = in->period_counts < (1u << 24) ? in->period_counts << 8 : 0u;
    /* floor(cmp_max 2^24 / N): its compare value round(d N / 2^24) <= cmp_max. */
    fw->duty_max = in->pwm_cmp_max == 0u
                       ? FX_ONE
                       : (q24_t)(((uint64_t)in->pwm_cmp_max << 24) / in->period_counts);
    fw->off_q8[0] = fw->off_q8[1] = fw->off_q8[2] = (int32_t)fw->adc_zero * 256;
    fw->calib_samples = cfg->calib_samples;
    memset(&fw->applied, 0, sizeof fw->applied);
    fw_state_init(&fw->sm);
    return FW_OK;
}

int fw_commission_start(fw_t *fw, const uint8_t *steps, uint8_t n, uint8_t *missing)
{
    if (fw == NULL || steps == NULL) {
        return FW_EINVAL;
    }
    if (fw_state(fw) != FW_STATE_READY || fw_cmd_pending(fw, FW_REQ_CM)) {
        return FW_EBUSY;
    }
    if (fw->cm_what != NULL) {
        return FW_ERANGE;
    }
    if (cm_prepare(&fw->cm, steps, n, missing) != CM_E_NONE) {
        return FW_ENOENT;
    }
    fw_request(fw, FW_REQ_CM); /* after fw->cm is set up (release) */
    return FW_OK;
}

void fw_commission_results(const fw_t *fw, cm_si_t *out)
{
    if (fw != NULL && out != NULL) {
        cm_results_si(&fw->cm, fw->enc_neg != 0u ? -1 : 1, (uint8_t)fw->params.pole_pairs,
                      1.0 / (double)fw->info.pwm_freq_hz, out);
    }
}

/* fw_commission_apply's rewrite (the interrupt held off). */
static int fw_commission_adopt(fw_t *fw)
{
    cm_si_t r;
    fw_commission_results(fw, &r);
    ctrl_machine_t m = fw->machine_own;
    if ((r.have & CM_HAVE_RS) != 0u) {
        m.rs_ohm = r.rs_ohm;
    }
    if ((r.have & CM_HAVE_LDQ) != 0u) {
        m.ld_h = r.ld_h;
        m.lq_h = r.lq_h;
    }
    if ((r.have & CM_HAVE_FLUX) != 0u) {
        m.psi_pm_wb = r.psi_wb;
    }
#if CM_MECH
    const double old_fric[2] = {fw->cfg.coulomb_nm, fw->cfg.viscous_nms};
#endif
    if (cm_si_has(&r, CM_HAVE_MECH)) {
        m.inertia_kgm2 = r.inertia_kgm2;
#if CM_MECH
        /* friction: a negative fit (noise about none) is none */
        fw->cfg.coulomb_nm = isfinite(r.coulomb_nm) && r.coulomb_nm > 0.0 ? r.coulomb_nm : 0.0;
        fw->cfg.viscous_nms =
            isfinite(r.friction_nms) && r.friction_nms > 0.0 ? r.friction_nms : 0.0;
#endif
    }
    const ctrl_machine_t old = fw->machine_own;
    const double old_torque_nm = fw->bases.torque_nm;
    const fx_angle_t old_off = fw->enc_offset;
    const uint32_t old_neg = fw->enc_neg;
    const bool enc = (r.have & CM_HAVE_ENC) != 0u;
    fw->machine_own = m;
    if (enc) {
        fw->enc_offset = fw->cm.res.enc_off;
        fw->enc_neg = r.enc_dir < 0 ? 0xFFFFFFFFu : 0u;
    }
    const int rc = fw_setup_machine(fw, &fw->cfg, fw->ctrl, NULL);
    if (rc != FW_OK) {
        /* Back to the configuration that worked before. */
        fw->machine_own = old;
#if CM_MECH
        fw->cfg.coulomb_nm = old_fric[0];
        fw->cfg.viscous_nms = old_fric[1];
#endif
        fw->enc_offset = old_off;
        fw->enc_neg = old_neg;
        (void)fw_setup_machine(fw, &fw->cfg, fw->ctrl, NULL);
        return rc;
    }
    cm_rebase(&fw->cm, &fw->bases, enc);
    /* The torque reference keeps its N m in the new torque base, clamped
     * to the new limit (the interrupt is held off: no fence needed). */
    const q24_t tref = ctrl_q24_from_double(ctrl_q24_to_double(fw->ml.torque_ref) * old_torque_nm /
                                            fw->bases.torque_nm);
    fw->ml.torque_ref = tref;
    fw->ml.torque_ref_lim = fx_clamp(tref, fw->torque_ref_min, fw->torque_ref_max);
    /* The encoder position restarts from the counter in the new direction. */
    fw->enc_primed = false;
    fw->enc_index_valid = false;
    fw->cm.apply = 0u;
    return FW_OK;
}

int fw_commission_apply(fw_t *fw)
{
    if (fw == NULL) {
        return FW_EINVAL;
    }
    if (fw_state(fw) != FW_STATE_READY || fw_gates_on_or_pending(fw)) {
        return FW_EBUSY; /* an arm taken next period would gate half-set data */
    }
    /* Everything below rewrites what the interrupt reads in every state
     * (conversion, protections, the encoder's tracking): with it held off. */
    hal_ctrl_hold(fw->hal, true);
    const int rc = fw_commission_adopt(fw);
    hal_ctrl_hold(fw->hal, false);
    return rc;
}

void fw_kept_read(const fw_t *fw, fw_kept_t *k)
{
    /* every field fw_commission_adopt writes beyond fw->machine_own */
    k->enc_offset = fw->enc_offset;
    k->enc_direction = fw->enc_neg != 0u ? -1 : 1;
#if CM_MECH
    k->coulomb_nm = fw->cfg.coulomb_nm;
    k->viscous_nms = fw->cfg.viscous_nms;
#endif
}

void fw_kept_config(const fw_kept_t *k, fw_config_t *c)
{
    c->enc_offset = k->enc_offset;
    c->enc_direction = k->enc_direction;
#if CM_MECH
    c->coulomb_nm = k->coulomb_nm;
    c->viscous_nms = k->viscous_nms;
#endif
}

void fw_in_force_read(const fw_t *fw, fw_in_force_t *f)
{
    f->cfg = fw->cfg;
    f->cfg.ctrl = fw->ctrl;
    memcpy(f->ctrl_cfg.bytes, fw->ctrl_cfg.bytes, CTRL_CFG_MAX);
}

bool fw_in_force_config(const fw_in_force_t *f, const ctrl_machine_t *m, const fw_kept_t *kept,
                        fw_config_t *c)
{
    if (f->cfg.ctrl == NULL) {
        return false;
    }
    *c = f->cfg;
    c->machine = m;
    c->ctrl_cfg = f->ctrl_cfg.bytes;
    fw_kept_config(kept, c);
    return true;
}

bool fw_commission_poll(fw_t *fw)
{
    if (fw == NULL || fw->cm.apply == 0u || fw_state(fw) != FW_STATE_READY) {
        return false;
    }
    fw->cm.apply = 0u;
    return fw_commission_apply(fw) == FW_OK;
}

#if CTRL_COGGING
/* The anti-cogging look-ahead (cogging_ff.h's lead): tau, the delay from the
 * position sampled at k to the torque that answers the reference formed from
 * it, derived from what the controller is (docs/anticogging.md has it
 * measured against each controller in the plant):
 *   FOC: 1.5 Ts + 1 / wc. The duties computed at k act over [k+1, k+2) (one
 *        period of computation, half a period of the PWM's zero-order
 *        hold); the current loop, Kp = L wc, Ki = R wc (pole cancelled), is
 *        a first-order closed loop of time constant 1 / wc (wc from Kp_q / Lq
 *        when Kp_q is set, else the tunable wc, else 2 pi fs / 20, as
 *        ctrl_foc_config.c).
 *   The predictive controllers of the torque (duty-ratio DTC, MPC,
 *        SVM-DTC): 2 Ts. From the state predicted for k+1 they choose the
 *        voltage of [k+1, k+2) that brings the torque to the reference at
 *        k+2: the torque reaches each reference two periods after the
 *        position it was formed from, along a ramp (no zero-order hold).
 *   The hysteresis controllers (the switching tables, HDTC, HP-DTC, FOC with
 *        hysteresis current control; fw_cog_hysteresis): 0. They switch as
 *        soon as the error leaves its band, most on the prediction for k+1,
 *        and keep the torque (current) inside a band around the reference:
 *        no loop lag to lead.
 * The speed it multiplies: the encoder's (a count per period at most at low
 * speed: 0 or 1 count at 30 r/min, 16384 counts, 10 kHz) averaged over
 * 1 / (2 pi FW_COG_SPEED_HZ) = 8 ms; at constant speed the average's delay
 * costs nothing, and it is tau (0.5 ms) times the speed's change in 8 ms
 * when the speed changes.
 * 0, or -1 when the lead does not fit (half a turn per rated speed). */
#define FW_COG_SPEED_HZ 20.0
static bool fw_cog_hysteresis(const char *name)
{
    static const char *const hyst[] = {"bst",  "mbst",      "ast",   "zst",     "fst",
                                       "hdtc", "hdtc_pred", "hpdtc", "foc_hyst"};
    for (size_t i = 0; i < sizeof hyst / sizeof hyst[0]; i++) {
        if (strcmp(name, hyst[i]) == 0) {
            return true;
        }
    }
    return false;
}

static int fw_cogging_lead(fw_t *fw)
{
    const double fs = (double)fw->params.fs_hz;
    double tau = 2.0 / fs;
    if (fw->ctrl != NULL && fw_cog_hysteresis(fw->ctrl->name)) {
        tau = 0.0;
    } else if (fw->ctrl != NULL && strcmp(fw->ctrl->name, "foc") == 0) {
        const ctrl_foc_cfg_t *c = (const ctrl_foc_cfg_t *)(const void *)fw->ctrl_cfg.bytes;
        double wc = c->wc > 0.0 ? c->wc : CTRL_TWO_PI * fs / 20.0;
        if (c->kp_q > 0.0 && fw->machine->lq_h > 0.0) {
            wc = c->kp_q / fw->machine->lq_h;
        }
        tau = 1.5 / fs + 1.0 / wc;
    }
    /* Q32 turns per pu electrical speed: tau w_base / (2 pi p) turns */
    const double lead =
        tau * fw->bases.w_rad_s / (CTRL_TWO_PI * (double)fw->params.pole_pairs) * 4294967296.0;
    const q24_t w_k = ctrl_q24_from_double(1.0 - ctrl_cfg_exp(-CTRL_TWO_PI * FW_COG_SPEED_HZ / fs));
    if (!(lead >= 0.0) || !(lead < 2147483647.0)) {
        (void)ctrl_cogging_set_lead(&fw->cog.map, 0, w_k);
        return -1;
    }
    return ctrl_cogging_set_lead(&fw->cog.map, (int32_t)llround(lead), w_k);
}
#endif

/* Initialise desc with cfg into the state block; keep both on success. */
static int fw_ctrl_install(fw_t *fw, const ctrl_desc_t *d, const unsigned char *cfg)
{
#if PMSM_LIVE_PARAMS
    /* A live change the interrupt has not taken yet is superseded (cfg holds
     * it): withdrawn before the state is written, so that the interrupt no
     * longer touches the state. */
    fw_request_withdraw(fw, FW_REQ_CTRL_TUNE);
#endif
    union {
        max_align_t align;
        unsigned char bytes[CTRL_STATE_MAX];
    } st;
    memset(&st, 0, sizeof st);
    memset(&fw->why, 0, sizeof fw->why);
    /* A controller that forms its currents from the torque (FOC) holds no
     * fixed flux reference: the field-weakening limit and its flux reference
     * are then those of MTPA (a limit formed at a flux the controller does
     * not hold would neither weaken its flux in time nor bound its torque). */
    const q24_t psi_ref_old = fw->params.psi_ref;
    fw->params.psi_ref = d->flux_free != 0u ? 0 : fw->psi_ref_cfg;
    const ctrl_setup_t setup = {fw->machine, &fw->bases, &fw->params, &fw->why};
    if (ctrl_init(d, st.bytes, cfg, &setup) != CTRL_OK) {
        fw->params.psi_ref = psi_ref_old;
        return FW_ECTRL;
    }
    d->reset(st.bytes);
    memcpy(fw->ctrl_state.bytes, st.bytes, sizeof st.bytes);
    memcpy(fw->ctrl_cfg.bytes, cfg, CTRL_CFG_MAX);
    fw->ctrl = d;
#if CTRL_COGGING
    (void)fw_cogging_lead(fw); /* fw_cogging_enable refuses a lead that does not fit */
#endif
    /* Skip the estimates the controller never reads (telemetry takes the
     * rotor-frame values and derives |psi_s| and the sector itself). */
    ctrl_estimator_set_outputs(&fw->est, CTRL_EST_ALL & ~(unsigned)d->est_unused);
    return FW_OK;
}

int fw_select_controller(fw_t *fw, const ctrl_desc_t *d, const void *cfg)
{
    if (fw == NULL || d == NULL || d->init == NULL || d->reset == NULL || d->step == NULL ||
        fw->machine == NULL) {
        return FW_EINVAL;
    }
    if (fw_gates_on_or_pending(fw)) {
        return FW_EBUSY; /* the interrupt may be stepping the state replaced here */
    }
    if (d->state_size > CTRL_STATE_MAX || d->cfg_size > CTRL_CFG_MAX) {
        return FW_ECTRL;
    }
#if CTRL_SL_HFI
    if (fw->cfg.hfi && !fw_hfi_controller_ok(d)) {
        /* named: "controller bst refused: ..." (ctrl_diag_format) */
        const ctrl_diag_t why = {CTRL_EINVAL,
                                 d->name,
                                 "controller",
                                 1.0,
                                 1.0,
                                 0.0,
                                 "the injection (hfi) is added to a modulated voltage: foc, "
                                 "m2ptfc or drr"};
        fw->why = why;
        return FW_ECTRL;
    }
#endif
    union {
        max_align_t align;
        unsigned char bytes[CTRL_CFG_MAX];
    } c;
    memset(&c, 0, sizeof c);
    if (cfg != NULL) {
        memcpy(c.bytes, cfg, d->cfg_size);
    } else if (d->cfg_default != NULL) {
        d->cfg_default(c.bytes, fw->machine);
    }
    return fw_ctrl_install(fw, d, c.bytes);
}

#if PMSM_LIVE_PARAMS
bool fw_tunable_is_live(const fw_t *fw, size_t index)
{
    const ctrl_desc_t *d = fw != NULL ? fw->ctrl : NULL;
    return d != NULL && d->retune != NULL && index < 32u && ((d->live >> index) & 1u) != 0u;
}
#endif

int fw_speed_retune(fw_t *fw, double bw_hz, double pm_deg, double kp, double ki)
{
    if (fw == NULL || fw->machine == NULL) {
        return FW_EINVAL;
    }
#if !PMSM_LIVE_PARAMS
    (void)bw_hz;
    (void)pm_deg;
    (void)kp;
    (void)ki;
    return FW_EBUSY;
#else
    if (fw_tune_pending(fw, FW_REQ_SPEED_TUNE)) {
        return FW_EBUSY;
    }
    /* In fw->cfg (the interrupt reads none of these), back on a refusal. */
    fw_config_t *c = &fw->cfg;
    const double old[4] = {c->speed_bw_hz, c->speed_pm_deg, c->speed_kp, c->speed_ki};
    c->speed_bw_hz = bw_hz;
    c->speed_pm_deg = pm_deg;
    c->speed_kp = kp;
    c->speed_ki = ki;
    fw_speed_info_t si = fw->speed_info;
    const int rc = fw_speed_gains(fw, c, &fw->speed_pi_next, &si);
    if (rc != FW_OK) {
        c->speed_bw_hz = old[0];
        c->speed_pm_deg = old[1];
        c->speed_kp = old[2];
        c->speed_ki = old[3];
        return rc;
    }
    fw->speed_info = si;
    fw_request(fw, FW_REQ_SPEED_TUNE); /* after the gains (a release fence) */
    return FW_OK;
#endif
}

#if CTRL_SL_HFI
/* "hfi.<field>" (hfi_config.h, ctrl_hfi_desc): the injection's settings in
 * fw_config_t.hfi_cfg and, with the injection on, the drive set up again
 * with them (the controller's tunables kept); refused, the previous ones stay
 * (and fw->why says why). */
static int fw_hfi_set(fw_t *fw, const char *name, double value)
{
    const ctrl_hfi_config_t old = fw->cfg.hfi_cfg;
    const int rc = ctrl_tunable_set(&ctrl_hfi_desc, &fw->cfg.hfi_cfg, name, value);
    if (rc != CTRL_OK) {
        return rc == CTRL_ENOENT ? FW_ENOENT : FW_EINVAL;
    }
    if (!fw->cfg.hfi) {
        return FW_OK; /* kept for when it is switched on */
    }
    union {
        max_align_t align;
        unsigned char bytes[CTRL_CFG_MAX];
    } c;
    memcpy(c.bytes, fw->ctrl_cfg.bytes, CTRL_CFG_MAX);
    /* fw_setup_machine rewrites what the interrupt reads in every state (as
     * fw_commission_apply): with it held off */
    hal_ctrl_hold(fw->hal, true);
    const int s = fw_setup_machine(fw, &fw->cfg, fw->ctrl, c.bytes);
    if (s != FW_OK) {
        const ctrl_diag_t why = fw->why;
        fw->cfg.hfi_cfg = old;
        (void)fw_setup_machine(fw, &fw->cfg, fw->ctrl, c.bytes);
        fw->why = why;
    }
    hal_ctrl_hold(fw->hal, false);
    return s;
}
#endif

int fw_tunable_set(fw_t *fw, const char *name, double value)
{
    if (fw == NULL || fw->ctrl == NULL || name == NULL) {
        return FW_EINVAL;
    }
    const ctrl_desc_t *d = fw->ctrl;
    /* With the gates on (or about to go on) only a live tunable, and not
     * while the previous live change waits for the interrupt. */
    const bool live = fw_gates_on_or_pending(fw);
#if CTRL_SL_HFI
    if (strncmp(name, "hfi.", 4u) == 0) { /* none live: the drive is set up again */
        return live ? FW_EBUSY : fw_hfi_set(fw, name, value);
    }
#endif
#if !PMSM_LIVE_PARAMS
    if (live) {
        return FW_EBUSY; /* as fw_select_controller */
    }
#else
    if (live) {
        size_t i = 0;
        while (i < d->n_tunables && strcmp(d->tunables[i].name, name) != 0) {
            i++;
        }
        if (i < d->n_tunables &&
            (!fw_tunable_is_live(fw, i) || fw_tune_pending(fw, FW_REQ_CTRL_TUNE))) {
            return FW_EBUSY;
        }
    }
#endif
    union {
        max_align_t align;
        unsigned char bytes[CTRL_CFG_MAX];
    } c;
    memcpy(c.bytes, fw->ctrl_cfg.bytes, CTRL_CFG_MAX);
    const int rc = ctrl_tunable_set(d, c.bytes, name, value);
    if (rc == CTRL_ENOENT) {
        return FW_ENOENT;
    }
    if (rc != CTRL_OK) {
        return FW_EINVAL;
    }
    if (!live) {
        return fw_ctrl_install(fw, d, c.bytes);
    }
#if !PMSM_LIVE_PARAMS
    return FW_EBUSY; /* not reached: no controller is live (CTRL_RETUNE) */
#else
    /* Live (ctrl_desc_t.retune): the state for the changed configuration made
     * here, the interrupt takes from it what the change sets at its next
     * period (fw_apply_commands). */
    memset(&fw->why, 0, sizeof fw->why);
    const ctrl_setup_t setup = {fw->machine, &fw->bases, &fw->params, &fw->why};
    if (ctrl_init(d, fw->ctrl_next.bytes, c.bytes, &setup) != CTRL_OK) {
        return FW_ECTRL;
    }
    memcpy(fw->ctrl_cfg.bytes, c.bytes, CTRL_CFG_MAX);
    fw_request(fw, FW_REQ_CTRL_TUNE); /* after the state (a release fence) */
    return FW_OK;
#endif
}

int fw_tunable_get(const fw_t *fw, const char *name, double *value)
{
    if (fw == NULL || fw->ctrl == NULL || name == NULL || value == NULL) {
        return FW_EINVAL;
    }
#if CTRL_SL_HFI
    if (strncmp(name, "hfi.", 4u) == 0) {
        const int h = ctrl_tunable_get(&ctrl_hfi_desc, &fw->cfg.hfi_cfg, name, value);
        return h == CTRL_OK ? FW_OK : (h == CTRL_ENOENT ? FW_ENOENT : FW_EINVAL);
    }
#endif
    const int rc = ctrl_tunable_get(fw->ctrl, fw->ctrl_cfg.bytes, name, value);
    return rc == CTRL_OK ? FW_OK : (rc == CTRL_ENOENT ? FW_ENOENT : FW_EINVAL);
}

void fw_set_torque_ref_nm(fw_t *fw, double nm)
{
    if (fw != NULL && isfinite(nm)) {
        fw_set_torque_ref(fw, ctrl_q24_from_double(nm / fw->bases.torque_nm));
    }
}

void fw_set_speed_ref_rpm(fw_t *fw, double rpm)
{
    if (fw != NULL && isfinite(rpm)) {
        /* the speed limit, as fw_set_torque_ref clamps the torque (the link
         * refuses a value outside it; the simulator warns) */
        const double lim = fw->speed_info.speed_ref_max_rpm;
        const double we = ctrl_rpm_to_elec(fmin(fmax(rpm, -lim), lim), fw->params.pole_pairs);
        fw_set_speed_ref(fw, ctrl_q24_from_double(we / fw->bases.w_rad_s));
    }
}

#if CTRL_COGGING
int fw_cogging_enable(fw_t *fw, bool on)
{
    if (fw == NULL) {
        return FW_EINVAL;
    }
    if (!on) {
        fw->cog_on = 0u;
        return FW_OK;
    }
    if (fw->cfg.sensorless) {
        return FW_EINVAL;
    }
    if (fw->cog.valid == 0u || fw->cog.cal_cpr != fw->enc_cpr) {
        return FW_ENOENT;
    }
    if (fw_cogging_lead(fw) != 0) {
        return FW_ERANGE;
    }
    fw->cog_on = 1u;
    return FW_OK;
}

int fw_cogging_load(fw_t *fw, const int16_t *table, uint32_t n)
{
    if (fw == NULL || table == NULL) {
        return FW_EINVAL;
    }
    if (n != CTRL_COG_N) {
        return FW_ERANGE;
    }
    if (fw_gates_on_or_pending(fw)) {
        return FW_EBUSY;
    }
    memmove(fw->cog.table, table, sizeof fw->cog.table); /* table may be fw->cog.table */
    fw->cog.cal_cpr = fw->enc_cpr;
    fw->cog.valid = 1u;
    return FW_OK;
}

const int16_t *fw_cogging_table(const fw_t *fw, uint32_t *n)
{
    if (fw == NULL || fw->cog.valid == 0u) {
        return NULL;
    }
    if (n != NULL) {
        *n = CTRL_COG_N;
    }
    return fw->cog.table;
}
#else
int fw_cogging_enable(fw_t *fw, bool on)
{
    (void)fw;
    return on ? FW_ENOENT : FW_OK;
}

int fw_cogging_load(fw_t *fw, const int16_t *table, uint32_t n)
{
    (void)fw;
    (void)table;
    (void)n;
    return FW_ENOENT;
}

const int16_t *fw_cogging_table(const fw_t *fw, uint32_t *n)
{
    (void)fw;
    (void)n;
    return NULL;
}
#endif
