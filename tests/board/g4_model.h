/*
 * A register-level model of the STM32G4 peripherals the G4 HAL touches, for
 * host (and QEMU) tests: the peripheral base addresses are arrays
 * (G4_MEM_ARRAYS), every access goes through g4_trace_read / g4_trace_write
 * (G4_REG_TRACE), which log the writes in order and model what the hardware
 * does that the HAL waits for (ready flags, calibration end, write-1-to-clear
 * and write-0-to-clear flags, the software break, the TIM1 update phase).
 * The model is deliberately simple: it answers the HAL's polls, it does not
 * convert or count.
 */
#ifndef TESTS_BOARD_G4_MODEL_H
#define TESTS_BOARD_G4_MODEL_H

#include <stdbool.h>
#include <stdint.h>

#include "g4_regs.h"

#define G4_MODEL_LOG_MAX 4096u

typedef struct {
    uintptr_t reg;
    uint32_t value; /* the value written (before the model's side effects) */
} g4_write_t;

typedef struct {
    g4_write_t log[G4_MODEL_LOG_MAX];
    uint32_t n_log;
    bool log_overflow;
    /* behaviour switches */
    bool hse_broken;      /* HSERDY never rises */
    bool sws_stuck;       /* RCC_CFGR.SWS keeps its value (a switch never completes) */
    bool uev_at_valley;   /* the TIM1 update falls at the counter valley */
    uint16_t adc_regular; /* result of every regular conversion */
    bool comp_high;       /* every comparator output high (and the break input with it) */
    /* The next read of irq_on_read runs irq() right after the load (an
     * interrupt inside a read-modify-write); one shot. */
    uintptr_t irq_on_read;
    void (*irq)(void);
    /* PRIMASK (g4_irq_lock sets it, g4_irq_unlock puts the previous value
     * back): while set, the irq above is held pending and taken at the
     * unlock that clears it, as the core takes a pended interrupt. */
    uint32_t primask;
    uint32_t n_locks;          /* g4_irq_lock calls so far */
    void (*irq_pending)(void); /* taken when PRIMASK clears */
    /* Called after every register write (NULL: none): a test's probe. */
    void (*on_write)(uintptr_t reg, uint32_t value);
    /* USART2's receiver (g4_model_usart_rx): RDR, or with CR1.FIFOEN the
     * RXFIFO, oldest first; each entry a character, | 0x100 for a framing
     * error. */
    uint16_t usart_fifo[G4_USART_FIFO_DEPTH];
    uint32_t usart_n;
    uint32_t usart_lost; /* characters an overrun lost */
    /* state the model keeps */
    bool rcr_before_cen;
    bool rcr_written;
    bool flash_key1; /* FLASH_KEYR: KEY1 was the last key written */
} g4_model_t;

extern g4_model_t g4_model;

/* Every register to its RM0440 reset value; clears the log and the switches.
 * The settings pages (g4_mem_flash_settings) keep their content, as the flash
 * does across a power cycle (erased before the first reset). */
void g4_model_reset(void);
/* The TIM1 break interrupt would be taken (again): BIE and a break flag set. */
bool g4_model_break_pending(void);
/* Name of a register address ("TIM1+0x44") for messages. */
const char *g4_model_name(uintptr_t reg);
/* Index in the log of the first write to reg with (value & mask) == want at
 * or after `from`; -1 if none. */
int g4_model_find(uintptr_t reg, uint32_t mask, uint32_t want, int from);
/* The same, last such write. */
int g4_model_find_last(uintptr_t reg, uint32_t mask, uint32_t want);
/* A character arrives on USART2's RX pin (received only with CR1.UE and
 * RE): into RDR, with CR1.FIFOEN into the 8-character RXFIFO; with no room
 * it is lost and ORE set (RM0440 USART_ISR.ORE; RDR's, the RXFIFO's
 * content is kept). framing_error: FE with the character when it reaches
 * RDR. ISR.RXNE (RXFNE), RXFF and FE follow; a read of RDR pops it. */
void g4_model_usart_rx(uint8_t c, bool framing_error);
/* Current register content. */
uint32_t g4_model_get(uintptr_t reg);
void g4_model_put(uintptr_t reg, uint32_t value);

#endif /* TESTS_BOARD_G4_MODEL_H */
