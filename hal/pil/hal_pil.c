/* hal.h over the PIL link (hal_pil.h). */
#include "hal_pil.h"

#include <stddef.h>
#include <string.h>

void hal_pil_init(hal_t *h, const hal_info_t *info, uint32_t (*cycles)(void),
                  uint32_t cycle_clock_hz)
{
    memset(h, 0, sizeof *h);
    h->info = *info;
    h->info.cycle_clock_hz = cycle_clock_hz;
    h->cycles = cycles;
}

void hal_pil_sample(hal_t *h, const hal_adc_raw_t *adc, const hal_encoder_raw_t *enc, bool trip)
{
    h->adc = *adc;
    h->enc = *enc;
    h->trip = trip;
    h->pwm_written = false;
    h->trip_cleared = false;
}

void hal_pil_outputs(const hal_t *h, hal_pwm_t *pwm, bool *pwm_written, bool *gates,
                     bool *trip_cleared)
{
    *pwm = h->pwm;
    *pwm_written = h->pwm_written;
    *gates = h->gates && !h->link_fault;
    *trip_cleared = h->trip_cleared;
}

void hal_pil_link_fault(hal_t *h)
{
    h->link_fault = true;
    h->gates = false;
}

/* ---- hal.h ---- */

void hal_info_get(const hal_t *h, hal_info_t *info)
{
    if (h != NULL && info != NULL) {
        *info = h->info;
    }
}

void hal_adc_read(hal_t *h, hal_adc_raw_t *raw)
{
    if (h != NULL && raw != NULL) {
        *raw = h->adc;
    }
}

void hal_encoder_read(hal_t *h, hal_encoder_raw_t *enc)
{
    if (h != NULL && enc != NULL) {
        *enc = h->enc;
    }
}

void hal_pwm_write(hal_t *h, const hal_pwm_t *pwm)
{
    if (h != NULL && pwm != NULL) {
        h->pwm = *pwm;
        h->pwm_written = true;
    }
}

void hal_ctrl_hold(hal_t *h, bool hold)
{
    (void)h; /* the period runs in the main loop when a sample arrives */
    (void)hold;
}

void hal_gate_enable(hal_t *h, bool enable)
{
    if (h != NULL) {
        h->gates = enable && !h->link_fault;
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
        h->trip_cleared = true;
    }
}

uint32_t hal_cycles(const hal_t *h)
{
    return (h != NULL && h->cycles != NULL) ? h->cycles() : 0u;
}
