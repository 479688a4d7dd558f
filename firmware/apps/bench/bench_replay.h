/*
 * Replay of a bench recording (bench_blob.h) through fw_isr, shared by the PC
 * (bench_host) and the Cortex-M4 image (bench_cm4). The hal.h back-end is the
 * replay HAL (tests/target_pil/hal_replay.*).
 */
#ifndef TOOLS_BENCH_FW_BENCH_REPLAY_H
#define TOOLS_BENCH_FW_BENCH_REPLAY_H

#include <stddef.h>
#include <stdint.h>

#include "bench_blob.h"
#include "hal_replay.h"
#include "pipeline.h"

typedef struct {
    const bench_hdr_t *hdr;
    const bench_rec_t *rec;
    const ctrl_desc_t *desc;
    ctrl_machine_t machine;
    hal_info_t info;
    pil_in_t in; /* the present period's samples (hal_replay points here) */
} bench_replay_t;

/* Checks the header (magic, version, size, controller in this image's
 * registry); returns NULL or a message. `size` = bytes available. */
const char *bench_replay_open(bench_replay_t *r, const void *blob, size_t size);

/* fw_init with the recording's machine, HAL info and calibration length.
 * Returns FW_OK or a FW_E* code. */
int bench_replay_init(bench_replay_t *r, fw_t *fw, hal_t *hal);

/* Loads record k into the HAL and applies its commands (call before fw_isr). */
void bench_replay_input(bench_replay_t *r, fw_t *fw, hal_t *hal, uint32_t k);

/* 1 if the ISR of record k wrote other compare values (or reached another
 * state) than in the recording, else 0 (call after fw_isr). */
int bench_replay_differs(const bench_replay_t *r, const fw_t *fw, const hal_t *hal, uint32_t k);

#endif /* TOOLS_BENCH_FW_BENCH_REPLAY_H */
