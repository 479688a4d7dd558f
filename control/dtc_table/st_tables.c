/* Switching tables of thesis chapter 4, stored as the offset n of V_{x+n}. */
#include "st_tables.h"

#include "vectors.h"

#define Z 0xFFu /* table entry "ZVV" */

/* [flux row: 0 = e_psi 1, 1 = e_psi -1][torque column] */
static const uint8_t bst[2][3] = {
    /* e_T = 1, 0, -1 */
    {1u, Z, 5u}, /* e_psi = 1: V_{x+1}, ZVV, V_{x+5} (Table 4.1) */
    {2u, Z, 4u}, /* e_psi = -1: V_{x+2}, ZVV, V_{x+4} */
};
static const uint8_t mbst[2][3] = {
    {1u, Z, 0u}, /* V_{x+1}, ZVV, V_x (Table 4.3) */
    {3u, Z, 4u}, /* V_{x+3}, ZVV, V_{x+4} */
};
static const uint8_t ast[2][2] = {
    /* e_T = 1, -1 */
    {1u, 5u}, /* Table 4.4 */
    {2u, 4u},
};
static const uint8_t zst[2][2] = {
    {1u, 5u}, /* Table 4.5 */
    {2u, Z},
};
/* [torque row: 0 = T_err >= 0, 1 = T_err < 0][flux row][mode] (Table 4.6) */
static const uint8_t fst[2][2][3] = {
    /* steady fwd, steady bwd, dynamic */
    {{1u, Z, 1u}, {2u, Z, 2u}},
    {{Z, 5u, 5u}, {Z, 4u, 4u}},
};

static uint8_t entry(uint8_t x, uint8_t n)
{
    if (x < 1u || x > 6u || n == Z) {
        return ST_ZVV;
    }
    return ctrl_vec_offset(x, n); /* every offset in the tables is 0..5 */
}

static unsigned col3(int e_t)
{
    return e_t > 0 ? 0u : (e_t == 0 ? 1u : 2u);
}

static unsigned row2(int e)
{
    return e > 0 ? 0u : 1u;
}

uint8_t st_lookup_bst(uint8_t x, int e_psi, int e_t)
{
    return entry(x, bst[row2(e_psi)][col3(e_t)]);
}

uint8_t st_lookup_mbst(uint8_t x, int e_psi, int e_t)
{
    return entry(x, mbst[row2(e_psi)][col3(e_t)]);
}

uint8_t st_lookup_ast(uint8_t x, int e_psi, int e_t)
{
    return entry(x, ast[row2(e_psi)][row2(e_t)]);
}

uint8_t st_lookup_zst(uint8_t x, int e_psi, int e_t)
{
    return entry(x, zst[row2(e_psi)][row2(e_t)]);
}

uint8_t st_lookup_fst(uint8_t x, int t_err_nonneg, int psi_err_nonneg, st_fst_mode_t mode)
{
    const unsigned m = (unsigned)mode;
    if (m > 2u) {
        return ST_ZVV;
    }
    return entry(x, fst[t_err_nonneg ? 0u : 1u][psi_err_nonneg ? 0u : 1u][m]);
}
