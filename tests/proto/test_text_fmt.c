/*
 * The firmware's text formatter (text_fmt.h): the conversions the messages
 * use, C's snprintf contract (length of the whole text, truncation, NUL), and
 * a real configuration message carrying its value's digits. In the cm4 build
 * this test links libc's snprintf/vsnprintf replaced by the formatter
 * (libc_small.c), as the B-G431B-ESC1 image does: there the message check runs
 * on the target's newlib-nano, whose own printf would print %g as nothing.
 */
#include <limits.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "speed_loop.h"
#include "text_fmt.h"
#include "unity.h"

void setUp(void)
{
}

void tearDown(void)
{
}

static void assert_fmt(const char *want, const char *fmt, ...)
{
    char buf[96];
    va_list ap;
    va_start(ap, fmt);
    const int n = text_vformat(buf, sizeof buf, fmt, ap);
    va_end(ap);
    TEST_ASSERT_EQUAL_STRING(want, buf);
    TEST_ASSERT_EQUAL_INT((int)strlen(want), n);
}

/* The expected texts are C's own for these arguments (C11 7.21.6.1): the
 * formatter agrees with snprintf wherever cmd_num_format's form coincides
 * with %g's (plain decimal here). */
static void test_conversions(void)
{
    assert_fmt("R_s = 0.01235 Ohm outside [0, 10]", "%s = %.4g %s outside [%.4g, %.4g]", "R_s",
               0.0123456, "Ohm", 0.0, 10.0);
    assert_fmt("inertia -0.5 kg", "inertia %g kg", -0.5);
    assert_fmt("1234.57", "%g", 1234.5678);
    assert_fmt("3", "%.1g", 3.14159);
    assert_fmt("3", "%.0g", 3.14159);
    assert_fmt("0.000125", "%g", 0.000125);
    assert_fmt("-2147483648 4294967295 ff", "%d %u %x", INT_MIN, UINT_MAX, 255u);
    assert_fmt("-9223372036854775808 18446744073709551615", "%lld %llu", LLONG_MIN, ULLONG_MAX);
    assert_fmt("-7 7 12", "%ld %lu %zu", -7L, 7UL, (size_t)12);
    assert_fmt("100 % a", "100 %% %c", 'a');
    assert_fmt("ab", "%.2s", "abc");
}

/* Not supported (flags, widths): shown as written, so a message never loses
 * text silently. */
static void test_unsupported_visible(void)
{
    assert_fmt("[%5d]", "[%5d]");
    assert_fmt("x%", "x%");
}

static void test_truncation(void)
{
    char buf[6];
    memset(buf, 'Z', sizeof buf);
    const int n = text_format(buf, sizeof buf, "value %g", 12.5);
    TEST_ASSERT_EQUAL_INT(10, n); /* the whole text's length */
    TEST_ASSERT_EQUAL_STRING("value", buf);
    TEST_ASSERT_EQUAL_INT(3, text_format(NULL, 0, "%d", 123));
    char one[1] = {'Z'};
    TEST_ASSERT_EQUAL_INT(2, text_format(one, sizeof one, "ab"));
    TEST_ASSERT_EQUAL_CHAR('\0', one[0]);
}

/* A configuration message with a value, through libc's vsnprintf (the
 * formatter itself in the target builds): its digits are in the text. */
static void test_message_carries_value(void)
{
    ctrl_machine_t m;
    memset(&m, 0, sizeof m);
    m.inertia_kgm2 = -0.0025;
    fw_speed_design_t d;
    memset(&d, 0, sizeof d);
    char why[128] = "";
    TEST_ASSERT_NOT_EQUAL(0, fw_speed_loop_design(&d, &m, 1000.0, 200.0, why, sizeof why));
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(why, "inertia -0.0025 kg*m^2"), why);
    char buf[32];
    TEST_ASSERT_EQUAL_INT(6, snprintf(buf, sizeof buf, "v=%.4g V", 12.0));
    TEST_ASSERT_EQUAL_STRING("v=12 V", buf);
}

/* strcmp (libc_small.c's in the target builds): C's contract, characters
 * compared as unsigned char. */
static void test_strcmp(void)
{
    TEST_ASSERT_EQUAL_INT(0, strcmp("drr_d1", "drr_d1"));
    TEST_ASSERT_TRUE(strcmp("drr", "drr_d1") < 0);
    TEST_ASSERT_TRUE(strcmp("foc_hyst", "foc") > 0);
    TEST_ASSERT_TRUE(strcmp("a\xff", "a\x01") > 0);
    TEST_ASSERT_TRUE(strcmp("", "x") < 0);
}

/* strlen, strcpy, strncpy (libc_small.c's in the target builds): C's
 * contract. Called through volatile pointers, so that the compiler cannot
 * fold them into constants. */
static void test_str_copy_length(void)
{
    size_t (*volatile len)(const char *) = strlen;
    char *(*volatile cpy)(char *, const char *) = strcpy;
    char *(*volatile ncpy)(char *, const char *, size_t) = strncpy;
    char buf[8];
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)len(""));
    TEST_ASSERT_EQUAL_UINT32(7u, (uint32_t)len("drr_d1x"));
    memset(buf, 'x', sizeof buf);
    TEST_ASSERT_EQUAL_PTR(buf, cpy(buf, "motor"));
    TEST_ASSERT_EQUAL_STRING("motor", buf);
    TEST_ASSERT_EQUAL_CHAR('x', buf[6]); /* nothing past the null */
    /* shorter source: the rest of n filled with nulls, nothing beyond n */
    memset(buf, 'x', sizeof buf);
    TEST_ASSERT_EQUAL_PTR(buf, ncpy(buf, "ab", 5u));
    TEST_ASSERT_EQUAL_MEMORY("ab\0\0\0xxx", buf, sizeof buf);
    /* longer source: n characters, no null */
    memset(buf, 'x', sizeof buf);
    (void)ncpy(buf, "abcdefg", 3u);
    TEST_ASSERT_EQUAL_MEMORY("abcxxxxx", buf, sizeof buf);
    (void)ncpy(buf, "q", 0u);
    TEST_ASSERT_EQUAL_CHAR('a', buf[0]);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_conversions);
    RUN_TEST(test_unsupported_visible);
    RUN_TEST(test_truncation);
    RUN_TEST(test_message_carries_value);
    RUN_TEST(test_strcmp);
    RUN_TEST(test_str_copy_length);
    return UNITY_END();
}
