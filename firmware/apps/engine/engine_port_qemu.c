/*
 * The engine's HAL port in the QEMU images: hal/qemu_mps2 (engine_port.h).
 * The deadline budget is that of a Cortex-M4 running one instruction per
 * cycle at ENGINE_QEMU_CPU_HZ (hal_qemu.h; 100 MHz, hal/sim's cycle clock, so
 * host and target runs have the same budget).
 */
#include "engine_port.h"

#include <string.h>

#include "qemu_mps2.h"

#ifndef ENGINE_QEMU_CPU_HZ
#define ENGINE_QEMU_CPU_HZ 100000000u
#endif

void engine_hal_config_default(engine_hal_config_t *c, uint32_t pwm_freq_hz, double current_max_a,
                               double vdc_v)
{
    hal_qemu_plant_config_default(c, pwm_freq_hz, current_max_a, vdc_v);
}

int engine_hal_init(hal_t *h, const engine_hal_config_t *c, plant_t *plant)
{
    hal_qemu_plant_t *models = hal_qemu_plant_init(c, plant);
    if (models == NULL || hal_qemu_init(h, models, ENGINE_QEMU_CPU_HZ) != HAL_QEMU_OK) {
        return -1;
    }
    return 0;
}

void engine_hal_begin(hal_t *h)
{
    hal_qemu_period_begin(h);
}

int engine_hal_end(hal_t *h)
{
    return hal_qemu_period_end(h);
}

bool engine_hal_gates_on(const hal_t *h)
{
    return hal_qemu_plant_gates_on(h->plant);
}

/* The firmware whose medium task PendSV runs (set before the first pend). */
static fw_t *engine_medium_fw;

static void engine_medium_run(void)
{
    fw_medium(engine_medium_fw);
}

void engine_medium(fw_t *fw)
{
    if (engine_medium_fw != fw) {
        engine_medium_fw = fw;
        board_pendsv_set(engine_medium_run);
    }
    board_pendsv_pend();
}
