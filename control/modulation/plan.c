/*
 * Period-average voltage of leg duties (plan.h).
 */
#include "plan.h"

void ctrl_legs_voltage(const ctrl_legs_t *legs, q24_t vdc, q24_t *v_alpha, q24_t *v_beta)
{
    q24_t ua;
    q24_t ub;
    ctrl_legs_uab(legs, &ua, &ub);
    *v_alpha = fx_mul(vdc, ua);
    *v_beta = fx_mul(vdc, ub);
}
