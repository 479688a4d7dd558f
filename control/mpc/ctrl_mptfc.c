/* FS-MPTFC, thesis §6.4.1 with (6.13). Integer only. */
#include "ctrl_mptfc.h"

#include "mtpa.h"
#include "plan.h"

void ctrl_mptfc_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out)
{
    ctrl_mptfc_t *s = state;
    ctrl_mpc_in_t in;
    ctrl_mpc_in(&s->model, &s->flux, ctx, &in);

    /* Zero vector (V0 = V7): duty 0 of any active vector. */
    int64_t best_g =
        ctrl_mpc_cost_at(in.b.d0, in.b.q0, in.b.t0, in.t_ref, in.psi_ref, s->zeta, INT64_MAX);
    uint8_t best_v = 0u;
    s->trace.vec[0] = 0u;
    s->trace.duty[0] = 0;
    for (uint8_t i = 1u; i <= 6u; i++) {
        q24_t vd;
        q24_t vq;
        ctrl_mpc_vec_dq(&in.b, i, &vd, &vq);
        /* psi(k+2) = psi0 + Ts V_i (ctrl_mpc_flux with the duty 1, exactly) */
        const q24_t pd = in.b.d0 + vd;
        const q24_t pq = in.b.q0 + vq;
        const int64_t g = ctrl_mpc_cost_at(pd, pq, ctrl_mpc_torque(&s->model, pd, pq), in.t_ref,
                                           in.psi_ref, s->zeta, best_g);
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
