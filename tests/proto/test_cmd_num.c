/*
 * Strict decimal parser and formatter: the grammar of cmd_num.h, exactness of
 * the decimal representation, limits, and round trips through the formatter.
 */
#include <string.h>

#include "cmd_num.h"
#include "unity.h"

void setUp(void)
{
}

void tearDown(void)
{
}

static cmd_num_status_t parse(const char *s, cmd_num_t *n)
{
    return cmd_num_parse(s, strlen(s), n);
}

static void assert_num(const char *s, int64_t mant, int32_t exp10)
{
    cmd_num_t n = {123, 456};
    TEST_ASSERT_EQUAL_INT_MESSAGE(CMD_NUM_OK, parse(s, &n), s);
    TEST_ASSERT_EQUAL_INT64_MESSAGE(mant, n.mant, s);
    TEST_ASSERT_EQUAL_INT32_MESSAGE(exp10, n.exp10, s);
}

static void assert_bad(const char *s, cmd_num_status_t want)
{
    cmd_num_t n = {123, 456};
    TEST_ASSERT_EQUAL_INT_MESSAGE(want, parse(s, &n), s);
    /* the output is untouched on error */
    TEST_ASSERT_EQUAL_INT64(123, n.mant);
    TEST_ASSERT_EQUAL_INT32(456, n.exp10);
}

static void test_accepts_grammar(void)
{
    assert_num("5", 5, 0);
    assert_num("-0.25", -25, -2);
    assert_num(".5", 5, -1);
    assert_num("5.", 5, 0);
    assert_num("+007", 7, 0);
    assert_num("1e3", 1, 3);
    assert_num("2.5E-3", 25, -4);
    assert_num("-1.5e+2", -15, 1);
    assert_num("1200", 12, 2); /* trailing zeros move to the exponent, exactly */
    assert_num("0.000001", 1, -6);
    assert_num("0", 0, 0);
    assert_num("-0.0", 0, 0);
    assert_num("0e999999999", 0, 0); /* zero is zero whatever the exponent */
    assert_num("0.123456789012345678", 123456789012345678, -18); /* 18 digits */
    assert_num("1234567890123456780000e-7", 123456789012345678, -3);
    assert_num("00000000000000000000000000001", 1, 0); /* leading zeros are free */
    assert_num("1e15", 1, 15);
    assert_num("-1e15", -1, 15);
    assert_num("1e-15", 1, -15);
    assert_num("999999999999999.9", 9999999999999999, -1);
}

static void test_rejects_syntax(void)
{
    static const char *const bad[] = {"",      "+",     "-",     ".",   "--1",  "+-1",   "-+1",
                                      "1e",    "1e+",   "1e-",   "e5",  ".e5",  "1.2.3", "0x10",
                                      "inf",   "nan",   "-inf",  "NaN", "1 ",   " 1",    "1,5",
                                      "1_000", "1e5.0", "1e1e1", "5-",  "1..2", "١"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        assert_bad(bad[i], CMD_NUM_SYNTAX);
    }
    /* NULL arguments */
    cmd_num_t n;
    TEST_ASSERT_EQUAL_INT(CMD_NUM_SYNTAX, cmd_num_parse(NULL, 0, &n));
    TEST_ASSERT_EQUAL_INT(CMD_NUM_SYNTAX, cmd_num_parse("1", 1, NULL));
    /* length is honoured: "12" of "123" */
    TEST_ASSERT_EQUAL_INT(CMD_NUM_OK, cmd_num_parse("123", 2, &n));
    TEST_ASSERT_EQUAL_INT64(12, n.mant);
}

static void test_rejects_range(void)
{
    assert_bad("1e999", CMD_NUM_RANGE);
    assert_bad("-1e999", CMD_NUM_RANGE);
    assert_bad("1e-999", CMD_NUM_RANGE);
    assert_bad("1e16", CMD_NUM_RANGE);
    assert_bad("1.0000000001e15", CMD_NUM_RANGE);
    assert_bad("1e-16", CMD_NUM_RANGE);
    assert_bad("9.99e-16", CMD_NUM_RANGE);
    assert_bad("1234567890123456789", CMD_NUM_RANGE); /* 19 significant digits */
    assert_bad("0.1234567890123456789", CMD_NUM_RANGE);
    assert_bad("1e99999999999999999999", CMD_NUM_RANGE); /* exponent saturates */
}

static void test_to_double(void)
{
    cmd_num_t n;
    TEST_ASSERT_EQUAL_INT(CMD_NUM_OK, parse("0.1", &n));
    TEST_ASSERT_TRUE(cmd_num_to_double(&n) == 0.1); /* one correctly rounded division */
    TEST_ASSERT_EQUAL_INT(CMD_NUM_OK, parse("-2.4", &n));
    TEST_ASSERT_TRUE(cmd_num_to_double(&n) == -2.4);
    TEST_ASSERT_EQUAL_INT(CMD_NUM_OK, parse("6e-4", &n));
    TEST_ASSERT_TRUE(cmd_num_to_double(&n) == 6e-4);
    TEST_ASSERT_EQUAL_INT(CMD_NUM_OK, parse("1e15", &n));
    TEST_ASSERT_TRUE(cmd_num_to_double(&n) == 1e15);
    TEST_ASSERT_EQUAL_INT(CMD_NUM_OK, parse("1.23456789012345678e-15", &n));
    TEST_ASSERT_DOUBLE_WITHIN(1e-29, 1.23456789012345678e-15, cmd_num_to_double(&n));
    TEST_ASSERT_EQUAL_INT(CMD_NUM_OK, parse("999999999999999", &n)); /* integers < 2^53: exact */
    TEST_ASSERT_TRUE(cmd_num_to_double(&n) == 999999999999999.0);
}

static void test_parse_u32(void)
{
    uint32_t v = 7;
    TEST_ASSERT_EQUAL_INT(CMD_NUM_OK, cmd_num_parse_u32("4294967295", 10, &v));
    TEST_ASSERT_EQUAL_UINT32(4294967295u, v);
    TEST_ASSERT_EQUAL_INT(CMD_NUM_OK, cmd_num_parse_u32("0010", 4, &v));
    TEST_ASSERT_EQUAL_UINT32(10u, v);
    TEST_ASSERT_EQUAL_INT(CMD_NUM_RANGE, cmd_num_parse_u32("4294967296", 10, &v));
    TEST_ASSERT_EQUAL_INT(CMD_NUM_RANGE, cmd_num_parse_u32("99999999999999999999999", 23, &v));
    TEST_ASSERT_EQUAL_INT(CMD_NUM_SYNTAX, cmd_num_parse_u32("", 0, &v));
    TEST_ASSERT_EQUAL_INT(CMD_NUM_SYNTAX, cmd_num_parse_u32("+1", 2, &v));
    TEST_ASSERT_EQUAL_INT(CMD_NUM_SYNTAX, cmd_num_parse_u32("1e2", 3, &v));
    TEST_ASSERT_EQUAL_UINT32(10u, v);
}

static void assert_fmt(double x, unsigned sig, const char *want)
{
    char b[40];
    const size_t n = cmd_num_format(b, sizeof b, x, sig);
    TEST_ASSERT_EQUAL_STRING(want, b);
    TEST_ASSERT_EQUAL_UINT(strlen(want), n);
}

static void test_format(void)
{
    assert_fmt(0.0, 7, "0");
    assert_fmt(1.0, 7, "1");
    assert_fmt(-2.4, 7, "-2.4");
    assert_fmt(1500.0, 7, "1500");
    assert_fmt(0.048, 7, "0.048");
    assert_fmt(0.006843, 7, "0.006843");
    assert_fmt(1.0 / 3.0, 7, "0.3333333");
    assert_fmt(2.0 / 3.0, 3, "0.667");
    assert_fmt(9.9999999, 7, "10"); /* rounding carries into a new decade */
    assert_fmt(123456789.0, 7, "123456800");
    assert_fmt(1e9, 7, "1e9");
    assert_fmt(-1.5e-5, 7, "-1.5e-5");
    assert_fmt(1e-4, 7, "0.0001");
    assert_fmt(6.02214076e23, 4, "6.022e23");
    assert_fmt(1e300, 7, "1e300");
    assert_fmt(4.9e-324, 2, "4.9e-324");
    assert_fmt(1.7976931348623157e308, 3, "1.8e308");
    const double zero = 0.0;
    assert_fmt(1.0 / zero, 7, "inf");
    assert_fmt(-1.0 / zero, 7, "-inf");
    assert_fmt(zero / zero, 7, "nan");
    char small[3];
    TEST_ASSERT_EQUAL_UINT(0, cmd_num_format(small, sizeof small, -1.5, 7));
    TEST_ASSERT_EQUAL_STRING("", small);
    TEST_ASSERT_EQUAL_UINT(2, cmd_num_format(small, sizeof small, -1.0, 7));
}

/* format(x, 15) parsed back gives x within the 15-digit rounding: relative
 * error <= 0.5e-14 plus a few ulp. */
static void test_format_parse_round_trip(void)
{
    uint32_t s = 12345u;
    for (int i = 0; i < 2000; i++) {
        s = s * 1664525u + 1013904223u;                                /* LCG: deterministic */
        const double mant = (double)(s >> 8) / 16777216.0 * 9.0 + 1.0; /* [1, 10) */
        const int e = (int)((s >> 3) % 29u) - 14;                      /* [-14, 14] */
        double x = mant;
        for (int k = 0; k < e; k++) {
            x *= 10.0;
        }
        for (int k = 0; k > e; k--) {
            x /= 10.0;
        }
        if ((s & 1u) != 0u) {
            x = -x;
        }
        char b[40];
        TEST_ASSERT_NOT_EQUAL(0, (int)cmd_num_format(b, sizeof b, x, 15));
        cmd_num_t n;
        TEST_ASSERT_EQUAL_INT_MESSAGE(CMD_NUM_OK, parse(b, &n), b);
        const double y = cmd_num_to_double(&n);
        const double tol = (x < 0 ? -x : x) * 1e-14;
        TEST_ASSERT_DOUBLE_WITHIN(tol, x, y);
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_accepts_grammar);
    RUN_TEST(test_rejects_syntax);
    RUN_TEST(test_rejects_range);
    RUN_TEST(test_to_double);
    RUN_TEST(test_parse_u32);
    RUN_TEST(test_format);
    RUN_TEST(test_format_parse_round_trip);
    return UNITY_END();
}
