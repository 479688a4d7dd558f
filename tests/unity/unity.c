/*
 * Unity-API test harness (see unity.h). Output goes character by character
 * through unity_output_char() so that the same code prints on a host terminal
 * and on the QEMU target's UART; no printf is needed (newlib-nano's printf has
 * no floating point by default).
 */
#include "unity.h"

#include <string.h>

UnityState Unity;

static const char unity_str_breaker[] = "-----------------------";

/* ---- Printing ---------------------------------------------------------------------------- */

static int unity_is_nan(double x);
static int unity_is_inf(double x);

static void unity_print(const char *s)
{
    if (s == NULL) {
        return;
    }
    while (*s != '\0') {
        unity_output_char((unsigned char)*s);
        s++;
    }
}

static void unity_print_eol(void)
{
    unity_output_char('\n');
}

static void unity_print_unsigned(uint64_t v)
{
    char buf[24];
    int n = 0;
    do {
        buf[n++] = (char)('0' + (int)(v % 10u));
        v /= 10u;
    } while (v != 0u);
    while (n > 0) {
        unity_output_char(buf[--n]);
    }
}

static void unity_print_signed(int64_t v)
{
    if (v < 0) {
        unity_output_char('-');
        /* -(v+1)+1 avoids overflow for INT64_MIN. */
        unity_print_unsigned((uint64_t)(-(v + 1)) + 1u);
    } else {
        unity_print_unsigned((uint64_t)v);
    }
}

static void unity_print_hex(uint64_t v, int nibbles)
{
    static const char digits[] = "0123456789ABCDEF";
    unity_print("0x");
    for (int i = nibbles - 1; i >= 0; i--) {
        unity_output_char(digits[(v >> (4 * i)) & 0xFu]);
    }
}

static void unity_print_number(int64_t v, UNITY_DISPLAY_STYLE_T style)
{
    switch (style) {
    case UNITY_DISPLAY_STYLE_UINT:
        unity_print_unsigned((uint64_t)v);
        break;
    case UNITY_DISPLAY_STYLE_HEX8:
        unity_print_hex((uint64_t)v, 2);
        break;
    case UNITY_DISPLAY_STYLE_HEX16:
        unity_print_hex((uint64_t)v, 4);
        break;
    case UNITY_DISPLAY_STYLE_HEX32:
        unity_print_hex((uint64_t)v, 8);
        break;
    case UNITY_DISPLAY_STYLE_HEX64:
        unity_print_hex((uint64_t)v, 16);
        break;
    case UNITY_DISPLAY_STYLE_CHAR:
        if (v >= 32 && v < 127) {
            unity_output_char('\'');
            unity_output_char((int)v);
            unity_output_char('\'');
        } else {
            unity_print_signed(v);
        }
        break;
    case UNITY_DISPLAY_STYLE_INT:
    default:
        unity_print_signed(v);
        break;
    }
}

/*
 * A double in Unity's %.9g-like format: 9 significant digits, trailing zeros
 * dropped, fixed notation from 1e-4 up to below 1e9, otherwise d.ddde+XX
 * (exponent with at least two digits); "nan", "inf", "-0".
 */
static void unity_print_double(double x)
{
    if (x < 0.0 || (x == 0.0 && 1.0 / x < 0.0)) {
        unity_output_char('-');
        x = -x;
    }
    if (x == 0.0) {
        unity_output_char('0');
        return;
    }
    if (unity_is_nan(x)) {
        unity_print("nan");
        return;
    }
    if (unity_is_inf(x)) {
        unity_print("inf");
        return;
    }
    int exp10 = 0;
    while (x >= 10.0) {
        x /= 10.0;
        exp10++;
    }
    while (x < 1.0) {
        x *= 10.0;
        exp10--;
    }
    /* x in [1, 10): 9 significant digits as an integer. */
    uint64_t digits = (uint64_t)(x * 1e8 + 0.5);
    if (digits >= 1000000000u) {
        digits /= 10u;
        exp10++;
    }
    char d[9];
    for (int i = 8; i >= 0; i--) {
        d[i] = (char)('0' + (int)(digits % 10u));
        digits /= 10u;
    }
    int last = 8; /* drop trailing zeros */
    while (last > 0 && d[last] == '0') {
        last--;
    }
    if (exp10 >= -4 && exp10 <= 8) {
        if (exp10 < 0) {
            unity_print("0.");
            for (int i = -1; i > exp10; i--) {
                unity_output_char('0');
            }
            for (int i = 0; i <= last; i++) {
                unity_output_char(d[i]);
            }
        } else {
            for (int i = 0; i <= exp10; i++) {
                unity_output_char(i <= last ? d[i] : '0');
            }
            if (last > exp10) {
                unity_output_char('.');
                for (int i = exp10 + 1; i <= last; i++) {
                    unity_output_char(d[i]);
                }
            }
        }
    } else {
        unity_output_char(d[0]);
        if (last > 0) {
            unity_output_char('.');
            for (int i = 1; i <= last; i++) {
                unity_output_char(d[i]);
            }
        }
        unity_output_char('e');
        unity_output_char(exp10 < 0 ? '-' : '+');
        const int e = exp10 < 0 ? -exp10 : exp10;
        if (e < 10) {
            unity_output_char('0');
        }
        unity_print_unsigned((uint64_t)e);
    }
}

/* "file:line:test:" */
static void unity_results_begin(unsigned long line)
{
    unity_print(Unity.TestFile);
    unity_output_char(':');
    unity_print_unsigned(line);
    unity_output_char(':');
    unity_print(Unity.CurrentTestName);
    unity_output_char(':');
}

static void unity_fail_begin(unsigned long line)
{
    unity_results_begin(line);
    unity_print("FAIL:");
}

static void unity_add_msg(const char *msg)
{
    if (msg != NULL) {
        unity_print(". ");
        unity_print(msg);
    }
}

/* Ends the current test: back to UnityDefaultTestRun. */
static void unity_fail_and_bail(void)
{
    Unity.CurrentTestFailed = 1;
    unity_print_eol();
    longjmp(Unity.AbortFrame, 1);
}

/* ---- Test running ------------------------------------------------------------------------ */

void UnityBegin(const char *filename)
{
    memset(&Unity, 0, sizeof Unity);
    Unity.TestFile = filename;
}

int UnityEnd(void)
{
    unity_print_eol();
    unity_print(unity_str_breaker);
    unity_print_eol();
    unity_print_unsigned(Unity.NumberOfTests);
    unity_print(" Tests ");
    unity_print_unsigned(Unity.TestFailures);
    unity_print(" Failures ");
    unity_print_unsigned(Unity.TestIgnores);
    unity_print(" Ignored ");
    unity_print_eol();
    unity_print(Unity.TestFailures == 0u ? "OK" : "FAIL");
    unity_print_eol();
    unity_output_flush();
    return (int)Unity.TestFailures;
}

static void unity_conclude_test(void)
{
    if (Unity.CurrentTestIgnored) {
        Unity.TestIgnores++;
    } else if (!Unity.CurrentTestFailed) {
        unity_results_begin(Unity.CurrentTestLineNumber);
        unity_print("PASS");
        unity_print_eol();
    } else {
        Unity.TestFailures++;
    }
    Unity.CurrentTestFailed = 0;
    Unity.CurrentTestIgnored = 0;
    unity_output_flush();
}

void UnityDefaultTestRun(UnityTestFunction func, const char *name, int line)
{
    Unity.CurrentTestName = name;
    Unity.CurrentTestLineNumber = (unsigned long)line;
    Unity.NumberOfTests++;
    if (TEST_PROTECT()) {
        setUp();
        func();
    }
    if (TEST_PROTECT()) {
        tearDown();
    }
    unity_conclude_test();
}

void UnityMessage(const char *msg, unsigned long line)
{
    unity_results_begin(line);
    unity_print("INFO");
    if (msg != NULL) {
        unity_print(": ");
        unity_print(msg);
    }
    unity_print_eol();
}

/* ---- Assertions -------------------------------------------------------------------------- */

/* A failure inside tearDown after a failure in the test is reported once. */
#define UNITY_RETURN_IF_FAIL_OR_IGNORE                                                             \
    do {                                                                                           \
        if (Unity.CurrentTestFailed || Unity.CurrentTestIgnored) {                                 \
            longjmp(Unity.AbortFrame, 1);                                                          \
        }                                                                                          \
    } while (0)

void UnityFail(const char *msg, unsigned long line)
{
    UNITY_RETURN_IF_FAIL_OR_IGNORE;
    unity_results_begin(line);
    unity_print("FAIL");
    if (msg != NULL) {
        unity_output_char(':');
        if (msg[0] != ' ') {
            unity_output_char(' ');
        }
        unity_print(msg);
    }
    unity_fail_and_bail();
}

void UnityIgnore(const char *msg, unsigned long line)
{
    UNITY_RETURN_IF_FAIL_OR_IGNORE;
    unity_results_begin(line);
    unity_print("IGNORE");
    if (msg != NULL) {
        unity_print(": ");
        unity_print(msg);
    }
    unity_print_eol();
    Unity.CurrentTestIgnored = 1;
    longjmp(Unity.AbortFrame, 1);
}

void UnityAssertEqualNumber(int64_t expected, int64_t actual, const char *msg, unsigned long line,
                            UNITY_DISPLAY_STYLE_T style)
{
    if (expected == actual) {
        return;
    }
    UNITY_RETURN_IF_FAIL_OR_IGNORE;
    unity_fail_begin(line);
    unity_print(" Expected ");
    unity_print_number(expected, style);
    unity_print(" Was ");
    unity_print_number(actual, style);
    unity_add_msg(msg);
    unity_fail_and_bail();
}

void UnityAssertNumbersWithin(uint64_t delta, int64_t expected, int64_t actual, const char *msg,
                              unsigned long line, UNITY_DISPLAY_STYLE_T style)
{
    /* |actual - expected| computed in uint64_t: no signed overflow for any inputs. */
    uint64_t diff = actual > expected ? (uint64_t)actual - (uint64_t)expected
                                      : (uint64_t)expected - (uint64_t)actual;
    if (diff <= delta) {
        return;
    }
    UNITY_RETURN_IF_FAIL_OR_IGNORE;
    unity_fail_begin(line);
    unity_print(" Values Not Within Delta ");
    unity_print_number((int64_t)delta,
                       style == UNITY_DISPLAY_STYLE_INT ? UNITY_DISPLAY_STYLE_UINT : style);
    unity_print(" Expected ");
    unity_print_number(expected, style);
    unity_print(" Was ");
    unity_print_number(actual, style);
    unity_add_msg(msg);
    unity_fail_and_bail();
}

void UnityAssertGreaterOrLess(int64_t threshold, int64_t actual, UNITY_COMPARISON_T compare,
                              const char *msg, unsigned long line, UNITY_DISPLAY_STYLE_T style)
{
    int ok = 0;
    const char *what = "";
    switch (compare) {
    case UNITY_GREATER_THAN:
        ok = actual > threshold;
        what = " to be greater than ";
        break;
    case UNITY_GREATER_OR_EQUAL:
        ok = actual >= threshold;
        what = " to be greater than or equal to ";
        break;
    case UNITY_SMALLER_THAN:
        ok = actual < threshold;
        what = " to be less than ";
        break;
    case UNITY_SMALLER_OR_EQUAL:
    default:
        ok = actual <= threshold;
        what = " to be less than or equal to ";
        break;
    }
    if (ok) {
        return;
    }
    UNITY_RETURN_IF_FAIL_OR_IGNORE;
    unity_fail_begin(line);
    unity_print(" Expected ");
    unity_print_number(actual, style);
    unity_print(what);
    unity_print_number(threshold, style);
    unity_add_msg(msg);
    unity_fail_and_bail();
}

/* Fails when exactly one of two array pointers is NULL. */
static void unity_check_not_null(const void *expected, const void *actual, const char *msg,
                                 unsigned long line)
{
    if (expected != NULL && actual != NULL) {
        return;
    }
    UNITY_RETURN_IF_FAIL_OR_IGNORE;
    unity_fail_begin(line);
    unity_print(expected == NULL ? " Expected pointer to be NULL" : " Actual pointer was NULL");
    unity_add_msg(msg);
    unity_fail_and_bail();
}

static int64_t unity_load_element(const void *base, uint32_t i, unsigned size, int is_signed)
{
    const unsigned char *p = (const unsigned char *)base + (size_t)i * size;
    switch (size) {
    case 1u: {
        int8_t s;
        uint8_t u;
        memcpy(&s, p, 1);
        memcpy(&u, p, 1);
        return is_signed ? (int64_t)s : (int64_t)u;
    }
    case 2u: {
        int16_t s;
        uint16_t u;
        memcpy(&s, p, 2);
        memcpy(&u, p, 2);
        return is_signed ? (int64_t)s : (int64_t)u;
    }
    case 4u: {
        int32_t s;
        uint32_t u;
        memcpy(&s, p, 4);
        memcpy(&u, p, 4);
        return is_signed ? (int64_t)s : (int64_t)u;
    }
    default: {
        int64_t s;
        memcpy(&s, p, 8);
        return s;
    }
    }
}

void UnityAssertEqualIntArray(const void *expected, const void *actual, uint32_t num_elements,
                              unsigned size, const char *msg, unsigned long line,
                              UNITY_DISPLAY_STYLE_T style)
{
    if (num_elements == 0u) {
        UNITY_RETURN_IF_FAIL_OR_IGNORE;
        unity_fail_begin(line);
        unity_print(" You Asked Me To Compare Nothing, Which Was Pointless.");
        unity_add_msg(msg);
        unity_fail_and_bail();
    }
    if (expected == actual) {
        return; /* both NULL or the same array */
    }
    unity_check_not_null(expected, actual, msg, line);
    const int is_signed = style == UNITY_DISPLAY_STYLE_INT;
    for (uint32_t i = 0; i < num_elements; i++) {
        int64_t e = unity_load_element(expected, i, size, is_signed);
        int64_t a = unity_load_element(actual, i, size, is_signed);
        if (e != a) {
            UNITY_RETURN_IF_FAIL_OR_IGNORE;
            unity_fail_begin(line);
            unity_print(" Element ");
            unity_print_unsigned(i);
            unity_print(" Expected ");
            unity_print_number(e, style);
            unity_print(" Was ");
            unity_print_number(a, style);
            unity_add_msg(msg);
            unity_fail_and_bail();
        }
    }
}

static void unity_print_quoted(const char *s)
{
    if (s == NULL) {
        unity_print("NULL");
        return;
    }
    unity_output_char('\'');
    unity_print(s);
    unity_output_char('\'');
}

void UnityAssertEqualString(const char *expected, const char *actual, const char *msg,
                            unsigned long line)
{
    if (expected != NULL && actual != NULL && strcmp(expected, actual) == 0) {
        return;
    }
    if (expected == NULL && actual == NULL) {
        return;
    }
    UNITY_RETURN_IF_FAIL_OR_IGNORE;
    unity_fail_begin(line);
    unity_print(" Expected ");
    unity_print_quoted(expected);
    unity_print(" Was ");
    unity_print_quoted(actual);
    unity_add_msg(msg);
    unity_fail_and_bail();
}

void UnityAssertEqualMemory(const void *expected, const void *actual, uint32_t length,
                            const char *msg, unsigned long line)
{
    if (length == 0u) {
        UNITY_RETURN_IF_FAIL_OR_IGNORE;
        unity_fail_begin(line);
        unity_print(" You Asked Me To Compare Nothing, Which Was Pointless.");
        unity_add_msg(msg);
        unity_fail_and_bail();
    }
    if (expected == actual) {
        return;
    }
    unity_check_not_null(expected, actual, msg, line);
    const unsigned char *e = (const unsigned char *)expected;
    const unsigned char *a = (const unsigned char *)actual;
    for (uint32_t i = 0; i < length; i++) {
        if (e[i] != a[i]) {
            UNITY_RETURN_IF_FAIL_OR_IGNORE;
            unity_fail_begin(line);
            unity_print(" Memory Mismatch. Byte ");
            unity_print_unsigned(i);
            unity_print(" Expected ");
            unity_print_number(e[i], UNITY_DISPLAY_STYLE_HEX8);
            unity_print(" Was ");
            unity_print_number(a[i], UNITY_DISPLAY_STYLE_HEX8);
            unity_add_msg(msg);
            unity_fail_and_bail();
        }
    }
}

static int unity_is_nan(double x)
{
    return x != x;
}

static int unity_is_inf(double x)
{
    return !unity_is_nan(x) && unity_is_nan(x - x);
}

void UnityAssertDoublesWithin(double delta, double expected, double actual, const char *msg,
                              unsigned long line)
{
    /* Unity's rules: equal infinities pass, NaN == NaN passes, any other NaN or
     * infinite difference fails. */
    int ok;
    if (unity_is_inf(expected) && unity_is_inf(actual) && ((expected < 0) == (actual < 0))) {
        ok = 1;
    } else if (unity_is_nan(expected) && unity_is_nan(actual)) {
        ok = 1;
    } else {
        double diff = actual - expected;
        diff = diff < 0.0 ? -diff : diff;
        delta = delta < 0.0 ? -delta : delta;
        ok = !(unity_is_nan(diff) || unity_is_inf(diff) || diff > delta);
    }
    if (ok) {
        return;
    }
    UNITY_RETURN_IF_FAIL_OR_IGNORE;
    unity_fail_begin(line);
    unity_print(" Expected ");
    unity_print_double(expected);
    unity_print(" Was ");
    unity_print_double(actual);
    unity_add_msg(msg);
    unity_fail_and_bail();
}

void UnityAssertDoubleIsFinite(double actual, const char *msg, unsigned long line)
{
    if (!unity_is_nan(actual) && !unity_is_inf(actual)) {
        return;
    }
    UNITY_RETURN_IF_FAIL_OR_IGNORE;
    unity_fail_begin(line);
    unity_print(" Expected Determinate Was ");
    unity_print_double(actual);
    unity_add_msg(msg);
    unity_fail_and_bail();
}
