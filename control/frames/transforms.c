/*
 * Clarke (3.3) and Park (3.7) transforms and their inverses, Q24.
 * Each output is computed from 64-bit products with a single rounding.
 */
#include "transforms.h"

void ctrl_clarke(q24_t ia, q24_t ib, q24_t *al, q24_t *be)
{
    /* alpha = a; beta = (a + 2b)/sqrt(3) with c = -a - b (3.3). |sum| <=
     * 2^31 (1/sqrt3 + 2/sqrt3) 2^30 < 2^62: no overflow. */
    *al = ia;
    *be = fx_round_sat((int64_t)ia * FX_Q30_INV_SQRT3 + (int64_t)ib * FX_Q30_2_SQRT3, 30u);
}

void ctrl_inv_clarke(q24_t al, q24_t be, q24_t *a, q24_t *b, q24_t *c)
{
    const int64_t half = (int64_t)al * FX_Q30_HALF;
    const int64_t bq = (int64_t)be * FX_Q30_SQRT3_2;
    *a = al;
    *b = fx_round_sat(bq - half, 30u);
    *c = fx_round_sat(-bq - half, 30u);
}

/* |s|, |c| <= 2^24, so each product < 2^55 and the sums cannot overflow. */
void ctrl_park(q24_t al, q24_t be, q24_t s, q24_t c, q24_t *d, q24_t *q)
{
    *d = fx_round_sat((int64_t)c * al + (int64_t)s * be, FX_QBITS);
    *q = fx_round_sat((int64_t)c * be - (int64_t)s * al, FX_QBITS);
}

void ctrl_inv_park(q24_t d, q24_t q, q24_t s, q24_t c, q24_t *al, q24_t *be)
{
    *al = fx_round_sat((int64_t)c * d - (int64_t)s * q, FX_QBITS);
    *be = fx_round_sat((int64_t)s * d + (int64_t)c * q, FX_QBITS);
}
