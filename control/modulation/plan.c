/*
 * Period-average voltage of leg duties (plan.h).
 */
#include "plan.h"

void ctrl_legs_voltage(const ctrl_legs_t *legs, q24_t vdc, q24_t *v_alpha, q24_t *v_beta)
{
    /* The duties taken within [-2, 2) (one SSAT each): leg duties in [0, 1]
     * and the dead-time-corrected ones of ctrl_fobs_voltage (<= 1 + t_d)
     * alike. Then |2 d_a - d_b - d_c| <= 2^27 and |d_b - d_c| <= 2^26, times
     * a Q30 constant below 2^57: ctrl_legs_uab's values without its
     * saturation; the product with vdc saturates. */
    const int32_t lim = 2 * FX_ONE;
    const int32_t da = fx_clamp(legs->duty[0], -lim, lim - 1);
    const int32_t db = fx_clamp(legs->duty[1], -lim, lim - 1);
    const int32_t dc = fx_clamp(legs->duty[2], -lim, lim - 1);
    const q24_t ua = fx_round_nosat((int64_t)(2 * da - db - dc) * FX_Q30_1_3, 30u);
    const q24_t ub = fx_round_nosat((int64_t)(db - dc) * FX_Q30_INV_SQRT3, 30u);
    *v_alpha = fx_mul(vdc, ua);
    *v_beta = fx_mul(vdc, ub);
}
