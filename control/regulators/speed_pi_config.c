/*
 * Speed PI: SI gains -> fixed point (configuration, floating point allowed).
 *
 * The controller works on electrical speed in pu (omega_pu * w_base = omega_e
 * in rad/s) and outputs torque in pu (T_base). A gain given in N*m per speed
 * unit u becomes  k_pu = k_SI * (w_base * f_u) / T_base  with f_u the size of
 * one electrical rad/s in unit u: 1/p (mechanical rad/s), 60/(2 pi p) (r/min),
 * 1 (electrical rad/s). The integral gain also gets Ts of the loop.
 */
#include <math.h>
#include <stddef.h>

#include "ctrl_cfg_math.h"
#include "ctrl_units.h"
#include "speed_pi.h"
#include "speed_pi_config.h"

/* Normalise a positive gain g to a mantissa in [2^30, 2^31) and a shift in
 * [1, max_shift]; a gain needing more than max_shift fractional bits keeps
 * max_shift (fewer significant bits; reported as ERANGE if it rounds to 0). */
static int gain_q(double g, unsigned max_shift, int32_t *mant, uint8_t *shift)
{
    if (g == 0.0) {
        *mant = 0;
        *shift = 1u;
        return CTRL_OK;
    }
    int s = 31 - ctrl_cfg_exponent(g);
    if (s < 1) {
        return CTRL_ERANGE; /* gain >= 2^30 pu: absurd */
    }
    if (s > (int)max_shift) {
        s = (int)max_shift;
    }
    double m = ctrl_cfg_ldexp(g, s);
    if (m > 2147483647.0) {
        m = 2147483647.0;
    }
    const long long r = ctrl_cfg_llround(m);
    if (r == 0) {
        return CTRL_ERANGE;
    }
    *mant = (int32_t)r;
    *shift = (uint8_t)s;
    return CTRL_OK;
}

/* Names a per-unit quantity the fixed point cannot take (why may be NULL). */
static int speed_pi_refuse(ctrl_diag_t *why, const char *quantity, double value, double min,
                           double max, const char *depends)
{
    if (why != NULL) {
        const ctrl_diag_t d = {CTRL_ERANGE, quantity, "pu", value, min, max, depends};
        *why = d;
    }
    return CTRL_ERANGE;
}

int ctrl_speed_pi_config(ctrl_speed_pi_t *pi, const ctrl_bases_t *bases, int pole_pairs, double kp,
                         double ki, ctrl_speed_unit_t unit, double out_limit_nm, uint32_t loop_hz)
{
    return ctrl_speed_pi_config_diag(pi, bases, pole_pairs, kp, ki, unit, out_limit_nm, loop_hz,
                                     NULL);
}

int ctrl_speed_pi_config_diag(ctrl_speed_pi_t *pi, const ctrl_bases_t *bases, int pole_pairs,
                              double kp, double ki, ctrl_speed_unit_t unit, double out_limit_nm,
                              uint32_t loop_hz, ctrl_diag_t *why)
{
    if (pi == NULL || bases == NULL || pole_pairs < 1 || loop_hz == 0u || !isfinite(kp) ||
        !isfinite(ki) || kp < 0.0 || ki < 0.0 || !isfinite(out_limit_nm) || out_limit_nm <= 0.0 ||
        !(bases->w_rad_s > 0.0) || !(bases->torque_nm > 0.0)) {
        return CTRL_EINVAL;
    }
    double f_u;
    switch (unit) {
    case CTRL_SPEED_UNIT_RAD_S_MECH:
        f_u = 1.0 / (double)pole_pairs;
        break;
    case CTRL_SPEED_UNIT_RPM:
        f_u = 60.0 / (CTRL_TWO_PI * (double)pole_pairs);
        break;
    case CTRL_SPEED_UNIT_RAD_S_ELEC:
        f_u = 1.0;
        break;
    default:
        return CTRL_EINVAL;
    }
    const double scale = bases->w_rad_s * f_u / bases->torque_nm;
    const double kp_pu = kp * scale;
    const double ki_ts_pu = ki * scale / (double)loop_hz;
    const double out_pu = out_limit_nm / bases->torque_nm;
    if (!(out_pu * 16777216.0 < 2147483647.0) || out_pu * 16777216.0 < 1.0) {
        return speed_pi_refuse(why, "speed-loop torque limit", out_pu, 0x1p-24, 128.0,
                               "speed_out_max_nm, torque base");
    }
    const q24_t out_max = (q24_t)ctrl_cfg_llround(out_pu * 16777216.0);
    /* integ <= out_max * 2^ki_shift must stay below 2^61 (no overflow of
     * integ + e * ki_ts, each term < 2^62). */
    unsigned bits = 0u;
    while (bits < 32u && ((uint32_t)out_max >> bits) != 0u) {
        bits++;
    }
    const unsigned ki_max_shift = 61u - bits;
    int32_t kp_m;
    int32_t ki_m;
    uint8_t kp_s;
    uint8_t ki_s;
    /* A gain rounds to 0 below 2^-(shift + 1) (gain_q); 2^30 pu and above is absurd. */
    if (gain_q(kp_pu, 62u, &kp_m, &kp_s) != CTRL_OK) {
        return speed_pi_refuse(why, "speed PI proportional gain", kp_pu, 0x1p-63, 0x1p30,
                               "speed_kp, or inertia_kgm2 and the speed-loop bandwidth");
    }
    if (gain_q(ki_ts_pu, ki_max_shift, &ki_m, &ki_s) != CTRL_OK) {
        return speed_pi_refuse(why, "speed PI integral gain x loop period", ki_ts_pu,
                               ctrl_cfg_ldexp(1.0, -(int)ki_max_shift - 1), 0x1p30,
                               "speed_ki, or inertia_kgm2 and the speed-loop bandwidth");
    }
    pi->kp = kp_m;
    pi->kp_shift = kp_s;
    pi->ki_ts = ki_m;
    pi->ki_shift = ki_s;
    pi->out_max = out_max;
    pi->integ = 0;
    return CTRL_OK;
}
