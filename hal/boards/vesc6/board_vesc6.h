/*
 * VESC 6 (hardware "60", the first revision: VESC hwconf/trampa/vesc6/hw_60.h
 * with hw_60_core.h): STM32F405RG at 168 MHz from an 8 MHz crystal, TI
 * DRV8301 gate driver on SPI3's pins, three in-line phase shunts with their
 * own amplifiers, USART3 on the COMM port, servo input on the PPM pin.
 * Its later revisions (60 MK3..MK6) differ: the DRV8301's MISO/MOSI move to
 * PB3/PB4 (not SPI3's order), a shutdown pin, phase filters; they are not
 * this description.
 */
#ifndef HAL_BOARDS_VESC6_BOARD_VESC6_H
#define HAL_BOARDS_VESC6_BOARD_VESC6_H

#include "f4_board.h"

/* Ratings of the power stage (the description's vbus_max_v and
 * current_peak_a, and the ranges of the machine parameters). */
#define VESC6_VBUS_MAX_V 57.0      /* [HW60] HW_LIM_VIN */
#define VESC6_CURRENT_PEAK_A 160.0 /* [HW60] HW_LIM_CURRENT_ABS (phase current range 165 A) */

extern const f4_board_t f4_board_vesc6;

#endif /* HAL_BOARDS_VESC6_BOARD_VESC6_H */
