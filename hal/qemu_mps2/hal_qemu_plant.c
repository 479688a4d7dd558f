/*
 * hal/sim's models (hal_sim.c) compiled unchanged for the QEMU
 * PIL back-end. hal_sim.c defines hal.h's functions on its own struct hal; here
 * they are renamed with the preprocessor so that hal_qemu.c can implement
 * hal.h (Timer1 cycle counter, plant sequencing) and forward to them.
 */
#define hal hal_qemu_plant
#define hal_info_get hal_qemu_sim_info_get
#define hal_adc_read hal_qemu_sim_adc_read
#define hal_encoder_read hal_qemu_sim_encoder_read
#define hal_pwm_write hal_qemu_sim_pwm_write
#define hal_gate_enable hal_qemu_sim_gate_enable
#define hal_trip_active hal_qemu_sim_trip_active
#define hal_trip_clear hal_qemu_sim_trip_clear
#define hal_cycles hal_qemu_sim_cycles
#define hal_ctrl_hold hal_qemu_sim_ctrl_hold
#include "../sim/hal_sim.c"
#undef hal
#undef hal_info_get
#undef hal_adc_read
#undef hal_encoder_read
#undef hal_pwm_write
#undef hal_gate_enable
#undef hal_trip_active
#undef hal_trip_clear
#undef hal_cycles
#undef hal_ctrl_hold

#include "hal_qemu_plant.h"

static struct hal_qemu_plant hal_qemu_plant_instance;

void hal_qemu_plant_config_default(hal_qemu_plant_config_t *cfg, uint32_t pwm_freq_hz,
                                   double current_max_a, double vdc_v)
{
    hal_sim_config_t c;
    hal_sim_config_default(&c, pwm_freq_hz, current_max_a, vdc_v);
    memset(cfg, 0, sizeof *cfg);
    cfg->pwm_freq_hz = c.pwm_freq_hz;
    cfg->timer_clock_hz = c.timer_clock_hz;
    cfg->cycle_clock_hz = c.cycle_clock_hz;
    cfg->cycles_per_read = c.cycles_per_read;
    cfg->adc_bits = c.adc_bits;
    cfg->i_fullscale_a = c.i_fullscale_a;
    cfg->vdc_fullscale_v = c.vdc_fullscale_v;
    for (int i = 0; i < 4; i++) {
        cfg->adc_offset_counts[i] = c.adc_offset_counts[i];
        cfg->adc_gain_err[i] = c.adc_gain_err[i];
    }
    cfg->adc_noise_counts = c.adc_noise_counts;
    cfg->enc_lines = c.enc_lines;
    cfg->enc_index = c.enc_index;
    cfg->enc_zero_count = c.enc_zero_count;
    cfg->enc_zero_rad = c.enc_zero_rad;
    cfg->enc_dir = c.enc_dir;
    cfg->adc_invert = c.adc_invert;
    cfg->trip_level_a = c.trip_level_a;
    cfg->seed = c.seed;
}

hal_qemu_plant_t *hal_qemu_plant_init(const hal_qemu_plant_config_t *cfg, plant_t *plant)
{
    if (cfg == NULL || plant == NULL) {
        return NULL;
    }
    hal_sim_config_t c;
    memset(&c, 0, sizeof c);
    c.pwm_freq_hz = cfg->pwm_freq_hz;
    c.timer_clock_hz = cfg->timer_clock_hz;
    c.cycle_clock_hz = cfg->cycle_clock_hz;
    c.cycles_per_read = cfg->cycles_per_read;
    c.adc_bits = cfg->adc_bits;
    c.i_fullscale_a = cfg->i_fullscale_a;
    c.vdc_fullscale_v = cfg->vdc_fullscale_v;
    for (int i = 0; i < 4; i++) {
        c.adc_offset_counts[i] = cfg->adc_offset_counts[i];
        c.adc_gain_err[i] = cfg->adc_gain_err[i];
    }
    c.adc_noise_counts = cfg->adc_noise_counts;
    c.enc_lines = cfg->enc_lines;
    c.enc_index = cfg->enc_index;
    c.enc_zero_count = cfg->enc_zero_count;
    c.enc_zero_rad = cfg->enc_zero_rad;
    c.enc_dir = cfg->enc_dir;
    c.adc_invert = cfg->adc_invert;
    c.trip_level_a = cfg->trip_level_a;
    c.seed = cfg->seed;
    c.sense_motor_side = cfg->sense_motor_side;
    if (hal_sim_init(&hal_qemu_plant_instance, &c, plant) != HAL_SIM_OK) {
        return NULL;
    }
    return &hal_qemu_plant_instance;
}

void hal_qemu_plant_begin(hal_qemu_plant_t *m)
{
    hal_sim_period_begin(m);
}

int hal_qemu_plant_end(hal_qemu_plant_t *m)
{
    return hal_sim_period_end(m);
}

bool hal_qemu_plant_gates_on(const hal_qemu_plant_t *m)
{
    return hal_sim_gates_on(m);
}

void hal_qemu_plant_info(const hal_qemu_plant_t *m, hal_info_t *info)
{
    hal_qemu_sim_info_get(m, info);
}

void hal_qemu_plant_adc(hal_qemu_plant_t *m, hal_adc_raw_t *raw)
{
    hal_qemu_sim_adc_read(m, raw);
}

void hal_qemu_plant_encoder(hal_qemu_plant_t *m, hal_encoder_raw_t *enc)
{
    hal_qemu_sim_encoder_read(m, enc);
}

void hal_qemu_plant_pwm(hal_qemu_plant_t *m, const hal_pwm_t *pwm)
{
    hal_qemu_sim_pwm_write(m, pwm);
}

void hal_qemu_plant_gate(hal_qemu_plant_t *m, bool enable)
{
    hal_qemu_sim_gate_enable(m, enable);
}

bool hal_qemu_plant_trip(const hal_qemu_plant_t *m)
{
    return hal_qemu_sim_trip_active(m);
}

void hal_qemu_plant_trip_clear(hal_qemu_plant_t *m)
{
    hal_qemu_sim_trip_clear(m);
}
