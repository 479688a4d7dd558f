/*
 * Command interpreter against a mock firmware: every documented command is
 * accepted and calls exactly its op; malformed, overlong, out-of-range or
 * unknown input is rejected with "err <code>" and calls no state-changing op.
 */
#include <stdio.h>
#include <string.h>

#include "cmd.h"
#include "cmd_mock.h"
#include "telemetry.h"
#include "unity.h"

static mock_t m;
static cmd_t c;

void setUp(void)
{
    mock_init(&m);
    cmd_init(&c, mock_ops(), &m);
}

void tearDown(void)
{
}

/* Every output line ends with CRLF, is at most CMD_OUT_MAX bytes, contains only
 * printable bytes, and the response starts with ok/err; "ok <n>" lists are
 * followed by exactly n lines that start with two spaces. */
static void check_output_shape(const char *out)
{
    long pending = 0; /* continuation lines still expected */
    const char *p = out;
    while (*p != '\0') {
        const char *e = strstr(p, "\r\n");
        TEST_ASSERT_NOT_NULL_MESSAGE(e, "line without CRLF");
        const size_t len = (size_t)(e - p) + 2u;
        TEST_ASSERT_LESS_OR_EQUAL_UINT32(CMD_OUT_MAX, (uint32_t)len);
        for (const char *q = p; q < e; q++) {
            TEST_ASSERT_TRUE(*q >= 0x20 && *q <= 0x7E);
        }
        if (pending > 0) {
            TEST_ASSERT_TRUE_MESSAGE(p[0] == ' ' && p[1] == ' ', "continuation line");
            pending--;
        } else if (strncmp(p, "ok", 2) == 0) {
            /* "ok <digits>" alone announces a list */
            const char *q = p + 2;
            if (*q == ' ' && q[1] >= '0' && q[1] <= '9') {
                long n = 0;
                q++;
                while (*q >= '0' && *q <= '9') {
                    n = n * 10 + (*q - '0');
                    q++;
                }
                if (q == e) {
                    pending = n;
                }
            }
        } else {
            TEST_ASSERT_EQUAL_INT_MESSAGE(0, strncmp(p, "err ", 4), p);
        }
        p = e + 2;
    }
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, pending, "list shorter than announced");
}

/* Run one line; returns the output. */
static const char *run(const char *line)
{
    mock_clear_out(&m);
    mock_feed(&c, line);
    mock_feed(&c, "\r\n");
    check_output_shape(m.out);
    return m.out;
}

static void assert_ok(const char *line, const char *expected_prefix)
{
    const char *out = run(line);
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, strncmp(out, expected_prefix, strlen(expected_prefix)), out);
}

/* The line is rejected with this code and nothing changed. */
static void assert_rejected(const char *line, int code)
{
    const mock_state_t before = m.st;
    const unsigned mut = m.mut_calls;
    const char *out = run(line);
    char want[16] = "err ";
    size_t k = 4;
    if (code >= 10) {
        want[k++] = (char)('0' + code / 10);
    }
    want[k++] = (char)('0' + code % 10);
    want[k++] = ' ';
    want[k] = '\0';
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, strncmp(out, want, k), out);
    TEST_ASSERT_EQUAL_UINT_MESSAGE(mut, m.mut_calls, line);
    TEST_ASSERT_TRUE_MESSAGE(mock_state_equal(&before, &m.st), line);
}

static void test_help_status_lists(void)
{
    /* one more line with the anti-cogging commands in the image */
    assert_ok("help", CTRL_COGGING ? "ok 15\r\n  help" : "ok 14\r\n  help");
    assert_ok("status", "ok 10\r\n  state=ready\r\n  armed=0\r\n  ctrl=bst\r\n");
    TEST_ASSERT_NOT_NULL(strstr(run("status"), "  speed_rpm=1500\r\n  torque_nm=1.8\r\n"));
    assert_ok("ctrl list", "ok 3\r\n  * bst mock controller\r\n  - fst");
    assert_ok("param list", "ok 4\r\n  h_T 0.048 N*m [0, 1] torque");
    TEST_ASSERT_NOT_NULL(strstr(m.out, "  fs 10000 Hz [1000, 40000] ro control"));
    char tel[64];
    /* every signal of this image (two more with the injection, telemetry.h) */
    (void)snprintf(tel, sizeof tel, "ok %u\r\n  0 i_a A phase current a\r\n",
                   (unsigned)TEL_SIG_COUNT);
    assert_ok("tel list", tel);
    assert_ok("fault", "ok fault 0 none");
    TEST_ASSERT_EQUAL_UINT(0, m.mut_calls);
}

static void test_state_changing_commands(void)
{
    assert_ok("ctrl select fst", "ok ctrl fst");
    TEST_ASSERT_EQUAL_INT(1, m.st.ctrl);
    TEST_ASSERT_EQUAL_STRING("fst", m.last_name);
    assert_ok("ref torque -1.25", "ok ref torque -1.25");
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, -1.25, m.st.torque_ref);
    assert_ok("ref speed 2.5e3", "ok ref speed 2500");
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 2500.0, m.st.speed_ref);
    TEST_ASSERT_EQUAL_INT(CMD_MODE_SPEED, m.st.mode);
    assert_ok("param set h_T .05", "ok h_T 0.05");
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 0.05, m.st.param[0]);
    assert_ok("param get h_T", "ok h_T 0.05 N*m");
    assert_ok("param set kp -4.5", "ok kp -4.5");
    assert_ok("arm", "ok armed");
    TEST_ASSERT_TRUE(m.st.armed);
    assert_ok("arm", "ok armed"); /* idempotent, no second call */
    assert_ok("tel start i_a i_b torque every 10", "ok tel mask=0x00000043 every=10 bytes=");
    TEST_ASSERT_EQUAL_HEX32(0x43u, m.st.tel_mask);
    TEST_ASSERT_EQUAL_UINT32(10u, m.st.tel_every);
    char all[48];
    (void)snprintf(all, sizeof all, "ok tel mask=0x%08lx every=1", (unsigned long)TEL_MASK_ALL);
    assert_ok("tel start all", all);
    assert_ok("tel stop", "ok tel stopped");
    TEST_ASSERT_EQUAL_HEX32(0u, m.st.tel_mask);
    assert_ok("disarm", "ok disarmed");
    TEST_ASSERT_FALSE(m.st.armed);
    /* select, torque, speed, param x2, arm, tel x3, disarm = 10 calls */
    TEST_ASSERT_EQUAL_UINT(10, m.mut_calls);
    m.st.fault = 1;
    assert_ok("fault", "ok fault 1 overcurrent");
    assert_ok("fault clear", "ok fault 0 none");
    TEST_ASSERT_EQUAL_UINT32(0u, m.st.fault);
}

static void test_unknown_and_argument_errors(void)
{
    assert_rejected("frobnicate", CMD_E_UNKNOWN);
    assert_rejected("ARM", CMD_E_UNKNOWN); /* keywords are case-sensitive */
    assert_rejected("arm now", CMD_E_ARGS);
    assert_rejected("disarm 1", CMD_E_ARGS);
    assert_rejected("ctrl", CMD_E_ARGS);
    assert_rejected("ctrl select", CMD_E_ARGS);
    assert_rejected("ctrl select bst fst", CMD_E_ARGS);
    assert_rejected("ctrl select nope", CMD_E_NAME);
    assert_ok("ctrl select nope", "err 5 name nope: not in this image\r\n");
    assert_rejected("ctrl select BST", CMD_E_NAME);
    assert_rejected("ref", CMD_E_ARGS);
    assert_rejected("ref torque", CMD_E_ARGS);
    assert_rejected("ref flux 1", CMD_E_ARGS);
    assert_rejected("ref torque 1 2", CMD_E_ARGS);
    assert_rejected("param", CMD_E_ARGS);
    assert_rejected("param get", CMD_E_ARGS);
    assert_rejected("param get nope", CMD_E_NAME);
    assert_rejected("param set h_T", CMD_E_ARGS);
    assert_rejected("param set nope 1", CMD_E_NAME);
    assert_rejected("param set fs 20000", CMD_E_READONLY);
    assert_rejected("fault reset", CMD_E_ARGS);
    assert_rejected("tel", CMD_E_ARGS);
    assert_rejected("tel start", CMD_E_ARGS);
    assert_rejected("tel start every 10", CMD_E_ARGS);
    assert_rejected("tel start i_a nope", CMD_E_NAME);
    assert_rejected("tel start i_a every", CMD_E_NAME); /* "every" without N is a name */
    assert_rejected("tel start i_a every 0", CMD_E_RANGE);
    assert_rejected("tel start i_a every 100001", CMD_E_RANGE);
    assert_rejected("tel start i_a every 99999999999", CMD_E_RANGE);
    assert_rejected("tel start i_a every 1e2", CMD_E_NUMBER);
    assert_rejected("tel start i_a every -1", CMD_E_NUMBER);
    assert_rejected("tel stop now", CMD_E_ARGS);
    assert_rejected("echo", CMD_E_ARGS);
    assert_rejected("help me", CMD_E_ARGS);
#if CTRL_COGGING
    assert_rejected("cogging on", CMD_E_UNSUPPORTED); /* the mock has no feed-forward */
#endif
    assert_rejected("config save", CMD_E_UNSUPPORTED); /* the mock keeps no settings */
    assert_rejected("a b c d e f g h i j k l m n o p q r s t u v w x y", CMD_E_ARGS);
}

static void test_number_and_range_errors(void)
{
    static const char *const bad[] = {"ref torque --1",    "ref torque +-1", "ref torque 1e",
                                      "ref torque .",      "ref torque nan", "ref torque inf",
                                      "ref torque 1.2.3",  "ref torque 0x1", "ref torque 1,5",
                                      "ref torque -",      "ref torque e1",  "ref torque 1e+",
                                      "param set h_T 0.1x"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        assert_rejected(bad[i], CMD_E_NUMBER);
    }
    assert_rejected("ref torque 1e999", CMD_E_RANGE);
    assert_rejected("ref torque 1e-999", CMD_E_RANGE);
    assert_rejected("ref torque 2.4000001", CMD_E_RANGE);
    assert_rejected("ref torque -2.41", CMD_E_RANGE);
    assert_rejected("ref speed 3001", CMD_E_RANGE);
    assert_rejected("ref speed 1234567890123456789", CMD_E_RANGE);
    assert_rejected("param set h_T 1.0000001", CMD_E_RANGE);
    assert_rejected("param set h_T -0.001", CMD_E_RANGE);
    assert_rejected("param set lambda 0", CMD_E_RANGE);
    /* the limits themselves are accepted */
    assert_ok("ref torque -2.4", "ok ref torque -2.4");
    assert_ok("ref speed 3000", "ok ref speed 3000");
    assert_ok("param set lambda 1", "ok lambda 1");
    assert_ok("param set h_T 0", "ok h_T 0");
}

static void test_state_preconditions_and_op_failures(void)
{
    m.st.armed = true;
    assert_rejected("ctrl select drr", CMD_E_STATE);
    m.st.armed = false;
    m.st.fault = 3;
    assert_rejected("arm", CMD_E_FAULT);
    m.st.armed = true; /* a fault with the gates still on: firmware must disarm first */
    assert_rejected("fault clear", CMD_E_STATE);
    m.st.armed = false;
    /* the op refuses: its code is reported, the mock state is unchanged */
    m.fail_next = CMD_E_FAULT;
    const char *out = run("fault clear");
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, strncmp(out, "err 9 fault", 11), out);
    TEST_ASSERT_EQUAL_UINT32(3u, m.st.fault);
    m.st.fault = 0;
    m.fail_next = 77; /* not a cmd_err_t: reported as failed */
    out = run("ref torque 1");
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, strncmp(out, "err 10 failed", 13), out);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 0.0, m.st.torque_ref);
    m.fail_next = CMD_E_STATE;
    out = run("param set h_T 0.5");
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, strncmp(out, "err 8 state", 11), out);
}

static void test_line_editing(void)
{
    /* CRLF gives one response, CR alone and LF alone one each */
    mock_clear_out(&m);
    mock_feed(&c, "fault\r\nfault\rfault\n");
    check_output_shape(m.out);
    TEST_ASSERT_EQUAL_STRING("ok fault 0 none\r\nok fault 0 none\r\nok fault 0 none\r\n", m.out);
    /* empty lines and comments produce nothing */
    mock_clear_out(&m);
    mock_feed(&c, "\r\n\r\n  \t \n# arm\n");
    TEST_ASSERT_EQUAL_UINT(0, m.out_len);
    TEST_ASSERT_EQUAL_UINT(0, m.mut_calls);
    /* backspace and DEL erase */
    assert_ok("armx\b", "ok armed");
    assert_ok("disarmm\x7f", "ok disarmed");
    assert_ok("ref torque 19\b\b1.5", "ok ref torque 1.5");
    assert_ok("\b\b\bfault", "ok fault 0"); /* backspace on an empty line is harmless */
    /* tabs separate like spaces */
    assert_ok("ref\ttorque\t 0.5", "ok ref torque 0.5");
    /* the buffer is clean after each line */
    assert_ok("fault", "ok fault 0");
}

static void test_overlong_and_bad_bytes(void)
{
    char line[3 * CMD_LINE_MAX];
    /* exactly CMD_LINE_MAX characters is accepted ... */
    memset(line, ' ', sizeof line);
    memcpy(line, "fault", 5);
    line[CMD_LINE_MAX] = '\0';
    assert_ok(line, "ok fault 0");
    /* ... one more is rejected entirely, even with backspaces after the overflow */
    memset(line, ' ', sizeof line);
    memcpy(line, "arm", 3);
    line[CMD_LINE_MAX + 1] = '\0';
    assert_rejected(line, CMD_E_LONG);
    line[CMD_LINE_MAX + 1] = '\b';
    line[CMD_LINE_MAX + 2] = '\b';
    line[CMD_LINE_MAX + 3] = '\0';
    assert_rejected(line, CMD_E_LONG);
    memset(line, 'x', sizeof line);
    line[sizeof line - 1] = '\0';
    assert_rejected(line, CMD_E_LONG);
    /* non-printable bytes */
    assert_rejected("ar\x01m", CMD_E_CHAR);
    assert_rejected("arm\x1b[A", CMD_E_CHAR);
    assert_rejected("arm\xff", CMD_E_CHAR);
    assert_rejected("\x80", CMD_E_CHAR);
    mock_clear_out(&m);
    cmd_feed_byte(&c, 'a');
    cmd_feed_byte(&c, 0x00);
    cmd_feed_byte(&c, 'r');
    cmd_feed_byte(&c, 'm');
    cmd_feed_byte(&c, '\n');
    TEST_ASSERT_EQUAL_STRING("err 7 char\r\n", m.out);
    TEST_ASSERT_EQUAL_UINT(0, m.mut_calls);
    /* the next line works again */
    assert_ok("arm", "ok armed");
    /* cmd_execute checks its input too */
    mock_clear_out(&m);
    cmd_execute(&c, "ar\nm", 4);
    TEST_ASSERT_EQUAL_STRING("err 7 char\r\n", m.out);
    mock_clear_out(&m);
    cmd_execute(&c, line, CMD_LINE_MAX + 1u);
    TEST_ASSERT_EQUAL_STRING("err 6 long\r\n", m.out);
}

/* Bytes the receiver lost (cmd_line_lost before the next byte): the whole
 * line up to its end of line is void, whatever is left of it ("arm" after
 * "dis" was lost), backspace does not revive it, the answer names the loss;
 * the next line is parsed alone. */
static void test_lost_bytes_void_their_line(void)
{
    const mock_state_t before = m.st;
    mock_clear_out(&m);
    mock_feed(&c, "ref torque 0.");
    cmd_line_lost(&c, "overrun (ORE)");
    cmd_line_lost(&c, "framing (FE)"); /* the first loss is named */
    mock_feed(&c, "5\b\b\r");
    TEST_ASSERT_EQUAL_STRING("err 13 lost overrun (ORE)\r\n", m.out);
    mock_clear_out(&m);
    cmd_line_lost(&c, "overrun (ORE)");
    mock_feed(&c, "arm\r\nfault\r\n");
    TEST_ASSERT_EQUAL_STRING("err 13 lost overrun (ORE)\r\nok fault 0 none\r\n", m.out);
    TEST_ASSERT_EQUAL_UINT(0, m.mut_calls);
    TEST_ASSERT_TRUE(mock_state_equal(&before, &m.st));
    /* a loss right before the end of line voids the line it ends */
    mock_clear_out(&m);
    mock_feed(&c, "arm");
    cmd_line_lost(&c, NULL);
    mock_feed(&c, "\n");
    TEST_ASSERT_EQUAL_STRING("err 13 lost on reception\r\n", m.out);
    assert_ok("arm", "ok armed");
}

static void test_echo(void)
{
    assert_ok("echo on", "ok echo on");
    mock_clear_out(&m);
    mock_feed(&c, "fa\bault\r\n");
    TEST_ASSERT_EQUAL_STRING("fa\b \bault\r\nok fault 0 none\r\n", m.out);
    mock_clear_out(&m);
    mock_feed(&c, "echo off\r");
    TEST_ASSERT_EQUAL_STRING("echo off\r\nok echo off\r\n", m.out);
    mock_clear_out(&m);
    mock_feed(&c, "fault\r");
    TEST_ASSERT_EQUAL_STRING("ok fault 0 none\r\n", m.out);
}

/* A NULL op is reported, not called. */
static void test_unsupported_ops(void)
{
    cmd_ops_t ops = *mock_ops();
    ops.arm = NULL;
    ops.telemetry_start = NULL;
    ops.get_status = NULL;
    cmd_init(&c, &ops, &m);
    assert_rejected("arm", CMD_E_UNSUPPORTED);
    assert_rejected("tel start i_a", CMD_E_UNSUPPORTED);
    assert_rejected("status", CMD_E_UNSUPPORTED);
    assert_rejected("ref torque 1", CMD_E_UNSUPPORTED); /* limits unknown */
    assert_ok("disarm", "ok disarmed");
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_help_status_lists);
    RUN_TEST(test_state_changing_commands);
    RUN_TEST(test_unknown_and_argument_errors);
    RUN_TEST(test_number_and_range_errors);
    RUN_TEST(test_state_preconditions_and_op_failures);
    RUN_TEST(test_line_editing);
    RUN_TEST(test_overlong_and_bad_bytes);
    RUN_TEST(test_lost_bytes_void_their_line);
    RUN_TEST(test_echo);
    RUN_TEST(test_unsupported_ops);
    return UNITY_END();
}
