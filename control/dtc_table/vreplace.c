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
    /* n of V_{x+n}, 0..5 (vec - x in -5..5) */
    const int d = (int)vec - (int)sector;
    const unsigned n = (unsigned)(d < 0 ? d + 6 : d);
    if (n == 0u || n == 3u) {
        return vec;
    }
    const q24_t *u = (n == 2u || n == 5u) ? c->u_lo[sector - 1u] : c->u_hi[sector - 1u];
    const int side = cross_sign(u[0], u[1], psi_alpha, psi_beta);
    if (n == 2u || n == 5u) {
        /* Subsector I, (4.20): theta_s <= a + sigma: V_{x+n} -> V_{x+n-1}. */
        return side <= 0 ? ctrl_vec_offset(sector, n - 1u) : vec;
    }
    /* Subsector II, (4.21): theta_s > b - sigma: V_{x+n} -> V_{x+n+1}. */
    return side > 0 ? ctrl_vec_offset(sector, n + 1u) : vec;
}
