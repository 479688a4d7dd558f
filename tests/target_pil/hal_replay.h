/*
 * Replay back-end of hal.h (host and QEMU): ADC and encoder samples come from a
 * recording (pil_data.h), PWM writes and gate requests are captured. The
 * cycle counter advances by a fixed amount per read, as hal/sim's does
 * (cycles_per_read = 50), so the deadline logic and tm.cycles replay too.
 */
#ifndef TESTS_TARGET_PIL_HAL_REPLAY_H
#define TESTS_TARGET_PIL_HAL_REPLAY_H

#include <stdbool.h>
#include <stdint.h>

#include "hal.h"
#include "pil_data.h"

#define HAL_REPLAY_CYCLES_PER_READ 50u

struct hal {
    hal_info_t info;
    const pil_in_t *in; /* sample of the present period */
    hal_pwm_t pwm;      /* last compare values written */
    bool gates;         /* last gate request */
    bool trip;
    uint32_t cycles;
};

void hal_replay_init(hal_t *h, const hal_info_t *info);
/* The period's samples (valid until the next call). */
void hal_replay_set_input(hal_t *h, const pil_in_t *in);

#endif /* TESTS_TARGET_PIL_HAL_REPLAY_H */
