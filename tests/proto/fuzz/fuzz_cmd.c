/*
 * libFuzzer target: arbitrary bytes into cmd_feed_byte with a mock firmware.
 * Invariants (abort on violation):
 *  - every response line is at most CMD_OUT_MAX bytes, printable, ends CRLF;
 *  - a response starts with "ok" or "err "; "ok <n>" is followed by exactly
 *    n continuation lines starting with two spaces;
 *  - writes that are not response lines are echo (only while echo is on);
 *  - the mock's state changes only together with an "ok" response.
 * The first input byte chooses the initial state (armed / fault) and whether
 * the mock makes state-changing ops fail.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cmd.h"
#include "cmd_mock.h"

typedef struct {
    mock_t m;
    cmd_t c;
    mock_state_t snap; /* state at the last response */
    long pending;      /* continuation lines still expected */
} fz_t;

static fz_t fz;

#define FZ_CHECK(cond)                                                                             \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "invariant failed: %s (line %d)\n", #cond, __LINE__);                  \
            abort();                                                                               \
        }                                                                                          \
    } while (0)

static void fz_write(void *ctx, const char *s, size_t n)
{
    fz_t *f = ctx;
    const bool echo_like = (n == 1 && s[0] >= 0x20 && s[0] <= 0x7E) ||
                           (n == 3 && memcmp(s, "\b \b", 3) == 0) ||
                           (n == 2 && memcmp(s, "\r\n", 2) == 0);
    if (n <= 3) {
        FZ_CHECK(echo_like);
        FZ_CHECK(f->c.echo);
        return;
    }
    FZ_CHECK(n <= CMD_OUT_MAX);
    FZ_CHECK(s[n - 2] == '\r' && s[n - 1] == '\n');
    for (size_t i = 0; i + 2 < n; i++) {
        FZ_CHECK(s[i] >= 0x20 && s[i] <= 0x7E);
    }
    if (f->pending > 0) {
        FZ_CHECK(s[0] == ' ' && s[1] == ' ');
        f->pending--;
        FZ_CHECK(mock_state_equal(&f->snap, &f->m.st));
        return;
    }
    const bool ok = (n >= 4 && s[0] == 'o' && s[1] == 'k' && (s[2] == ' ' || s[2] == '\r'));
    const bool err = (n >= 6 && memcmp(s, "err ", 4) == 0);
    FZ_CHECK(ok || err);
    if (err) {
        FZ_CHECK(mock_state_equal(&f->snap, &f->m.st));
    }
    if (ok && s[2] == ' ' && s[3] >= '0' && s[3] <= '9') {
        long k = 0;
        size_t i = 3;
        while (i < n - 2 && s[i] >= '0' && s[i] <= '9' && k < 100000) {
            k = k * 10 + (s[i] - '0');
            i++;
        }
        if (i == n - 2) {
            f->pending = k;
        }
    }
    f->snap = f->m.st;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static cmd_ops_t ops;
    ops = *mock_ops();
    ops.write = fz_write;
    mock_init(&fz.m);
    uint8_t cfg = 0;
    if (size > 0) {
        cfg = data[0];
        data++;
        size--;
    }
    fz.m.st.armed = (cfg & 1u) != 0u;
    fz.m.st.fault = (cfg & 2u) != 0u ? 1u : 0u;
    fz.snap = fz.m.st;
    fz.pending = 0;
    /* ctx = &fz: the mock ops read it as mock_t *, its first member (C11 6.7.2.1p15) */
    cmd_init(&fz.c, &ops, &fz);
    for (size_t i = 0; i < size; i++) {
        if ((cfg & 4u) != 0u && (i % 5u) == 0u) {
            fz.m.fail_next = (int)(data[i] % 14u) - 1; /* -1 (unknown code) .. 12, 0 = succeed */
        }
        cmd_feed_byte(&fz.c, data[i]);
        FZ_CHECK(fz.c.len <= CMD_LINE_MAX);
    }
    /* no state change without a response */
    FZ_CHECK(mock_state_equal(&fz.snap, &fz.m.st));
    FZ_CHECK(fz.pending == 0);
    return 0;
}
