/*
 * Switching-table DTC controllers of thesis chapter 4: BST (Table 4.1),
 * MBST (Table 4.3, sectors (4.18)), AST (Table 4.4), ZST (Table 4.5) and the
 * flexible table FST (Table 4.6, §4.5.3, voltage replacement (4.19)-(4.21)).
 *
 * Delay compensation (docs/conventions.md, thesis §4.6.2): the vector chosen at
 * sample k acts during [k+1, k+2), so every decision uses the one-step-ahead
 * prediction est->next (torque, flux amplitude, flux vector -> sector), i.e.
 * the state at the instant the vector starts to act. The flux amplitude is
 * compared by its square (psi_amp_sq against the squared reference and band
 * edges): the decisions of |psi| = fx_mag, without the square root.
 *
 * Flux reference: ctrl_flux_ref (mtpa.h) of the torque reference.
 *
 * Output: one vector for the whole period (n_seg = 1, duration FX_ONE). A
 * table entry "ZVV" becomes V0 or V7 by ctrl_zero_after(previous vector), so
 * exactly one leg switches (§4.5.2); the previous vector is the one this
 * controller chose at k-1 (V0 after reset, the inverter's idle state).
 */
#ifndef CONTROL_ST_DTC_H
#define CONTROL_ST_DTC_H

#include <stdint.h>

#include "controller.h"
#include "fx.h"
#include "hysteresis.h"
#include "mtpa.h"
#include "st_tables.h"
#include "vreplace.h"

/* Which table a hysteresis-based controller uses. */
typedef enum { ST_KIND_BST = 0, ST_KIND_MBST, ST_KIND_AST, ST_KIND_ZST } st_kind_t;

/* Runtime state of BST/MBST/AST/ZST. */
typedef struct {
    uint8_t kind;              /* st_kind_t */
    uint8_t prev_vec;          /* vector chosen at k-1, 0..7 */
    ctrl_hyst2_sq_t flux;      /* two-level flux regulator on |psi|^2, band h_psi (Q24 pu) */
    ctrl_hyst3_t torque3;      /* three-level torque regulator (BST, MBST), band h_T */
    ctrl_hyst2_t torque2;      /* two-level torque regulator (AST, ZST), band h_T */
    ctrl_flux_memo_t flux_ref; /* the flux reference (mtpa.h); flux's limits follow it */
} st_hyst_state_t;

/* Operating-state logic of FST, §4.5.3 / Fig. 4.6. */
typedef struct {
    q24_t dt_step;            /* step threshold, Q24 pu (>= 0) */
    q24_t tref_prev;          /* T_ref[k-1], Q24 pu */
    uint8_t flag;             /* 1: reference step seen, active vectors only */
    uint8_t terr_nonneg_prev; /* (T_err[k-1] >= 0) */
} st_fst_logic_t;

/* Runtime state of FST. Mean-torque-error integrator (off = the thesis' FST):
 * the decisions use T_vref = T_ref + g, g += k_i (T_ref - T(k+1)) in the
 * steady-state modes, |g| <= g_max. With one vector per period the torque is
 * piecewise linear between the samples, so the mean of T_ref - T(k+1) over
 * the samples is the mean torque error: the integrator removes the error
 * (Delta T_active - |Delta T_zero|) / 2 that sign decisions leave when one
 * period's torque step is not small (docs/algorithms.md, "FST"). */
typedef struct {
    st_fst_logic_t logic;
    ctrl_vreplace_t vr;
    uint8_t prev_vec;
    q24_t ki;                  /* integrator gain per period (2 pi f_i Ts), Q24; 0 = off */
    q24_t g_max;               /* |g| limit: the rated torque, Q24 pu */
    q24_t g;                   /* integrator, Q24 pu torque */
    ctrl_flux_memo_t flux_ref; /* the flux reference (mtpa.h) */
    uint64_t psi_le_lim;       /* |psi|^2 below it: |psi| <= the reference (fx_mag_le_lim) */
} st_fst_state_t;

/* Clear the FST logic (flag 0, T_ref[k-1] = 0, T_err[k-1] >= 0), keep dt_step. */
void st_fst_logic_reset(st_fst_logic_t *l);

/*
 * One sample of the §4.5.3 logic with T_ref[k], T_err[k] = T_ref - T^{k+1} and
 * the electrical speed omega (all Q24 pu):
 *   |T_ref[k] - T_ref[k-1]| > dt_step          -> flag = 1 (a step)
 *   else if flag and sign(T_err) changed since k-1 (the torque crossed the
 *        reference) and T_ref * omega >= 0       -> flag = 0
 * The reset is not tested on the step sample itself: there the error sign
 * changes because the reference moved, not because the torque crossed it.
 * Returns ST_FST_DYNAMIC while the flag is set, else the steady-state column
 * by the rotation direction (forward for omega >= 0).
 * FST's step passes T_ref without the anti-cogging feed-forward
 * (ctrl_refs_t.torque_ff): a known cancellation of the cogging that moves at
 * each encoder count is not a reference step (docs/anticogging.md, "FST").
 */
st_fst_mode_t st_fst_logic_update(st_fst_logic_t *l, q24_t tref, q24_t terr, q24_t omega);

extern const ctrl_desc_t ctrl_desc_bst;
extern const ctrl_desc_t ctrl_desc_mbst;
extern const ctrl_desc_t ctrl_desc_ast;
extern const ctrl_desc_t ctrl_desc_zst;
extern const ctrl_desc_t ctrl_desc_fst;

/* ---- Internal: shared by st_dtc.c (per sample) and st_dtc_config.c
 * (descriptors, defaults, init). Not for other modules. ---- */
void st_hyst_reset(void *state);
void st_hyst_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out);
void st_fst_reset(void *state);
void st_fst_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out);

#endif /* CONTROL_ST_DTC_H */
