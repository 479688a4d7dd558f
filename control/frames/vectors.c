/*
 * Voltage vectors of the two-level inverter (Table 4.2) and sectors ((4.5), (4.18)).
 */
#include "vectors.h"

/* V0=000, V1=100, V2=110, V3=010, V4=011, V5=001, V6=101, V7=111 (Table 4.2);
 * the remaining entries are 0. */
const uint8_t ctrl_vec_legs[256] = {0u, 1u, 3u, 2u, 6u, 4u, 5u, 7u};

/* 000->V0, 100->V1, 010->V3, 110->V2, 001->V5, 101->V6, 011->V4, 111->V7. */
const uint8_t ctrl_vec_of_legs[8] = {0u, 1u, 3u, 2u, 5u, 6u, 4u, 7u};

/* One leg switches: V1, V3, V5 have one leg high -> V0; V2, V4, V6 two -> V7. */
const uint8_t ctrl_vec_zero_after[8] = {0u, 0u, 7u, 0u, 7u, 0u, 7u, 7u};

/* V_i / Vdc: alpha = 2/3 cos((i-1) pi/3), beta = 2/3 sin((i-1) pi/3). */
const int32_t ctrl_vec_ab_q30[8][2] = {
    {0, 0},
    {FX_Q30_2_3, 0},
    {FX_Q30_1_3, FX_Q30_INV_SQRT3},
    {-FX_Q30_1_3, FX_Q30_INV_SQRT3},
    {-FX_Q30_2_3, 0},
    {-FX_Q30_1_3, -FX_Q30_INV_SQRT3},
    {FX_Q30_1_3, -FX_Q30_INV_SQRT3},
    {0, 0},
};

/* cos, sin of (i-1) pi/3. */
const q24_t ctrl_vec_dir_q24[8][2] = {
    {0, 0},
    {FX_ONE, 0},
    {FX_Q24_HALF, FX_Q24_SQRT3_2},
    {-FX_Q24_HALF, FX_Q24_SQRT3_2},
    {-FX_ONE, 0},
    {-FX_Q24_HALF, -FX_Q24_SQRT3_2},
    {FX_Q24_HALF, -FX_Q24_SQRT3_2},
    {0, 0},
};

void ctrl_vector_ab(uint8_t idx, q24_t vdc, q24_t *v_alpha, q24_t *v_beta)
{
    if (idx > 7u) {
        idx = 0u;
    }
    *v_alpha = fx_round_sat((int64_t)vdc * ctrl_vec_ab_q30[idx][0], 30u);
    *v_beta = fx_round_sat((int64_t)vdc * ctrl_vec_ab_q30[idx][1], 30u);
}

uint8_t ctrl_vec_wrap(int x)
{
    /* ((x - 1) mod 6) + 1 without overflow at INT_MIN: reduce first. */
    int m = x % 6 - 1; /* in [-6, 4] */
    if (m < 0) {
        m += 6;
    }
    return (uint8_t)(m + 1);
}

uint8_t ctrl_zero_after(uint8_t vec)
{
    return vec <= 7u ? ctrl_vec_zero_after[vec] : 0u;
}

/* 3 a^2 < b^2 exactly (|a|, |b| <= 2^31: 3 a^2 < 2^64). */
static int sq3_less(q24_t a, q24_t b)
{
    const uint64_t ua = (uint64_t)(a < 0 ? -(int64_t)a : (int64_t)a);
    const uint64_t ub = (uint64_t)(b < 0 ? -(int64_t)b : (int64_t)b);
    return 3u * ua * ua < ub * ub;
}

uint8_t ctrl_sector(q24_t x, q24_t y)
{
    /* Boundaries at +-30, 90, 150 deg (4.5). |theta| < 30 deg from the alpha
     * axis <=> 3 y^2 < x^2; a point on a 30-deg line would need sqrt(3)
     * rational, so only x == 0 (90/270 deg) is an exact boundary: 90 deg
     * belongs to sector 2, 270 deg to sector 5 (upper bound inclusive). */
    if (x > 0) {
        if (sq3_less(y, x)) {
            return 1u;
        }
        return y > 0 ? 2u : 6u;
    }
    if (x < 0) {
        if (sq3_less(y, x)) {
            return 4u;
        }
        return y > 0 ? 3u : 5u;
    }
    if (y > 0) {
        return 2u;
    }
    return y < 0 ? 5u : 1u; /* origin: theta taken as 0 */
}

uint8_t ctrl_sector_mbst(q24_t x, q24_t y)
{
    /* Boundaries at 0, 60, 120, 180 ... deg (4.18): within 30 deg of the beta
     * axis <=> 3 x^2 < y^2. Exact boundaries only on y == 0: 0 deg belongs to
     * sector 6, 180 deg to sector 3. */
    if (y > 0) {
        if (sq3_less(x, y)) {
            return 2u;
        }
        return x > 0 ? 1u : 3u;
    }
    if (y < 0) {
        if (sq3_less(x, y)) {
            return 5u;
        }
        return x < 0 ? 4u : 6u;
    }
    return x < 0 ? 3u : 6u; /* origin: theta taken as 0 */
}
