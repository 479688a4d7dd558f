/* Conventional M2PTFC (M1), thesis §6.4.2 with (5.18) and (6.13). Integer only. */
#include "ctrl_m1.h"

#include "mtpa.h"
#include "plan.h"

/* The search order: the last period's vector first, then 1..6 without it
 * (row: the last vector - 1). */
static const uint8_t m1_order[6][6] = {
    {1, 2, 3, 4, 5, 6}, {2, 1, 3, 4, 5, 6}, {3, 1, 2, 4, 5, 6},
    {4, 1, 2, 3, 5, 6}, {5, 1, 2, 3, 4, 6}, {6, 1, 2, 3, 4, 5},
};

void ctrl_m1_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out)
{
    ctrl_m1_t *s = state;
    ctrl_mpc_in_t in;
    ctrl_mpc_in(&s->model, &s->flux, ctx, &in);
    const ctrl_mpc_basis_t *b = &in.b;

    /* (5.18) for each vector: D_f = (T_ref - Te0(k+2)) / (Te(k+2) - Te0(k+2)),
     * Te(k+2) with the vector the whole period (t_full). */
    const q24_t num = fx_sub(in.t_ref, b->t0);
    q24_t t_full[6];
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC unroll 6 /* constant vector offsets: 45 instructions less per period (tools/bench) */
#endif
    for (uint8_t i = 1u; i <= 6u; i++) {
        q24_t vd;
        q24_t vq;
        ctrl_mpc_vec_dq(b, i, &vd, &vq);
        t_full[i - 1u] = ctrl_mpc_torque(&s->model, b->d0 + vd, b->q0 + vq);
        s->trace.vec[i - 1u] = i;
        s->trace.duty[i - 1u] = ctrl_mpc_duty_sat(num, fx_sub(t_full[i - 1u], b->t0));
    }
    /* argmin of (6.13) over V1..V6, the lowest index among equal costs. The
     * last period's vector goes first: usually the best or near it, so more
     * of the others' torque terms alone reach its cost and their square roots
     * are skipped (ctrl_mpc_cost_at); the decision is that of the search in
     * index order. */
    const uint8_t first = s->last_vec >= 1u && s->last_vec <= 6u ? s->last_vec : 1u;
    int64_t best_g = INT64_MAX;
    uint8_t best_v = 0u; /* none yet */
    /* Every duty-0 candidate has the flux psi0 and the torque t0, the same
     * cost: formed at most once (g_zero, -1 until then; a value >= bound
     * instead of INT64_MAX decides the same, see ctrl_mpc_cost_at). */
    int64_t g_zero = -1;
    for (uint8_t k = 0u; k < 6u; k++) {
        const uint8_t i = m1_order[first - 1u][k];
        const q24_t duty = s->trace.duty[i - 1u];
        /* wins when below best_g, or equal to it with a lower index */
        const int64_t bound = best_v != 0u && i < best_v ? best_g + 1 : best_g;
        /* (6.13), or a value >= bound when not below it */
        int64_t g;
        if (duty == 0 && g_zero >= 0) {
            g = g_zero;
        } else {
            q24_t vd;
            q24_t vq;
            ctrl_mpc_vec_dq(b, i, &vd, &vq);
            g = ctrl_mpc_cost_duty(&s->model, b, vd, vq, duty, t_full[i - 1u], in.t_ref, in.psi_ref,
                                   s->zeta, bound);
            if (duty == 0 && g != INT64_MAX) {
                g_zero = g;
            }
        }
        if (g < bound) {
            best_g = g;
            best_v = i;
        }
    }
    s->trace.n = 6u;
    /* best_v >= 1: the first candidate's cost (below 2^34) is below INT64_MAX */
    s->last_vec = best_v;
    ctrl_out_active_zero(out, best_v, s->trace.duty[best_v - 1u]);
}
