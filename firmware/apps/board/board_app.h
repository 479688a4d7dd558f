/*
 * What every board image shares above its chip's HAL: the firmware and its
 * command link, the machine data the link can change (machine fields,
 * encoder, throttle, the board's common values), the re-initialisation
 * that keeps the previous data when the core refuses new ones, the main
 * loop's liveness service (firmware watchdog kick, independent watchdog
 * refreshed only while the control interrupt runs, millisecond clock,
 * throttle), the throttle's decisions, the power stage's temperature check,
 * the settings record in flash.
 *
 * The board image gives what differs (board_app_port_t): its control
 * interrupt's mask, the dead time its timer inserts, a hardware over-current
 * threshold to move with the machine (or none), its throttle capture, its
 * watchdog and clock; and, in its board_app_cfg.h (the sources here are
 * compiled into each board image), its back-end of hal.h (whose struct hal
 * keeps the hal_info_t it reports as `info`), its own parameters
 * (BOARD_APP_EXTRA_PARAMS) and the ranges BOARD_APP_VDC_MAX_V and
 * BOARD_APP_CURRENT_MAX_A.
 */
#ifndef FIRMWARE_APPS_BOARD_BOARD_APP_H
#define FIRMWARE_APPS_BOARD_BOARD_APP_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "board_isr_watch.h"
#include "board_uart.h"
#include "controller.h"
#include "ctrl_params.h"
#include "fw_link.h"
#include "fw_settings.h"
#include "hal.h"
#include "help_text.h"
#include "pipeline.h"
#include "throttle.h"

typedef struct board_app board_app_t;

typedef struct {
    const char *tag;               /* message prefix, e.g. "vesc6: " */
    const ctrl_machine_t *machine; /* the compiled-in machine */
    const char *ctrl;              /* controller after power-up */
    uint32_t encoder_cpr;          /* compiled-in encoder counts per revolution */
    /* the control interrupt masked (false) or back on (true) */
    void (*control_irq)(bool on);
    /* the dead time the inverter inserts (the firmware's dead_time_s), s */
    double (*dead_time_s)(const board_app_t *a);
    /* a machine's hardware over-current threshold set (main loop); NULL when
     * the board's threshold does not follow the machine. 0 or a negative
     * code. */
    int (*set_trip)(board_app_t *a, const ctrl_machine_t *m);
    /* one new throttle pulse since the last call: width and period, us */
    bool (*throttle_read)(board_app_t *a, uint32_t *width_us, uint32_t *period_us);
    void (*watchdog_refresh)(void);
    /* The watchdog's long window (on) while the main loop blocks without the
     * control interrupt (the firmware's re-initialisation), its run window
     * again (off); NULL: none. */
    void (*watchdog_long)(const board_app_t *a, bool on);
    /* The gate outputs on as the hardware has them, and what the main loop
     * does when the control interrupt has stopped with them on
     * (board_isr_watch): gates off and held, the reason said. NULL: not
     * watched. */
    bool (*gates_on)(void);
    void (*isr_stalled)(board_app_t *a);
    /* a free-running clock (the main loop's milliseconds) and its rate */
    uint32_t (*ticks)(void);
    uint32_t ticks_hz;
} board_app_port_t;

struct board_app {
    const board_app_port_t *port;
    hal_t *hal;
    fw_t fw;
    fw_link_t link;
    fw_config_t fc;
    ctrl_machine_t machine; /* staged for fw_init; in force: fw.machine_own ("ident apply") */
    uint32_t encoder_cpr;
    board_uart_t uart;
    volatile uint32_t isr_count; /* control interrupts so far */
    uint32_t last_isr;           /* isr_count at the last watchdog refresh */
    board_isr_watch_t isr_watch; /* the interrupt's progress with the gates on */
    uint32_t isr_watch_ticks;    /* BOARD_ISR_WATCH_US in port->ticks() */
    uint32_t reset_flags;        /* the reset cause's flags (b.reset) */
    thr_t thr;                   /* the throttle ([throttle] settings in thr.cfg) */
    q24_t thr_tref;              /* speed mode: the torque when the signal was lost, Q24 pu */
    uint32_t thr_losses;         /* signal losses so far (reported by the main loop) */
    uint32_t thr_losses_told;
    bool offsets_told;
    uint32_t now_ms;   /* main loop's millisecond clock */
    uint32_t ms_tick;  /* port->ticks() at its last millisecond */
    uint32_t ms_ticks; /* ticks per millisecond */
    bool temp_check;   /* power-stage over-temperature trip enabled */
    double temp_c;     /* last temperature (NaN: sensor open/short) */
    bool temp_trip;    /* the over-temperature trip is latched */
    fw_settings_t settings;
    union {
        max_align_t align;
        unsigned char bytes[CTRL_CFG_MAX];
    } ctrl_cfg; /* the controller's configuration a record gives (fw_settings_config) */
};

/* fw_config_default for machine m and controller ctrl, with the dead time
 * the board inserts (port->dead_time_s). */
void board_app_config_default(const board_app_t *a, fw_config_t *c, const ctrl_machine_t *m,
                              const ctrl_desc_t *ctrl);

/* The firmware on the compiled-in machine, the command link (bytes out
 * through the console's ring), the parameters, the throttle decoder off
 * with its defaults. fw_init's result. */
int board_app_start(board_app_t *a, const board_app_port_t *port, hal_t *hal);

/* Re-initialises the firmware with new machine data, encoder resolution
 * and configuration (NULL: the defaults for m and the controller in use)
 * while the gates are off: control interrupt masked meanwhile, the hardware
 * threshold moved (port->set_trip). Without a configuration (cfg NULL) the
 * defaults for m, with what the drive held beyond its machine data
 * (fw_kept_t: encoder offset and direction, friction). On a refusal the
 * previous data are restored - the machine, the configuration in force and
 * the controller's tunables - and the core's reason kept for "err 10
 * failed". CMD_OK,
 * CMD_E_STATE (gates on or about to be), CMD_E_RANGE (encoder counts) or
 * CMD_E_FAILED. */
int board_app_reconfigure(board_app_t *a, const ctrl_machine_t *m, uint32_t encoder_cpr,
                          const fw_config_t *cfg);

/* The main loop's liveness (also run while the console waits for transmit
 * space): firmware watchdog kicked, independent watchdog refreshed only
 * when the control interrupt has run since the last refresh, millisecond
 * clock, throttle. While the board holds its gates off for good (the link's
 * hold) no control interrupt runs by design: the main loop's liveness alone
 * refreshes the watchdog then. ctx: the board_app_t. */
void board_app_service(void *ctx);

/* The throttle's pulses to its decoder, its decisions to the drive (arm,
 * disarm, reference); a loss counts in thr_losses. */
void board_app_throttle_poll(board_app_t *a);

/* A new temperature reading (NaN: sensor open or shorted): latches or
 * releases the over-temperature trip with 10 C hysteresis below trip_c
 * (temp_check off: released). Returns whether the trip is latched. */
bool board_app_temperature(board_app_t *a, double temp_c, double trip_c);

/* Main loop: the console's received bytes fed to the command link up to the
 * end of one command line (the watchdogs are served between lines). next:
 * the chip's reader (board_uart_getc's values: bits 8..11 say bytes were
 * lost before this one, whose line is then discarded and answered err 13;
 * -1: nothing more). */
void board_app_console(board_app_t *a, int (*next)(board_uart_t *u));

/* Main loop: the lines it owes (a throttle loss, the measured current
 * offsets once their calibration has ended). */
void board_app_messages(board_app_t *a);

/* The settings record in the board's flash (its two pages/sectors):
 * applied at start-up, or the defaults, said on the console; the "config"
 * commands attached; with PMSM_LIVE_PARAMS the configuration beyond the
 * machine data (fw_params_drive: est.*, inv.*, speed.*, ...) as parameters
 * too, written through the record's apply. */
void board_app_settings_start(board_app_t *a, const settings_flash_t *flash);

/* Entries of a parameter table (fw_link_param_t): written with the gates
 * off, within its range; written also while the drive runs; read-only. */
#define BOARD_APP_RW(name, unit, lo, hi, help, get, set)                                           \
    {                                                                                              \
        {name, unit, HELP_TEXT(help), CMD_PARAM_RW, lo, hi}, get, set                              \
    }
#define BOARD_APP_LIVE(name, unit, lo, hi, help, get, set)                                         \
    {                                                                                              \
        {name, unit, HELP_TEXT(help), CMD_PARAM_LIVE, lo, hi}, get, set                            \
    }
#define BOARD_APP_RO(name, unit, help, get)                                                        \
    {                                                                                              \
        {name, unit, HELP_TEXT(help), CMD_PARAM_RO, 0.0, 0.0}, get, NULL                           \
    }

/* The parameter table (board_params.c): the machine, encoder, common board
 * and throttle values, then BOARD_APP_EXTRA_PARAMS (BOARD_APP_N_EXTRA_PARAMS
 * entries) of the board image's board_app_cfg.h. */
void board_app_params_attach(board_app_t *a);

#endif /* FIRMWARE_APPS_BOARD_BOARD_APP_H */
