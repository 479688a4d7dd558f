/* The gate pins made safe (f4_board.h: f4_hal_gate_pins_safe): GPIO only,
 * apart from the hal.h back-end, so that an image without it (the PIL
 * image, firmware/apps/f405_pil) links it alone. */
#include "f4_board.h"
#include "f4_periph.h"

void f4_hal_gate_pins_safe(const f4_board_t *b)
{
    f4_gpio_write(b->en_gate, false);
    f4_gpio_config(b->en_gate, F4_PIN_OUTPUT, 2u);
    for (unsigned x = 0; x < 3u; x++) {
        f4_gpio_write(b->pwm_high[x], b->gate_active_low);
        f4_gpio_write(b->pwm_low[x], b->gate_active_low);
        f4_gpio_config(b->pwm_high[x], F4_PIN_OUTPUT, 2u);
        f4_gpio_config(b->pwm_low[x], F4_PIN_OUTPUT, 2u);
    }
    for (unsigned k = 0; k < 8u; k++) {
        f4_gpio_write(b->hold_low[k], false);
        f4_gpio_config(b->hold_low[k], F4_PIN_OUTPUT, 0u);
    }
    for (unsigned k = 0; k < 2u; k++) {
        f4_gpio_write(b->hold_high[k], true);
        f4_gpio_config(b->hold_high[k], F4_PIN_OUTPUT, 0u);
    }
}
