/*
 * The STM32F405 board image's part of the shared parameter table
 * (firmware/apps/board/board_params.c): the ranges its power stage sets and
 * its own values.
 */
#ifndef FIRMWARE_APPS_F405_BOARD_APP_CFG_H
#define FIRMWARE_APPS_F405_BOARD_APP_CFG_H

#include "board_app.h"
#include "f4_hal.h"
#include F405_BOARD_HEADER

/* From the board's description header (one home for each rating). */
#define BOARD_APP_VDC_MAX_V F405_BOARD_VBUS_MAX_V
#define BOARD_APP_CURRENT_MAX_A F405_BOARD_CURRENT_PEAK_A
#define BOARD_APP_RESET_HELP                                                                       \
    "RCC_CSR reset flags >> 24: 2 brown-out, 4 pin, 8 power-on, 16 software, 32 watchdog"

int f405_get_trip(void *ctx, const fw_link_param_t *p, double *v);
int f405_get_drv_status(void *ctx, const fw_link_param_t *p, double *v);
int f405_get_drv_vds(void *ctx, const fw_link_param_t *p, double *v);

#define BOARD_APP_N_EXTRA_PARAMS 3
#define BOARD_APP_EXTRA_PARAMS                                                                     \
    BOARD_APP_RO("b.trip", "-",                                                                    \
                 "trip latch: 1 DRV8301 nFAULT, 2 break, 4 board (temp), 8 held off, 16 driver "   \
                 "configuration lost",                                                             \
                 f405_get_trip),                                                                   \
        BOARD_APP_RO("b.drv_status", "-",                                                          \
                     "DRV8301 status 1 bits last read (bit 10 FAULT ... bit 0 FETLC_OC)",          \
                     f405_get_drv_status),                                                         \
        BOARD_APP_RO("b.drv_vds_mv", "mV", "DRV8301 VDS over-current threshold (OC_ADJ_SET)",      \
                     f405_get_drv_vds),

#endif /* FIRMWARE_APPS_F405_BOARD_APP_CFG_H */
