/*
 * Switching tables of thesis chapter 4 (control/st_tables.h): for every sector
 * and every regulator state the lookup returns the vector the thesis table
 * lists. The expected arrays below are the thesis tables written out by hand
 * for x = 1..6 (V_{x+n} expanded with the wrap of (4.14)); 0 stands for "ZVV".
 * They do not use the implementation's offset tables (thesis_tables.h).
 * Also checked: BST equals S1 Table 3 (Luukko) including its zero vectors
 * when the zero vector follows the rule "one leg switches", and the rule
 * itself (ctrl_zero_after) against the switching states of Table 4.2.
 */
#include <stddef.h>

#include "st_tables.h"
#include "unity.h"
#include "vectors.h"

void setUp(void)
{
}
void tearDown(void)
{
}

#include "thesis_tables.h"

static const int E_PSI[2] = {1, -1};
static const int E_T3[3] = {1, 0, -1};
static const int E_T2[2] = {1, -1};

static void test_bst_table_4_1(void)
{
    for (uint8_t x = 1; x <= 6; x++) {
        for (int r = 0; r < 2; r++) {
            for (int c = 0; c < 3; c++) {
                TEST_ASSERT_EQUAL_UINT8(BST[r][c][x - 1], st_lookup_bst(x, E_PSI[r], E_T3[c]));
            }
        }
    }
}

static void test_mbst_table_4_3(void)
{
    for (uint8_t x = 1; x <= 6; x++) {
        for (int r = 0; r < 2; r++) {
            for (int c = 0; c < 3; c++) {
                TEST_ASSERT_EQUAL_UINT8(MBST[r][c][x - 1], st_lookup_mbst(x, E_PSI[r], E_T3[c]));
            }
        }
    }
}

static void test_ast_zst_tables_4_4_4_5(void)
{
    for (uint8_t x = 1; x <= 6; x++) {
        for (int r = 0; r < 2; r++) {
            for (int c = 0; c < 2; c++) {
                TEST_ASSERT_EQUAL_UINT8(AST[r][c][x - 1], st_lookup_ast(x, E_PSI[r], E_T2[c]));
                TEST_ASSERT_EQUAL_UINT8(ZST[r][c][x - 1], st_lookup_zst(x, E_PSI[r], E_T2[c]));
            }
        }
    }
}

static void test_fst_table_4_6(void)
{
    static const st_fst_mode_t modes[3] = {ST_FST_STEADY_FWD, ST_FST_STEADY_BWD, ST_FST_DYNAMIC};
    for (uint8_t x = 1; x <= 6; x++) {
        for (int t = 0; t < 2; t++) {
            for (int f = 0; f < 2; f++) {
                for (int m = 0; m < 3; m++) {
                    TEST_ASSERT_EQUAL_UINT8(FST[t][f][m][x - 1],
                                            st_lookup_fst(x, t == 0, f == 0, modes[m]));
                }
            }
        }
    }
}

static int legs_changed(uint8_t a, uint8_t b)
{
    return (LEGS[a][0] != LEGS[b][0]) + (LEGS[a][1] != LEGS[b][1]) + (LEGS[a][2] != LEGS[b][2]);
}

/* After each vector, the zero vector switches exactly one leg (none after a zero vector). */
static void test_zero_after_switches_one_leg(void)
{
    for (uint8_t v = 0; v <= 7; v++) {
        const uint8_t z = ctrl_zero_after(v);
        TEST_ASSERT_TRUE(z == 0u || z == 7u);
        TEST_ASSERT_EQUAL_INT((v == 0u || v == 7u) ? 0 : 1, legs_changed(v, z));
        TEST_ASSERT_EQUAL_UINT8((v == 0u || v == 7u) ? v : z, z); /* V0 after V0, V7 after V7 */
    }
}

/* BST with the one-leg zero-vector rule reproduces S1 Table 3, zero vectors
 * included, when the zero vector follows the row's torque-increasing vector
 * (the usual sequence: increase until Te reaches Tref, then hold). */
static void test_bst_equals_s1_table_3(void)
{
    for (uint8_t x = 1; x <= 6; x++) {
        for (int r = 0; r < 2; r++) {
            TEST_ASSERT_EQUAL_UINT8(S1_T3[r][0][x - 1], st_lookup_bst(x, E_PSI[r], 1));
            TEST_ASSERT_EQUAL_UINT8(S1_T3[r][2][x - 1], st_lookup_bst(x, E_PSI[r], -1));
            TEST_ASSERT_EQUAL_UINT8(ST_ZVV, st_lookup_bst(x, E_PSI[r], 0));
            const uint8_t prev = st_lookup_bst(x, E_PSI[r], 1);
            TEST_ASSERT_EQUAL_UINT8(S1_T3[r][1][x - 1], ctrl_zero_after(prev));
        }
    }
}

/* Physics of Fig. 4.1(a), independent of any transcription: at the centre of
 * sector x, theta = (x-1) pi/3, an active vector V_i at (i-1) pi/3 changes |psi|
 * with the sign of cos((i-x) pi/3) and the load angle (torque, rotor flux
 * lagging) with the sign of sin((i-x) pi/3). BST's entries must agree with the
 * regulator outputs they serve. Signs from the angle difference d = i - x:
 * cos > 0 for d = 0, 1, 5; sin > 0 for d = 1, 2. */
static void test_bst_ast_directions(void)
{
    static const int cos_sign[6] = {1, 1, -1, -1, -1, 1};
    static const int sin_sign[6] = {0, 1, 1, 0, -1, -1};
    for (uint8_t x = 1; x <= 6; x++) {
        for (int r = 0; r < 2; r++) {
            for (int c = 0; c < 2; c++) {
                const uint8_t v = st_lookup_ast(x, E_PSI[r], E_T2[c]);
                const int d = ((int)v - (int)x + 6) % 6;
                TEST_ASSERT_EQUAL_INT(E_PSI[r], cos_sign[d]);
                TEST_ASSERT_EQUAL_INT(E_T2[c], sin_sign[d]);
            }
        }
    }
}

static void test_bad_input(void)
{
    TEST_ASSERT_EQUAL_UINT8(ST_ZVV, st_lookup_bst(0, 1, 1));
    TEST_ASSERT_EQUAL_UINT8(ST_ZVV, st_lookup_bst(7, 1, 1));
    TEST_ASSERT_EQUAL_UINT8(ST_ZVV, st_lookup_mbst(200, 1, 1));
    TEST_ASSERT_EQUAL_UINT8(ST_ZVV, st_lookup_ast(0, 1, 1));
    TEST_ASSERT_EQUAL_UINT8(ST_ZVV, st_lookup_zst(9, 1, 1));
    TEST_ASSERT_EQUAL_UINT8(ST_ZVV, st_lookup_fst(0, 1, 1, ST_FST_DYNAMIC));
    TEST_ASSERT_EQUAL_UINT8(ST_ZVV, st_lookup_fst(1, 1, 1, (st_fst_mode_t)7));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_bst_table_4_1);
    RUN_TEST(test_mbst_table_4_3);
    RUN_TEST(test_ast_zst_tables_4_4_4_5);
    RUN_TEST(test_fst_table_4_6);
    RUN_TEST(test_zero_after_switches_one_leg);
    RUN_TEST(test_bst_equals_s1_table_3);
    RUN_TEST(test_bst_ast_directions);
    RUN_TEST(test_bad_input);
    return UNITY_END();
}
