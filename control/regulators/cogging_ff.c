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
    return 0;
}
