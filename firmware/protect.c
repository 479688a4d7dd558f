/* Drive protections (criteria in protect.h). Integer-only: per period. */
#include "protect.h"

#include <stddef.h>

const char *fw_fault_name(uint32_t code)
{
    static const char *const names[FW_FAULT_COUNT] = {
        "none",          "overcurrent",  "hw_trip",  "dc_overvoltage", "dc_undervoltage",
        "encoder_stuck", "encoder_jump", "deadline", "watchdog",       "adc_calibration",
    };
    return code < (uint32_t)FW_FAULT_COUNT ? names[code] : "unknown";
}

void fw_protect_init(fw_protect_t *p, const fw_protect_cfg_t *cfg)
{
    if (p == NULL || cfg == NULL) {
        return;
    }
    p->cfg = *cfg;
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
    p->enc_rate_q16 = 0;
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
    if (vdc > p->cfg.vdc_max) {
        return FW_FAULT_DC_OVERVOLT;
    }
    if (vdc < p->cfg.vdc_min) {
        return FW_FAULT_DC_UNDERVOLT;
    }
    return FW_FAULT_NONE;
}

uint32_t fw_protect_encoder(fw_protect_t *p, uint32_t count)
{
    if (p->enc_primed == 0u) {
        p->enc_last = count;
        p->enc_primed = 1u;
        return FW_FAULT_NONE;
    }
    /* Modulo-2^32 difference read as signed: well defined via the unsigned
     * subtraction, then a range-checked conversion. */
    const uint32_t du = count - p->enc_last;
    const int32_t delta = du <= (uint32_t)INT32_MAX ? (int32_t)du : -(int32_t)(UINT32_MAX - du) - 1;
    p->enc_last = count;

    uint32_t fault = FW_FAULT_NONE;
    if (p->enc_primed == 1u) {
        /* First difference: nothing to compare the rate with yet. */
        p->enc_primed = 2u;
        p->enc_last_delta = delta;
        p->enc_rate_q16 = 0;
        return FW_FAULT_NONE;
    }
    if (delta != 0) {
        const int64_t dd = (int64_t)delta - p->enc_last_delta;
        if (dd > p->cfg.enc_jump_max || dd < -(int64_t)p->cfg.enc_jump_max) {
            fault = FW_FAULT_ENC_JUMP;
        }
        /* Rate at this move: counts over the periods it took (Q16.16). */
        const int64_t mag = delta < 0 ? -(int64_t)delta : (int64_t)delta;
        /* mag < 2^15: the Q16.16 rate fits 32 bits, a 32-bit UDIV (no
         * 64-bit division, __aeabi_ldivmod, in the interrupt). */
        const int64_t rate = mag < 32768 ? (int64_t)(((uint32_t)mag << 16) / (p->enc_still + 1u))
                                         : mag * 65536 / (int64_t)(p->enc_still + 1u);
        p->enc_rate_q16 = rate > INT32_MAX ? INT32_MAX : (int32_t)rate;
        p->enc_still = 0u;
    } else {
        if (p->enc_still < UINT32_MAX) {
            p->enc_still++;
        }
        if (p->enc_still >= p->cfg.enc_stuck_periods &&
            p->enc_rate_q16 >= p->cfg.enc_rate_min_q16) {
            fault = FW_FAULT_ENC_STUCK;
        }
    }
    p->enc_last_delta = delta;
    return fault;
}

uint32_t fw_protect_deadline(const fw_protect_t *p, uint32_t elapsed_cycles)
{
    if (p->cfg.deadline_cycles != 0u && elapsed_cycles > p->cfg.deadline_cycles) {
        return FW_FAULT_DEADLINE;
    }
    return FW_FAULT_NONE;
}

uint32_t fw_protect_watchdog_tick(fw_protect_t *p)
{
    if (p->wdg_count < UINT32_MAX) {
        p->wdg_count++;
    }
    if (p->cfg.wdg_periods != 0u && p->wdg_count > p->cfg.wdg_periods) {
        return FW_FAULT_WATCHDOG;
    }
    return FW_FAULT_NONE;
}

void fw_protect_watchdog_kick(fw_protect_t *p)
{
    if (p != NULL) {
        p->wdg_count = 0u;
    }
}
