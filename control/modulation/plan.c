/*
 * Switching plans and their realisation as centre-aligned leg duties.
 */
#include "plan.h"

#include "vectors.h"

_Static_assert(CTRL_PLAN_MAX_SEG == 4, "the plan helpers fill exactly four segments");

void ctrl_plan_single(ctrl_plan_t *p, uint8_t vec)
{
    p->n_seg = 1u;
    p->vec[0] = vec;
    p->vec[1] = 0u;
    p->vec[2] = 0u;
    p->vec[3] = 0u;
    p->dur[0] = FX_ONE;
    p->dur[1] = 0;
    p->dur[2] = 0;
    p->dur[3] = 0;
}

void ctrl_plan_active_zero(ctrl_plan_t *p, uint8_t vec, q24_t duty)
{
    const q24_t d = fx_clamp(duty, 0, FX_ONE);
    p->n_seg = 2u;
    p->vec[0] = vec;
    p->vec[1] = vec <= 7u ? ctrl_vec_zero_after[vec] : 0u;
    p->vec[2] = 0u;
    p->vec[3] = 0u;
    p->dur[0] = d;
    p->dur[1] = FX_ONE - d;
    p->dur[2] = 0;
    p->dur[3] = 0;
}

void ctrl_plan_two_active(ctrl_plan_t *p, uint8_t v1, q24_t d1, uint8_t v2, q24_t d2)
{
    const q24_t a = fx_clamp(d1, 0, FX_ONE);
    const q24_t b = fx_clamp(d2, 0, FX_ONE - a);
    ctrl_plan_single(p, v1);
    p->n_seg = 3u;
    p->dur[0] = a;
    p->vec[1] = v2;
    p->dur[1] = b;
    p->vec[2] = ctrl_zero_after(v1);
    p->dur[2] = FX_ONE - a - b;
}

void ctrl_plan_to_legs(const ctrl_plan_t *p, ctrl_legs_t *legs)
{
    /* Leg duty = total on-time of the segments with that leg high: the same
     * period-average pole voltages as the sequence of vectors. At most 4
     * segments of at most FX_ONE each: the sums fit an int32_t. */
    int32_t acc_a = 0;
    int32_t acc_b = 0;
    int32_t acc_c = 0;
    const unsigned n = p->n_seg < CTRL_PLAN_MAX_SEG ? p->n_seg : CTRL_PLAN_MAX_SEG;
    for (unsigned i = 0u; i < n; i++) {
        const q24_t dur = fx_clamp(p->dur[i], 0, FX_ONE);
        const unsigned m = p->vec[i] <= 7u ? ctrl_vec_legs[p->vec[i]] : 0u;
        acc_a += (m & 1u) != 0u ? dur : 0;
        acc_b += (m & 2u) != 0u ? dur : 0;
        acc_c += (m & 4u) != 0u ? dur : 0;
    }
    legs->duty[0] = fx_min(acc_a, FX_ONE);
    legs->duty[1] = fx_min(acc_b, FX_ONE);
    legs->duty[2] = fx_min(acc_c, FX_ONE);
}

/* V_i / Vdc in Q30 (Table 4.2): alpha = 2/3 cos((i-1) pi/3), beta = 2/3 sin((i-1) pi/3). */
#define K_2_3 715827883
#define K_1_3 357913941
#define K_1_SQRT3 619925131
static const int32_t plan_v_alpha_q30[8] = {0, K_2_3, K_1_3, -K_1_3, -K_2_3, -K_1_3, K_1_3, 0};
static const int32_t plan_v_beta_q30[8] = {0, 0,          K_1_SQRT3,  K_1_SQRT3,
                                           0, -K_1_SQRT3, -K_1_SQRT3, 0};

void ctrl_plan_voltage(const ctrl_plan_t *p, q24_t vdc, q24_t *v_alpha, q24_t *v_beta)
{
    /* (4.4) averaged over the period: v = sum dur_i V_i. Durations clamped to
     * [0, FX_ONE] and bad indices skipped as in ctrl_plan_to_legs; for every
     * plan whose durations sum to at most FX_ONE (all plans the helpers build)
     * this is exactly the voltage of the leg duties the PWM stage realises.
     * Zero vectors (0, 7) contribute nothing and are skipped with the bad
     * indices (one unsigned compare). The coefficient sum (Q54, |.| <= 4 * 2^24
     * * 2^30 = 2^56) is rounded to Q24 once (< 2^26: no saturation needed),
     * then times Vdc. */
    int64_t sa = 0;
    int64_t sb = 0;
    const unsigned n = p->n_seg < CTRL_PLAN_MAX_SEG ? p->n_seg : CTRL_PLAN_MAX_SEG;
    for (unsigned i = 0u; i < n; i++) {
        const unsigned v = p->vec[i];
        if (v - 1u > 5u) {
            continue; /* V0, V7 or an index > 7 */
        }
        const q24_t dur = fx_clamp(p->dur[i], 0, FX_ONE);
        sa += (int64_t)dur * plan_v_alpha_q30[v];
        sb += (int64_t)dur * plan_v_beta_q30[v];
    }
    *v_alpha = fx_mul(vdc, fx_round_nosat(sa, 30u));
    *v_beta = fx_mul(vdc, fx_round_nosat(sb, 30u));
}
