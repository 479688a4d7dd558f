/* Three-candidate M2PTFC (M3), thesis §6.4.2 with (6.1), (5.18), (6.13). Integer only. */
#include "ctrl_m3.h"

#include "mtpa.h"
#include "plan.h"

/* V_{x+1}, V_{x+2}, V_{x+5}, V_{x+4} of (6.1), wrapped into 1..6 as
 * ctrl_vec_wrap does, for x mod 6 (row): the same for any sector value. */
static const uint8_t m3_cand_tab[6][4] = {
    {1, 2, 5, 4}, {2, 3, 6, 5}, {3, 4, 1, 6}, {4, 5, 2, 1}, {5, 6, 3, 2}, {6, 1, 4, 3},
};

void ctrl_m3_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out)
{
    ctrl_m3_t *s = state;
    ctrl_mpc_in_t in;
    ctrl_mpc_in(&s->model, &s->flux, ctx, &in);
    const ctrl_mstate_t *n = &ctx->est->next;

    /* (6.1) by the sign of the torque error. */
    const uint8_t *row = m3_cand_tab[n->sector % 6u];
    const unsigned base = in.t_ref >= n->torque ? 0u : 2u;
    const uint8_t cand[2] = {row[base], row[base + 1u]};
    const q24_t num = fx_sub(in.t_ref, in.b.t0); /* (5.18) numerator */
    int64_t best_g = INT64_MAX;
    unsigned best = 2u;
    q24_t duty[2];
    for (unsigned k = 0; k < 2u; k++) {
        q24_t vd;
        q24_t vq;
        ctrl_mpc_vec_dq(&in.b, cand[k], &vd, &vq);
        const q24_t t_full = ctrl_mpc_torque(&s->model, in.b.d0 + vd, in.b.q0 + vq);
        duty[k] = ctrl_mpc_duty_sat(num, fx_sub(t_full, in.b.t0));
        const int64_t g = ctrl_mpc_cost_weighted(&s->model, &in.b, vd, vq, duty[k], in.t_ref,
                                                 in.psi_ref, s->zeta, best_g); /* (6.13) */
        s->trace.vec[k] = cand[k];
        s->trace.duty[k] = duty[k];
        if (g < best_g) {
            best_g = g;
            best = k;
        }
    }
    /* The zero vector all period. */
    const int64_t g0 =
        ctrl_mpc_cost_at(in.b.d0, in.b.q0, in.b.t0, in.t_ref, in.psi_ref, s->zeta, best_g);
    s->trace.vec[2] = 0u;
    s->trace.duty[2] = 0;
    s->trace.n = 3u;
    if (g0 < best_g) {
        ctrl_mpc_out_zero(out, &s->last_vec);
    } else {
        ctrl_out_active_zero(out, cand[best], duty[best]);
        s->last_vec = cand[best];
    }
}
