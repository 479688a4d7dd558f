/*
 * hal.h on the emulated Cortex-M4 (QEMU mps2-an386), processor in the loop:
 * ADC, encoder, PWM and gate drive are backed by the plant model compiled into
 * the image (sim_host/plant.c, double precision, soft-float on the M4F) and
 * by hal/sim's ADC/encoder/PWM models (hal/sim/hal_sim.c compiled under other
 * names in hal_qemu_plant.c: same code, same behaviour as on the host).
 * hal_cycles is the board's Timer1 (25 MHz ticks of QEMU's virtual time).
 *
 * Timing (see README-pil.md): CMSDK Timer0 fires at a rate slow enough for
 * plant + pipeline; each firing is ONE control period Ts of plant time:
 *   hal_qemu_period_end, hal_qemu_period_begin: advance the plant through
 *                        the previous period with the compare values active
 *                        then, sample ADC and encoder at the new period start
 *                        (not timed)
 *   fw_isr(fw):          the pipeline, timed with hal_cycles (Timer1) only
 * The deadline budget the firmware sees is that of a 1-instruction-per-cycle
 * Cortex-M4 at cpu_hz (hal_qemu_init's argument; the PIL application uses
 * 100 MHz, hal/sim's default cycle clock): hal_info's cycle_clock_hz is cpu_hz
 * scaled to Timer1 ticks per emulated instruction (calibrated at init, so
 * independent of the -icount shift).
 */
#ifndef HAL_QEMU_MPS2_HAL_QEMU_H
#define HAL_QEMU_MPS2_HAL_QEMU_H

#include <stdbool.h>
#include <stdint.h>

#include "hal.h"
#include "hal_qemu_plant.h"

#define HAL_QEMU_OK 0
#define HAL_QEMU_EINVAL (-1)

/* The back-end's handle (hal_t of hal.h). Fields are private. */
struct hal {
    hal_qemu_plant_t *plant;   /* plant + ADC/encoder/PWM models */
    hal_info_t info;           /* the plant models' info, cycle clock replaced */
    uint32_t ticks_per_kinstr; /* Timer1 ticks of 1000 emulated instructions */
    uint64_t periods;          /* hal_qemu_period_begin calls */
    bool primed;               /* a period has been sampled */
    uint32_t hold_depth;       /* hal_ctrl_hold's nesting */
    bool hold_was_on;          /* Timer0's interrupt was enabled at the outermost hold */
    int plant_rc;              /* first plant error (PLANT_OK while fine) */
};

/* Bind the plant models (already initialised by hal_qemu_plant_init) and
 * calibrate Timer1 against emulated instructions. cpu_hz: the modelled CPU
 * clock for the deadline budget (> 0). */
int hal_qemu_init(hal_t *h, hal_qemu_plant_t *plant, uint32_t cpu_hz);

/* Timer1 ticks per 1000 emulated instructions (measured by hal_qemu_init). */
uint32_t hal_qemu_ticks_per_kinstr(const hal_t *h);

/* Emulated instructions in `ticks` Timer1 ticks (rounded). */
uint32_t hal_qemu_ticks_to_instr(const hal_t *h, uint32_t ticks);

/* Plant part of the PWM interrupt (before fw_isr, excluded from its timing),
 * in two halves so that callers can observe the plant between them (metrics
 * at the period boundary): end = advance through the period that just ended
 * (no-op before the first begin; PLANT_OK or the plant's error code);
 * begin = sample. */
int hal_qemu_period_end(hal_t *h);
void hal_qemu_period_begin(hal_t *h);

/* The plant models (for observation: gate state, plant access by the caller). */
hal_qemu_plant_t *hal_qemu_plant_models(hal_t *h);

/* CMSDK UART0 receive for the command interface (polled from the main loop):
 * hal_qemu_uart_rx_enable sets CTRL bit 1; hal_qemu_uart_getc returns the
 * received byte, or -1 when STATE bit 1 (RX buffer full) is clear. */
void hal_qemu_uart_rx_enable(void);
int hal_qemu_uart_getc(void);

#endif /* HAL_QEMU_MPS2_HAL_QEMU_H */
