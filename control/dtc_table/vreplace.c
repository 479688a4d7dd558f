/* Voltage replacement (4.19)-(4.21); see vreplace.h. Integer-only. */
#include "vreplace.h"

#include <stddef.h>

#include "vectors.h"

/* cos/sin of the lower sector boundary a = (2x-3)pi/6, x = 1..6, Q24.
 * 14529495 = round(2^24 * sqrt(3)/2); 8388608 = 2^24 / 2. */
#define SQ3_2 14529495
#define HALF 8388608
static const q24_t bound_cos[6] = {SQ3_2, SQ3_2, 0, -SQ3_2, -SQ3_2, 0};
static const q24_t bound_sin[6] = {-HALF, HALF, FX_ONE, HALF, -HALF, -FX_ONE};
/* Direction of the sector centre (x-1)pi/3 = direction of V_x, Q24. */
static const q24_t centre_cos[6] = {FX_ONE, HALF, -HALF, -FX_ONE, -HALF, HALF};
static const q24_t centre_sin[6] = {0, SQ3_2, SQ3_2, 0, -SQ3_2, -SQ3_2};

/* (c1*c2 - s1*s2, s1*c2 + c1*s2) rounded once: u(phi1 + phi2) from the parts
 * (fx_cross / fx_dot: one rounding, saturated, defined for any inputs). */
static void rotate(q24_t c1, q24_t s1, q24_t c2, q24_t s2, q24_t *c, q24_t *s)
{
    *c = fx_cross(c1, s1, s2, c2);
    *s = fx_dot(s1, c1, c2, s2);
}

/* Sign of u x psi = ux*py - uy*px, exact (|u| <= 2^25, |psi| <= 2^31: < 2^57). */
static int cross_sign(q24_t ux, q24_t uy, q24_t px, q24_t py)
{
    int64_t cr = (int64_t)ux * py - (int64_t)uy * px;
    return (cr > 0) - (cr < 0);
}

uint8_t ctrl_vreplace(const ctrl_vreplace_t *c, uint8_t vec, uint8_t sector, q24_t psi_alpha,
                      q24_t psi_beta)
{
    if (c == NULL || c->enabled == 0u || c->sin_sigma <= 0 || sector < 1u || sector > 6u ||
        vec < 1u || vec > 6u) {
        return vec;
    }
    const unsigned i = (unsigned)sector - 1u;
    /* Inconsistent input (psi not around sector x, or psi = 0): leave vec. */
    if ((int64_t)centre_cos[i] * psi_alpha + (int64_t)centre_sin[i] * psi_beta <= 0) {
        return vec;
    }
    /* n of V_{x+n}, 0..5 */
    const int n = ((int)vec - (int)sector + 6) % 6;
    if (n == 0 || n == 3) {
        return vec;
    }
    const unsigned j = (i + 1u) % 6u; /* upper boundary b of sector x = lower of x+1 */
    q24_t ux;
    q24_t uy;
    if (n == 2 || n == 5) {
        /* Subsector I, (4.20): theta_s <= a + sigma. */
        rotate(bound_cos[i], bound_sin[i], c->cos_sigma, c->sin_sigma, &ux, &uy);
        if (cross_sign(ux, uy, psi_alpha, psi_beta) <= 0) {
            return ctrl_vec_wrap((int)sector + n - 1);
        }
    } else {
        /* Subsector II, (4.21): theta_s > b - sigma (rotation by -sigma). */
        rotate(bound_cos[j], bound_sin[j], c->cos_sigma, fx_neg(c->sin_sigma), &ux, &uy);
        if (cross_sign(ux, uy, psi_alpha, psi_beta) > 0) {
            return ctrl_vec_wrap((int)sector + n + 1);
        }
    }
    return vec;
}
