/*
 * Machine state from the stator flux ((3.9) inverted, (3.6), (4.3), (4.5)) and
 * the one-step prediction (5.15)/(6.10)-(6.12), generalised to Ld != Lq in dq.
 */
#include "predict.h"

#include "transforms.h"
#include "vectors.h"

fx_angle_t ctrl_angle_step(const ctrl_params_t *p, q24_t omega_e)
{
    /* |omega| <= 2^31, omega_to_dangle < 2^31: product < 2^62. The increment
     * is taken modulo 2^32 (modulo one turn, which is what an angle needs):
     * the low 32 bits of the rounded shift, no signed conversion. */
    const uint64_t u = (uint64_t)((int64_t)omega_e * p->omega_to_dangle) + ((uint64_t)1 << 23);
    return (fx_angle_t)(u >> FX_QBITS);
}

/* The rotor-frame quantities of ctrl_mstate_from_flux_sc except |psi| and the
 * sector (shared by the two functions below). Park (3.7) and
 * its inverse written with fx_dot/fx_cross: d = c a + s b, q = c b - s a;
 * alpha = c d - s q, beta = s d + c q (each one rounding, saturated). */
static void mstate_from_flux_core(const ctrl_params_t *p, q24_t psi_alpha, q24_t psi_beta,
                                  fx_angle_t theta_e, q24_t sin_theta, q24_t cos_theta,
                                  ctrl_mstate_t *out)
{
    const q24_t psi_d = fx_dot(cos_theta, sin_theta, psi_alpha, psi_beta);
    const q24_t psi_q = fx_cross(cos_theta, sin_theta, psi_alpha, psi_beta);
    /* (3.9) inverted: i_d = (psi_d - psi_pm)/Ld, i_q = psi_q/Lq (reciprocals
     * precomputed; (6.12) for Ld = Lq). */
    const q24_t i_d = fx_mul(fx_sub(psi_d, p->psi_pm), p->inv_ld);
    const q24_t i_q = fx_mul(psi_q, p->inv_lq);
    out->psi_alpha = psi_alpha;
    out->psi_beta = psi_beta;
    out->psi_d = psi_d;
    out->psi_q = psi_q;
    out->i_d = i_d;
    out->i_q = i_q;
    out->i_alpha = fx_cross(cos_theta, sin_theta, i_q, i_d);
    out->i_beta = fx_dot(sin_theta, cos_theta, i_d, i_q);
    /* (3.10): Te = psi_d i_q - psi_q i_d (pu), rotation-invariant form of (3.6). */
    out->torque = fx_cross(psi_d, psi_q, i_d, i_q);
    out->theta_e = theta_e;
    out->sin_theta = sin_theta;
    out->cos_theta = cos_theta;
}

void ctrl_mstate_from_flux_sc(const ctrl_params_t *p, q24_t psi_alpha, q24_t psi_beta,
                              fx_angle_t theta_e, q24_t sin_theta, q24_t cos_theta,
                              ctrl_mstate_t *out)
{
    mstate_from_flux_core(p, psi_alpha, psi_beta, theta_e, sin_theta, cos_theta, out);
    out->psi_amp = fx_mag(psi_alpha, psi_beta);
    out->sector = ctrl_sector(psi_alpha, psi_beta);
}

void ctrl_mstate_from_flux_noamp(const ctrl_params_t *p, q24_t psi_alpha, q24_t psi_beta,
                                 fx_angle_t theta_e, q24_t sin_theta, q24_t cos_theta,
                                 ctrl_mstate_t *out)
{
    mstate_from_flux_core(p, psi_alpha, psi_beta, theta_e, sin_theta, cos_theta, out);
    out->psi_amp = 0;
    out->sector = ctrl_sector(psi_alpha, psi_beta);
}

void ctrl_mstate_from_flux(const ctrl_params_t *p, q24_t psi_alpha, q24_t psi_beta,
                           fx_angle_t theta_e, ctrl_mstate_t *out)
{
    q24_t s;
    q24_t c;
    fx_sincos(theta_e, &s, &c);
    ctrl_mstate_from_flux_sc(p, psi_alpha, psi_beta, theta_e, s, c, out);
}

void ctrl_predict_flux(const ctrl_params_t *p, const ctrl_mstate_t *now, q24_t v_alpha,
                       q24_t v_beta, q24_t *psi_alpha, q24_t *psi_beta)
{
    /* (5.15): psi + Ts v - Ts Rs i, both products in one rounding; psi 2^24
     * is a multiple of 2^24, so rounding the whole sum once equals psi plus
     * the rounded increment, saturated once. ctrl_params_init keeps Ts <= 1 pu
     * and Ts Rs <= 1 pu, so |Ts v| and |Ts Rs i| are < 2^55 and the sum < 2^57. */
    const int64_t da = (int64_t)p->ts * v_alpha - (int64_t)p->ts_rs * now->i_alpha;
    const int64_t db = (int64_t)p->ts * v_beta - (int64_t)p->ts_rs * now->i_beta;
    *psi_alpha = fx_round_sat((int64_t)now->psi_alpha * FX_ONE + da, FX_QBITS);
    *psi_beta = fx_round_sat((int64_t)now->psi_beta * FX_ONE + db, FX_QBITS);
}

void ctrl_predict(const ctrl_params_t *p, const ctrl_mstate_t *now, q24_t v_alpha, q24_t v_beta,
                  q24_t omega_e, ctrl_mstate_t *next)
{
    q24_t pa;
    q24_t pb;
    ctrl_predict_flux(p, now, v_alpha, v_beta, &pa, &pb);
    /* (6.12): rotor angle theta + omega Ts. */
    ctrl_mstate_from_flux(p, pa, pb, now->theta_e + ctrl_angle_step(p, omega_e), next);
}
