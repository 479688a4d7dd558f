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

void ctrl_mstate_from_current(const ctrl_params_t *p, q24_t i_alpha, q24_t i_beta,
                              fx_angle_t theta_e, q24_t sin_theta, q24_t cos_theta,
                              ctrl_mstate_t *out)
{
    q24_t i_d;
    q24_t i_q;
    ctrl_park(i_alpha, i_beta, sin_theta, cos_theta, &i_d, &i_q);
    /* (3.9): psi_d = Ld i_d + psi_pm, psi_q = Lq i_q. */
    const q24_t psi_d = fx_add(fx_mul(p->ld, i_d), p->psi_pm);
    const q24_t psi_q = fx_mul(p->lq, i_q);
    out->i_alpha = i_alpha;
    out->i_beta = i_beta;
    out->i_d = i_d;
    out->i_q = i_q;
    out->psi_d = psi_d;
    out->psi_q = psi_q;
    ctrl_inv_park(psi_d, psi_q, sin_theta, cos_theta, &out->psi_alpha, &out->psi_beta);
    out->torque = fx_cross(psi_d, psi_q, i_d, i_q); /* (3.10) */
    out->psi_amp = fx_mag(psi_d, psi_q);            /* (4.3), rotation-invariant */
    out->theta_e = theta_e;
    out->sin_theta = sin_theta;
    out->cos_theta = cos_theta;
    out->sector = ctrl_sector(out->psi_alpha, out->psi_beta);
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
    s->psi_amp = fx_mag(pa, pb);
    s->sector = ctrl_sector(pa, pb);
}

/* Signed angle difference in [-pi, pi) as an int32_t, without the
 * implementation-defined unsigned -> signed conversion. */
static int32_t angle_diff(fx_angle_t a, fx_angle_t b)
{
    const uint32_t d = a - b;
    return d < 0x80000000u ? (int32_t)d : -(int32_t)(~d) - 1;
}

void ctrl_estimator_update(ctrl_estimator_t *e, const ctrl_params_t *p, const ctrl_meas_t *m,
                           const ctrl_plan_t *applied, ctrl_estimate_t *est)
{
    q24_t i_alpha;
    q24_t i_beta;
    q24_t s;
    q24_t c;
    ctrl_clarke(m->i_a, m->i_b, &i_alpha, &i_beta);
    fx_sincos(m->theta_e, &s, &c);

    /* Speed: omega = dtheta / Ts (pu), then a first-order EMA kept in Q48 so
     * that it settles to the input exactly (no dead band). */
    if (e->primed != 0u) {
        const int32_t dth = angle_diff(m->theta_e, e->theta_prev);
        const q24_t raw =
            fx_sat32(fx_rshift64_round((int64_t)dth * p->dangle_to_omega, CTRL_DANGLE_SHIFT));
        const q24_t out = fx_sat32(fx_rshift64_round(e->omega_acc, FX_QBITS));
        const q24_t diff = fx_sub(raw, out);
        e->omega_acc += (int64_t)diff * p->speed_lpf_k; /* |.| < 2^55 */
    }
    const q24_t omega = fx_sat32(fx_rshift64_round(e->omega_acc, FX_QBITS));

    ctrl_mstate_from_current(p, i_alpha, i_beta, m->theta_e, s, c, &est->now);
    if (e->flux_source == CTRL_FLUX_VOLTAGE_MODEL) {
        ctrl_flux_vm_update(&e->vm, p, e->v_prev_alpha, e->v_prev_beta, i_alpha, i_beta,
                            est->now.psi_alpha, est->now.psi_beta);
        state_from_vm(e, &est->now);
    }

    q24_t va = 0;
    q24_t vb = 0;
    if (applied != 0) {
        ctrl_plan_voltage(applied, m->vdc, &va, &vb);
    }
    ctrl_predict(p, &est->now, va, vb, omega, &est->next);

    est->omega_e = omega;
    est->vdc = m->vdc;
    e->v_prev_alpha = va;
    e->v_prev_beta = vb;
    e->theta_prev = m->theta_e;
    e->primed = 1u;
}
