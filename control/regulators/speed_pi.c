/*
 * Speed PI with clamping anti-windup (outer loop of the thesis experiments).
 */
#include "speed_pi.h"

/* x / 2^n rounded; n == 0 (a zeroed, unconfigured struct) is a plain copy. */
static int64_t pi_shift(int64_t x, uint8_t n)
{
    return n > 0u ? fx_rshift64_round(x, n) : x;
}

void ctrl_speed_pi_reset(ctrl_speed_pi_t *pi, q24_t out)
{
    const q24_t o = fx_clamp(out, -pi->out_max, pi->out_max);
    pi->integ = (int64_t)o * ((int64_t)1 << pi->ki_shift);
}

q24_t ctrl_speed_pi_step(ctrl_speed_pi_t *pi, q24_t omega_ref, q24_t omega)
{
    const int64_t e = fx_sat32((int64_t)omega_ref - omega);
    /* |e| < 2^31 and gains < 2^31: products < 2^62. */
    const int64_t prop = pi_shift(e * pi->kp, pi->kp_shift);
    const int64_t lim = (int64_t)pi->out_max * ((int64_t)1 << pi->ki_shift);
    int64_t cand = pi->integ + e * pi->ki_ts; /* |integ| <= 2^61 (config): no overflow */
    cand = cand > lim ? lim : (cand < -lim ? -lim : cand);
    const int64_t u_cand = prop + pi_shift(cand, pi->ki_shift);
    /* Clamping: do not integrate further into saturation. */
    const int wind_up =
        (u_cand > pi->out_max && e > 0) || (u_cand < -(int64_t)pi->out_max && e < 0);
    if (!wind_up) {
        pi->integ = cand;
    }
    const int64_t u = prop + pi_shift(pi->integ, pi->ki_shift);
    return u > pi->out_max ? pi->out_max : (u < -(int64_t)pi->out_max ? -pi->out_max : (q24_t)u);
}

#if PMSM_LIVE_PARAMS
/* pi_shift for the retune: the shift out of line (fx_rshift64_round_call). */
static int64_t pi_shift_call(int64_t x, uint8_t n)
{
    return n > 0u ? fx_rshift64_round_call(x, n) : x;
}

FX_NOINLINE void ctrl_speed_pi_retune(ctrl_speed_pi_t *pi, const ctrl_speed_pi_t *to, q24_t e)
{
    /* The output for e under the old gains less the new gains' proportional
     * part: the new integrator's torque (Q24; |e kp| < 2^62; the read-out
     * rounds by half an LSB at most). */
    const int64_t u = pi_shift_call((int64_t)e * pi->kp, pi->kp_shift) +
                      pi_shift_call(pi->integ, pi->ki_shift) -
                      pi_shift_call((int64_t)e * to->kp, to->kp_shift);
    pi->kp = to->kp;
    pi->kp_shift = to->kp_shift;
    pi->ki_ts = to->ki_ts;
    pi->ki_shift = to->ki_shift;
    ctrl_speed_pi_reset(pi, fx_sat32(u)); /* within the output limit */
}
#endif
