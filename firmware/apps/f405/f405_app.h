/*
 * The image of an STM32F405 board with a DRV8301 gate driver (VESC 6, ODrive
 * v3.6 M0; the board is chosen at build time: F405_BOARD, PMSM_BOARD): the
 * F4 back-end of hal.h (hal/stm32f4) under the shared board application
 * (firmware/apps/board), the firmware's period in the ADC interrupt, the
 * console on the board's USART, the settings in flash sectors 1 and 2.
 *
 * Start-up never ends in a silent halt: when it fails (the clock falls back
 * to HSI, the watchdog's LSI does not run, the DRV8301 does not answer or
 * refuses its configuration, a timer does not start) the gates are held off
 * for good, the reason is said on the
 * console and given as the detail of every refused "arm" (fw_link_set_hold),
 * and the console keeps answering.
 */
#ifndef FIRMWARE_APPS_F405_F405_APP_H
#define FIRMWARE_APPS_F405_F405_APP_H

#include <stdbool.h>
#include <stdint.h>

#include "board_app.h"
#include "f405_uart.h"
#include "f4_board.h"
#include "f4_clock.h"
#include "f4_hal.h"
#include "f4_periph.h"
#include "f4_tim.h"
#include "stm32_fault.h"

#ifndef F405_FS_HZ
#define F405_FS_HZ 20000u /* PWM = control frequency */
#endif
#ifndef F405_CTRL
#define F405_CTRL "foc" /* controller after power-up ("ctrl select" changes it) */
#endif
#ifndef F405_ENCODER_CPR
#define F405_ENCODER_CPR 16384u /* the default machine's 14-bit encoder */
#endif

/* Independent watchdog (nominal 32 kHz LSI; the window with the LSI's
 * spread in brackets): through the start-up 2 s (1.36 .. 3.76 s: the whole
 * start-up on the fall-back HSI, 16 MHz, when the crystal does not start:
 * 5.33 M instructions, and the firmware's initialisation, 0.76 M, once more
 * when a settings record is applied: 0.57 s at CPI 1.5; ctest
 * <board>_qemu_wdg counts them), in the main loop 100 ms
 * (68 .. 188 ms), around a settings sector's erase 2 s (1.36 .. 3.76 s:
 * above the erase's 1 s BSY time-out at the fastest LSI). */
#define F405_IWDG_BOOT_MS 2000u
#define F405_IWDG_RUN_MS 100u
#define F405_IWDG_ERASE_MS 2000u

typedef struct {
    board_app_t app;
    hal_t hal;
    const f4_board_t *board;
    f4_clocks_t clk;
    int clock_rc;     /* f4_clock_init's result */
    int hal_rc;       /* f4_hal_init's result */
    f4_usart_t usart; /* the console's USART */
    f4_capture_t throttle;
    int wdg_rc;     /* the independent watchdog's start (F4_E_LSI: no watchdog) */
    bool had_fault; /* the previous run ended in a fault (fault below) */
    stm32_fault_rec_t fault;
    char hold_why[128];  /* why the gates are held off (fw_link_set_hold) */
    uint32_t drv_status; /* the DRV8301's status bits last reported */
} f405_t;

/* The board's name as it prefixes messages ("vesc6: "). */
extern const char f405_tag[];

/* The control interrupt's body (ADC, end of the injected sequence): flags
 * acknowledged, the firmware's period (fw_isr_fast; PendSV pended when the
 * medium-rate task is due), the interrupt counted. f405_isr.c, also built
 * into the QEMU image that counts its instructions. */
void f405_control_isr(f405_t *s);

/* The board image's parameters after the shared ones (f405_params.c). */
int f405_get_trip(void *ctx, const fw_link_param_t *p, double *v);
int f405_get_drv_status(void *ctx, const fw_link_param_t *p, double *v);
int f405_get_drv_vds(void *ctx, const fw_link_param_t *p, double *v);

/* The settings sectors through hal/stm32f4/f4_flash.h, the watchdog given
 * F405_IWDG_ERASE_MS around each erase (f405_settings.c). */
void f405_settings_start(f405_t *s);

/* Start-up lines by polled output (f405_report.c): "<tag>reset: <cause>",
 * the fault the previous run ended with ("<tag>previous run stopped:
 * BusFault at pc ..."), "<tag>clock: 168 MHz from the 8 MHz crystal" or
 * "<tag>clock failed: <why>; running on HSI 16 MHz", the watchdog's window
 * or why there is none. */
void f405_report_startup(f405_t *s, uint32_t csr);
void f405_report_line(f405_t *s, const char *a, const char *b, const char *c);
/* "<tag>stack: <used> of <size> B used (high-water mark)": the main stack's
 * deepest use since reset (fw_stack.h), after the start-up. */
void f405_report_stack(f405_t *s, uint32_t used, uint32_t size);
/* The watchdog's window for a time-out (the values above reach one). */
void f405_watchdog_set(const f405_t *s, uint32_t ms);

#endif /* FIRMWARE_APPS_F405_F405_APP_H */
