/* The engine's HAL port on the host: hal/sim (engine_port.h). */
#include "engine_port.h"

void engine_hal_config_default(engine_hal_config_t *c, uint32_t pwm_freq_hz, double current_max_a,
                               double vdc_v)
{
    hal_sim_config_default(c, pwm_freq_hz, current_max_a, vdc_v);
}

int engine_hal_init(hal_t *h, const engine_hal_config_t *c, plant_t *plant)
{
    return hal_sim_init(h, c, plant) == HAL_SIM_OK ? 0 : -1;
}

void engine_hal_begin(hal_t *h)
{
    hal_sim_period_begin(h);
}

int engine_hal_end(hal_t *h)
{
    return hal_sim_period_end(h);
}

bool engine_hal_gates_on(const hal_t *h)
{
    return hal_sim_gates_on(h);
}

void engine_medium(fw_t *fw)
{
    fw_medium(fw);
}
