/* Drive protections (criteria in protect.h). Integer-only: per period. */
#include "protect.h"

#include <stddef.h>

const char *fw_fault_name(uint32_t code)
{
    static const char *const names[FW_FAULT_COUNT] = {
        "none",          "overcurrent",  "hw_trip",  "dc_overvoltage", "dc_undervoltage",
        "encoder_stuck", "encoder_jump", "deadline", "watchdog",       "adc_calibration",
        "overspeed",
    };
    return code < (uint32_t)FW_FAULT_COUNT ? names[code] : "unknown";
}

void fw_protect_init(fw_protect_t *p, const fw_protect_cfg_t *cfg)
{
    if (p == NULL || cfg == NULL) {
        return;
    }
    p->cfg = *cfg;
    /* Constants of the unsigned compares (fw_protect_t). */
    const q24_t lim = cfg->i_max;
    p->i_fast = lim >= 0 && lim <= ((q24_t)1 << 30) ? 1u : 0u;
    p->i_off = p->i_fast != 0u ? (uint32_t)lim : (lim < 0 ? 1u : 0u);
    p->i_span = p->i_fast != 0u ? 2u * (uint32_t)lim : 0u;
    p->j_off = cfg->enc_jump_max >= 0 ? (uint32_t)cfg->enc_jump_max : 0u;
    p->j_span = 2u * p->j_off;
    p->deadline_lim = cfg->deadline_cycles != 0u ? cfg->deadline_cycles : UINT32_MAX;
    p->wdg_lim = cfg->wdg_periods != 0u ? cfg->wdg_periods : UINT32_MAX;
    fw_protect_reset(p);
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
    p->enc_move_still = 0u;
    p->enc_primed = 0u;
    p->wdg_count = 0u;
}

uint32_t fw_protect_current(const fw_protect_t *p, q24_t i_a, q24_t i_b)
{
    /* i_c = -(i_a + i_b): the third phase is checked from the other two. */
    const q24_t i_c = fx_neg(fx_add(i_a, i_b));
    const q24_t lim = p->cfg.i_max;
    if (fx_abs(i_a) > lim || fx_abs(i_b) > lim || fx_abs(i_c) > lim) {
        return FW_FAULT_OVERCURRENT;
    }
    return FW_FAULT_NONE;
}

uint32_t fw_protect_vdc(const fw_protect_t *p, q24_t vdc)
{
    return fw_protect_vdc_fast(p, vdc);
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
        p->enc_move_still = 0u;
        return FW_FAULT_NONE;
    }
    return fw_protect_encoder_check(p, count);
}

uint32_t fw_protect_encoder(fw_protect_t *p, uint32_t count)
{
    return fw_protect_encoder_fast(p, count);
}

uint32_t fw_protect_deadline(const fw_protect_t *p, uint32_t elapsed_cycles)
{
    return fw_protect_deadline_fast(p, elapsed_cycles);
}

uint32_t fw_protect_watchdog_tick(fw_protect_t *p)
{
    return fw_protect_watchdog_tick_fast(p);
}

void fw_protect_watchdog_kick(fw_protect_t *p)
{
    if (p != NULL) {
        p->wdg_count = 0u;
    }
}
