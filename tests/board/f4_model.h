/*
 * A register-level model of the STM32F405 peripherals the F4 chip support
 * touches, for host (and QEMU) tests: the peripheral base addresses are
 * arrays (F4_MEM_ARRAYS), every access goes through f4_trace_read /
 * f4_trace_write (F4_REG_TRACE), which log the writes in order and model what
 * the hardware does that the code waits for or relies on: ready flags, the
 * clock switch, write-0-to-clear and write-1-to-clear flags, the software
 * break, the TIM1 update phase, SPI frames to a peer (the DRV8301 model),
 * GPIO levels, the flash interface's unlock, erase and programming of the
 * settings sectors. Every register starts at its RM0090 reset value.
 */
#ifndef TESTS_BOARD_F4_MODEL_H
#define TESTS_BOARD_F4_MODEL_H

#include <stdbool.h>
#include <stdint.h>

#include "f4_regs.h"

#define F4_MODEL_LOG_MAX 8192u

typedef struct {
    uintptr_t reg;
    uint32_t value; /* the value written (before the model's side effects) */
} f4_write_t;

typedef struct {
    f4_write_t log[F4_MODEL_LOG_MAX];
    uint32_t n_log;
    bool log_overflow;
    /* behaviour switches */
    bool hse_broken;             /* HSERDY never rises */
    bool pll_broken;             /* PLLRDY never rises */
    bool sws_stuck;              /* RCC_CFGR.SWS keeps its value */
    bool latency_stuck;          /* FLASH_ACR.LATENCY reads 0 */
    bool uev_at_valley;          /* the TIM1 update falls at the counter valley */
    bool tim1_dead;              /* TIM1 never updates (as in QEMU) */
    bool adc_dead;               /* regular conversions never end (EOC) */
    uint16_t adc_regular;        /* result of every regular conversion */
    uint16_t gpio_in[4];         /* levels of the input pins of ports A..D */
    bool flash_wrp[12];          /* write-protected sectors */
    bool flash_bsy_stuck;        /* BSY never clears */
    bool lsi_dead;               /* LSIRDY never rises (as in QEMU, which has no RCC) */
    uint32_t iwdg_update_cycles; /* IWDG_SR PVU / RVU stay set this many core
                                    cycles (CYCCNT) after PR / RLR are written */
    /* SPI peer: frames written to SPIn's DR go to it, its answer is read
     * back; NULL: the bus reads 0 (nothing connected). */
    uint16_t (*spi_peer)(uint32_t spi, uint16_t out);
    /* state the model keeps */
    bool rcr_before_cen;
    bool rcr_written;
    bool flash_key1; /* KEY1 written, KEY2 expected */
    uint32_t spi_frames;
    uint32_t iwdg_written_at; /* CYCCNT when PR or RLR was last written */
    /* ES0182 "Delay after an RCC peripheral clock enabling": an RCC enable
     * register whose write set a new bit and has not been read back since
     * (0: none), and how many accesses to another register came first (each
     * could reach a peripheral whose clock is not yet on). */
    uintptr_t rcc_enable_pending;
    uint32_t rcc_enable_unsynced;
    /* The next read of irq_on_read runs irq() right after the load (an
     * interrupt inside a read-modify-write); one shot. */
    uintptr_t irq_on_read;
    void (*irq)(void);
    /* PRIMASK (f4_irq_lock sets it, f4_irq_unlock puts the previous value
     * back): while set, the irq above is held pending and taken at the
     * unlock that clears it, as the core takes a pended interrupt. */
    uint32_t primask;
    uint32_t n_locks;          /* f4_irq_lock calls so far */
    void (*irq_pending)(void); /* taken when PRIMASK clears */
    /* A USART's receiver (f4_model_usart_rx): the character in DR, whether
     * SR was read since the last read of DR (the clearing sequence), the
     * characters an overrun lost. */
    uintptr_t usart_rx_base;
    uint8_t usart_rdr;
    bool usart_sr_read;
    uint32_t usart_lost;
} f4_model_t;

extern f4_model_t f4_model;
extern uint32_t f4_mem_flash_settings[];

/* Every register to its RM0090 reset value; clears the log and the switches;
 * the settings sectors erased (0xFF), every input pin high. */
void f4_model_reset(void);
/* Name of a register address ("TIM1+0x44") for messages. */
const char *f4_model_name(uintptr_t reg);
/* Index in the log of the first write to reg with (value & mask) == want at
 * or after `from`; -1 if none. */
int f4_model_find(uintptr_t reg, uint32_t mask, uint32_t want, int from);
int f4_model_find_last(uintptr_t reg, uint32_t mask, uint32_t want);
/* A character arrives on the RX pin of the USART at base (received only
 * with CR1.UE and RE): into DR with SR.RXNE, and SR's FE / NF from errors
 * for it; with RXNE still set it is lost and ORE set, DR keeping its
 * character (RM0090 sec. 30.6.1 USART_SR.ORE). A read of DR clears RXNE,
 * and ORE, FE, NF when SR was read before it. */
void f4_model_usart_rx(uintptr_t base, uint8_t c, uint32_t errors);
/* Current register content. */
uint32_t f4_model_get(uintptr_t reg);
void f4_model_put(uintptr_t reg, uint32_t value);
/* Output level of a pin as the GPIO's ODR drives it. */
bool f4_model_pin_out(uint32_t port, uint32_t pin);
/* Mode of a pin (MODER: 0 input, 1 output, 2 AF, 3 analog) and its AF. */
uint32_t f4_model_pin_mode(uint32_t port, uint32_t pin);
uint32_t f4_model_pin_af(uint32_t port, uint32_t pin);
/* Input level a test sets (nFAULT, ...). */
void f4_model_pin_in(uint32_t port, uint32_t pin, bool high);

#endif /* TESTS_BOARD_F4_MODEL_H */
