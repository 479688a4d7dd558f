/* Replay back-end of hal.h (see hal_replay.h). */
#include "hal_replay.h"

#include <string.h>

void hal_replay_init(hal_t *h, const hal_info_t *info)
{
    memset(h, 0, sizeof *h);
    h->info = *info;
}

void hal_replay_set_input(hal_t *h, const pil_in_t *in)
{
    h->in = in;
    h->trip = in != NULL && in->trip != 0u;
}

void hal_info_get(const hal_t *h, hal_info_t *info)
{
    if (h != NULL && info != NULL) {
        *info = h->info;
    }
}

void hal_adc_read(hal_t *h, hal_adc_raw_t *raw)
{
    if (h == NULL || raw == NULL || h->in == NULL) {
        return;
    }
    raw->i_a = h->in->adc[0];
    raw->i_b = h->in->adc[1];
    raw->i_c = h->in->adc[2];
    raw->vdc = h->in->adc[3];
}

void hal_encoder_read(hal_t *h, hal_encoder_raw_t *enc)
{
    if (h == NULL || enc == NULL || h->in == NULL) {
        return;
    }
    enc->count = h->in->enc_count;
    enc->index_seen = h->in->index_seen != 0u;
    enc->index_count = h->in->index_count;
}

void hal_pwm_write(hal_t *h, const hal_pwm_t *pwm)
{
    if (h != NULL && pwm != NULL) {
        h->pwm = *pwm;
    }
}

void hal_ctrl_hold(hal_t *h, bool hold)
{
    (void)h; /* the replay calls the periods itself */
    (void)hold;
}

void hal_gate_enable(hal_t *h, bool enable)
{
    if (h != NULL) {
        h->gates = enable;
    }
}

bool hal_trip_active(const hal_t *h)
{
    return h != NULL && h->trip;
}

void hal_trip_clear(hal_t *h)
{
    if (h != NULL) {
        h->trip = false;
    }
}

uint32_t hal_cycles(const hal_t *h)
{
    if (h == NULL) {
        return 0u;
    }
    /* A read of a free-running counter; the handle is never defined const. */
    hal_t *m = (hal_t *)(uintptr_t)h;
    m->cycles += HAL_REPLAY_CYCLES_PER_READ;
    return m->cycles;
}
