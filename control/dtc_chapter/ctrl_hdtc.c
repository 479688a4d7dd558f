/*
 * Hysteresis DTC of the book chapter (S1 §3, Table 3), per-sample part
 * (integer-only). S1 Table 3 equals thesis Table 4.1: the switching-table
 * family's st_lookup_bst and hysteresis regulators are reused. See ctrl_s1_dtc.h.
 *
 * hdtc decides on the sampled flux and torque errors, as the chapter does;
 * hdtc_pred on the k+1 prediction of the estimator (5.15), which compensates
 * the one-period delay between the sample and the vector's application.
 */
#include <stddef.h>

#include "ctrl_s1_dtc.h"
#include "plan.h"
#include "st_tables.h"
#include "vectors.h"

void ctrl_hdtc_reset(void *state)
{
    ctrl_hdtc_state_t *s = state;
    s->prev_vec = 0u;
    ctrl_hyst2_reset(&s->flux.h);
    ctrl_hyst3_reset(&s->torque);
}

/* Table 3 on the state m (sector, torque) and its |psi|^2 (Q48 pu). */
static void hdtc_decide(ctrl_hdtc_state_t *s, const ctrl_ctx_t *ctx, const ctrl_mstate_t *m,
                        uint64_t psi_amp_sq, ctrl_out_t *out)
{
    const q24_t psi_ref = ctx->ref->psi > 0 ? ctx->ref->psi : s->psi_ref;
    /* Table 3: phi in {1, 0} -> +1 / -1 of the two-level regulator; tau three-level. */
    const int phi = ctrl_s1_flux_phi(&s->flux, &s->flux_lim_ref, psi_ref, psi_amp_sq);
    const int tau = ctrl_hyst3_update(&s->torque, fx_sub(ctx->ref->torque, m->torque));
    const uint8_t n = st_lookup_bst(m->sector, phi, tau);
    const uint8_t v = n == ST_ZVV ? ctrl_zero_after(s->prev_vec) : n;
    ctrl_out_single(out, v);
    s->prev_vec = v;
}

void ctrl_hdtc_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out)
{
    const ctrl_mstate_t *now = &ctx->est->now;
    /* |psi(k)|^2 from the rotor frame (rotation-invariant): each square
     * <= 2^62, so their sum as unsigned <= 2^63 cannot wrap. */
    const uint64_t amp_sq =
        (uint64_t)((int64_t)now->psi_d * now->psi_d) + (uint64_t)((int64_t)now->psi_q * now->psi_q);
    hdtc_decide(state, ctx, now, amp_sq, out);
}

void ctrl_hdtc_pred_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out)
{
    const ctrl_mstate_t *nx = &ctx->est->next; /* delay compensation */
    hdtc_decide(state, ctx, nx, nx->psi_amp_sq, out);
}
