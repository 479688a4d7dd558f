/* PM-flux tracking: the observer's per-period gains -> N periods (configuration). */
#include "psi_track.h"

int ctrl_psi_track_setup(ctrl_psi_track_t *t, const ctrl_params_t *p)
{
    ctrl_fobs_t *const o = &t->obs;
    if (o->mode != CTRL_FOBS_ENCODER || p->speed_rated_e <= 0) {
        return CTRL_EINVAL;
    }
    /* At most a quarter turn (2^30) between two corrections at twice the
     * rated speed, the angle of one period from omega_to_dangle (not wrapped:
     * below 2^31 times 2^31, shifted). */
    const uint64_t step =
        ((uint64_t)(2u * (uint32_t)p->speed_rated_e) * (uint32_t)p->omega_to_dangle) >> FX_QBITS;
    uint32_t div =
        step >= ((uint64_t)1 << 30)
            ? 1u
            : (step == 0u ? CTRL_PSI_TRACK_DIV_MAX : ((uint32_t)1 << 30) / (uint32_t)step);
    if (div > CTRL_PSI_TRACK_DIV_MAX) {
        div = CTRL_PSI_TRACK_DIV_MAX;
    }
    /* N periods in one: 1 - (1 - w_c Ts)^N and 1 - (1 - (1 - exp(-Ts / tau)))^N
     * = 1 - exp(-N Ts / tau), the powers in Q24 (factors in [0, 1]: no
     * saturation; N roundings of half an LSB). */
    q24_t keep_c = FX_ONE;
    q24_t keep_e = FX_ONE;
    for (uint32_t k = 0u; k < div; k++) {
        keep_c = fx_mul_nosat(keep_c, FX_ONE - o->kenc_ts);
        keep_e = fx_mul_nosat(keep_e, FX_ONE - o->psi_k);
    }
    o->kenc_ts = FX_ONE - keep_c;
    t->psi_k_n = o->psi_k != 0 ? FX_ONE - keep_e : 0;
    /* the EMA's speed gate is the tracker's (the encoder's speed) */
    t->speed_min = o->psi_speed_min;
    o->psi_speed_min = 0;
    o->psi_k = 0;
    t->div = (uint8_t)div;
    t->duty_v = o->dt_frac == 0 && o->v_fwd == 0 ? 1u : 0u;
    ctrl_psi_track_reset(t);
    return CTRL_OK;
}
