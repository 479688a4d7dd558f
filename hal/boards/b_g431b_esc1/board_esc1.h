/*
 * ST B-G431B-ESC1 Discovery kit (MB1419): STM32G431CB, three low-side shunts
 * through the on-chip op-amps, L6387 gate drivers, STL180N6F7 MOSFETs, ST-LINK
 * with a virtual COM port on USART2.
 */
#ifndef HAL_BOARDS_B_G431B_ESC1_BOARD_ESC1_H
#define HAL_BOARDS_B_G431B_ESC1_BOARD_ESC1_H

#include "g4_board.h"

extern const g4_board_t g4_board_esc1;

#endif /* HAL_BOARDS_B_G431B_ESC1_BOARD_ESC1_H */
