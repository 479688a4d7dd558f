/*
 * Deliberately failing tests: the check script (tools/cmake/pmsm_expect_fail.cmake)
 * runs this binary and asserts that each failure is reported in Unity's format,
 * that a failing assertion ends its test (the statement after it never runs),
 * that the summary counts 10 tests / 9 failures / 0 ignored, and that the exit
 * status is non-zero. The expected lines are Unity's wording (upstream unity.c).
 */
#include <stddef.h>
#include <stdint.h>

#include "unity.h"

static volatile int after_failure;

void setUp(void)
{
}

void tearDown(void)
{
}

static void test_equal_fails(void)
{
    TEST_ASSERT_EQUAL_INT32(3, 4);
    after_failure = 1; /* must not run */
}

static void test_within_fails(void)
{
    TEST_ASSERT_INT32_WITHIN_MESSAGE(1, 100, 103, "delta check");
}

static void test_explicit_fail(void)
{
    TEST_FAIL_MESSAGE("explicit failure");
}

static void test_less_than_fails(void)
{
    TEST_ASSERT_LESS_THAN_INT32(5, 9);
}

static void test_double_fails(void)
{
    TEST_ASSERT_DOUBLE_WITHIN(0.001, 1.5, 1.25);
}

static void test_double_format(void)
{
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 1e9, -1e-5);
}

static void test_true_message_fails(void)
{
    TEST_ASSERT_TRUE_MESSAGE(0, "flag not set");
}

static void test_not_null_fails(void)
{
    TEST_ASSERT_NOT_NULL(NULL);
}

static void test_array_fails(void)
{
    const int32_t e[3] = {1, 2, 3};
    const int32_t a[3] = {1, 2, -3};
    TEST_ASSERT_EQUAL_INT32_ARRAY(e, a, 3);
}

static void test_after_failure_not_run(void)
{
    TEST_ASSERT_EQUAL_INT(0, after_failure);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_equal_fails);
    RUN_TEST(test_within_fails);
    RUN_TEST(test_explicit_fail);
    RUN_TEST(test_less_than_fails);
    RUN_TEST(test_double_fails);
    RUN_TEST(test_double_format);
    RUN_TEST(test_true_message_fails);
    RUN_TEST(test_not_null_fails);
    RUN_TEST(test_array_fails);
    RUN_TEST(test_after_failure_not_run);
    return UNITY_END();
}
