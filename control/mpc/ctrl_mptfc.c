/* FS-MPTFC, thesis §6.4.1 with (6.13). Integer only. */
#include "ctrl_mptfc.h"

#include "mtpa.h"
#include "plan.h"

void ctrl_mptfc_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out)
{
    ctrl_mptfc_t *s = state;
    ctrl_mpc_basis_t b;
    ctrl_mpc_model_track(&s->model, ctx->params);
    ctrl_mpc_basis(&s->model, ctx->est, &b);
    const q24_t t_ref = ctx->ref->torque;
    const q24_t psi_ref = ctrl_flux_ref(ctx->params, ctx->ref->psi, ctx->ref->torque);

    /* Zero vector (V0 = V7): duty 0 of any active vector. */
    int64_t best_g = ctrl_mpc_cost_weighted(&s->model, &b, 0, 0, 0, t_ref, psi_ref, s->zeta);
    uint8_t best_v = 0u;
    s->trace.vec[0] = 0u;
    s->trace.duty[0] = 0;
    for (uint8_t i = 1u; i <= 6u; i++) {
        q24_t vd;
        q24_t vq;
        ctrl_mpc_vec_dq(&b, i, &vd, &vq);
        const int64_t g =
            ctrl_mpc_cost_weighted(&s->model, &b, vd, vq, FX_ONE, t_ref, psi_ref, s->zeta);
        s->trace.vec[i] = i;
        s->trace.duty[i] = FX_ONE;
        if (g < best_g) {
            best_g = g;
            best_v = i;
        }
    }
    s->trace.n = 7u;
    if (best_v == 0u) {
        ctrl_mpc_out_zero(out, &s->last_vec);
    } else {
        ctrl_out_single(out, best_v);
        s->last_vec = best_v;
    }
}
