/* Rotor angle at standstill from the saliency, modulo pi (initial_angle.h). */
#include "initial_angle.h"

#include <stddef.h>

#define IA_LIM (8 * FX_ONE)      /* inputs taken within +-8 pu: products < 2^54 */
#define IA_ACC_SHIFT 8u          /* sums in Q40: terms < 2^47, 24 x 64 of them < 2^58 */
#define IA_Q30_SQRT3_2 929887697 /* sqrt(3) / 2 in Q30 */
#define IA_Q30_HALF 536870912    /* 1 / 2 in Q30 */

/* The six directions 0, 30, ..., 150 deg (cos, sin) in Q30. */
static const int32_t ia_dir[CTRL_IA_DIRS][2] = {
    {1073741824, 0}, {IA_Q30_SQRT3_2, IA_Q30_HALF},  {IA_Q30_HALF, IA_Q30_SQRT3_2},
    {0, 1073741824}, {-IA_Q30_HALF, IA_Q30_SQRT3_2}, {-IA_Q30_SQRT3_2, IA_Q30_HALF},
};

static uint32_t ia_pulses(const ctrl_ia_t *ia)
{
    return (uint32_t)ia->rounds * CTRL_IA_DIRS * CTRL_IA_PER_DIR;
}

int ctrl_ia_init(ctrl_ia_t *ia, q24_t v_amp, uint32_t rounds, int32_t sal_sign)
{
    if (ia == NULL || v_amp <= 0 || rounds < 1u || rounds > CTRL_IA_ROUNDS_MAX ||
        (sal_sign != 1 && sal_sign != -1)) {
        return -1;
    }
    ia->v_amp = v_amp;
    ia->rounds = (uint8_t)rounds;
    ia->sal_sign = (int8_t)sal_sign;
    ctrl_ia_start(ia);
    return 0;
}

void ctrl_ia_start(ctrl_ia_t *ia)
{
    ia->n = 0u;
    ia->i_prev_a = 0;
    ia->i_prev_b = 0;
    ia->acc_a = 0;
    ia->acc_b = 0;
}

uint32_t ctrl_ia_periods(const ctrl_ia_t *ia)
{
    return ia_pulses(ia) + CTRL_IA_DELAY;
}

/* a b - c d (each within +-IA_LIM) in Q40 */
static int64_t ia_cross(q24_t a, q24_t b, q24_t c, q24_t d)
{
    return fx_rshift64_round((int64_t)a * b - (int64_t)c * d, IA_ACC_SHIFT);
}

uint8_t ctrl_ia_step(ctrl_ia_t *ia, q24_t v_alpha, q24_t v_beta, q24_t i_alpha, q24_t i_beta,
                     q24_t *v_alpha_out, q24_t *v_beta_out)
{
    const uint32_t pulses = ia_pulses(ia);
    const uint32_t n = ia->n;
    if (n >= CTRL_IA_DELAY && n < pulses + CTRL_IA_DELAY) {
        /* the change the pulse asked for at n - 2 made, against the voltage
         * actually applied */
        const q24_t da = fx_clamp(fx_sub(i_alpha, ia->i_prev_a), -IA_LIM, IA_LIM);
        const q24_t db = fx_clamp(fx_sub(i_beta, ia->i_prev_b), -IA_LIM, IA_LIM);
        const q24_t va = fx_clamp(v_alpha, -IA_LIM, IA_LIM);
        const q24_t vb = fx_clamp(v_beta, -IA_LIM, IA_LIM);
        ia->acc_a += ia_cross(da, va, db, vb);
        ia->acc_b += ia_cross(da, vb, -db, va);
    }
    ia->i_prev_a = i_alpha;
    ia->i_prev_b = i_beta;
    q24_t oa = 0;
    q24_t ob = 0;
    if (n < pulses) {
        const uint32_t dir = (n / CTRL_IA_PER_DIR) % CTRL_IA_DIRS;
        const uint32_t sub = n % CTRL_IA_PER_DIR;
        const q24_t amp = (sub == 0u || sub == 3u) ? ia->v_amp : fx_neg(ia->v_amp);
        oa = fx_mul_qn(amp, ia_dir[dir][0], 30u);
        ob = fx_mul_qn(amp, ia_dir[dir][1], 30u);
    }
    *v_alpha_out = oa;
    *v_beta_out = ob;
    if (n + 1u >= pulses + CTRL_IA_DELAY) {
        ia->n = (uint16_t)(pulses + CTRL_IA_DELAY);
        return 0u;
    }
    ia->n = (uint16_t)(n + 1u);
    return 1u;
}

fx_angle_t ctrl_ia_angle(const ctrl_ia_t *ia)
{
    /* 2 t = atan2(B, A) for Ld < Lq (sign flipped for Ld > Lq) */
    int64_t x = ia->sal_sign > 0 ? ia->acc_a : -ia->acc_a;
    int64_t y = ia->sal_sign > 0 ? ia->acc_b : -ia->acc_b;
    /* both into int32 with one shift (|x|, |y| < 2^58) */
    while (x > INT32_MAX / 2 || x < -(INT32_MAX / 2) || y > INT32_MAX / 2 || y < -(INT32_MAX / 2)) {
        x = fx_rshift64_round(x, 1u);
        y = fx_rshift64_round(y, 1u);
    }
    return fx_atan2((int32_t)y, (int32_t)x) >> 1;
}
