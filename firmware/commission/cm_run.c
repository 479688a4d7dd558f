/*
 * Step "run" (bring-up): the first closed-loop run, in torque mode at
 * torque_run (10 % of the rated torque), with the selected controller and the
 * drive's present encoder offset and direction.
 *
 * Method: the controller and estimator are reset and driven with +torque_run
 * until the rotor reaches a fifth of the rated speed or n_run periods pass;
 * then with -torque_run until it is back at the starting speed (or 2 n_run);
 * then the gates go off. An unloaded rotor must accelerate in the torque's
 * direction. Verdicts:
 *   - it turned the other way (by more than 2 % of the rated speed):
 *     run_direction (encoder direction or offset wrong by about 180 deg);
 *   - it gained less than 2 % of the rated speed: run_no_accel (rotor
 *     blocked or loaded, or an offset wrong by about 90 deg);
 *   - the mean current magnitude above three times what the torque needs
 *     with the configured psi_pm (i = T / psi in pu): run_current.
 * Pass: detail[0] the speed gained (pu), detail[1] the periods it took,
 * detail[2] the mean estimated torque (pu).
 */
#include "cm_internal.h"

/* Scratch: a[0] start speed, s[0] sum |i|, s[1] sum torque estimate,
 * s[2] periods, a[1] speed gained. */

void cm_run_begin(cm_t *cm)
{
    (void)cm;
}

int cm_run_period(cm_t *cm, const cm_in_t *in, cm_out_t *out)
{
    cm_scratch_t *x = &cm->x;
    const cm_par_t *p = &cm->par;
    const q24_t w = cm_speed(cm);
    cm->progress = (uint16_t)(cm->phase * 333u);
    cm_out_off(cm, out);
    out->mode = CM_OUT_CTRL;
    if (cm->phase == 0u) {
        if (cm->t == 0u) {
            x->a[0] = w;
            out->ctrl_reset = 1u;
        }
        out->torque_ref = p->torque_run;
        x->s[0] += fx_mag(cm->io.i_al, cm->io.i_be);
        x->s[1] += in->torque_est;
        x->s[2]++;
        const q24_t dw = fx_sub(w, x->a[0]);
        if (dw >= p->w_rated / 5 || fx_neg(dw) >= p->w_rated / 5 || cm->t >= p->n_run) {
            x->a[1] = dw;
            x->k[0] = (int32_t)cm->t;
            cm_next(cm);
        }
        return CM_RUN;
    }
    if (cm->phase == 1u) {
        out->torque_ref = fx_neg(p->torque_run);
        const bool back = x->a[1] >= 0 ? w <= x->a[0] : w >= x->a[0];
        if (!back && cm->t < 2u * p->n_run) {
            return CM_RUN;
        }
    }
    cm_out_off(cm, out);
    const q24_t dw = x->a[1];
    const q24_t two = p->w_rated / 50;
    const q24_t i_mean = cm_mean(x->s[0], (uint32_t)x->s[2]);
    const q24_t t_mean = cm_mean(x->s[1], (uint32_t)x->s[2]);
    cm->detail[0] = dw;
    cm->detail[1] = x->k[0];
    cm->detail[2] = t_mean;
    if (dw < fx_neg(two)) {
        return cm_fail(cm, CM_E_RUN_DIRECTION, dw, x->k[0], t_mean);
    }
    if (dw < two) {
        return cm_fail(cm, CM_E_RUN_NO_ACCEL, dw, x->k[0], t_mean);
    }
    q24_t i_need = 0;
    (void)cm_ratio(p->torque_run, p->psi_cfg, &i_need);
    if (i_mean > 3 * i_need) {
        return cm_fail(cm, CM_E_RUN_CURRENT, i_mean, i_need, t_mean);
    }
    return CM_DONE;
}
