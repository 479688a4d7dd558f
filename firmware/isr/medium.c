/* The medium-rate task (pipeline.h; the two rates: docs/architecture.md).
 * Integer-only; runs once in mid_div PWM periods (and at period 0 of the
 * PM-flux tracker's N), after the interrupt that triggered it and before the
 * next one, on that interrupt's inputs. */
#include "pipeline.h"

#include <stdatomic.h>

/* The speed loop of one run: the PI on the speed error, its output clamped
 * to the configured torque limit; the speed-following protection on it. */
static q24_t fw_mid_speed(fw_t *fw, const fw_mid_in_t *in, uint8_t *fault)
{
    if (in->bump != 0u) {
        /* sensorless handover: from the torque it takes over */
        ctrl_speed_pi_reset(&fw->speed_pi, in->bump_torque);
    } else if (fw->mid_mode != (uint8_t)FW_REF_SPEED) {
        /* from torque mode: from the torque reference in force (bumpless) */
        ctrl_speed_pi_reset(&fw->speed_pi, in->torque_now);
    }
    /* Anti-windup against the torque limit of the last run (field
     * weakening) as well as the configured one: the integrator stays within
     * what the drive can deliver, so leaving the limit does not overshoot. */
    fw->speed_pi.out_max = fx_max(fx_min(fw->torque_ref_max, fw->torque_max), 1);
    const q24_t t = fx_clamp(ctrl_speed_pi_step(&fw->speed_pi, in->speed_ref, in->omega_e),
                             fw->torque_ref_min, fw->torque_ref_max);
    *fault = (uint8_t)fw_protect_speed_follow(&fw->prot, in->speed_ref, in->omega_e, t,
                                              fw->speed_pi.out_max);
    return t;
}

/* The PM-flux tracker's correction and EMA (psi_track.h) on the interrupt's
 * inputs of period 0 of its N; its estimate - which it only moves where the
 * voltage model is reliable - once it has left the 2 % band around the
 * configured value, into the parameters every consumer reads (the interrupt
 * takes them with the flux's step at its next period): 1/psi_pm by a Newton
 * step (y (2 - psi y)), the SPMSM's MTPA slope Lq/psi_pm. */
static void fw_mid_psi(fw_t *fw, const ctrl_psi_track_in_t *in, fw_mid_out_t *out)
{
    const ctrl_params_t *const p = &fw->params;
    out->psi_new = 0u;
    if (!ctrl_psi_track_correct(&fw->psi_track, p, in, out->psi_delta)) {
        return; /* no new estimate */
    }
    const q24_t psi = ctrl_fobs_psi_pm(&fw->psi_track.obs);
    if (!fw->psi_engaged) {
        if (fx_abs(fx_sub(psi, fw->psi_pm_cfg)) <= fw->psi_band) {
            return; /* agrees with the configured value: nothing changes */
        }
        fw->psi_engaged = true;
    }
    if (psi > 0 && psi != p->psi_pm) {
        out->psi_pm = psi;
        out->inv_psi_pm = fx_mul(p->inv_psi_pm, fx_sub(2 * FX_ONE, fx_mul(psi, p->inv_psi_pm)));
        out->mtpa_k = fx_mul(p->lq, out->inv_psi_pm);
        out->psi_new = 1u;
    }
}

void fw_medium(fw_t *fw)
{
    if (fw == NULL || fw->mid_done == fw->mid_req) {
        return; /* nothing requested */
    }
    atomic_signal_fence(memory_order_acquire); /* the slot after its count */
    const uint32_t done = fw->mid_done + 1u;
    const fw_mid_in_t *const in = &fw->mid_in[done & 1u];
    fw_mid_out_t *const out = &fw->mid_out[done & 1u];
    if (in->run == 0u) {
        /* the tracker's run alone: the last run's outputs stay in force */
        *out = fw->mid_out[fw->mid_done & 1u];
        out->fault = FW_FAULT_NONE;
    }
    if (in->track != 0u) {
        fw_mid_psi(fw, &in->psi, out);
    }
    if (in->run == 0u) {
        atomic_signal_fence(memory_order_release); /* the slot before its count */
        fw->mid_done = done;
        return;
    }
    if (in->reset != 0u) {
        ctrl_speed_pi_reset(&fw->speed_pi, 0);
        ctrl_fieldweak_reset(&fw->fieldweak);
        fw->torque_max = fw->torque_ref_max;
        fw->mid_mode = in->ref_mode;
    }
#if PMSM_LIVE_PARAMS
    if (in->retune != 0u) {
        /* a live change of the speed PI's gains (fw_apply_tune), bumpless
         * from this run's error (speed_pi.h), here between two steps */
        ctrl_speed_pi_retune(&fw->speed_pi, &in->retune_pi,
                             fx_sat32((int64_t)in->speed_ref - in->omega_e));
    }
#endif
    out->fault = FW_FAULT_NONE;
    /* The speed loop runs in speed mode unless the sensorless start holds it;
     * otherwise its output follows the torque reference (a later switch to
     * speed mode starts from there). */
    q24_t t_req = in->tref;
    if (in->ref_mode == (uint8_t)FW_REF_SPEED && in->hold == 0u) {
        t_req = fw_mid_speed(fw, in, &out->fault);
        out->speed_tref = t_req;
    } else {
        out->speed_tref = in->torque_now;
    }
    fw->mid_mode = in->hold == 0u ? in->ref_mode : (uint8_t)FW_REF_TORQUE;
    /* Field weakening on the DC link's mean over the run's periods (the
     * filter's coefficient is per run, pipeline_config.c); 0 <= sum < n 2^31. */
    const uint32_t n = in->n != 0u ? in->n : 1u;
    const q24_t vdc = (q24_t)((in->vdc_sum + (int64_t)(n / 2u)) / (int64_t)n);
    /* ctrl_fieldweak_step_lazy without its inline shortcut (the same outputs,
     * field_weak.h; flash matters more than time here) */
    q24_t w = in->omega_e;
#if CTRL_SL_HFI
    if (fx_abs(w) < fw->hfi_w_still) {
        /* the injection's speed estimate at standstill scatters about 0: a
         * torque against its sign is not braking (the braking margin of
         * field_weak.h is for a rotor that turns away from a standing flux) */
        w = 0;
    }
#endif
    ctrl_fieldweak_out_t lim;
    ctrl_fieldweak_limits_lazy(&fw->fieldweak, &fw->params,
                               ctrl_fieldweak_vdc_filter(&fw->fieldweak, vdc), w, t_req, &lim);
    fw->torque_max = lim.torque_max;
    out->torque_max = lim.torque_max;
    out->psi_ref = lim.psi_ref;
    out->limit = lim.limit;
    out->weakening = lim.weakening;
    if (in->first != 0u) {
        fw_mid_first_step(fw, in, out); /* before the run counts as ended */
    }
    /* the slot before its count: the interrupt may preempt the task here */
    atomic_signal_fence(memory_order_release);
    fw->mid_done = done;
}
