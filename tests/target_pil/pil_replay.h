/*
 * Replays a recording (pil_data.h) through fw_isr with the replay HAL and
 * compares every period's outputs with the recorded ones, bit for bit. The
 * same code runs on the host (test_pil_replay_host) and in QEMU.
 */
#ifndef TESTS_TARGET_PIL_PIL_REPLAY_H
#define TESTS_TARGET_PIL_PIL_REPLAY_H

#include <stdint.h>

#include "hal_replay.h"
#include "pil_data.h"
#include "pipeline.h"

typedef struct {
    uint32_t period;   /* index into the recording */
    const char *field; /* first differing field */
    int64_t want, got;
} pil_mismatch_t;

/* 0: identical; 1: mismatch (described in *mm); -1: setup error (mm->field
 * says which). fw and hal are work space (fw_t is large: static on a target). */
int pil_replay_run(const pil_rec_t *rec, fw_t *fw, hal_t *hal, pil_mismatch_t *mm);

#endif /* TESTS_TARGET_PIL_PIL_REPLAY_H */
