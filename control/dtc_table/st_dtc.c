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

q24_t st_psi_reference(const ctrl_params_t *p, const ctrl_refs_t *ref)
{
    if (ref != NULL && ref->psi > 0) {
        return ref->psi;
    }
    if (p == NULL) {
        return FX_ONE; /* psi_pm: the no-load flux */
    }
    if (p->psi_ref > 0) {
        return p->psi_ref;
    }
    return ctrl_mtpa_psi(p, ref != NULL ? ref->torque : 0); /* (4.15) */
}

/* One vector for the whole period; a table "ZVV" becomes V0/V7 by the
 * previous vector so that one leg switches (§4.5.2). */
static void st_emit(ctrl_plan_t *out, uint8_t *prev_vec, uint8_t n)
{
    const uint8_t v = (n == ST_ZVV) ? ctrl_zero_after(*prev_vec) : n;
    ctrl_plan_single(out, v);
    *prev_vec = v;
}

void st_hyst_reset(void *state)
{
    st_hyst_state_t *s = state;
    if (s == NULL) {
        return;
    }
    s->prev_vec = 0u;
    ctrl_hyst2_reset(&s->flux);
    ctrl_hyst3_reset(&s->torque3);
    ctrl_hyst2_reset(&s->torque2);
}

void st_hyst_step(void *state, const ctrl_ctx_t *ctx, ctrl_plan_t *out)
{
    st_hyst_state_t *s = state;
    if (out == NULL) {
        return;
    }
    if (s == NULL || !ctrl_ctx_ok(ctx)) {
        ctrl_plan_single(out, s != NULL ? ctrl_zero_after(s->prev_vec) : 0u); /* no voltage */
        return;
    }
    /* Delay compensation: decide on the state predicted for k+1. */
    const ctrl_mstate_t *nx = &ctx->est->next;
    const q24_t psi_err = fx_sub(st_psi_reference(ctx->params, ctx->ref), nx->psi_amp);
    const q24_t t_err = fx_sub(ctx->ref->torque, nx->torque);
    const int e_psi = ctrl_hyst2_update(&s->flux, psi_err);
    uint8_t n;
    switch ((st_kind_t)s->kind) {
    case ST_KIND_BST:
        n = st_lookup_bst(ctrl_sector(nx->psi_alpha, nx->psi_beta), e_psi,
                          ctrl_hyst3_update(&s->torque3, t_err));
        break;
    case ST_KIND_MBST:
        /*
         * MBST has a voltage (speed) limit that BST does not share; it is a
         * property of Table 4.3 with sectors (4.18), not a bug. To raise the
         * torque only V_{x+1} and V_{x+3} are available, 120 deg apart. With
         * |psi_s| held in its band their mix lies on the chord between them,
         * whose part along the flux's direction of motion at flux angle u
         * into the sector is |V| / (2 cos(30 deg - u)), |V| = 2/3 Vdc: from
         * Vdc/3 (mid-sector) to 2 Vdc / (3 sqrt 3) (edges), time average
         * pi Vdc / 9. BST (V_{x+1}, V_{x+2}, 60 deg apart) gets sqrt(3)
         * times more. So the flux can turn at most at
         * omega_e |psi_s| = pi Vdc / 9 - R_s i. Thesis SPMSM, Vdc 220 V,
         * 1.8 N*m with MTPA flux 0.0966 Wb: 76.8 V - 2.9 V, i.e. about
         * 1830 r/min (BST: 133 V, about 3200 r/min). At 2250 r/min the flux
         * must turn at 942 rad/s * 0.0966 Wb = 91 V, more than the 84.7 V at
         * the best sector position: it falls behind the rotor at any band,
         * sample rate or sensor resolution, the load angle walks negative
         * while the table keeps asking for more torque, and the current
         * |psi_s - psi_pm| / L reaches the 10.5 A trip (after 6.7 ms in
         * ./tools/sim, load angle -41 deg). Measured: the simulator holds
         * 1.68 N*m at 750 r/min, 1.30 at 1800, 0.57 at 1900, slips at 2000;
         * at 2250 r/min it stays in motoring with Vdc 270 V, slips at 250 V (limit
         * 9 (91 + 3) / pi = 269 V). The thesis predicts this (§4.4.2: V_{x+1}
         * and V_{x+3} fail to raise the torque at high speed; Fig. 4.10(b):
         * MBST unstable at 3000 r/min); its 2250 r/min MBST experiment
         * (Fig. 4.13) cannot be met at the stated 220 V. Test:
         * tables_closed_loop, test_mbst_voltage_limit.
         */
        n = st_lookup_mbst(ctrl_sector_mbst(nx->psi_alpha, nx->psi_beta), e_psi,
                           ctrl_hyst3_update(&s->torque3, t_err));
        break;
    case ST_KIND_AST:
        n = st_lookup_ast(ctrl_sector(nx->psi_alpha, nx->psi_beta), e_psi,
                          ctrl_hyst2_update(&s->torque2, t_err));
        break;
    case ST_KIND_ZST:
        n = st_lookup_zst(ctrl_sector(nx->psi_alpha, nx->psi_beta), e_psi,
                          ctrl_hyst2_update(&s->torque2, t_err));
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

st_fst_mode_t st_fst_logic_update(st_fst_logic_t *l, q24_t tref, q24_t terr, q24_t omega)
{
    if (l == NULL) {
        return ST_FST_DYNAMIC; /* active vectors only: always stable */
    }
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

void st_fst_reset(void *state)
{
    st_fst_state_t *s = state;
    if (s == NULL) {
        return;
    }
    s->prev_vec = 0u;
    st_fst_logic_reset(&s->logic);
}

void st_fst_step(void *state, const ctrl_ctx_t *ctx, ctrl_plan_t *out)
{
    st_fst_state_t *s = state;
    if (out == NULL) {
        return;
    }
    if (s == NULL || !ctrl_ctx_ok(ctx)) {
        ctrl_plan_single(out, s != NULL ? ctrl_zero_after(s->prev_vec) : 0u);
        return;
    }
    /* Signs of the errors replace the hysteresis regulators (§4.5.1); both
     * errors on the state predicted for k+1 (delay compensation). */
    const ctrl_mstate_t *nx = &ctx->est->next;
    const q24_t tref = ctx->ref->torque;
    const q24_t t_err = fx_sub(tref, nx->torque);
    const q24_t psi_err = fx_sub(st_psi_reference(ctx->params, ctx->ref), nx->psi_amp);
    const st_fst_mode_t mode = st_fst_logic_update(&s->logic, tref, t_err, ctx->est->omega_e);
    const uint8_t x = ctrl_sector(nx->psi_alpha, nx->psi_beta);
    uint8_t n = st_lookup_fst(x, t_err >= 0, psi_err >= 0, mode);
    if (n != ST_ZVV) {
        n = ctrl_vreplace(&s->vr, n, x, nx->psi_alpha, nx->psi_beta); /* (4.19)-(4.21) */
    }
    st_emit(out, &s->prev_vec, n);
}
