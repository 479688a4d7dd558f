/*
 * Step "vbus": DC link and current-sensor readings with the gates off.
 *
 * Method: average n_vbus samples of the DC link and of the three offset-
 * corrected current channels (the pipeline calibrated the offsets at boot),
 * and their standard deviation. Checks, in this order:
 *   - DC link inside the test window [vbus_min, vbus_max] (vbus_low/high);
 *   - each current's mean within max(4 counts, 2 % of rated) of zero: the
 *     boot calibration still holds (offset);
 *   - each current's standard deviation below max(4 counts, 2 % of rated)
 *     (noise).
 * The gates stay off. This is also the bring-up's first check ("Vbus and ADC
 * offsets with gates off", docs/identification.md).
 */
#include "cm_internal.h"

void cm_vbus_begin(cm_t *cm)
{
    (void)cm;
}

int cm_vbus_period(cm_t *cm, const cm_in_t *in, cm_out_t *out)
{
    cm_out_off(cm, out);
    cm_scratch_t *x = &cm->x;
    const q24_t i_c = cm->par.has_i_c ? in->i_c : fx_neg(fx_add(in->i_a, in->i_b));
    const q24_t ix[3] = {in->i_a, in->i_b, i_c};
    x->s[0] += in->vdc;
    for (int k = 0; k < 3; k++) {
        /* Clamped to +-4 pu so that n squares fit int64_t (an over-current
         * trips long before). */
        const q24_t c = fx_clamp(ix[k], -(FX_ONE * 4), FX_ONE * 4);
        x->s[1 + k] += c;
        x->s[4 + k] += (int64_t)c * c;
    }
    x->n++;
    cm->progress = (uint16_t)(x->n * 1000u / cm->par.n_vbus);
    if (x->n < cm->par.n_vbus) {
        return CM_RUN;
    }
    const uint32_t n = x->n;
    const q24_t vbus = cm_mean(x->s[0], n);
    cm->res.vbus = vbus;
    if (vbus < cm->par.vbus_min) {
        return cm_fail(cm, CM_E_VBUS_LOW, vbus, cm->par.vbus_min, 0);
    }
    if (vbus > cm->par.vbus_max) {
        return cm_fail(cm, CM_E_VBUS_HIGH, vbus, cm->par.vbus_max, 0);
    }
    const q24_t four = 4 * cm->par.i_lsb;
    const q24_t two_pct = cm->par.i_rated / 50;
    const q24_t tol = fx_max(four, two_pct);
    for (int k = 0; k < 3; k++) {
        const q24_t mean = cm_mean(x->s[1 + k], n);
        /* Variance in Q48: E[i^2] - mean^2, then the integer square root. */
        const int64_t e2 = x->s[4 + k] / (int64_t)n;
        const int64_t var = e2 - (int64_t)mean * mean;
        const q24_t sd = (q24_t)fx_isqrt64(var > 0 ? (uint64_t)var : 0u);
        cm->res.i_off[k] = mean;
        cm->res.i_noise[k] = sd;
    }
    for (int k = 0; k < 3; k++) {
        if (fx_abs(cm->res.i_off[k]) > tol) {
            return cm_fail(cm, CM_E_OFFSET, k, cm->res.i_off[k], tol);
        }
    }
    for (int k = 0; k < 3; k++) {
        if (cm->res.i_noise[k] > tol) {
            return cm_fail(cm, CM_E_NOISE, k, cm->res.i_noise[k], tol);
        }
    }
    return CM_DONE;
}
