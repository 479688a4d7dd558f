/*
 * Voltage replacement of the flexible switching table (thesis §4.5.2),
 * also used by DRR-DTC (§5.3.5).
 *
 * Subsectors of sector x, (4.19), with a = (2x-3)pi/6 and b = (2x-1)pi/6:
 *   I : a < theta_s <= a + sigma        II : b - sigma < theta_s <= b
 * Replacements: in I  V_{x+2} -> V_{x+1}, V_{x+5} -> V_{x+4}   (4.20)
 *               in II V_{x+1} -> V_{x+2}, V_{x+4} -> V_{x+5}   (4.21)
 * Any other vector (V_x, V_{x+3}, V0, V7) is returned unchanged.
 *
 * The subsector test uses no angle: with u(phi) = (cos phi, sin phi),
 * u x psi = |psi| sin(theta_s - phi), so for psi inside sector x
 *   theta_s <= a + sigma  <=>  u(a + sigma) x psi <= 0
 *   theta_s >  b - sigma  <=>  u(b - sigma) x psi >  0,
 * and a + sigma, b - sigma are the direction of V_x ((x-1) pi/3,
 * ctrl_vec_dir_q24) turned by -(pi/6 - sigma) and +(pi/6 - sigma): one
 * rotation by the configured (cos, sin)(pi/6 - sigma), rounded once to Q24;
 * the cross products are exact in 64 bits, so the only error is the Q24
 * rounding of u: an angular error below 2^-23 rad.
 */
#ifndef CONTROL_VREPLACE_H
#define CONTROL_VREPLACE_H

#include <stdint.h>

#include "fx.h"

typedef struct {
    q24_t cos_b, sin_b; /* of pi/6 - sigma, sigma the subsector width in (0, pi/6], Q24 */
    /* per sector x (index x - 1): u(a + sigma) and u(b - sigma), Q24, the
     * direction of V_x turned as above (formed by ctrl_vreplace_config) */
    q24_t u_lo[6][2], u_hi[6][2];
    uint8_t enabled; /* 0 (sigma == 0): ctrl_vreplace returns vec unchanged */
} ctrl_vreplace_t;

/*
 * Apply (4.19)-(4.21) to the vector vec (0..7) selected in sector 1..6 for the
 * stator flux (psi_alpha, psi_beta) (Q24 pu). psi is expected in the sector
 * (e.g. the sector came from ctrl_sector on the same psi); if it lies more
 * than pi/2 away from the sector centre, or c is NULL / disabled, the sector
 * is out of range or vec is not V_{x+1,x+2,x+4,x+5}, vec is returned unchanged.
 */
uint8_t ctrl_vreplace(const ctrl_vreplace_t *c, uint8_t vec, uint8_t sector, q24_t psi_alpha,
                      q24_t psi_beta);

#endif /* CONTROL_VREPLACE_H */
