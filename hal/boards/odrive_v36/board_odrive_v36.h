/*
 * ODrive v3.6, axis M0 (ODrive Firmware/Board/v3, HW_VERSION 3.6, the 56 V
 * variant): STM32F405RG at 168 MHz from an 8 MHz crystal, two TI DRV8301
 * gate drivers (one per axis) sharing EN_GATE and nFAULT, on SPI3; low-side
 * shunts on phases B and C, amplified by M0's DRV8301; UART4 on GPIO1/2.
 * This image drives axis M0; axis M1's gate inputs and its brake-resistor
 * switch are held off.
 */
#ifndef HAL_BOARDS_ODRIVE_V36_BOARD_ODRIVE_V36_H
#define HAL_BOARDS_ODRIVE_V36_BOARD_ODRIVE_V36_H

#include "f4_board.h"

/* Ratings of the power stage (the description's vbus_max_v and
 * current_peak_a, and the ranges of the machine parameters). */
#define ODRIVE_V36_VBUS_MAX_V 56.0 /* the 56 V board */
/* The current range of the sense at gain 40: 1.35 V / (40 x 0.5 mOhm) =
 * 67.5 A; ODrive's default range 60 A. */
#define ODRIVE_V36_CURRENT_PEAK_A 60.0

extern const f4_board_t f4_board_odrive_v36;

#endif /* HAL_BOARDS_ODRIVE_V36_BOARD_ODRIVE_V36_H */
