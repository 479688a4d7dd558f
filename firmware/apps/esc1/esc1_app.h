/*
 * The B-G431B-ESC1 application: board HAL (hal/stm32g4 + the board
 * description), the firmware's period in the ADC end-of-conversion
 * interrupt, the command and telemetry link on USART2, machine data that the
 * command interface can change (esc1_params.c).
 */
#ifndef FIRMWARE_APPS_ESC1_ESC1_APP_H
#define FIRMWARE_APPS_ESC1_ESC1_APP_H

#include <stdbool.h>
#include <stdint.h>

#include "controller.h"
#include "ctrl_params.h"
#include "esc1_uart.h"
#include "fw_link.h"
#include "g4_core.h"
#include "g4_hal.h"
#include "pipeline.h"
#include "throttle.h"

/* Build-time defaults (compile definitions may override them). */
#ifndef ESC1_FS_HZ
#define ESC1_FS_HZ 20000u /* PWM = control frequency */
#endif
#ifndef ESC1_CTRL
#define ESC1_CTRL "foc" /* controller after power-up ("ctrl select" changes it) */
#endif
#ifndef ESC1_ENCODER_CPR
#define ESC1_ENCODER_CPR 4096u /* 1024-line encoder on J8, x4 */
#endif
#define ESC1_IWDG_MS 100u /* independent watchdog time-out */

typedef struct {
    /* The HAL and the firmware first: the control interrupt's and the
     * medium task's fields then lie within an instruction's reach of the
     * struct's start (the main loop's small fields first cost the
     * interrupt 6..12 instructions and the medium task 11 per run on the
     * bench, for 240 B of flash). */
    hal_t hal;
    fw_t fw;
    volatile uint32_t isr_count;
    uint32_t last_isr;            /* isr_count at the last watchdog refresh */
    uint32_t reset_csr;           /* RCC_CSR at start-up (b.reset) */
    uint32_t thr_losses;          /* signal losses so far (the main loop reports each) */
    uint32_t now_ms;              /* main loop's millisecond clock */
    uint32_t ms_cycle;            /* cycle count at its last tick */
    uint32_t ms_cycles;           /* core cycles per millisecond */
    uint32_t t_temp, temp_period; /* the temperature's last reading, its period (cycles) */
    uint32_t thr_losses_told;     /* throttle losses reported */
    uint32_t init_cycles;         /* longest fw_init with the interrupt held, core cycles */
    bool offsets_told;            /* the calibration's offsets reported */
    bool blink;                   /* the LED's phase on a fault */
    bool temp_check;              /* board over-temperature trip enabled */
    double temp_c;                /* last board temperature (NaN: sensor open/short) */
    q24_t thr_tref;               /* speed mode: the torque when the signal was lost, Q24 pu */
    thr_t thr;                    /* throttle on the PWM pad ([throttle] settings in thr.cfg) */
    ctrl_machine_t machine;       /* staged for fw_init; in force: fw.machine_own ("ident apply") */
    uint32_t encoder_cpr;
    g4_hal_cfg_t hc;
    fw_link_t link;
    fw_config_t fc;
    esc1_uart_t uart;
#if defined(ESC1_SETTINGS)
    fw_settings_t settings; /* the record in flash (esc1_settings.c) */
    union {
        max_align_t align;
        unsigned char bytes[CTRL_CFG_MAX];
    } ctrl_cfg; /* the controller's configuration a record gives (fw_settings_config) */
#endif
} esc1_t;

/* The compiled-in machine, generated at build time from a machine file
 * (CMake cache PMSM_ESC1_MACHINE_INI, default sim_host/machines/
 * gbm5208_gimbal.ini: the Rctimer GBM5208 gimbal motor on 12 V, 0.3 A rated,
 * 1 A trip; tools/board/machine_c.py). Changed over the link with the m.*
 * parameters (esc1_params.c). tests/board/test_esc1_machine.c checks it
 * against the file, the board's ratings and the core's range. */
extern const ctrl_machine_t esc1_default_machine;

/* Hardware over-current threshold for a machine: 1.5 x current_max_a, at
 * least 8 A (below that the comparator's input offset and the DAC step are a
 * large share of the threshold), at most the board's peak rating. */
double esc1_hw_trip_a(const g4_board_t *b, const ctrl_machine_t *m);

/* The firmware's configuration for a machine on this board: fw_config_default
 * with the dead time TIM1 inserts (TIMx_BDTR.DTG encoded from the board's
 * dead_time_ns at f_DTS = SYSCLK, as g4_hal_init programs it). Without the
 * duties' compensation (PMSM_DEAD_COMP off in the board preset) the flux
 * observers take it out of the applied voltage themselves. */
void esc1_config_default(fw_config_t *c, const g4_board_t *b, const ctrl_machine_t *m,
                         const ctrl_desc_t *ctrl);

/* Re-initialises the firmware with new machine data / encoder resolution
 * (drive not running; control interrupt masked meanwhile). On failure the
 * previous data are restored. Returns CMD_OK, CMD_E_STATE (running),
 * CMD_E_RANGE (encoder counts) or CMD_E_FAILED (the core refused them). */
int esc1_reconfigure(esc1_t *s, const ctrl_machine_t *m, uint32_t encoder_cpr);
/* The same with a whole configuration (NULL: fw_config_default for m and the
 * controller in use); cfg->machine is replaced by the kept copy of m. */
int esc1_reconfigure_cfg(esc1_t *s, const ctrl_machine_t *m, uint32_t encoder_cpr,
                         const fw_config_t *cfg);

#if defined(ESC1_SETTINGS)
/* Start-up (interrupts running, drive not armed): the newest settings record
 * applied, or the compiled-in defaults, with a line on the serial link saying
 * which; the "config" commands attached (esc1_settings.c). */
void esc1_settings_start(esc1_t *s);
#endif

/* The firmware's initialisation started at cycle count t0 has ended: the
 * longest so far kept for the start-up report (against the watchdog's
 * window: docs/bringup.md). */
static inline void esc1_init_time(esc1_t *s, uint32_t t0)
{
    const uint32_t d = g4_cycles() - t0;
    if (d > s->init_cycles) {
        s->init_cycles = d;
    }
}

/* The body of the ADC1_2 interrupt (end of the injected sequence): flags
 * acknowledged, the firmware's period (fw_isr_fast; PendSV pended when the
 * medium-rate task is due), the telemetry sample. esc1_isr.c, also
 * built into the QEMU image that counts its instructions. */
void esc1_control_isr(esc1_t *s);

/* The throttle's pin (AF, pull-down) and TIM2 capture; decoder off
 * (throttle.mode 0) with the default end points. */
void esc1_throttle_init(esc1_t *s, uint32_t f_cpu_hz);
/* Main loop: the throttle's pulses (TIM2 capture) to its decoder, and its
 * decisions to the drive (arm, disarm, reference); a loss counts in
 * thr_losses (the main loop reports it with the cause). */
void esc1_throttle_poll(esc1_t *s);

/* The parameter table for fw_link_set_params. */
void esc1_params_attach(esc1_t *s);

/* One pass of the main loop (esc1_loop.c): the received bytes up to one
 * command line (answered), telemetry out, esc1_service, the break
 * interrupt's re-arm, the reports, the temperature and the LED (every
 * temp_period cycles). */
void esc1_loop_once(esc1_t *s);
/* The watchdogs (the firmware's kick; the independent one refreshed while
 * the control interrupt runs), the millisecond clock, the throttle; also the
 * serial writer's idle hook. */
void esc1_service(void *ctx);

#endif /* FIRMWARE_APPS_ESC1_ESC1_APP_H */
