/* Discrete-duty M2PTFC (M2), thesis §6.4.2 with (6.15)-(6.17). Integer only. */
#include "ctrl_m2.h"

#include "mtpa.h"
#include "plan.h"
#include "st_tables.h"
#include "vectors.h"

uint8_t ctrl_m2_table(uint8_t sector, int torque_up, int flux_up)
{
    /* Table 4.4 (two-level torque), the switching-table module's lookup; any
     * sector value is wrapped into 1..6 as V_{x+n} arithmetic does (4.14). */
    return st_lookup_ast(ctrl_vec_wrap((int)sector), flux_up ? 1 : -1, torque_up ? 1 : -1);
}

void ctrl_m2_reset(void *state)
{
    ctrl_m2_t *s = state;
    s->trace.n = 0u;
    s->last_vec = 0u;
    s->flux.valid = 0u;
}

void ctrl_m2_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out)
{
    ctrl_m2_t *s = state;
    ctrl_mpc_in_t in;
    ctrl_mpc_in(&s->model, &s->flux, ctx, &in);

    const int32_t r2 = ctrl_mpc_amp2(in.psi_ref, 0);
    const int32_t a2_zero = ctrl_mpc_amp2(in.b.d0, in.b.q0); /* |psi0|^2 */
    const uint8_t vec = ctrl_m2_table(ctx->est->next.sector, in.t_ref >= in.b.t0, r2 >= a2_zero);
    q24_t vd;
    q24_t vq;
    ctrl_mpc_vec_dq(&in.b, vec, &vd, &vq);

    /* Band of (6.17) on squared amplitudes. */
    const q24_t lo = fx_max(fx_sub(in.psi_ref, s->eps_psi), 0);
    const int32_t lo2 = ctrl_mpc_amp2(lo, 0);
    const int32_t hi2 = ctrl_mpc_amp2(fx_add(in.psi_ref, s->eps_psi), 0);

    int64_t best_g = INT64_MAX; /* best feasible |T_ref - Te| (6.16) */
    unsigned best = 0u;
    int32_t a2[CTRL_M2_Y_MAX + 1]; /* |psi(k+2)|^2 of each duty */
    for (unsigned nu = 0; nu <= s->y; nu++) {
        /* D_0 = 0: psi0, its square and t0 as formed (ctrl_mpc_flux and
         * ctrl_mpc_torque give exactly these); D_y = 1: psi0 + Ts V. */
        const q24_t d = s->d_nu[nu];
        q24_t pd = in.b.d0;
        q24_t pq = in.b.q0;
        if (d == FX_ONE) {
            pd += vd;
            pq += vq;
        } else if (d != 0) {
            ctrl_mpc_flux(&in.b, vd, vq, d, &pd, &pq);
        }
        a2[nu] = d != 0 ? ctrl_mpc_amp2(pd, pq) : a2_zero;
        s->trace.vec[nu] = vec;
        s->trace.duty[nu] = s->d_nu[nu];
        if (a2[nu] < lo2 || a2[nu] > hi2) {
            continue; /* phi = infinity (6.17) */
        }
        const q24_t te = d != 0 ? ctrl_mpc_torque(&s->model, pd, pq) : in.b.t0;
        const int64_t e_t = (int64_t)in.t_ref - te;
        const int64_t g = e_t < 0 ? -e_t : e_t;
        if (g < best_g) {
            best_g = g;
            best = nu;
        }
    }
    s->trace.n = (uint8_t)(s->y + 1u);
    if (best_g == INT64_MAX) {
        /* None in the band: the smallest |psi_ref - |psi|| (the first on ties). */
        for (unsigned nu = 1u; nu <= s->y; nu++) {
            if (ctrl_mpc_closer(a2[nu], a2[best], r2) < 0) {
                best = nu;
            }
        }
    }
    if (best == 0u) {
        ctrl_mpc_out_zero(out, &s->last_vec);
    } else {
        ctrl_out_active_zero(out, vec, s->d_nu[best]);
        s->last_vec = vec;
    }
}
