/* Drive protections (criteria and the inline checks in protect.h): names,
 * set-up and the rare encoder paths. Integer-only. */
#include "protect.h"

#include <stddef.h>
#include <stdint.h>

const char *fw_fault_name(uint32_t code)
{
    static const char *const names[FW_FAULT_COUNT] = {
        "none",          "overcurrent",  "hw_trip",      "dc_overvoltage", "dc_undervoltage",
        "encoder_stuck", "encoder_jump", "deadline",     "watchdog",       "adc_calibration",
        "overspeed",     "commission",   "speed_follow", "torque_follow",  "sl_start",
    };
    return code < (uint32_t)FW_FAULT_COUNT ? names[code] : "unknown";
}

int fw_protect_init(fw_protect_t *p, const fw_protect_cfg_t *cfg)
{
    if (p == NULL || cfg == NULL || cfg->i_max < 0 || cfg->i_max > FW_PROTECT_I_MAX_LIM) {
        return CTRL_EINVAL;
    }
    p->cfg = *cfg;
    /* Constants of the unsigned compares (fw_protect_t). */
    p->i_off = (uint32_t)cfg->i_max;
    p->i_span = 2u * (uint32_t)cfg->i_max;
    p->j_off = cfg->enc_jump_max >= 0 ? (uint32_t)cfg->enc_jump_max : 0u;
    p->j_span = 2u * p->j_off;
    p->deadline_lim = cfg->deadline_cycles != 0u ? cfg->deadline_cycles : UINT32_MAX;
    p->wdg_lim = cfg->wdg_periods != 0u ? cfg->wdg_periods : UINT32_MAX;
    fw_protect_reset(p);
    return CTRL_OK;
}

void fw_protect_reset(fw_protect_t *p)
{
    if (p == NULL) {
        return;
    }
    p->enc_last = 0u;
    p->enc_last_delta = 0;
    p->enc_still = 0u;
    p->enc_move_delta = 0;
    p->enc_move_dist = 0u;
    p->enc_move_still = 0u;
    p->enc_primed = 0u;
    p->follow_ref = 0;
    p->follow_min = INT32_MAX;
    p->follow_count = 0u;
}

uint32_t fw_protect_encoder_prime(fw_protect_t *p, uint32_t count)
{
    if (p->enc_primed == 0u) {
        p->enc_last = count;
        p->enc_primed = 1u;
        return FW_FAULT_NONE;
    }
    if (p->enc_primed == 1u) {
        /* First difference: nothing to compare the rate with yet (rate 0). */
        p->enc_last_delta = fx_u2i(count - p->enc_last);
        p->enc_last = count;
        p->enc_primed = p->cfg.enc_jump_max >= 0 ? 2u : 3u;
        p->enc_move_delta = 0;
        p->enc_move_dist = 0u;
        p->enc_move_still = 0u;
        return FW_FAULT_NONE;
    }
    return fw_protect_encoder_check(p, count);
}

/* Speed following (criterion in protect.h). */
uint32_t fw_protect_speed_follow(fw_protect_t *p, q24_t speed_ref, q24_t omega, q24_t t,
                                 q24_t t_max)
{
    const q24_t e = fx_sub(speed_ref, omega);
    const int toward = e > 0 ? t >= t_max : (e < 0 && t <= fx_neg(t_max));
    if (!toward || speed_ref != p->follow_ref) {
        p->follow_ref = speed_ref;
        p->follow_min = INT32_MAX; /* the next saturated period sets it */
        p->follow_count = 0u;
        return FW_FAULT_NONE;
    }
    const q24_t a = fx_abs(e);
    p->follow_min = fx_min(p->follow_min, a);
    /* 0 <= follow_min <= a: the difference fits; band = omega_max / 16 */
    p->follow_count = a - p->follow_min > (p->cfg.omega_max >> 4) ? p->follow_count + 1u : 0u;
    return p->follow_count > p->cfg.follow_periods ? FW_FAULT_SPEED_FOLLOW : FW_FAULT_NONE;
}
