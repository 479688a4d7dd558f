/*
 * Switching-table DTC, per-sample part (integer-only). Thesis chapter 4:
 * hysteresis regulators (Fig. 4.2) + BST/MBST/AST/ZST, and the flexible
 * table FST with its operating-state logic (§4.5.3) and voltage replacement
 * (4.19)-(4.21). Conventions and delay compensation: st_dtc.h.
 */
#include "st_dtc.h"

#include <stddef.h>

#include "mtpa.h"
#include "plan.h"
#include "vectors.h"

/* One vector for the whole period; a table "ZVV" becomes V0/V7 by the
 * previous vector so that one leg switches (§4.5.2). */
static void st_emit(ctrl_out_t *out, uint8_t *prev_vec, uint8_t n)
{
    const uint8_t v = (n == ST_ZVV) ? ctrl_zero_after(*prev_vec) : n;
    ctrl_out_single(out, v);
    *prev_vec = v;
}

void st_hyst_reset(void *state)
{
    st_hyst_state_t *s = state;
    s->prev_vec = 0u;
    ctrl_hyst2_reset(&s->flux.h);
    ctrl_hyst3_reset(&s->torque3);
    ctrl_hyst2_reset(&s->torque2);
    s->flux_ref.valid = 0u;
}

void st_hyst_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out)
{
    st_hyst_state_t *s = state;
    /* Delay compensation: decide on the state predicted for k+1. */
    const ctrl_mstate_t *nx = &ctx->est->next;
    /* The flux reference (mtpa.h) and, where it moved, the flux regulator's
     * band edges on |psi|^2. */
    if (ctrl_flux_memo_hit(&s->flux_ref, ctx->params, ctx->ref->psi, ctx->ref->torque) == 0) {
        s->flux_ref.value = ctrl_flux_ref(ctx->params, ctx->ref->psi, ctx->ref->torque);
        ctrl_hyst2_sq_limits(&s->flux, s->flux_ref.value);
    }
    const q24_t t_err = fx_sub(ctx->ref->torque, nx->torque);
    const int e_psi = ctrl_hyst2_sq_update(&s->flux, nx->psi_amp_sq);
    uint8_t n;
    switch ((st_kind_t)s->kind) {
    case ST_KIND_BST:
        n = st_lookup_bst(nx->sector, e_psi, ctrl_hyst3_update(&s->torque3, t_err));
        break;
    case ST_KIND_MBST:
        /* Sectors (4.18). Average-voltage limit of Table 4.3 at high speed:
         * docs/algorithms.md, "MBST". */
        n = st_lookup_mbst(ctrl_sector_mbst(nx->psi_alpha, nx->psi_beta), e_psi,
                           ctrl_hyst3_update(&s->torque3, t_err));
        break;
    case ST_KIND_AST:
        n = st_lookup_ast(nx->sector, e_psi, ctrl_hyst2_update(&s->torque2, t_err));
        break;
    case ST_KIND_ZST:
        n = st_lookup_zst(nx->sector, e_psi, ctrl_hyst2_update(&s->torque2, t_err));
        break;
    default:
        n = ST_ZVV; /* corrupted state: apply no voltage */
        break;
    }
    st_emit(out, &s->prev_vec, n);
}

void st_fst_logic_reset(st_fst_logic_t *l)
{
    if (l == NULL) {
        return;
    }
    l->tref_prev = 0;
    l->flag = 0u;
    l->terr_nonneg_prev = 1u;
}

/* st_fst_logic_update's body (inline in the step) */
static inline st_fst_mode_t st_fst_logic_step(st_fst_logic_t *l, q24_t tref, q24_t terr,
                                              q24_t omega)
{
    const uint8_t nonneg = terr >= 0 ? 1u : 0u;
    const uint8_t crossed = nonneg != l->terr_nonneg_prev ? 1u : 0u;
    const int64_t d_tref = (int64_t)tref - l->tref_prev;
    const int64_t d_abs = d_tref < 0 ? -d_tref : d_tref;
    if (d_abs > (int64_t)l->dt_step) {
        l->flag = 1u; /* Delta T_ref != 0: a reference step, go dynamic */
    } else if (l->flag != 0u && crossed != 0u && fx_sign(tref) * fx_sign(omega) >= 0) {
        l->flag = 0u; /* torque crossed its reference, and T_ref * omega >= 0 */
    }
    l->tref_prev = tref;
    l->terr_nonneg_prev = nonneg;
    if (l->flag != 0u) {
        return ST_FST_DYNAMIC;
    }
    return omega >= 0 ? ST_FST_STEADY_FWD : ST_FST_STEADY_BWD;
}

st_fst_mode_t st_fst_logic_update(st_fst_logic_t *l, q24_t tref, q24_t terr, q24_t omega)
{
    if (l == NULL) {
        return ST_FST_DYNAMIC; /* active vectors only: always stable */
    }
    return st_fst_logic_step(l, tref, terr, omega);
}

void st_fst_reset(void *state)
{
    st_fst_state_t *s = state;
    s->prev_vec = 0u;
    s->g = 0;
    st_fst_logic_reset(&s->logic);
    s->flux_ref.valid = 0u;
}

void st_fst_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out)
{
    st_fst_state_t *s = state;
    /* Signs of the errors replace the hysteresis regulators (§4.5.1); both
     * errors on the state predicted for k+1 (delay compensation). */
    const ctrl_mstate_t *nx = &ctx->est->next;
    const q24_t tref = ctx->ref->torque;
    const q24_t t_err = fx_sub(fx_add(tref, s->g), nx->torque); /* g = 0 when off */
    /* psi_ref - |psi| >= 0 by the squares (fx.h), the limit formed where the
     * flux reference (mtpa.h) moved */
    if (ctrl_flux_memo_hit(&s->flux_ref, ctx->params, ctx->ref->psi, tref) == 0) {
        s->flux_ref.value = ctrl_flux_ref(ctx->params, ctx->ref->psi, tref);
        s->psi_le_lim = fx_mag_le_lim(s->flux_ref.value);
    }
    const int psi_inc = nx->psi_amp_sq < s->psi_le_lim;
    /* Step detection on the commanded reference, not on T_vref, nor on the
     * anti-cogging feed-forward (ctrl_refs_t.torque_ff): that is a known
     * cancellation of the cogging moving at each encoder count, and taken as
     * a step it kept FST out of its steady-state modes (docs/anticogging.md,
     * "FST"). */
#if CTRL_COGGING
    const q24_t tcmd = fx_sub(tref, ctx->ref->torque_ff);
#else
    const q24_t tcmd = tref;
#endif
    const st_fst_mode_t mode = st_fst_logic_step(&s->logic, tcmd, t_err, ctx->est->omega_e);
    if (mode != ST_FST_DYNAMIC) {
        /* Integrate in steady state only (a step's error is the dynamics').
         * k_i <= 0.5 (2^23), |error| <= 2^31: |product| <= 2^54, no saturation. */
        const q24_t inc = fx_mul_nosat(s->ki, fx_sub(tref, nx->torque));
        s->g = fx_clamp(fx_add(s->g, inc), fx_neg(s->g_max), s->g_max);
    }
    const uint8_t x = nx->sector;
    uint8_t n = st_lookup_fst(x, t_err >= 0, psi_inc, mode);
    if (n != ST_ZVV) {
        n = ctrl_vreplace(&s->vr, n, x, nx->psi_alpha, nx->psi_beta); /* (4.19)-(4.21) */
    }
    st_emit(out, &s->prev_vec, n);
}
