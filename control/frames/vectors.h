/*
 * Inverter voltage vectors (Table 4.2, (4.4)) and sector detection ((4.5), (4.18)).
 *
 * V_i = 2Vdc/3 (S1 + S2 e^{j2pi/3} + S3 e^{j4pi/3}); V1=100, V2=110, V3=010,
 * V4=011, V5=001, V6=101, V0=000, V7=111 (S1 = leg a). Active vector V_i
 * points at angle (i-1) pi/3.
 * Sectors are found with sign and exact integer square comparisons (no atan,
 * no irrational constant): every integer point gets the sector the exact
 * definition gives it. The origin (no angle) is treated as theta = 0.
 */
#ifndef CONTROL_VECTORS_H
#define CONTROL_VECTORS_H

#include <stdint.h>

#include "fx.h"

/* The geometry of Table 4.2, one table per format (vectors.c):
 *   ctrl_vec_legs[v]      leg states of vector index v: bit 0 = leg a (S1), bit 1 = leg b
 *                         (S2), bit 2 = leg c (S3); 256 entries, 0 (no leg high) for
 *                         v > 7, so any uint8_t index is safe without a test;
 *   ctrl_vec_of_legs[m]   the vector index of leg-state mask m (inverse of the above);
 *   ctrl_vec_zero_after[v] the zero vector that switches one leg after v (V0 after
 *                         V0/V1/V3/V5, V7 after V7/V2/V4/V6);
 *   ctrl_vec_ab_q30[v]    V_v / Vdc in alpha/beta, Q30 ((4.4): 2/3 e^{j(v-1)pi/3}, 0 for V0, V7);
 *   ctrl_vec_dir_q24[v]   unit vector of V_v (direction (v-1) pi/3), Q24 (0 for V0, V7).
 * Sector boundaries of (4.5) bisect two neighbouring vectors: the lower
 * boundary of sector x lies at V_x rotated by -pi/6. */
extern const uint8_t ctrl_vec_legs[256];
extern const uint8_t ctrl_vec_of_legs[8];
extern const uint8_t ctrl_vec_zero_after[8];
extern const int32_t ctrl_vec_ab_q30[8][2];
extern const q24_t ctrl_vec_dir_q24[8][2];

/* alpha/beta voltage of vector idx 0..7 at DC link vdc (Q24 pu), Table 4.2.
 * V0, V7 and idx > 7 give (0, 0). */
void ctrl_vector_ab(uint8_t idx, q24_t vdc, q24_t *v_alpha, q24_t *v_beta);

/* Index arithmetic V_{x+n} of (4.14) and its footnote: maps any int to 1..6
 * ((x - 1) mod 6) + 1, also for negative x. */
uint8_t ctrl_vec_wrap(int x);

/* V_{x+n} for an active vector x (1..6) and an offset n in 0..6, the tables'
 * case of ctrl_vec_wrap(x + n): the sum wraps at most once (no division). */
static inline uint8_t ctrl_vec_offset(uint8_t x, unsigned n)
{
    const unsigned v = (unsigned)x + n;
    return (uint8_t)(v > 6u ? v - 6u : v);
}

/* Zero vector that switches one leg after vec: V0 after V0, V1, V3, V5;
 * V7 after V7, V2, V4, V6 (thesis §5.4, docs/conventions.md). Other idx: V0. */
uint8_t ctrl_zero_after(uint8_t vec);

/* Sector 1..6 of the vector (x, y) by (4.5): (2s-3)pi/6 < theta <= (2s-1)pi/6. */
uint8_t ctrl_sector(q24_t x, q24_t y);

/* MBST sector 1..6 by (4.18): (2s-2)pi/6 < theta <= 2s pi/6 (theta = 0 -> 6). */
uint8_t ctrl_sector_mbst(q24_t x, q24_t y);

#endif /* CONTROL_VECTORS_H */
