/*
 * hal.h on an STM32F405/407 motor board with a DRV8301 gate driver,
 * described by an f4_board_t.
 *
 * One PWM period k runs from one TIM1 counter peak to the next (the counter
 * counts ARR -> 0 -> ARR). At the peak every leg with a compare value below
 * ARR has its low-side switch on: the zero vector V0, centred on the peak,
 * the instant the plant model samples. The update event (RCR = 1, at the
 * peak) loads the compare values written during k-1 and, as TRGO, starts
 * the injected conversions of the ADCs that sample the phase currents and
 * the DC link; the end of the longest sequence (JEOC) raises the ADC
 * interrupt, which runs the firmware's period (fw_isr), whose compare values
 * act from the next peak: hal.h's timing contract. Compare values are
 * limited to cmp_max so that no leg switches within dead time + settling
 * time of the sampling (hal_info_t.pwm_cmp_max).
 *
 * Hardware protection: the DRV8301 watches every MOSFET's drain-source
 * voltage (OC_ADJ_SET) and, in latch shut-down mode, turns the gates off by
 * itself; its nFAULT output (also for under-voltage and over-temperature)
 * interrupts through EXTI, whose handler clears MOE and latches the trip for
 * hal_trip_active(). A board with a TIM1_BKIN signal gets the break too.
 *
 * The gate driver's configuration is written over SPI at start-up and read
 * back; the gates are never enabled unless it reads back as written, no
 * status bit is set and nFAULT is high (f4_hal_init holds them off for good
 * otherwise: hal_trip_active stays true).
 */
#ifndef HAL_STM32F4_F4_HAL_H
#define HAL_STM32F4_F4_HAL_H

#include <stdbool.h>
#include <stdint.h>

#include "drv8301.h"
#include "f4_board.h"
#include "f4_clock.h"
#include "f4_spi.h"
#include "hal.h"
#include "stm32_calc.h"

#define F4_HAL_FS_MIN_HZ 10000u
#define F4_HAL_FS_MAX_HZ 40000u

/* Run-time choices (they depend on the machine, not the board). */
typedef struct {
    uint32_t fs_hz;       /* PWM = control frequency, 10..40 kHz */
    uint32_t encoder_cpr; /* quadrature counts per mechanical revolution, 4..65535 */
} f4_hal_cfg_t;

/* Why the trip latch is set (f4_hal_trip_cause). */
#define F4_TRIP_DRIVER 0x1u  /* the DRV8301's nFAULT (over-current, UV, OT) */
#define F4_TRIP_BREAK 0x2u   /* TIM1 break input */
#define F4_TRIP_BOARD 0x4u   /* set by the board application (over-temperature) */
#define F4_TRIP_HOLD 0x8u    /* start-up failed: gates held off for good */
#define F4_TRIP_CONFIG 0x10u /* the gate driver's control registers changed */

struct hal {
    const f4_board_t *board;
    f4_clocks_t clk;
    hal_info_t info;
    stm32_pwm_timing_t timing;
    uint32_t cmp_max;   /* largest compare value written */
    uint32_t mirror;    /* 0xFFF when the sense gain is negative: raw = 4095 - code */
    uintptr_t jdr[4];   /* data registers of i_a, i_b, i_c, vdc (0: phase rebuilt) */
    uint32_t rebuilt;   /* the phase rebuilt from the other two, 3: none */
    uint32_t rebuild_k; /* 3 x the zero-current code: raw = k - raw_b - raw_c */
    uintptr_t irq_adc;  /* the ADC whose JEOC raises the interrupt */
    uint32_t adc_mask;  /* bit n: ADCn samples */
    uintptr_t enc_tim;
    uint32_t enc_index_ch;
    stm32_enc_ext_t enc;
    bool index_seen;
    uint32_t index_count;
    uint32_t nfault_line; /* EXTI line of nFAULT */
    /* Trip latch, one writer per word: fault_n / break_n counted by the
     * interrupts, *_acked by hal_trip_clear, board_trip, cfg_lost and hold
     * by the main loop. */
    volatile uint32_t fault_n, fault_acked;
    volatile uint32_t break_n, break_acked;
    volatile bool board_trip;
    volatile bool cfg_lost;
    uint8_t hold_depth; /* hal_ctrl_hold's nesting (main loop) */
    bool hold_was_on;   /* the ADC interrupt was enabled at the outermost hold */
    volatile bool hold;
    /* gate driver */
    f4_spi_t spi;
    uint32_t spi_timeout; /* core cycles */
    drv8301_t drv;
    int drv_rc;           /* the start-up configuration's result */
    uint32_t faults_seen; /* fault_n when the main loop last looked */
    uint16_t reported[2]; /* the status bits last reported (f4_hal_drv_service) */
};

/* The hal.h description for a board and configuration (timing, gains, zero
 * levels), no register access: F4_OK or F4_E_CONFIG. */
int f4_hal_describe(hal_t *h, const f4_board_t *b, const f4_hal_cfg_t *c, const f4_clocks_t *clk);

/* Start-up, in this order (each step only when the ones before it passed):
 *   1. f4_hal_describe (F4_E_CONFIG);
 *   2. the gate pins driven inactive, EN_GATE low (f4_hal_gate_pins_safe);
 *   3. the gate driver: EN_GATE low 40 us (its reset), high, 20 ms, the SPI,
 *      its control registers written and read back, its status read, nFAULT
 *      high (F4_E_DRIVER; EN_GATE back low: the driver holds every gate low;
 *      h->drv says why);
 *   4. only on the PLL's clock (F4_E_CLOCK otherwise: the PWM timing and the
 *      ADC clock assume it): ADCs, TIM1 (outputs safe), injected
 *      conversions armed, gate pins to TIM1, encoder, nFAULT's interrupt
 *      line, TIM1 started and its update phase checked (F4_E_TIM).
 * On any error h->hold is set: the gates are never enabled. */
int f4_hal_init(hal_t *h, const f4_board_t *b, const f4_hal_cfg_t *c, const f4_clocks_t *clk);

/* Compare values that keep the switching window around the samples:
 * cmp_max = ARR - ceil((dead time + settling) f_TIM), and it must also
 * cover the last current sample after the peak. F4_E_CONFIG if the window
 * takes more than a quarter of the period. */
int f4_hal_cmp_max(const f4_board_t *b, const stm32_pwm_timing_t *t, uint32_t f_tim_hz,
                   uint32_t f_adc_hz, uint32_t *cmp_max);

/* The zero-current code of the phase channels as hal_adc_read returns them,
 * and its tolerance (the sense's zero_tol_v), counts. */
void f4_hal_current_zero(const f4_board_t *b, uint16_t *zero, uint16_t *tol);

/* From the interrupts (board application). */
void f4_hal_adc_irq_ack(hal_t *h); /* clears JEOC of every sampling ADC */
/* nFAULT's EXTI interrupt: gates off (MOE cleared), counted, pending bit
 * cleared. */
void f4_hal_nfault_irq(hal_t *h);
/* TIM1 break interrupt (a board with BKIN): gates off, counted, BIF cleared;
 * masked while the input is still active. */
void f4_hal_break_irq(hal_t *h);
/* nFAULT is low now (a driver fault active); a board without the signal
 * wired reads high (never). */
bool f4_hal_nfault_low(const hal_t *h);
/* Main loop: sets (gates off at once) or releases F4_TRIP_BOARD. */
void f4_hal_trip_board(hal_t *h, bool on);
/* The F4_TRIP_* causes latched now (0: no trip). */
uint32_t f4_hal_trip_cause(const hal_t *h);

/* Main loop, every 100 ms or so: the status registers read (h->drv.status;
 * reading clears their latched bits); returns true after an nFAULT edge or
 * when the status bits differ from those last reported, so that the
 * application names them once; while the drive is stopped (gates off) a latched
 * driver fault is reset (GATE_RESET); every call the control registers are
 * checked against what was written: when they changed (a GVDD
 * under-voltage or an EN_GATE glitch resets them) F4_TRIP_CONFIG latches
 * (gates off) and, once stopped, they are written again and F4_TRIP_CONFIG
 * released only when they read back as written. */
bool f4_hal_drv_service(hal_t *h, bool stopped);

/* Power stage temperature: one regular conversion (main loop); -1 on
 * time-out. */
int32_t f4_hal_temp_counts(hal_t *h);
/* The NTC's beta model: deg C, or NaN when the voltage says the sensor is
 * open or shorted (within 1 % of either rail). */
double f4_hal_temp_c(const f4_board_t *b, int32_t counts);

#endif /* HAL_STM32F4_F4_HAL_H */
