/*
 * Self-test of the Unity-API harness: every assertion macro that the project
 * uses must pass on values that satisfy it (this file), and fail with Unity's
 * message on values that do not (test_harness_fail.c, checked by a script).
 */
#include <stddef.h>
#include <stdint.h>

#include "unity.h"

static int setup_calls;
static int teardown_calls;

void setUp(void)
{
    setup_calls++;
}

void tearDown(void)
{
    teardown_calls++;
}

static void test_booleans(void)
{
    TEST_ASSERT_TRUE(1 + 1 == 2);
    TEST_ASSERT_FALSE(1 + 1 == 3);
    TEST_ASSERT(5 > 4);
    TEST_ASSERT_TRUE_MESSAGE(1, "true");
    TEST_ASSERT_FALSE_MESSAGE(0, "false");
}

static void test_integers(void)
{
    TEST_ASSERT_EQUAL_INT(-7, -7);
    TEST_ASSERT_EQUAL(3, 3);
    TEST_ASSERT_EQUAL_INT32(INT32_MIN, INT32_MIN);
    TEST_ASSERT_EQUAL_INT64(INT64_MAX, INT64_MAX);
    TEST_ASSERT_EQUAL_UINT32(UINT32_MAX, 0xFFFFFFFFu);
    TEST_ASSERT_EQUAL_UINT8(255u, (uint8_t)0xFFu);
    TEST_ASSERT_EQUAL_HEX32(0xDEADBEEFu, 0xDEADBEEFu);
    TEST_ASSERT_EQUAL_INT32_MESSAGE(1, 1, "msg");
    TEST_ASSERT_EQUAL_UINT32_MESSAGE(2u, 2u, "msg");
    TEST_ASSERT_NOT_EQUAL(1, 2);
    TEST_ASSERT_EQUAL_UINT64(UINT64_MAX, UINT64_MAX);
    TEST_ASSERT_EQUAL_HEX64(0x0123456789ABCDEFull, 0x0123456789ABCDEFull);
    TEST_ASSERT_EQUAL_size_t(sizeof(int32_t), 4u);
    TEST_ASSERT_EQUAL_PTR(&setup_calls, &setup_calls);
    TEST_ASSERT_EQUAL_DOUBLE(1.0 / 3.0, 1.0 / 3.0);
    TEST_ASSERT_EQUAL_FLOAT(0.1f, 0.1f);
}

static void test_within(void)
{
    TEST_ASSERT_INT32_WITHIN(2, 100, 102);
    TEST_ASSERT_INT32_WITHIN(2, 100, 98);
    /* The difference of the extremes does not fit int32_t: must not overflow. */
    TEST_ASSERT_INT32_WITHIN(UINT32_MAX, INT32_MIN, INT32_MAX);
    TEST_ASSERT_INT_WITHIN(0, 5, 5);
    TEST_ASSERT_UINT32_WITHIN(1u, 0xFFFFFFFFu, 0xFFFFFFFEu);
    TEST_ASSERT_INT64_WITHIN(10, INT64_MIN + 5, INT64_MIN);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 0.1 + 0.2, 0.3);
    TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(0.5, 1.0, 1.4, "msg");
    TEST_ASSERT_FLOAT_WITHIN(0.01f, 2.0f, 2.005f);
}

static void test_thresholds(void)
{
    TEST_ASSERT_LESS_THAN(10, 9);
    TEST_ASSERT_GREATER_THAN(10, 11);
    TEST_ASSERT_LESS_THAN_INT32(INT32_MIN + 1, INT32_MIN);
    TEST_ASSERT_GREATER_THAN_INT32(-1, 0);
    TEST_ASSERT_LESS_OR_EQUAL(3, 3);
    TEST_ASSERT_GREATER_OR_EQUAL(3, 3);
    TEST_ASSERT_LESS_THAN_UINT32(0x80000000u, 0x7FFFFFFFu);
}

static void test_arrays_strings_pointers(void)
{
    const int32_t a[4] = {1, -2, INT32_MAX, INT32_MIN};
    const int32_t b[4] = {1, -2, INT32_MAX, INT32_MIN};
    static const char hello[] = "hello";
    const int c[2] = {-1, 1};
    TEST_ASSERT_EQUAL_INT32_ARRAY(a, b, 4);
    TEST_ASSERT_EQUAL_INT_ARRAY(c, c, 2);
    TEST_ASSERT_EQUAL_STRING("hello", hello);
    TEST_ASSERT_NOT_NULL(hello);
    TEST_ASSERT_NULL(NULL);
    TEST_ASSERT_EQUAL_MEMORY(a, b, sizeof a);
}

static void test_ignored(void)
{
    TEST_IGNORE_MESSAGE("this test is ignored on purpose");
    TEST_FAIL_MESSAGE("not reached: IGNORE ends the test");
}

static int fixture_before;

static void test_fixture_runs_around_each_test(void)
{
    /* setUp ran once per test so far, tearDown once per completed test. */
    TEST_ASSERT_EQUAL_INT(fixture_before + 1, setup_calls);
    TEST_ASSERT_EQUAL_INT(fixture_before, teardown_calls);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_booleans);
    RUN_TEST(test_integers);
    RUN_TEST(test_within);
    RUN_TEST(test_thresholds);
    RUN_TEST(test_arrays_strings_pointers);
    RUN_TEST(test_ignored);
    fixture_before = setup_calls;
    RUN_TEST(test_fixture_runs_around_each_test);
    return UNITY_END();
}
