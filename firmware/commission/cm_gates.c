/*
 * Step "gates" (bring-up): gate test at low duty, without a motor.
 *
 * Method: first all three legs switch at 50 % duty together for n_gate
 * periods (every gate driver and switch toggles, but the legs make no line
 * voltage, so even a connected motor would draw nothing); then each leg in
 * turn switches at gate_duty while the other two stay low for n_gate
 * periods. With no motor on the terminals no current can flow; watch the
 * legs with an oscilloscope meanwhile (docs/bringup.md). Verdicts:
 *   - a phase current above i_gate_max: gates_current (a motor or a load is
 *     connected, or a leg conducts where it should not) - the gates go off in
 *     that period; the current then is small, since the duty is low;
 *   - the DC link sagging by more than 5 % of its value at the start:
 *     gates_vbus (shoot-through, or a weak supply);
 *   - the hardware trip or over-current protection: fault (cm_abort_fault).
 * Pass: every leg switched for n_gate periods with no current and a steady
 * DC link.
 */
#include "cm_internal.h"

void cm_gates_begin(cm_t *cm)
{
    cm->x.a[0] = 0; /* DC link at the start */
}

int cm_gates_period(cm_t *cm, const cm_in_t *in, cm_out_t *out)
{
    const cm_par_t *p = &cm->par;
    if (cm->phase == 0u && cm->t == 0u) {
        cm->x.a[0] = in->vdc;
    }
    cm->progress = (uint16_t)(cm->phase * 250u + cm->t * 250u / p->n_gate);
    const q24_t i_c = p->has_i_c ? in->i_c : fx_neg(fx_add(in->i_a, in->i_b));
    const q24_t ix[3] = {in->i_a, in->i_b, i_c};
    for (int k = 0; k < 3; k++) {
        if (fx_abs(ix[k]) > p->i_gate_max) {
            return cm_fail(cm, CM_E_GATES_CURRENT, k, ix[k], (int32_t)cm->phase);
        }
    }
    if (in->vdc < fx_sub(cm->x.a[0], cm->x.a[0] / 20)) {
        return cm_fail(cm, CM_E_GATES_VBUS, in->vdc, cm->x.a[0], (int32_t)cm->phase);
    }
    if (cm->phase >= 4u) {
        cm_out_off(cm, out);
        return CM_DONE;
    }
    if (cm->phase == 0u) {
        cm_legs(cm, FX_ONE / 2, FX_ONE / 2, FX_ONE / 2, out);
    } else {
        const uint32_t leg = cm->phase - 1u;
        cm_legs(cm, leg == 0u ? p->gate_duty : 0, leg == 1u ? p->gate_duty : 0,
                leg == 2u ? p->gate_duty : 0, out);
    }
    if (cm->t + 1u >= p->n_gate) {
        cm_next(cm);
    }
    return CM_RUN;
}
