/* The gate pins made safe (f4_board.h: f4_hal_gate_pins_safe): GPIO only,
 * apart from the hal.h back-end, so that an image without it (the PIL
 * image, firmware/apps/f405_pil) links it alone. */
#include "f4_board.h"
#include "f4_periph.h"

void f4_hal_gate_pins_safe(const f4_board_t *b)
{
    f4_gpio_output(b->en_gate, false, 2u);
    for (unsigned x = 0; x < 3u; x++) {
        f4_gpio_output(b->pwm_high[x], b->gate_active_low, 2u);
        f4_gpio_output(b->pwm_low[x], b->gate_active_low, 2u);
    }
    for (unsigned k = 0; k < 2u; k++) {
        f4_gpio_config(b->pull_up[k], F4_PIN_INPUT, 1u);
    }
    for (unsigned k = 0; k < 8u; k++) {
        f4_gpio_output(b->hold_low[k], false, 0u);
    }
    for (unsigned k = 0; k < 2u; k++) {
        f4_gpio_output(b->hold_high[k], true, 0u);
    }
}
