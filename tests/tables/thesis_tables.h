/*
 * The switching tables of thesis chapter 4 and S1 Table 3, written out by hand
 * for sectors x = 1..6 (V_{x+n} expanded with the wrap of (4.14)). 0 = "ZVV"
 * in the thesis tables. Shared by the table tests and the C++ reference; the
 * implementation's own tables (control/st_tables.c) are not used here.
 */
#ifndef TESTS_TABLES_THESIS_TABLES_H
#define TESTS_TABLES_THESIS_TABLES_H

#include <stdint.h>

#if defined(__GNUC__)
#define TT_UNUSED __attribute__((unused))
#else
#define TT_UNUSED
#endif

/* ---- Table 4.1 (BST): [e_psi = 1, -1][e_T = 1, 0, -1][x - 1] ---- */
TT_UNUSED static const uint8_t BST[2][3][6] = {
    {{2, 3, 4, 5, 6, 1}, {0, 0, 0, 0, 0, 0}, {6, 1, 2, 3, 4, 5}},
    {{3, 4, 5, 6, 1, 2}, {0, 0, 0, 0, 0, 0}, {5, 6, 1, 2, 3, 4}},
};
/* ---- Table 4.3 (MBST), sectors (4.18) ---- */
TT_UNUSED static const uint8_t MBST[2][3][6] = {
    {{2, 3, 4, 5, 6, 1}, {0, 0, 0, 0, 0, 0}, {1, 2, 3, 4, 5, 6}},
    {{4, 5, 6, 1, 2, 3}, {0, 0, 0, 0, 0, 0}, {5, 6, 1, 2, 3, 4}},
};
/* ---- Table 4.4 (AST): [e_psi = 1, -1][e_T = 1, -1][x - 1] ---- */
TT_UNUSED static const uint8_t AST[2][2][6] = {
    {{2, 3, 4, 5, 6, 1}, {6, 1, 2, 3, 4, 5}},
    {{3, 4, 5, 6, 1, 2}, {5, 6, 1, 2, 3, 4}},
};
/* ---- Table 4.5 (ZST) ---- */
TT_UNUSED static const uint8_t ZST[2][2][6] = {
    {{2, 3, 4, 5, 6, 1}, {6, 1, 2, 3, 4, 5}},
    {{3, 4, 5, 6, 1, 2}, {0, 0, 0, 0, 0, 0}},
};
/* ---- Table 4.6 (FST): [T_err >= 0, < 0][psi_err >= 0, < 0][steady fwd, steady bwd,
 * dynamic][x - 1] ---- */
TT_UNUSED static const uint8_t FST[2][2][3][6] = {
    {
        {{2, 3, 4, 5, 6, 1}, {0, 0, 0, 0, 0, 0}, {2, 3, 4, 5, 6, 1}},
        {{3, 4, 5, 6, 1, 2}, {0, 0, 0, 0, 0, 0}, {3, 4, 5, 6, 1, 2}},
    },
    {
        {{0, 0, 0, 0, 0, 0}, {6, 1, 2, 3, 4, 5}, {6, 1, 2, 3, 4, 5}},
        {{0, 0, 0, 0, 0, 0}, {5, 6, 1, 2, 3, 4}, {5, 6, 1, 2, 3, 4}},
    },
};
/* ---- S1 Table 3 (book chapter), Phi = 1 / 0, tau = 1, 0, -1, FS1..FS6, with its
 * fixed zero vectors (7 = V7) ---- */
TT_UNUSED static const uint8_t S1_T3[2][3][6] = {
    {{2, 3, 4, 5, 6, 1}, {7, 0, 7, 0, 7, 0}, {6, 1, 2, 3, 4, 5}},
    {{3, 4, 5, 6, 1, 2}, {0, 7, 0, 7, 0, 7}, {5, 6, 1, 2, 3, 4}},
};
/* Table 4.2 switching states S1 S2 S3 of V0..V7 */
TT_UNUSED static const uint8_t LEGS[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                             {0, 1, 1}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}};

#endif /* TESTS_TABLES_THESIS_TABLES_H */
