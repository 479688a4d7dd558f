/*
 * Hysteresis DTC of the book chapter (S1 §3, Table 3), per-sample part
 * (integer-only). S1 Table 3 equals thesis Table 4.1: the switching-table
 * family's st_lookup_bst and hysteresis regulators are reused. See ctrl_s1_dtc.h.
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

void ctrl_hdtc_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out)
{
    ctrl_hdtc_state_t *s = state;
    const ctrl_mstate_t *nx = &ctx->est->next; /* delay compensation */
    const q24_t psi_ref = ctx->ref->psi > 0 ? ctx->ref->psi : s->psi_ref;
    /* Table 3: phi in {1, 0} -> +1 / -1 of the two-level regulator; tau three-level. */
    const int phi = ctrl_s1_flux_phi(&s->flux, &s->flux_lim_ref, psi_ref, nx->psi_amp_sq);
    const int tau = ctrl_hyst3_update(&s->torque, fx_sub(ctx->ref->torque, nx->torque));
    const uint8_t n = st_lookup_bst(nx->sector, phi, tau);
    const uint8_t v = n == ST_ZVV ? ctrl_zero_after(s->prev_vec) : n;
    ctrl_out_single(out, v);
    s->prev_vec = v;
}
