/*
 * Switching tables of chapter 4 as pure lookups (no state).
 *
 * Each function returns the active vector index 1..6 (V_{x+n} with the wrap of
 * (4.14)), or ST_ZVV when the table lists a zero vector; the caller then picks
 * V0 or V7 with ctrl_zero_after() (one leg switches). An out-of-range sector
 * gives ST_ZVV (the safe choice: no active voltage).
 *
 * Regulator outputs: e_psi, e_t two-level read "> 0" as +1 and "<= 0" as -1;
 * the three-level e_t of BST/MBST reads the sign (+1, 0, -1).
 */
#ifndef CONTROL_ST_TABLES_H
#define CONTROL_ST_TABLES_H

#include <stdint.h>

#define ST_ZVV 0u /* "a zero vector": V0 or V7 decided by the previous vector */

/* Table 4.1 (= S1 Table 3), sector x by (4.5). e_t three-level. */
uint8_t st_lookup_bst(uint8_t x, int e_psi, int e_t);

/* Table 4.3, sector x by (4.18) (ctrl_sector_mbst). e_t three-level. */
uint8_t st_lookup_mbst(uint8_t x, int e_psi, int e_t);

/* Table 4.4, sector x by (4.5). e_t two-level. */
uint8_t st_lookup_ast(uint8_t x, int e_psi, int e_t);

/* Table 4.5, sector x by (4.5). e_t two-level. */
uint8_t st_lookup_zst(uint8_t x, int e_psi, int e_t);

/* Operating states of the flexible table, Table 4.6 columns. */
typedef enum {
    ST_FST_STEADY_FWD = 0, /* steady state, forward rotation (omega >= 0) */
    ST_FST_STEADY_BWD = 1, /* steady state, backward rotation (omega < 0) */
    ST_FST_DYNAMIC = 2     /* after a reference step: active vectors only */
} st_fst_mode_t;

/* Table 4.6, sector x by (4.5); t_err_nonneg = (T_err >= 0),
 * psi_err_nonneg = (psi_err >= 0). An invalid mode gives ST_ZVV. */
uint8_t st_lookup_fst(uint8_t x, int t_err_nonneg, int psi_err_nonneg, st_fst_mode_t mode);

#endif /* CONTROL_ST_TABLES_H */
