/*
 * The plant side of the QEMU processor-in-the-loop back-end: sim_host's plant
 * and hal/sim's ADC / encoder / PWM / gate / trip models, compiled for the
 * Cortex-M4 (hal_qemu_plant.c builds hal/sim/hal_sim.c under the hal_qemu_plant_*
 * names so that hal.h's functions stay free for hal_qemu.c). The models are
 * those of hal_sim.h; the defaults for PIL are hal_sim_config_default() with
 * the ADC noise set to 0.
 */
#ifndef HAL_QEMU_MPS2_HAL_QEMU_PLANT_H
#define HAL_QEMU_MPS2_HAL_QEMU_PLANT_H

#include <stdbool.h>
#include <stdint.h>

#include "plant.h"

/* hal.h's types, declared once here for users of both headers. */
#include "hal.h"

struct hal_qemu_plant; /* hal/sim's struct hal, renamed */
typedef struct hal_qemu_plant hal_qemu_plant_t;

/* The same fields and meaning as hal_sim_config_t (hal_sim.h). */
typedef struct {
    uint32_t pwm_freq_hz, timer_clock_hz, cycle_clock_hz, cycles_per_read;
    uint8_t adc_bits;
    double i_fullscale_a, vdc_fullscale_v;
    double adc_offset_counts[4], adc_gain_err[4];
    double adc_noise_counts;
    uint32_t enc_lines;
    bool enc_index;
    uint32_t enc_zero_count;
    double enc_zero_rad;
    int8_t enc_dir;
    uint8_t adc_invert;
    double trip_level_a;
    uint64_t seed;
    bool sense_motor_side;
} hal_qemu_plant_config_t;

/* hal_sim_config_default's values (hal_sim.h). */
void hal_qemu_plant_config_default(hal_qemu_plant_config_t *c, uint32_t pwm_freq_hz,
                                   double current_max_a, double vdc_v);

/* The one instance of the image (static storage in hal_qemu_plant.c); binds
 * the plant (not owned). NULL on a configuration hal_sim rejects. */
hal_qemu_plant_t *hal_qemu_plant_init(const hal_qemu_plant_config_t *cfg, plant_t *plant);

/* hal_sim_period_begin / hal_sim_period_end. */
void hal_qemu_plant_begin(hal_qemu_plant_t *m);
int hal_qemu_plant_end(hal_qemu_plant_t *m);
bool hal_qemu_plant_gates_on(const hal_qemu_plant_t *m);

/* hal.h on the models (hal_qemu.c forwards to these). */
void hal_qemu_plant_info(const hal_qemu_plant_t *m, hal_info_t *info);
void hal_qemu_plant_adc(hal_qemu_plant_t *m, hal_adc_raw_t *raw);
void hal_qemu_plant_encoder(hal_qemu_plant_t *m, hal_encoder_raw_t *enc);
void hal_qemu_plant_pwm(hal_qemu_plant_t *m, const hal_pwm_t *pwm);
void hal_qemu_plant_gate(hal_qemu_plant_t *m, bool enable);
bool hal_qemu_plant_trip(const hal_qemu_plant_t *m);
void hal_qemu_plant_trip_clear(hal_qemu_plant_t *m);

#endif /* HAL_QEMU_MPS2_HAL_QEMU_PLANT_H */
