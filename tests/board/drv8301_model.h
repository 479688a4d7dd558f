/*
 * A DRV8301 on the F4 model's SPI bus (f4_model_t.spi_peer), as its data
 * sheet describes the interface: 16-bit frames while nSCS is low, the
 * response word answering the previous frame (bit 15 frame error, 14:11 the
 * address, 10:0 the data), registers 0..3 (status 1, status 2 with device ID
 * 1, control 1, control 2; 11 bits, zero after reset), status 1 cleared by
 * its read unless the condition persists, EN_GATE low resetting everything
 * and silencing the bus (MISO floats: the model reads `idle`).
 * Failure switches for the tests: writes lost after a reset, control bits
 * that never take a 1, an answer that is always `idle` (not connected),
 * frames the driver takes as invalid (frame error).
 */
#ifndef TESTS_BOARD_DRV8301_MODEL_H
#define TESTS_BOARD_DRV8301_MODEL_H

#include <stdbool.h>
#include <stdint.h>

#include "f4_periph.h"

typedef struct {
    f4_pin_t en_gate, cs, nfault; /* the board's pins (f4_model GPIO levels) */
    uint32_t spi;                 /* its SPI (1..3) */
    uint16_t reg[4];
    uint16_t next;        /* the response word of the next frame */
    bool was_enabled;     /* EN_GATE was high at the last frame */
    bool connected;       /* false: nothing on the bus */
    uint16_t idle;        /* what a silent bus reads (0x0000 pulled down, 0xFFFF up) */
    unsigned lose_writes; /* writes ignored after each reset */
    unsigned lost;
    uint16_t stuck_zero[2]; /* CR1 / CR2 bits that stay 0 */
    uint16_t persist1;      /* status 1 bits whose condition persists */
    bool frame_fault;       /* every frame taken as invalid: ignored, its
                               response word with the frame-error bit (15) */
    uint32_t frames, writes, gate_resets;
} drv8301_model_t;

extern drv8301_model_t drv8301_model;

/* Attached to f4_model (spi_peer), connected, registers at reset. */
void drv8301_model_attach(f4_pin_t en_gate, f4_pin_t cs, f4_pin_t nfault, uint32_t spi);
/* A fault: status bits latched (and kept while persist), nFAULT pulled low. */
void drv8301_model_fault(uint16_t status1, bool persist);

#endif /* TESTS_BOARD_DRV8301_MODEL_H */
