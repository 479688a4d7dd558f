/* Conventional M2PTFC (M1), thesis §6.4.2 with (5.18) and (6.13). Integer only. */
#include "ctrl_m1.h"

#include "mtpa.h"
#include "plan.h"

void ctrl_m1_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out)
{
    ctrl_m1_t *s = state;
    ctrl_mpc_in_t in;
    ctrl_mpc_in(&s->model, &s->flux, ctx, &in);
    const ctrl_mpc_basis_t *b = &in.b;

    /* Numerator of (5.18): T_err - dTe[0] = T_ref - Te0(k+2). */
    const q24_t num = fx_sub(in.t_ref, b->t0);
    /* argmin of (6.13) over V1..V6, the lowest index among equal costs. The
     * last period's vector goes first: usually the best or near it, so more
     * of the others' torque terms alone reach its cost and their square roots
     * are skipped (ctrl_mpc_cost_at); the decision is that of the search in
     * index order. */
    const uint8_t first = s->last_vec >= 1u && s->last_vec <= 6u ? s->last_vec : 1u;
    int64_t best_g = INT64_MAX;
    uint8_t best_v = 0u; /* none yet */
    q24_t best_d = 0;
    /* A candidate with duty 0 or 1 has the flux and torque at k+2 already
     * formed: psi0 and t0, or psi0 + Ts V and t_full (ctrl_mpc_flux and
     * ctrl_mpc_torque give exactly these). Every duty-0 candidate has the same
     * cost, formed at most once (g_zero, -1 until then). */
    int64_t g_zero = -1;
    for (uint8_t k = 0u; k < 6u; k++) {
        /* first, then 1..6 without it */
        const uint8_t i = k == 0u ? first : (k < first ? k : (uint8_t)(k + 1u));
        q24_t vd;
        q24_t vq;
        ctrl_mpc_vec_dq(b, i, &vd, &vq);
        const q24_t t_full = ctrl_mpc_torque(&s->model, b->d0 + vd, b->q0 + vq);
        const q24_t duty = ctrl_mpc_duty_sat(num, fx_sub(t_full, b->t0)); /* (5.18) */
        s->trace.vec[i - 1u] = i;
        s->trace.duty[i - 1u] = duty;
        /* wins when below best_g, or equal to it with a lower index */
        const int64_t bound = best_v != 0u && i < best_v ? best_g + 1 : best_g;
        int64_t g; /* (6.13), or a value >= bound when not below it */
        if (duty == 0) {
            if (g_zero < 0) {
                g = ctrl_mpc_cost_at(b->d0, b->q0, b->t0, in.t_ref, in.psi_ref, s->zeta, bound);
                g_zero = g != INT64_MAX ? g : -1;
            } else {
                g = g_zero;
            }
        } else if (duty == FX_ONE) {
            g = ctrl_mpc_cost_at(b->d0 + vd, b->q0 + vq, t_full, in.t_ref, in.psi_ref, s->zeta,
                                 bound);
        } else {
            g = ctrl_mpc_cost_weighted(&s->model, b, vd, vq, duty, in.t_ref, in.psi_ref, s->zeta,
                                       bound);
        }
        if (g < bound) {
            best_g = g;
            best_v = i;
            best_d = duty;
        }
    }
    s->trace.n = 6u;
    s->last_vec = best_v;
    ctrl_out_active_zero(out, best_v, best_d);
}
