/*
 * The closed-loop engine's (sim_run.h) view of the HAL back-end that carries
 * the plant: hal/sim on the host, hal/qemu_mps2 (hal/sim's models compiled for
 * the Cortex-M4, Timer1 as the cycle counter) in the QEMU images. The engine
 * is the same code on both; only these six functions differ
 * (engine_port_sim.c, engine_port_qemu.c; ENGINE_PORT_QEMU selects).
 *
 * One period k: engine_hal_begin (compare values written during k-1 become
 * active, ADC and encoder sampled at t_k), fw_isr_fast (and engine_medium
 * when it triggered the medium-rate task), engine_hal_end (the plant through
 * [t_k, t_k + Ts) with the active compare values).
 */
#ifndef FIRMWARE_APPS_ENGINE_PORT_H
#define FIRMWARE_APPS_ENGINE_PORT_H

#include <stdbool.h>
#include <stdint.h>

#include "pipeline.h"
#include "plant.h"

#if defined(ENGINE_PORT_QEMU)
#include "hal_qemu.h"
/* hal_sim_config_t's fields under the QEMU back-end's name. */
typedef hal_qemu_plant_config_t engine_hal_config_t;
#else
#include "hal_sim.h"
typedef hal_sim_config_t engine_hal_config_t;
#endif

/* hal_sim_config_default: i_fullscale 1.5 current_max, vdc_fullscale 2 vdc,
 * 12 bit, noise 0.5 count, 2500 lines with index, trip at 1.25 current_max. */
void engine_hal_config_default(engine_hal_config_t *c, uint32_t pwm_freq_hz, double current_max_a,
                               double vdc_v);
/* Bind the models to the plant; 0 or -1 (a configuration the models reject). */
int engine_hal_init(hal_t *h, const engine_hal_config_t *c, plant_t *plant);
void engine_hal_begin(hal_t *h);
/* PLANT_OK or the plant's error code. */
int engine_hal_end(hal_t *h);
/* The switches may conduct in the present period (false: gates off). */
bool engine_hal_gates_on(const hal_t *h);
/* The medium-rate task the interrupt has just triggered: run at once (host),
 * or in the lowest-priority exception (QEMU: PendSV, after the Timer0
 * interrupt; its outputs act from the next period either way). */
void engine_medium(fw_t *fw);

#endif /* FIRMWARE_APPS_ENGINE_PORT_H */
