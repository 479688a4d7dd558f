/*
 * A mock firmware behind cmd_ops_t for the interpreter tests and the fuzz
 * target: records every op call, keeps a small drive state, and can be told
 * to make the next state-changing op fail.
 */
#ifndef TESTS_PROTO_CMD_MOCK_H
#define TESTS_PROTO_CMD_MOCK_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "cmd.h"

#define MOCK_NPARAM 4
#define MOCK_OUT_MAX 8192

/* Everything a state-changing op may modify (compared with memcmp). */
typedef struct {
    bool armed;
    int ctrl; /* index into the mock's controller list */
    uint32_t fault;
    cmd_mode_t mode;
    double torque_ref, speed_ref;
    double param[MOCK_NPARAM];
    uint32_t tel_mask, tel_every;
} mock_state_t;

typedef struct {
    mock_state_t st;
    unsigned mut_calls;               /* calls of state-changing ops */
    unsigned ro_calls;                /* calls of read-only ops */
    int fail_next;                    /* != 0: the next state-changing op returns this */
    char last_name[CMD_LINE_MAX + 1]; /* name argument of the last select/param op */
    double last_value;                /* value argument of the last ref/param op */
    char out[MOCK_OUT_MAX];           /* everything written, NUL-terminated */
    size_t out_len;
    unsigned writes;
} mock_t;

void mock_init(mock_t *m);
const cmd_ops_t *mock_ops(void);
/* Field-wise comparison (no padding bytes involved). */
bool mock_state_equal(const mock_state_t *a, const mock_state_t *b);
/* Forget the recorded output. */
void mock_clear_out(mock_t *m);
/* Feed a string byte by byte. */
void mock_feed(cmd_t *c, const char *s);

#endif /* TESTS_PROTO_CMD_MOCK_H */
