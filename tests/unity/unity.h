/*
 * A small test harness with the API and output format of ThrowTheSwitch Unity
 * (https://github.com/ThrowTheSwitch/Unity), so that the same test files build
 * against upstream Unity (configure with -DUNITY_ROOT=<checkout>).
 *
 * Each test file defines setUp() and tearDown() (may be empty) and a main():
 *
 *     int main(void)
 *     {
 *         UNITY_BEGIN();
 *         RUN_TEST(test_something);
 *         return UNITY_END();   // number of failures
 *     }
 *
 * Failure messages use Unity's wording ("Expected 3 Was 4", "Values Not Within
 * Delta 1 Expected 100 Was 103", "Expected 9 to be less than 5", ...; a
 * _MESSAGE variant appends ". message", or for the boolean and NULL asserts
 * prints only the message).
 *
 * Output, one line per test, then a summary:
 *     file.c:12:test_something:PASS
 *     file.c:34:test_other:FAIL: Expected 3 Was 4. message
 *     file.c:56:test_third:IGNORE: message
 *     -----------------------
 *     3 Tests 1 Failures 1 Ignored
 *     FAIL
 *
 * A failing assertion ends the current test (longjmp back to RUN_TEST, as Unity
 * does); tearDown() still runs. Characters go out through unity_output_char()
 * (stdout on the host, the UART on the QEMU target), see unity_output_*.c.
 * Usable from C and C++ (in C++, a failing assertion skips destructors of the
 * test's locals, exactly as with upstream Unity).
 */
#ifndef PMSM_UNITY_H
#define PMSM_UNITY_H

#include <setjmp.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Defined by every test file. */
void setUp(void);
void tearDown(void);

typedef void (*UnityTestFunction)(void);

/* Output hook: one character / flush at the end. Provided by the port. */
void unity_output_char(int c);
void unity_output_flush(void);

/* Kinds of number display (subset of Unity's UNITY_DISPLAY_STYLE_T). */
typedef enum {
    UNITY_DISPLAY_STYLE_INT = 0,
    UNITY_DISPLAY_STYLE_UINT = 1,
    UNITY_DISPLAY_STYLE_HEX8 = 2,
    UNITY_DISPLAY_STYLE_HEX16 = 3,
    UNITY_DISPLAY_STYLE_HEX32 = 4,
    UNITY_DISPLAY_STYLE_HEX64 = 5,
    UNITY_DISPLAY_STYLE_CHAR = 6
} UNITY_DISPLAY_STYLE_T;

/* Comparison kinds for the threshold asserts. */
typedef enum {
    UNITY_GREATER_THAN = 0,
    UNITY_GREATER_OR_EQUAL = 1,
    UNITY_SMALLER_THAN = 2,
    UNITY_SMALLER_OR_EQUAL = 3
} UNITY_COMPARISON_T;

typedef struct {
    const char *TestFile;
    const char *CurrentTestName;
    unsigned long CurrentTestLineNumber;
    unsigned long NumberOfTests;
    unsigned long TestFailures;
    unsigned long TestIgnores;
    unsigned char CurrentTestFailed;
    unsigned char CurrentTestIgnored;
    jmp_buf AbortFrame;
} UnityState;

extern UnityState Unity;

void UnityBegin(const char *filename);
int UnityEnd(void);
void UnityDefaultTestRun(UnityTestFunction func, const char *name, int line);

/* Assertion back-ends (they do not return when the assertion fails). */
void UnityFail(const char *msg, unsigned long line);
void UnityIgnore(const char *msg, unsigned long line);
void UnityAssertEqualNumber(int64_t expected, int64_t actual, const char *msg, unsigned long line,
                            UNITY_DISPLAY_STYLE_T style);
void UnityAssertNumbersWithin(uint64_t delta, int64_t expected, int64_t actual, const char *msg,
                              unsigned long line, UNITY_DISPLAY_STYLE_T style);
void UnityAssertGreaterOrLess(int64_t threshold, int64_t actual, UNITY_COMPARISON_T compare,
                              const char *msg, unsigned long line, UNITY_DISPLAY_STYLE_T style);
void UnityAssertEqualIntArray(const void *expected, const void *actual, uint32_t num_elements,
                              unsigned size, const char *msg, unsigned long line,
                              UNITY_DISPLAY_STYLE_T style);
void UnityAssertEqualString(const char *expected, const char *actual, const char *msg,
                            unsigned long line);
void UnityAssertEqualMemory(const void *expected, const void *actual, uint32_t length,
                            const char *msg, unsigned long line);
void UnityAssertDoublesWithin(double delta, double expected, double actual, const char *msg,
                              unsigned long line);
void UnityAssertDoubleIsFinite(double actual, const char *msg, unsigned long line);

/* ---- Test running ------------------------------------------------------------------------ */

#define UNITY_BEGIN() UnityBegin(__FILE__)
#define UNITY_END() UnityEnd()
#define RUN_TEST(func) UnityDefaultTestRun(func, #func, __LINE__)
#define TEST_PROTECT() (setjmp(Unity.AbortFrame) == 0)
#define TEST_ABORT() longjmp(Unity.AbortFrame, 1)
#define TEST_LINE_NUM ((unsigned long)__LINE__)

#define TEST_FAIL_MESSAGE(message) UnityFail((message), TEST_LINE_NUM)
#define TEST_FAIL() UnityFail(NULL, TEST_LINE_NUM)
#define TEST_IGNORE_MESSAGE(message) UnityIgnore((message), TEST_LINE_NUM)
#define TEST_IGNORE() UnityIgnore(NULL, TEST_LINE_NUM)
#define TEST_PASS() longjmp(Unity.AbortFrame, 1)
#define TEST_MESSAGE(message) UnityMessage((message), TEST_LINE_NUM)
void UnityMessage(const char *msg, unsigned long line);

/* ---- Boolean ----------------------------------------------------------------------------- */

/* As in Unity: the _MESSAGE variants print only the message on failure. */
#define UNITY_TEST_ASSERT_(condition, line, message)                                               \
    do {                                                                                           \
        if (!(condition)) {                                                                        \
            UnityFail((message), (line));                                                          \
        }                                                                                          \
    } while (0)

#define TEST_ASSERT_MESSAGE(condition, message)                                                    \
    UNITY_TEST_ASSERT_(condition, TEST_LINE_NUM, message)
#define TEST_ASSERT(condition)                                                                     \
    UNITY_TEST_ASSERT_(condition, TEST_LINE_NUM, " Expression Evaluated To FALSE")
#define TEST_ASSERT_TRUE_MESSAGE(condition, message)                                               \
    UNITY_TEST_ASSERT_(condition, TEST_LINE_NUM, message)
#define TEST_ASSERT_TRUE(condition)                                                                \
    UNITY_TEST_ASSERT_(condition, TEST_LINE_NUM, " Expected TRUE Was FALSE")
#define TEST_ASSERT_FALSE_MESSAGE(condition, message)                                              \
    UNITY_TEST_ASSERT_(!(condition), TEST_LINE_NUM, message)
#define TEST_ASSERT_FALSE(condition)                                                               \
    UNITY_TEST_ASSERT_(!(condition), TEST_LINE_NUM, " Expected FALSE Was TRUE")
#define TEST_ASSERT_UNLESS(condition)                                                              \
    UNITY_TEST_ASSERT_(!(condition), TEST_LINE_NUM, " Expression Evaluated To TRUE")

/* ---- Integers (equality) ----------------------------------------------------------------- */

#define UNITY_EQ_INT_(e, a, m, style)                                                              \
    UnityAssertEqualNumber((int64_t)(e), (int64_t)(a), (m), TEST_LINE_NUM, style)
/* Unsigned / hex values are compared on their own width (as Unity does). */
#define UNITY_EQ_UINT_(type, e, a, m, style)                                                       \
    UnityAssertEqualNumber((int64_t)(type)(e), (int64_t)(type)(a), (m), TEST_LINE_NUM, style)

#define TEST_ASSERT_EQUAL_INT_MESSAGE(e, a, m) UNITY_EQ_INT_(e, a, m, UNITY_DISPLAY_STYLE_INT)
#define TEST_ASSERT_EQUAL_INT8_MESSAGE(e, a, m)                                                    \
    UNITY_EQ_INT_((int8_t)(e), (int8_t)(a), m, UNITY_DISPLAY_STYLE_INT)
#define TEST_ASSERT_EQUAL_INT16_MESSAGE(e, a, m)                                                   \
    UNITY_EQ_INT_((int16_t)(e), (int16_t)(a), m, UNITY_DISPLAY_STYLE_INT)
#define TEST_ASSERT_EQUAL_INT32_MESSAGE(e, a, m)                                                   \
    UNITY_EQ_INT_((int32_t)(e), (int32_t)(a), m, UNITY_DISPLAY_STYLE_INT)
#define TEST_ASSERT_EQUAL_INT64_MESSAGE(e, a, m) UNITY_EQ_INT_(e, a, m, UNITY_DISPLAY_STYLE_INT)
#define TEST_ASSERT_EQUAL_UINT_MESSAGE(e, a, m)                                                    \
    UNITY_EQ_UINT_(unsigned int, e, a, m, UNITY_DISPLAY_STYLE_UINT)
#define TEST_ASSERT_EQUAL_UINT8_MESSAGE(e, a, m)                                                   \
    UNITY_EQ_UINT_(uint8_t, e, a, m, UNITY_DISPLAY_STYLE_UINT)
#define TEST_ASSERT_EQUAL_UINT16_MESSAGE(e, a, m)                                                  \
    UNITY_EQ_UINT_(uint16_t, e, a, m, UNITY_DISPLAY_STYLE_UINT)
#define TEST_ASSERT_EQUAL_UINT32_MESSAGE(e, a, m)                                                  \
    UNITY_EQ_UINT_(uint32_t, e, a, m, UNITY_DISPLAY_STYLE_UINT)
#define TEST_ASSERT_EQUAL_HEX8_MESSAGE(e, a, m)                                                    \
    UNITY_EQ_UINT_(uint8_t, e, a, m, UNITY_DISPLAY_STYLE_HEX8)
#define TEST_ASSERT_EQUAL_HEX16_MESSAGE(e, a, m)                                                   \
    UNITY_EQ_UINT_(uint16_t, e, a, m, UNITY_DISPLAY_STYLE_HEX16)
#define TEST_ASSERT_EQUAL_HEX32_MESSAGE(e, a, m)                                                   \
    UNITY_EQ_UINT_(uint32_t, e, a, m, UNITY_DISPLAY_STYLE_HEX32)
#define TEST_ASSERT_EQUAL_UINT64_MESSAGE(e, a, m)                                                  \
    UNITY_EQ_UINT_(uint64_t, e, a, m, UNITY_DISPLAY_STYLE_UINT)
#define TEST_ASSERT_EQUAL_HEX64_MESSAGE(e, a, m)                                                   \
    UNITY_EQ_UINT_(uint64_t, e, a, m, UNITY_DISPLAY_STYLE_HEX64)
#define TEST_ASSERT_EQUAL_size_t_MESSAGE(e, a, m)                                                  \
    UNITY_EQ_UINT_(size_t, e, a, m, UNITY_DISPLAY_STYLE_UINT)
#define TEST_ASSERT_EQUAL_PTR_MESSAGE(e, a, m)                                                     \
    UNITY_EQ_UINT_(uintptr_t, (uintptr_t)(const void *)(e), (uintptr_t)(const void *)(a), m,       \
                   sizeof(void *) > 4u ? UNITY_DISPLAY_STYLE_HEX64 : UNITY_DISPLAY_STYLE_HEX32)
#define TEST_ASSERT_EQUAL_CHAR_MESSAGE(e, a, m)                                                    \
    UNITY_EQ_INT_((char)(e), (char)(a), m, UNITY_DISPLAY_STYLE_CHAR)
#define TEST_ASSERT_EQUAL_MESSAGE(e, a, m) TEST_ASSERT_EQUAL_INT_MESSAGE(e, a, m)
#define TEST_ASSERT_NOT_EQUAL_MESSAGE(e, a, m) UNITY_TEST_ASSERT_((e) != (a), TEST_LINE_NUM, m)

#define TEST_ASSERT_EQUAL_INT(e, a) TEST_ASSERT_EQUAL_INT_MESSAGE(e, a, NULL)
#define TEST_ASSERT_EQUAL_INT8(e, a) TEST_ASSERT_EQUAL_INT8_MESSAGE(e, a, NULL)
#define TEST_ASSERT_EQUAL_INT16(e, a) TEST_ASSERT_EQUAL_INT16_MESSAGE(e, a, NULL)
#define TEST_ASSERT_EQUAL_INT32(e, a) TEST_ASSERT_EQUAL_INT32_MESSAGE(e, a, NULL)
#define TEST_ASSERT_EQUAL_INT64(e, a) TEST_ASSERT_EQUAL_INT64_MESSAGE(e, a, NULL)
#define TEST_ASSERT_EQUAL_UINT(e, a) TEST_ASSERT_EQUAL_UINT_MESSAGE(e, a, NULL)
#define TEST_ASSERT_EQUAL_UINT8(e, a) TEST_ASSERT_EQUAL_UINT8_MESSAGE(e, a, NULL)
#define TEST_ASSERT_EQUAL_UINT16(e, a) TEST_ASSERT_EQUAL_UINT16_MESSAGE(e, a, NULL)
#define TEST_ASSERT_EQUAL_UINT32(e, a) TEST_ASSERT_EQUAL_UINT32_MESSAGE(e, a, NULL)
#define TEST_ASSERT_EQUAL_HEX8(e, a) TEST_ASSERT_EQUAL_HEX8_MESSAGE(e, a, NULL)
#define TEST_ASSERT_EQUAL_HEX16(e, a) TEST_ASSERT_EQUAL_HEX16_MESSAGE(e, a, NULL)
#define TEST_ASSERT_EQUAL_HEX32(e, a) TEST_ASSERT_EQUAL_HEX32_MESSAGE(e, a, NULL)
#define TEST_ASSERT_EQUAL_UINT64(e, a) TEST_ASSERT_EQUAL_UINT64_MESSAGE(e, a, NULL)
#define TEST_ASSERT_EQUAL_HEX64(e, a) TEST_ASSERT_EQUAL_HEX64_MESSAGE(e, a, NULL)
#define TEST_ASSERT_EQUAL_size_t(e, a) TEST_ASSERT_EQUAL_size_t_MESSAGE(e, a, NULL)
#define TEST_ASSERT_EQUAL_PTR(e, a) TEST_ASSERT_EQUAL_PTR_MESSAGE(e, a, NULL)
#define TEST_ASSERT_EQUAL_CHAR(e, a) TEST_ASSERT_EQUAL_CHAR_MESSAGE(e, a, NULL)
#define TEST_ASSERT_EQUAL(e, a) TEST_ASSERT_EQUAL_INT_MESSAGE(e, a, NULL)
#define TEST_ASSERT_NOT_EQUAL(e, a) TEST_ASSERT_NOT_EQUAL_MESSAGE(e, a, " Expected Not-Equal")

/* ---- Integers (within a delta): |actual - expected| <= delta ------------------------------ */

#define UNITY_WITHIN_INT_(type, d, e, a, m)                                                        \
    UnityAssertNumbersWithin((uint64_t)(d), (int64_t)(type)(e), (int64_t)(type)(a), (m),           \
                             TEST_LINE_NUM, UNITY_DISPLAY_STYLE_INT)
#define UNITY_WITHIN_UINT_(type, d, e, a, m, style)                                                \
    UnityAssertNumbersWithin((uint64_t)(d), (int64_t)(type)(e), (int64_t)(type)(a), (m),           \
                             TEST_LINE_NUM, style)

#define TEST_ASSERT_INT_WITHIN_MESSAGE(d, e, a, m) UNITY_WITHIN_INT_(int, d, e, a, m)
#define TEST_ASSERT_INT8_WITHIN_MESSAGE(d, e, a, m) UNITY_WITHIN_INT_(int8_t, d, e, a, m)
#define TEST_ASSERT_INT16_WITHIN_MESSAGE(d, e, a, m) UNITY_WITHIN_INT_(int16_t, d, e, a, m)
#define TEST_ASSERT_INT32_WITHIN_MESSAGE(d, e, a, m) UNITY_WITHIN_INT_(int32_t, d, e, a, m)
#define TEST_ASSERT_INT64_WITHIN_MESSAGE(d, e, a, m) UNITY_WITHIN_INT_(int64_t, d, e, a, m)
#define TEST_ASSERT_UINT_WITHIN_MESSAGE(d, e, a, m)                                                \
    UNITY_WITHIN_UINT_(unsigned int, d, e, a, m, UNITY_DISPLAY_STYLE_UINT)
#define TEST_ASSERT_UINT8_WITHIN_MESSAGE(d, e, a, m)                                               \
    UNITY_WITHIN_UINT_(uint8_t, d, e, a, m, UNITY_DISPLAY_STYLE_UINT)
#define TEST_ASSERT_UINT16_WITHIN_MESSAGE(d, e, a, m)                                              \
    UNITY_WITHIN_UINT_(uint16_t, d, e, a, m, UNITY_DISPLAY_STYLE_UINT)
#define TEST_ASSERT_UINT32_WITHIN_MESSAGE(d, e, a, m)                                              \
    UNITY_WITHIN_UINT_(uint32_t, d, e, a, m, UNITY_DISPLAY_STYLE_UINT)
#define TEST_ASSERT_HEX32_WITHIN_MESSAGE(d, e, a, m)                                               \
    UNITY_WITHIN_UINT_(uint32_t, d, e, a, m, UNITY_DISPLAY_STYLE_HEX32)

#define TEST_ASSERT_INT_WITHIN(d, e, a) TEST_ASSERT_INT_WITHIN_MESSAGE(d, e, a, NULL)
#define TEST_ASSERT_INT8_WITHIN(d, e, a) TEST_ASSERT_INT8_WITHIN_MESSAGE(d, e, a, NULL)
#define TEST_ASSERT_INT16_WITHIN(d, e, a) TEST_ASSERT_INT16_WITHIN_MESSAGE(d, e, a, NULL)
#define TEST_ASSERT_INT32_WITHIN(d, e, a) TEST_ASSERT_INT32_WITHIN_MESSAGE(d, e, a, NULL)
#define TEST_ASSERT_INT64_WITHIN(d, e, a) TEST_ASSERT_INT64_WITHIN_MESSAGE(d, e, a, NULL)
#define TEST_ASSERT_UINT_WITHIN(d, e, a) TEST_ASSERT_UINT_WITHIN_MESSAGE(d, e, a, NULL)
#define TEST_ASSERT_UINT8_WITHIN(d, e, a) TEST_ASSERT_UINT8_WITHIN_MESSAGE(d, e, a, NULL)
#define TEST_ASSERT_UINT16_WITHIN(d, e, a) TEST_ASSERT_UINT16_WITHIN_MESSAGE(d, e, a, NULL)
#define TEST_ASSERT_UINT32_WITHIN(d, e, a) TEST_ASSERT_UINT32_WITHIN_MESSAGE(d, e, a, NULL)
#define TEST_ASSERT_HEX32_WITHIN(d, e, a) TEST_ASSERT_HEX32_WITHIN_MESSAGE(d, e, a, NULL)

/* ---- Integers (thresholds): TEST_ASSERT_LESS_THAN(t, a) asserts a < t ----------------------
 * Failure: "Expected <a> to be less than <t>" (Unity's wording). */

#define UNITY_CMP_INT_(type, t, a, cmp, m)                                                         \
    UnityAssertGreaterOrLess((int64_t)(type)(t), (int64_t)(type)(a), cmp, (m), TEST_LINE_NUM,      \
                             UNITY_DISPLAY_STYLE_INT)
#define UNITY_CMP_UINT_(type, t, a, cmp, m)                                                        \
    UnityAssertGreaterOrLess((int64_t)(type)(t), (int64_t)(type)(a), cmp, (m), TEST_LINE_NUM,      \
                             UNITY_DISPLAY_STYLE_UINT)

#define TEST_ASSERT_GREATER_THAN_MESSAGE(t, a, m) UNITY_CMP_INT_(int, t, a, UNITY_GREATER_THAN, m)
#define TEST_ASSERT_GREATER_THAN_INT_MESSAGE(t, a, m)                                              \
    UNITY_CMP_INT_(int, t, a, UNITY_GREATER_THAN, m)
#define TEST_ASSERT_GREATER_THAN_INT32_MESSAGE(t, a, m)                                            \
    UNITY_CMP_INT_(int32_t, t, a, UNITY_GREATER_THAN, m)
#define TEST_ASSERT_GREATER_THAN_INT64_MESSAGE(t, a, m)                                            \
    UNITY_CMP_INT_(int64_t, t, a, UNITY_GREATER_THAN, m)
#define TEST_ASSERT_GREATER_THAN_UINT32_MESSAGE(t, a, m)                                           \
    UNITY_CMP_UINT_(uint32_t, t, a, UNITY_GREATER_THAN, m)
#define TEST_ASSERT_GREATER_OR_EQUAL_MESSAGE(t, a, m)                                              \
    UNITY_CMP_INT_(int, t, a, UNITY_GREATER_OR_EQUAL, m)
#define TEST_ASSERT_GREATER_OR_EQUAL_INT_MESSAGE(t, a, m)                                          \
    UNITY_CMP_INT_(int, t, a, UNITY_GREATER_OR_EQUAL, m)
#define TEST_ASSERT_GREATER_OR_EQUAL_INT32_MESSAGE(t, a, m)                                        \
    UNITY_CMP_INT_(int32_t, t, a, UNITY_GREATER_OR_EQUAL, m)
#define TEST_ASSERT_GREATER_OR_EQUAL_INT64_MESSAGE(t, a, m)                                        \
    UNITY_CMP_INT_(int64_t, t, a, UNITY_GREATER_OR_EQUAL, m)
#define TEST_ASSERT_GREATER_OR_EQUAL_UINT32_MESSAGE(t, a, m)                                       \
    UNITY_CMP_UINT_(uint32_t, t, a, UNITY_GREATER_OR_EQUAL, m)
#define TEST_ASSERT_LESS_THAN_MESSAGE(t, a, m) UNITY_CMP_INT_(int, t, a, UNITY_SMALLER_THAN, m)
#define TEST_ASSERT_LESS_THAN_INT_MESSAGE(t, a, m) UNITY_CMP_INT_(int, t, a, UNITY_SMALLER_THAN, m)
#define TEST_ASSERT_LESS_THAN_INT32_MESSAGE(t, a, m)                                               \
    UNITY_CMP_INT_(int32_t, t, a, UNITY_SMALLER_THAN, m)
#define TEST_ASSERT_LESS_THAN_INT64_MESSAGE(t, a, m)                                               \
    UNITY_CMP_INT_(int64_t, t, a, UNITY_SMALLER_THAN, m)
#define TEST_ASSERT_LESS_THAN_UINT32_MESSAGE(t, a, m)                                              \
    UNITY_CMP_UINT_(uint32_t, t, a, UNITY_SMALLER_THAN, m)
#define TEST_ASSERT_LESS_OR_EQUAL_MESSAGE(t, a, m)                                                 \
    UNITY_CMP_INT_(int, t, a, UNITY_SMALLER_OR_EQUAL, m)
#define TEST_ASSERT_LESS_OR_EQUAL_INT_MESSAGE(t, a, m)                                             \
    UNITY_CMP_INT_(int, t, a, UNITY_SMALLER_OR_EQUAL, m)
#define TEST_ASSERT_LESS_OR_EQUAL_INT32_MESSAGE(t, a, m)                                           \
    UNITY_CMP_INT_(int32_t, t, a, UNITY_SMALLER_OR_EQUAL, m)
#define TEST_ASSERT_LESS_OR_EQUAL_INT64_MESSAGE(t, a, m)                                           \
    UNITY_CMP_INT_(int64_t, t, a, UNITY_SMALLER_OR_EQUAL, m)
#define TEST_ASSERT_LESS_OR_EQUAL_UINT32_MESSAGE(t, a, m)                                          \
    UNITY_CMP_UINT_(uint32_t, t, a, UNITY_SMALLER_OR_EQUAL, m)

#define TEST_ASSERT_GREATER_THAN(t, a) TEST_ASSERT_GREATER_THAN_MESSAGE(t, a, NULL)
#define TEST_ASSERT_GREATER_THAN_INT(t, a) TEST_ASSERT_GREATER_THAN_INT_MESSAGE(t, a, NULL)
#define TEST_ASSERT_GREATER_THAN_INT32(t, a) TEST_ASSERT_GREATER_THAN_INT32_MESSAGE(t, a, NULL)
#define TEST_ASSERT_GREATER_THAN_INT64(t, a) TEST_ASSERT_GREATER_THAN_INT64_MESSAGE(t, a, NULL)
#define TEST_ASSERT_GREATER_THAN_UINT32(t, a) TEST_ASSERT_GREATER_THAN_UINT32_MESSAGE(t, a, NULL)
#define TEST_ASSERT_GREATER_OR_EQUAL(t, a) TEST_ASSERT_GREATER_OR_EQUAL_MESSAGE(t, a, NULL)
#define TEST_ASSERT_GREATER_OR_EQUAL_INT(t, a) TEST_ASSERT_GREATER_OR_EQUAL_INT_MESSAGE(t, a, NULL)
#define TEST_ASSERT_GREATER_OR_EQUAL_INT32(t, a)                                                   \
    TEST_ASSERT_GREATER_OR_EQUAL_INT32_MESSAGE(t, a, NULL)
#define TEST_ASSERT_GREATER_OR_EQUAL_INT64(t, a)                                                   \
    TEST_ASSERT_GREATER_OR_EQUAL_INT64_MESSAGE(t, a, NULL)
#define TEST_ASSERT_GREATER_OR_EQUAL_UINT32(t, a)                                                  \
    TEST_ASSERT_GREATER_OR_EQUAL_UINT32_MESSAGE(t, a, NULL)
#define TEST_ASSERT_LESS_THAN(t, a) TEST_ASSERT_LESS_THAN_MESSAGE(t, a, NULL)
#define TEST_ASSERT_LESS_THAN_INT(t, a) TEST_ASSERT_LESS_THAN_INT_MESSAGE(t, a, NULL)
#define TEST_ASSERT_LESS_THAN_INT32(t, a) TEST_ASSERT_LESS_THAN_INT32_MESSAGE(t, a, NULL)
#define TEST_ASSERT_LESS_THAN_INT64(t, a) TEST_ASSERT_LESS_THAN_INT64_MESSAGE(t, a, NULL)
#define TEST_ASSERT_LESS_THAN_UINT32(t, a) TEST_ASSERT_LESS_THAN_UINT32_MESSAGE(t, a, NULL)
#define TEST_ASSERT_LESS_OR_EQUAL(t, a) TEST_ASSERT_LESS_OR_EQUAL_MESSAGE(t, a, NULL)
#define TEST_ASSERT_LESS_OR_EQUAL_INT(t, a) TEST_ASSERT_LESS_OR_EQUAL_INT_MESSAGE(t, a, NULL)
#define TEST_ASSERT_LESS_OR_EQUAL_INT32(t, a) TEST_ASSERT_LESS_OR_EQUAL_INT32_MESSAGE(t, a, NULL)
#define TEST_ASSERT_LESS_OR_EQUAL_INT64(t, a) TEST_ASSERT_LESS_OR_EQUAL_INT64_MESSAGE(t, a, NULL)
#define TEST_ASSERT_LESS_OR_EQUAL_UINT32(t, a) TEST_ASSERT_LESS_OR_EQUAL_UINT32_MESSAGE(t, a, NULL)

/* ---- Arrays, strings, memory, pointers --------------------------------------------------- */

#define TEST_ASSERT_EQUAL_INT32_ARRAY_MESSAGE(e, a, n, m)                                          \
    UnityAssertEqualIntArray((const void *)(e), (const void *)(a), (uint32_t)(n), 4u, (m),         \
                             TEST_LINE_NUM, UNITY_DISPLAY_STYLE_INT)
#define TEST_ASSERT_EQUAL_INT16_ARRAY_MESSAGE(e, a, n, m)                                          \
    UnityAssertEqualIntArray((const void *)(e), (const void *)(a), (uint32_t)(n), 2u, (m),         \
                             TEST_LINE_NUM, UNITY_DISPLAY_STYLE_INT)
#define TEST_ASSERT_EQUAL_INT8_ARRAY_MESSAGE(e, a, n, m)                                           \
    UnityAssertEqualIntArray((const void *)(e), (const void *)(a), (uint32_t)(n), 1u, (m),         \
                             TEST_LINE_NUM, UNITY_DISPLAY_STYLE_INT)
#define TEST_ASSERT_EQUAL_UINT32_ARRAY_MESSAGE(e, a, n, m)                                         \
    UnityAssertEqualIntArray((const void *)(e), (const void *)(a), (uint32_t)(n), 4u, (m),         \
                             TEST_LINE_NUM, UNITY_DISPLAY_STYLE_UINT)
#define TEST_ASSERT_EQUAL_UINT16_ARRAY_MESSAGE(e, a, n, m)                                         \
    UnityAssertEqualIntArray((const void *)(e), (const void *)(a), (uint32_t)(n), 2u, (m),         \
                             TEST_LINE_NUM, UNITY_DISPLAY_STYLE_UINT)
#define TEST_ASSERT_EQUAL_UINT8_ARRAY_MESSAGE(e, a, n, m)                                          \
    UnityAssertEqualIntArray((const void *)(e), (const void *)(a), (uint32_t)(n), 1u, (m),         \
                             TEST_LINE_NUM, UNITY_DISPLAY_STYLE_UINT)
#define TEST_ASSERT_EQUAL_INT_ARRAY_MESSAGE(e, a, n, m)                                            \
    UnityAssertEqualIntArray((const void *)(e), (const void *)(a), (uint32_t)(n),                  \
                             (unsigned)sizeof(int), (m), TEST_LINE_NUM, UNITY_DISPLAY_STYLE_INT)
#define TEST_ASSERT_EQUAL_INT_ARRAY(e, a, n) TEST_ASSERT_EQUAL_INT_ARRAY_MESSAGE(e, a, n, NULL)
#define TEST_ASSERT_EQUAL_INT32_ARRAY(e, a, n) TEST_ASSERT_EQUAL_INT32_ARRAY_MESSAGE(e, a, n, NULL)
#define TEST_ASSERT_EQUAL_INT16_ARRAY(e, a, n) TEST_ASSERT_EQUAL_INT16_ARRAY_MESSAGE(e, a, n, NULL)
#define TEST_ASSERT_EQUAL_INT8_ARRAY(e, a, n) TEST_ASSERT_EQUAL_INT8_ARRAY_MESSAGE(e, a, n, NULL)
#define TEST_ASSERT_EQUAL_UINT32_ARRAY(e, a, n)                                                    \
    TEST_ASSERT_EQUAL_UINT32_ARRAY_MESSAGE(e, a, n, NULL)
#define TEST_ASSERT_EQUAL_UINT16_ARRAY(e, a, n)                                                    \
    TEST_ASSERT_EQUAL_UINT16_ARRAY_MESSAGE(e, a, n, NULL)
#define TEST_ASSERT_EQUAL_UINT8_ARRAY(e, a, n) TEST_ASSERT_EQUAL_UINT8_ARRAY_MESSAGE(e, a, n, NULL)

#define TEST_ASSERT_EQUAL_STRING_MESSAGE(e, a, m)                                                  \
    UnityAssertEqualString((const char *)(e), (const char *)(a), (m), TEST_LINE_NUM)
#define TEST_ASSERT_EQUAL_STRING(e, a) TEST_ASSERT_EQUAL_STRING_MESSAGE(e, a, NULL)
#define TEST_ASSERT_EQUAL_MEMORY_MESSAGE(e, a, len, m)                                             \
    UnityAssertEqualMemory((const void *)(e), (const void *)(a), (uint32_t)(len), (m),             \
                           TEST_LINE_NUM)
#define TEST_ASSERT_EQUAL_MEMORY(e, a, len) TEST_ASSERT_EQUAL_MEMORY_MESSAGE(e, a, len, NULL)

#define TEST_ASSERT_NULL_MESSAGE(p, m) UNITY_TEST_ASSERT_((p) == NULL, TEST_LINE_NUM, m)
#define TEST_ASSERT_NOT_NULL_MESSAGE(p, m) UNITY_TEST_ASSERT_((p) != NULL, TEST_LINE_NUM, m)
#define TEST_ASSERT_NULL(p) TEST_ASSERT_NULL_MESSAGE(p, " Expected NULL")
#define TEST_ASSERT_NOT_NULL(p) TEST_ASSERT_NOT_NULL_MESSAGE(p, " Expected Non-NULL")

/* ---- Floating point (host tests and config code only) ------------------------------------ */

#define TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(d, e, a, m)                                              \
    UnityAssertDoublesWithin((double)(d), (double)(e), (double)(a), (m), TEST_LINE_NUM)
#define TEST_ASSERT_DOUBLE_WITHIN(d, e, a) TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(d, e, a, NULL)
#define TEST_ASSERT_FLOAT_WITHIN_MESSAGE(d, e, a, m)                                               \
    UnityAssertDoublesWithin((double)(d), (double)(e), (double)(a), (m), TEST_LINE_NUM)
#define TEST_ASSERT_FLOAT_WITHIN(d, e, a) TEST_ASSERT_FLOAT_WITHIN_MESSAGE(d, e, a, NULL)
/* Unity's relative tolerances: UNITY_DOUBLE_PRECISION 1e-12, UNITY_FLOAT_PRECISION 1e-5. */
#define TEST_ASSERT_EQUAL_DOUBLE_MESSAGE(e, a, m)                                                  \
    UnityAssertDoublesWithin((double)(e)*1e-12, (double)(e), (double)(a), (m), TEST_LINE_NUM)
#define TEST_ASSERT_EQUAL_DOUBLE(e, a) TEST_ASSERT_EQUAL_DOUBLE_MESSAGE(e, a, NULL)
#define TEST_ASSERT_EQUAL_FLOAT_MESSAGE(e, a, m)                                                   \
    UnityAssertDoublesWithin((double)(float)(e)*1e-5, (double)(float)(e), (double)(float)(a), (m), \
                             TEST_LINE_NUM)
#define TEST_ASSERT_EQUAL_FLOAT(e, a) TEST_ASSERT_EQUAL_FLOAT_MESSAGE(e, a, NULL)
#define TEST_ASSERT_DOUBLE_IS_DETERMINATE_MESSAGE(a, m)                                            \
    UnityAssertDoubleIsFinite((double)(a), (m), TEST_LINE_NUM)
#define TEST_ASSERT_DOUBLE_IS_DETERMINATE(a) TEST_ASSERT_DOUBLE_IS_DETERMINATE_MESSAGE(a, NULL)

#ifdef __cplusplus
}
#endif

#endif /* PMSM_UNITY_H */
