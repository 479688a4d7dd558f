/* Voltage replacement (4.19)-(4.21); see vreplace.h. Integer-only. */
#include "vreplace.h"

#include <stddef.h>

#include "vectors.h"

/* Sign of u x psi = ux*py - uy*px, exact (|u| <= 2^25, |psi| <= 2^31: < 2^57). */
static int cross_sign(q24_t ux, q24_t uy, q24_t px, q24_t py)
{
    int64_t cr = (int64_t)ux * py - (int64_t)uy * px;
    return (cr > 0) - (cr < 0);
}

uint8_t ctrl_vreplace(const ctrl_vreplace_t *c, uint8_t vec, uint8_t sector, q24_t psi_alpha,
                      q24_t psi_beta)
{
    if (c == NULL || c->enabled == 0u || sector < 1u || sector > 6u || vec < 1u || vec > 6u) {
        return vec;
    }
    const q24_t dx = ctrl_vec_dir_q24[sector][0]; /* direction of V_x: the sector centre */
    const q24_t dy = ctrl_vec_dir_q24[sector][1];
    /* Inconsistent input (psi not around sector x, or psi = 0): leave vec. */
    if ((int64_t)dx * psi_alpha + (int64_t)dy * psi_beta <= 0) {
        return vec;
    }
    /* n of V_{x+n}, 0..5 */
    const int n = ((int)vec - (int)sector + 6) % 6;
    if (n == 0 || n == 3) {
        return vec;
    }
    /* u = d e^{-+j(pi/6 - sigma)}: (dx cb +- dy sb, dy cb -+ dx sb), one rounding each. */
    if (n == 2 || n == 5) {
        /* Subsector I, (4.20): theta_s <= a + sigma. */
        const q24_t ux = fx_dot(dx, dy, c->cos_b, c->sin_b);
        const q24_t uy = fx_cross(dy, dx, c->sin_b, c->cos_b);
        if (cross_sign(ux, uy, psi_alpha, psi_beta) <= 0) {
            return ctrl_vec_wrap((int)sector + n - 1);
        }
    } else {
        /* Subsector II, (4.21): theta_s > b - sigma. */
        const q24_t ux = fx_cross(dx, dy, c->sin_b, c->cos_b);
        const q24_t uy = fx_dot(dy, dx, c->cos_b, c->sin_b);
        if (cross_sign(ux, uy, psi_alpha, psi_beta) > 0) {
            return ctrl_vec_wrap((int)sector + n + 1);
        }
    }
    return vec;
}
