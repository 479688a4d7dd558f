/* Torque supervision (criterion in torque_follow.h). Integer-only. */
#include "torque_follow.h"

#include <stddef.h>

#include "ctrl_params.h"
#include "protect.h"

#define TF_SHIFT_MAX 15u

/* The window's end out of line: the board image's link-time optimisation
 * would inline it at its one call in the interrupt (torque_follow.h). */
#if defined(__GNUC__)
#define TF_NOINLINE __attribute__((noinline))
#else
#define TF_NOINLINE
#endif

int fw_torque_follow_config(fw_torque_follow_cfg_t *cfg, uint32_t rate_hz, q24_t torque_rated,
                            uint32_t fault_windows)
{
    if (cfg == NULL || rate_hz == 0u || torque_rated <= 0) {
        return CTRL_EINVAL;
    }
    /* the window of speed following: 50 ms, as a power of two above it */
    const uint32_t want = rate_hz / 20u;
    uint8_t sh = 1u;
    while (sh < TF_SHIFT_MAX && ((uint32_t)1 << sh) < want) {
        sh++;
    }
    cfg->shift = sh;
    cfg->tol_rated = fx_max((q24_t)(((int64_t)torque_rated + 25) / 50), 1); /* 2 %, rounded */
    cfg->fault_windows = fault_windows;
    return CTRL_OK;
}

void fw_torque_follow_reset(fw_torque_follow_t *s)
{
    s->sum_err = 0;
    s->sum_ref = 0;
    s->n = 0u;
    s->missed = 0u;
    s->warn = 0u;
}

void fw_torque_follow_init(fw_torque_follow_t *s, const fw_torque_follow_cfg_t *cfg)
{
    s->cfg = *cfg;
    fw_torque_follow_reset(s);
}

TF_NOINLINE uint32_t fw_torque_follow_window(fw_torque_follow_t *s)
{
    const int64_t e = s->sum_err < 0 ? -s->sum_err : s->sum_err;
    const int64_t floor = (int64_t)s->cfg.tol_rated << s->cfg.shift;
    const bool miss = e * 20 > s->sum_ref && e > floor; /* |e| <= 2^47: 20 |e| fits */
    s->sum_err = 0;
    s->sum_ref = 0;
    s->n = 0u;
    if (!miss) {
        s->missed = 0u;
        s->warn = 0u;
        return FW_FAULT_NONE;
    }
    s->warn = 1u;
    if (s->missed < UINT32_MAX) {
        s->missed++;
    }
    return s->cfg.fault_windows != 0u && s->missed >= s->cfg.fault_windows ? FW_FAULT_TORQUE_FOLLOW
                                                                           : FW_FAULT_NONE;
}
