/*
 * hal.h over the processor-in-the-loop link (firmware/protocol/pil_frame.h):
 * the same back-end on QEMU and on a board. The sensors are what the PC's
 * plant models sampled at the period start (the SAMPLE frame: ADC codes,
 * encoder counter and index, trip comparator); the actuators are recorded
 * for the APPLY frame (compare values, gate request, trip clear). Nothing
 * here touches the board's power stage: in PIL the gates stay physically off
 * and the PC's plant is the only thing that switches.
 *
 * The cycle counter is the target's own (QEMU: Timer1, calibrated to
 * emulated instructions; board: DWT CYCCNT), given at init with its rate.
 * A latched link fault forces the gate request off for good.
 */
#ifndef HAL_PIL_HAL_PIL_H
#define HAL_PIL_HAL_PIL_H

#include <stdbool.h>
#include <stdint.h>

#include "hal.h"

/* The back-end's handle (hal_t of hal.h). Fields are private. */
struct hal {
    hal_info_t info;
    uint32_t (*cycles)(void);
    hal_adc_raw_t adc;
    hal_encoder_raw_t enc;
    bool trip;
    hal_pwm_t pwm;
    bool pwm_written, gates, trip_cleared;
    bool link_fault; /* latched: gates off */
};

/* info: the simulated hardware's description (its cycle_clock_hz replaced by
 * cycle_clock_hz, the rate of cycles()). */
void hal_pil_init(hal_t *h, const hal_info_t *info, uint32_t (*cycles)(void),
                  uint32_t cycle_clock_hz);
/* A period's sensor readings (before fw_isr); clears the output flags. */
void hal_pil_sample(hal_t *h, const hal_adc_raw_t *adc, const hal_encoder_raw_t *enc, bool trip);
/* The outputs of the period (after fw_isr). */
void hal_pil_outputs(const hal_t *h, hal_pwm_t *pwm, bool *pwm_written, bool *gates,
                     bool *trip_cleared);
/* Latch a link fault: the gate request is off from now on. */
void hal_pil_link_fault(hal_t *h);

#endif /* HAL_PIL_HAL_PIL_H */
