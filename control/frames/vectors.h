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

/* Leg states per vector index 0..7 (Table 4.2): bit 0 = leg a (S1), bit 1 = leg b
 * (S2), bit 2 = leg c (S3). One table for every module that maps vectors to legs. */
extern const uint8_t ctrl_vec_legs[8];

/* ctrl_zero_after() as a table, for per-sample code that indexes it directly. */
extern const uint8_t ctrl_vec_zero_after[8];

/* Switching state of leg 0..2 (a, b, c) for vector idx 0..7 (1 = upper switch on).
 * idx > 7 gives 0 (treated as V0). */
uint8_t ctrl_vector_leg(uint8_t idx, unsigned leg);

/* alpha/beta voltage of vector idx 0..7 at DC link vdc (Q24 pu), Table 4.2.
 * V0, V7 and idx > 7 give (0, 0). */
void ctrl_vector_ab(uint8_t idx, q24_t vdc, q24_t *v_alpha, q24_t *v_beta);

/* Index arithmetic V_{x+n} of (4.14) and its footnote: maps any int to 1..6
 * ((x - 1) mod 6) + 1, also for negative x. */
uint8_t ctrl_vec_wrap(int x);

/* Zero vector that switches one leg after vec: V0 after V0, V1, V3, V5;
 * V7 after V7, V2, V4, V6 (thesis §5.4 / REFERENCE §1). Other idx: V0. */
uint8_t ctrl_zero_after(uint8_t vec);

/* Sector 1..6 of the vector (x, y) by (4.5): (2s-3)pi/6 < theta <= (2s-1)pi/6. */
uint8_t ctrl_sector(q24_t x, q24_t y);

/* MBST sector 1..6 by (4.18): (2s-2)pi/6 < theta <= 2s pi/6 (theta = 0 -> 6). */
uint8_t ctrl_sector_mbst(q24_t x, q24_t y);

#endif /* CONTROL_VECTORS_H */
