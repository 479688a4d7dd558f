/*
 * Test fixture: machine states and estimates built the direct way (stator
 * frame, one table sine/cosine per angle), as inputs for controller tests and
 * as the slow oracle of the estimator's rotor-frame arithmetic
 * (estimator.h). Not part of the control core.
 *
 *   fixture_state_from_flux     every ctrl_mstate_t field from a stator flux
 *                               at a rotor angle: (3.9) inverted, (3.10),
 *                               (4.3), (4.5)
 *   fixture_state_from_current  the same from a stator current, (3.9)
 *   fixture_state_dq            the same from a rotor-frame current
 *   fixture_predict_dq          (5.15)/(6.10)-(6.12) in the rotor frame
 *   fixture_predict             discrete machine, (5.15)/(6.10)-(6.12):
 *                               psi += Ts (v - Rs i), theta += omega Ts
 *   fixture_rotation            the estimate's rotation over a period from its speed
 *   fixture_estimate            a ctrl_estimate_t with now = next = a state,
 *                               speed, DC link and the rotation over a period
 */
#ifndef TESTS_CORE_EST_FIXTURE_H
#define TESTS_CORE_EST_FIXTURE_H

#include <string.h>

#include "angle_source.h"
#include "ctrl_params.h"
#include "ctrl_types.h"
#include "fx.h"
#include "transforms.h"
#include "vectors.h"

/* x^2 + y^2 exact (Q48 for Q24 inputs), ctrl_mstate_t.psi_amp_sq */
static inline uint64_t fixture_amp_sq(q24_t x, q24_t y)
{
    return (uint64_t)((int64_t)x * x) + (uint64_t)((int64_t)y * y);
}

static inline void fixture_state_from_flux(const ctrl_params_t *p, q24_t pa, q24_t pb,
                                           fx_angle_t th, ctrl_mstate_t *o)
{
    q24_t s;
    q24_t c;
    fx_sincos(th, &s, &c);
    memset(o, 0, sizeof *o);
    o->psi_alpha = pa;
    o->psi_beta = pb;
    ctrl_park(pa, pb, s, c, &o->psi_d, &o->psi_q);
    o->i_d = fx_mul(fx_sub(o->psi_d, p->psi_pm), p->inv_ld);
    o->i_q = fx_mul(o->psi_q, p->inv_lq);
    ctrl_inv_park(o->i_d, o->i_q, s, c, &o->i_alpha, &o->i_beta);
    o->torque = fx_cross(o->psi_d, o->psi_q, o->i_d, o->i_q);
    o->psi_amp = fx_mag(pa, pb);
    o->psi_amp_sq = fixture_amp_sq(pa, pb);
    o->sector = ctrl_sector(pa, pb);
    o->theta_e = th;
    o->sin_theta = s;
    o->cos_theta = c;
}

static inline void fixture_state_from_current(const ctrl_params_t *p, q24_t ia, q24_t ib,
                                              fx_angle_t th, ctrl_mstate_t *o)
{
    q24_t s;
    q24_t c;
    fx_sincos(th, &s, &c);
    memset(o, 0, sizeof *o);
    o->i_alpha = ia;
    o->i_beta = ib;
    ctrl_park(ia, ib, s, c, &o->i_d, &o->i_q);
    o->psi_d = fx_add(fx_mul(p->ld, o->i_d), p->psi_pm);
    o->psi_q = fx_mul(p->lq, o->i_q);
    ctrl_inv_park(o->psi_d, o->psi_q, s, c, &o->psi_alpha, &o->psi_beta);
    o->torque = fx_cross(o->psi_d, o->psi_q, o->i_d, o->i_q);
    o->psi_amp = fx_mag(o->psi_d, o->psi_q);
    o->psi_amp_sq = fixture_amp_sq(o->psi_d, o->psi_q);
    o->sector = ctrl_sector(o->psi_alpha, o->psi_beta);
    o->theta_e = th;
    o->sin_theta = s;
    o->cos_theta = c;
}

/* The estimator's form of a state: rotor-frame current (i_d, i_q) at rotor
 * angle th, (3.9) and (3.10) in dq, the stator-frame values by the inverse
 * Park with the table sine/cosine at th. */
static inline void fixture_state_dq(const ctrl_params_t *p, q24_t i_d, q24_t i_q, fx_angle_t th,
                                    ctrl_mstate_t *o)
{
    q24_t s;
    q24_t c;
    fx_sincos(th, &s, &c);
    memset(o, 0, sizeof *o);
    o->i_d = i_d;
    o->i_q = i_q;
    o->psi_d = fx_add(fx_mul(p->ld, i_d), p->psi_pm);
    o->psi_q = fx_mul(p->lq, i_q);
    ctrl_inv_park(o->psi_d, o->psi_q, s, c, &o->psi_alpha, &o->psi_beta);
    ctrl_inv_park(i_d, i_q, s, c, &o->i_alpha, &o->i_beta);
    o->torque = fx_cross(o->psi_d, o->psi_q, i_d, i_q);
    o->psi_amp = fx_mag(o->psi_d, o->psi_q);
    o->psi_amp_sq = fixture_amp_sq(o->psi_d, o->psi_q);
    o->sector = ctrl_sector(o->psi_alpha, o->psi_beta);
    o->theta_e = th;
    o->sin_theta = s;
    o->cos_theta = c;
}

/* (5.15)/(6.10)-(6.12) in the rotor frame, written out with the transforms
 * (the estimator's order of operations, not its code): the stator-frame
 * voltage (va, vb) turned into the frame at now->theta_e (table), psi' =
 * psi + Ts v - Ts Rs i, the frame turned by omega Ts (fx_rot_q30), then
 * (3.9) inverted and (3.10); stator-frame values at theta(k+1) (table). */
static inline void fixture_predict_dq(const ctrl_params_t *p, const ctrl_mstate_t *now, q24_t va,
                                      q24_t vb, q24_t omega, ctrl_mstate_t *next)
{
    q24_t s;
    q24_t c;
    fx_sincos(now->theta_e, &s, &c);
    q24_t vd;
    q24_t vq;
    ctrl_park(va, vb, s, c, &vd, &vq);
    const q24_t hd = fx_round_sat((int64_t)now->psi_d * FX_ONE + (int64_t)p->ts * vd -
                                      (int64_t)p->ts_rs * now->i_d,
                                  FX_QBITS);
    const q24_t hq = fx_round_sat((int64_t)now->psi_q * FX_ONE + (int64_t)p->ts * vq -
                                      (int64_t)p->ts_rs * now->i_q,
                                  FX_QBITS);
    const int32_t dth = fx_u2i(ctrl_angle_step(p, omega));
    int32_t rc;
    int32_t rs;
    fx_rot_q30(dth, &rc, &rs);
    q24_t pd;
    q24_t pq;
    fx_rotate(hd, hq, rc, -rs, &pd, &pq);
    const fx_angle_t th1 = now->theta_e + (fx_angle_t)dth;
    q24_t s1;
    q24_t c1;
    fx_sincos(th1, &s1, &c1);
    memset(next, 0, sizeof *next);
    next->psi_d = pd;
    next->psi_q = pq;
    next->i_d = fx_mul(fx_sub(pd, p->psi_pm), p->inv_ld);
    next->i_q = fx_mul(pq, p->inv_lq);
    next->torque = fx_cross(pd, pq, next->i_d, next->i_q);
    ctrl_inv_park(pd, pq, s1, c1, &next->psi_alpha, &next->psi_beta);
    ctrl_inv_park(next->i_d, next->i_q, s1, c1, &next->i_alpha, &next->i_beta);
    next->psi_amp = fx_mag(pd, pq);
    next->psi_amp_sq = fixture_amp_sq(pd, pq);
    next->sector = ctrl_sector(next->psi_alpha, next->psi_beta);
    next->theta_e = th1;
    next->sin_theta = s1;
    next->cos_theta = c1;
}

static inline void fixture_predict(const ctrl_params_t *p, const ctrl_mstate_t *now, q24_t va,
                                   q24_t vb, q24_t omega, ctrl_mstate_t *next)
{
    const int64_t da = (int64_t)p->ts * va - (int64_t)p->ts_rs * now->i_alpha;
    const int64_t db = (int64_t)p->ts * vb - (int64_t)p->ts_rs * now->i_beta;
    const q24_t pa = fx_round_sat((int64_t)now->psi_alpha * FX_ONE + da, FX_QBITS);
    const q24_t pb = fx_round_sat((int64_t)now->psi_beta * FX_ONE + db, FX_QBITS);
    fixture_state_from_flux(p, pa, pb, now->theta_e + ctrl_angle_step(p, omega), next);
}

/* est->dtheta, rot_c, rot_s from est->omega_e, as the estimator sets them. */
static inline void fixture_rotation(const ctrl_params_t *p, ctrl_estimate_t *est)
{
    est->dtheta = fx_u2i(ctrl_angle_step(p, est->omega_e));
    fx_rot_q30(est->dtheta, &est->rot_c, &est->rot_s);
}

static inline void fixture_estimate(const ctrl_params_t *p, const ctrl_mstate_t *x, q24_t omega,
                                    q24_t vdc, ctrl_estimate_t *est)
{
    memset(est, 0, sizeof *est);
    est->now = *x;
    est->next = *x;
    est->omega_e = omega;
    est->vdc = vdc;
    fixture_rotation(p, est);
}

#endif /* TESTS_CORE_EST_FIXTURE_H */
