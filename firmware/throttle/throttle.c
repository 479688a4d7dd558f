/* Servo-style throttle decoding (throttle.h). */
#include "throttle.h"

#include <string.h>

void thr_config_default(thr_config_t *c)
{
    c->mode = THR_MODE_OFF;
    c->low_us = 1000u;
    c->high_us = 2000u;
    c->deadband_us = 30u;
}

int thr_config_check(const thr_config_t *c)
{
    if (c->mode > THR_MODE_SPEED) {
        return THR_BAD_MODE;
    }
    if (c->low_us < THR_PULSE_MIN_US || c->low_us > THR_LOW_MAX_US) {
        return THR_BAD_LOW;
    }
    if (c->high_us < THR_HIGH_MIN_US || c->high_us > THR_PULSE_MAX_US) {
        return THR_BAD_HIGH;
    }
    if (2u * (uint32_t)c->deadband_us >= (uint32_t)(c->high_us - c->low_us)) {
        return THR_BAD_DEADBAND;
    }
    return 0;
}

void thr_init(thr_t *t, const thr_config_t *c, uint32_t now_ms)
{
    const thr_config_t cfg = *c; /* c may be &t->cfg */
    memset(t, 0, sizeof *t);
    t->cfg = cfg;
    t->state = THR_WAIT_LOW;
    /* No pulse yet: as if the last valid one were a timeout ago. */
    t->t_valid_ms = now_ms - THR_TIMEOUT_MS - 1u;
}

/* Width -> Q24 fraction: 0 up to low + deadband, 1 from high on. The span
 * is > 0 and < 2^11 (thr_config_check), x < span: x 2^24 < 2^35 in 64 bits. */
static q24_t thr_map(const thr_config_t *c, uint32_t width_us)
{
    const uint32_t zero = (uint32_t)c->low_us + c->deadband_us;
    if (width_us <= zero) {
        return 0;
    }
    if (width_us >= c->high_us) {
        return FX_ONE;
    }
    const uint32_t span = (uint32_t)c->high_us - zero;
    return (q24_t)(((uint64_t)(width_us - zero) << 24) / span);
}

void thr_pulse(thr_t *t, uint32_t width_us, uint32_t period_us, uint32_t now_ms)
{
    if (width_us < THR_PULSE_MIN_US || width_us > THR_PULSE_MAX_US ||
        period_us < THR_PERIOD_MIN_US || period_us > THR_PERIOD_MAX_US) {
        t->n_invalid++;
        t->invalid_since_valid = true;
        return;
    }
    t->n_valid++;
    t->invalid_since_valid = false;
    t->t_valid_ms = now_ms;
    t->width_us = (uint16_t)width_us;
    t->cmd = thr_map(&t->cfg, width_us);
    const bool low = width_us <= (uint32_t)t->cfg.low_us + t->cfg.deadband_us;
    if (low && !t->low) {
        t->t_low_ms = now_ms;
    }
    t->low = low;
}

thr_out_t thr_update(thr_t *t, uint32_t now_ms)
{
    thr_out_t out = {THR_EV_NONE, 0, 0};
    const bool lost = now_ms - t->t_valid_ms > THR_TIMEOUT_MS;
    switch (t->state) {
    case THR_WAIT_LOW:
        if (lost) {
            t->low = false; /* the low-end run needs the signal throughout */
        } else if (t->low && now_ms - t->t_low_ms >= THR_ARM_LOW_MS) {
            t->state = THR_ARMED;
            t->cause = THR_CAUSE_NONE;
            out.event = THR_EV_ARM;
        }
        break;
    case THR_ARMED:
        out.ramp = FX_ONE;
        if (!lost) {
            out.ref = t->cmd;
            break;
        }
        t->state = THR_RAMP_DOWN;
        t->cause = t->invalid_since_valid ? THR_CAUSE_INVALID : THR_CAUSE_NO_PULSE;
        t->t_lost_ms = now_ms;
        t->ramp_from = t->cmd;
        out.ref = t->cmd;
        break;
    default: { /* THR_RAMP_DOWN */
        const uint32_t e = now_ms - t->t_lost_ms;
        if (e >= THR_RAMP_MS) {
            t->state = THR_WAIT_LOW;
            t->low = false; /* re-arming needs a fresh second at the low end */
            out.event = THR_EV_DISARM;
            break;
        }
        /* (RAMP - e) / RAMP in Q24: < 2^7 x 2^24; ramp_from in [0, 2^24]. */
        out.ramp = (q24_t)(((uint32_t)(THR_RAMP_MS - e) << 24) / THR_RAMP_MS);
        out.ref = (q24_t)((int64_t)t->ramp_from * out.ramp >> 24);
        break;
    }
    }
    return out;
}
