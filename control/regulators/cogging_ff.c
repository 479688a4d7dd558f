/* Anti-cogging feed-forward: configuration (cogging_ff.h). Integer-only. */
#include "cogging_ff.h"

#include <stddef.h>

int ctrl_cogging_init(ctrl_cogging_t *c, const int16_t *table, uint32_t n_log2, uint32_t cpr,
                      q24_t torque_rated)
{
    if (c == NULL || table == NULL || n_log2 < CTRL_COG_N_LOG2_MIN ||
        n_log2 > CTRL_COG_N_LOG2_MAX || cpr < 2u || cpr > 0x80000000u || torque_rated <= 0) {
        return -1;
    }
    c->table = table;
    c->n_log2 = n_log2;
    c->cpr = cpr;
    /* round(2^48 / cpr) */
    c->pos_q48 = (((uint64_t)1 << 48) + cpr / 2u) / cpr;
    c->torque_rated = torque_rated;
    c->lead = 0;
    c->w_k = FX_ONE;
    ctrl_cogging_restart(c);
    return 0;
}

int ctrl_cogging_set_lead(ctrl_cogging_t *c, int32_t lead, int32_t w_k)
{
    if (c == NULL || lead < 0 || w_k <= 0 || w_k > FX_ONE) {
        return -1;
    }
    c->lead = lead;
    c->w_k = w_k;
    ctrl_cogging_restart(c);
    return 0;
}
