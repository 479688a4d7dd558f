/*
 * Period-average voltage of leg duties (plan.h).
 */
#include "plan.h"

void ctrl_legs_voltage(const ctrl_legs_t *legs, q24_t vdc, q24_t *v_alpha, q24_t *v_beta)
{
    /* alpha / Vdc = (2 d_a - d_b - d_c) / 3, beta / Vdc = (d_b - d_c) / sqrt(3):
     * the differences are exact in 64 bits (|.| < 2^33 for any int32_t duties),
     * times a Q30 constant < 2^30 (< 2^63), rounded once to Q24, then times Vdc. */
    const int64_t da = legs->duty[0];
    const int64_t db = legs->duty[1];
    const int64_t dc = legs->duty[2];
    *v_alpha = fx_mul(vdc, fx_round_sat((2 * da - db - dc) * FX_Q30_1_3, 30u));
    *v_beta = fx_mul(vdc, fx_round_sat((db - dc) * FX_Q30_INV_SQRT3, 30u));
}
