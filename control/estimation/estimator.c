/*
 * Per-period estimator: current-model flux (3.4)/(3.9), torque (3.6), speed
 * from encoder differences, and the k+1 prediction (5.15)/(6.10)-(6.12).
 */
#include "estimator.h"

#include "plan.h"
#include "predict.h"
#include "transforms.h"
#include "vectors.h"

void ctrl_estimator_init(ctrl_estimator_t *e, const ctrl_params_t *p)
{
    (void)p; /* every parameter is read from p at each update */
    e->flux_source = CTRL_FLUX_CURRENT_MODEL;
    e->outputs = CTRL_EST_ALL;
    ctrl_flux_vm_init(&e->vm, CTRL_VM_CORR_NONE, 0);
    ctrl_estimator_reset(e);
}

void ctrl_estimator_reset(ctrl_estimator_t *e)
{
    e->theta_prev = 0u;
    e->omega_acc = 0;
    e->v_prev_alpha = 0;
    e->v_prev_beta = 0;
    e->primed = 0u;
    ctrl_flux_vm_init(&e->vm, e->vm.mode, e->vm.k_corr);
}

/* Current model (3.9) without |psi| and the sector. Park (3.7) and its inverse
 * with fx_dot/fx_cross (one rounding each, saturated): i_d = c a + s b,
 * i_q = c b - s a; psi_alpha = c psi_d - s psi_q, psi_beta = s psi_d + c psi_q. */
static void current_model(const ctrl_params_t *p, q24_t i_alpha, q24_t i_beta, fx_angle_t theta_e,
                          q24_t sin_theta, q24_t cos_theta, ctrl_mstate_t *out)
{
    const q24_t i_d = fx_dot(cos_theta, sin_theta, i_alpha, i_beta);
    const q24_t i_q = fx_cross(cos_theta, sin_theta, i_alpha, i_beta);
    /* (3.9): psi_d = Ld i_d + psi_pm, psi_q = Lq i_q. */
    const q24_t psi_d = fx_add(fx_mul(p->ld, i_d), p->psi_pm);
    const q24_t psi_q = fx_mul(p->lq, i_q);
    out->i_alpha = i_alpha;
    out->i_beta = i_beta;
    out->i_d = i_d;
    out->i_q = i_q;
    out->psi_d = psi_d;
    out->psi_q = psi_q;
    out->psi_alpha = fx_cross(cos_theta, sin_theta, psi_q, psi_d);
    out->psi_beta = fx_dot(sin_theta, cos_theta, psi_d, psi_q);
    out->torque = fx_cross(psi_d, psi_q, i_d, i_q); /* (3.10) */
    out->theta_e = theta_e;
    out->sin_theta = sin_theta;
    out->cos_theta = cos_theta;
}

void ctrl_mstate_from_current(const ctrl_params_t *p, q24_t i_alpha, q24_t i_beta,
                              fx_angle_t theta_e, q24_t sin_theta, q24_t cos_theta,
                              ctrl_mstate_t *out)
{
    current_model(p, i_alpha, i_beta, theta_e, sin_theta, cos_theta, out);
    out->psi_amp = fx_mag(out->psi_d, out->psi_q);            /* (4.3), rotation-invariant */
    out->sector = ctrl_sector(out->psi_alpha, out->psi_beta); /* (4.5) */
}

/* State with the voltage-model flux and the measured current. */
static void state_from_vm(const ctrl_estimator_t *e, ctrl_mstate_t *s)
{
    q24_t pa;
    q24_t pb;
    ctrl_flux_vm_get(&e->vm, &pa, &pb);
    s->psi_alpha = pa;
    s->psi_beta = pb;
    ctrl_park(pa, pb, s->sin_theta, s->cos_theta, &s->psi_d, &s->psi_q);
    s->torque = fx_cross(pa, pb, s->i_alpha, s->i_beta); /* (3.6) */
}

/* Signed angle difference in [-pi, pi) as an int32_t, without the
 * implementation-defined unsigned -> signed conversion. */
static int32_t angle_diff(fx_angle_t a, fx_angle_t b)
{
    return fx_u2i(a - b);
}

void ctrl_estimator_update(ctrl_estimator_t *e, const ctrl_params_t *p, const ctrl_meas_t *m,
                           const ctrl_legs_t *applied, ctrl_estimate_t *est)
{
    q24_t i_alpha;
    q24_t i_beta;
    q24_t s;
    q24_t c;
    ctrl_clarke(m->i_a, m->i_b, &i_alpha, &i_beta);
    fx_sincos(m->theta_e, &s, &c);

    /* Speed: omega = dtheta / Ts (pu), then a first-order EMA kept in Q48 so
     * that it settles to the input exactly (no dead band). |omega_acc| stays
     * below 2^55 (an average of values < 2^31 in Q24 with 24 guard bits). */
    if (e->primed != 0u) {
        const int32_t dth = angle_diff(m->theta_e, e->theta_prev);
        const q24_t raw = fx_round_sat((int64_t)dth * p->dangle_to_omega, CTRL_DANGLE_SHIFT);
        const q24_t out = fx_round_sat(e->omega_acc, FX_QBITS);
        const q24_t diff = fx_sub(raw, out);
        e->omega_acc += (int64_t)diff * p->speed_lpf_k; /* |.| < 2^55 */
    }
    const q24_t omega = fx_round_sat(e->omega_acc, FX_QBITS);

    ctrl_mstate_t *now = &est->now;
    current_model(p, i_alpha, i_beta, m->theta_e, s, c, now);
    if (e->flux_source == CTRL_FLUX_VOLTAGE_MODEL) {
        ctrl_flux_vm_update(&e->vm, p, e->v_prev_alpha, e->v_prev_beta, i_alpha, i_beta,
                            now->psi_alpha, now->psi_beta);
        state_from_vm(e, now);
    }
    /* (4.3) and (4.5) at k. Current model: the amplitude from the rotor-frame
     * flux (rotation invariant, one rounding less than from alpha/beta);
     * voltage model: from its alpha/beta flux. */
    const unsigned outputs = e->outputs;
    now->psi_amp = 0;
    if ((outputs & CTRL_EST_AMP_NOW) != 0u) {
        now->psi_amp = e->flux_source == CTRL_FLUX_VOLTAGE_MODEL
                           ? fx_mag(now->psi_alpha, now->psi_beta)
                           : fx_mag(now->psi_d, now->psi_q);
    }
    now->sector =
        (outputs & CTRL_EST_SECTOR_NOW) != 0u ? ctrl_sector(now->psi_alpha, now->psi_beta) : 0u;

    q24_t va = 0;
    q24_t vb = 0;
    if (applied != 0) {
        ctrl_legs_voltage(applied, m->vdc, &va, &vb);
    }
    /* Prediction (5.15)/(6.10)-(6.12): flux, angle theta + omega Ts, state. */
    q24_t pa;
    q24_t pb;
    ctrl_predict_flux(p, now, va, vb, &pa, &pb);
    const fx_angle_t th1 = m->theta_e + ctrl_angle_step(p, omega);
    q24_t s1;
    q24_t c1;
    fx_sincos(th1, &s1, &c1);
    ctrl_mstate_from_flux_noamp(p, pa, pb, th1, s1, c1, &est->next);
    if ((outputs & CTRL_EST_AMP_NEXT) != 0u) {
        est->next.psi_amp = fx_mag(pa, pb);
    }

    est->omega_e = omega;
    est->vdc = m->vdc;
    e->v_prev_alpha = va;
    e->v_prev_beta = vb;
    e->theta_prev = m->theta_e;
    e->primed = 1u;
}
