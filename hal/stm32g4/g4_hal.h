/*
 * hal.h on an STM32G4 motor board described by a g4_board_t.
 *
 * One PWM period k runs from one TIM1 counter peak to the next (the counter
 * counts ARR -> 0 -> ARR). At the peak every leg with a compare value below
 * ARR has its low-side switch on: the zero vector V0, centred on the peak,
 * the instant the plant model samples. The update event (RCR = 1, at the
 * peak) loads the compare values written during k-1 and, as TRGO2, starts
 * the injected conversions of ADC1 and ADC2 (the three phase currents and the
 * DC link); their end-of-sequence interrupt runs the firmware's period
 * (fw_isr), whose compare values act from the next peak: hal.h's timing
 * contract. Compare values are limited to cmp_max so that V0 lasts at least
 * dead time + settling time + the sampling before and after the peak
 * (hal_info_t.pwm_cmp_max).
 *
 * Hardware over-current: each phase's conditioned shunt voltage (op-amp plus
 * input) goes to a comparator whose threshold comes from DAC3; the
 * comparators drive the TIM1 break input, which clears MOE without software.
 * The break interrupt latches it for hal_trip_active().
 */
#ifndef HAL_STM32G4_G4_HAL_H
#define HAL_STM32G4_G4_HAL_H

#include <stdbool.h>
#include <stdint.h>

#include "g4_board.h"
#include "g4_tim.h"
#include "hal.h"

#define G4_HAL_FS_MIN_HZ 10000u
#define G4_HAL_FS_MAX_HZ 40000u

/* Run-time choices (they depend on the machine, not the board). */
typedef struct {
    uint32_t fs_hz;        /* PWM = control frequency, 10..40 kHz */
    uint32_t encoder_cpr;  /* quadrature counts per mechanical revolution, 4..65535 */
    double trip_current_a; /* hardware over-current threshold, A (see g4_hal_trip_codes) */
} g4_hal_cfg_t;

/* Why the trip latch is set (g4_hal_trip_cause). */
#define G4_TRIP_BREAK 0x1u  /* comparator -> TIM1 break (over-current) */
#define G4_TRIP_SYSTEM 0x2u /* TIM1 system break: clock failure, core lockup */
#define G4_TRIP_BOARD 0x4u  /* set by the board application (e.g. over-temperature) */

struct hal {
    const g4_board_t *board;
    hal_info_t info;
    g4_pwm_timing_t timing;
    uint32_t cmp_max;  /* largest compare value written */
    uint32_t mirror;   /* 0xFFF when the sense gain is negative: raw = 4095 - code */
    uintptr_t jdr[4];  /* data registers of i_a, i_b, i_c, vdc */
    uintptr_t irq_adc; /* the ADC whose end of sequence raises the interrupt */
    uintptr_t other_adc;
    g4_enc_ext_t enc;
    bool index_seen;
    uint32_t index_count;
    /* Trip latch, one writer per word (no read-modify-write shared between
     * priorities): break_n, system_n counted by the break interrupt,
     * break_acked set by hal_trip_clear, board_trip by the main loop. A
     * break counted and not yet acknowledged is latched (break_n !=
     * break_acked); the interrupt is masked only while one is. */
    volatile uint32_t break_n;     /* comparator breaks seen */
    volatile uint32_t break_acked; /* break_n at the last accepted clear */
    volatile uint32_t system_n;    /* system breaks seen (not clearable) */
    volatile bool board_trip;      /* G4_TRIP_BOARD */
    uint8_t hold_depth;            /* hal_ctrl_hold's nesting (main loop) */
    bool hold_was_on;              /* ADC1_2 was enabled at the outermost hold */
    uint16_t vinp_zero[3];         /* comparator plus inputs at zero current, ADC counts */
    uint32_t dac_code[2];          /* DAC3 channel 1, 2 thresholds */
    double trip_current_a;
};

/* Everything but the clock (g4_clock_init first): checks the configuration,
 * gates off, op-amps, ADCs (calibrated), comparator thresholds from the
 * zero-current levels, TIM1 (outputs safe), injected conversions armed,
 * encoder, then TIM1 started and its update phase checked. Returns G4_OK or a
 * G4_E_* code; on any error the gates were never enabled. */
int g4_hal_init(hal_t *h, const g4_board_t *b, const g4_hal_cfg_t *c);

/* Comparator threshold codes for a trip current (phases sharing a DAC
 * channel get the lower code: every phase trips at or below the current).
 * Threshold on the op-amp plus input: V_zero + |sense_gain| / pga_gain x
 * R_shunt x I_trip (the plus input moves by 1/pga_gain of the output).
 * G4_E_CONFIG when I_trip is not in (0, current_peak_a] or a code is out of
 * the DAC's range. */
int g4_hal_trip_codes(const g4_board_t *b, const uint16_t vinp_zero[3], double trip_a,
                      uint32_t code[2]);
/* Re-programs the thresholds (main loop). */
int g4_hal_set_trip_current(hal_t *h, double trip_a);

/* Compare values that keep the zero-vector window for the current samples:
 * cmp_max = ARR - ceil((dead time + settling) f_TIM), and the window must
 * also cover the last current sample after the peak. G4_E_CONFIG if the
 * window takes more than a quarter of the period. */
int g4_hal_cmp_max(const g4_board_t *b, const g4_pwm_timing_t *t, uint32_t *cmp_max);

/* The six gate pins as GPIO outputs at their inactive level (both switches
 * of every leg off), taken from TIM1: init's first step, and the fault
 * handlers' last. */
void g4_hal_gate_pins_safe(const g4_board_t *b);

/* From the interrupts (board application). */
void g4_hal_adc_irq_ack(hal_t *h); /* clears the end-of-sequence flags */
/* The TIM1 break interrupt's handler: gates off (MOE cleared, no software
 * break), counts and clears the break flags; masks the interrupt while a
 * break input is still active. */
void g4_hal_break_irq(hal_t *h);
/* Main loop (and hal_trip_clear): once the break inputs are released,
 * clears the flags the masked interrupt left and enables it again. True when
 * the interrupt was enabled already (nothing to do). */
bool g4_hal_break_rearm(hal_t *h);
/* Main loop: sets (gates off at once) or releases G4_TRIP_BOARD. */
void g4_hal_trip_board(hal_t *h, bool on);
/* The G4_TRIP_* causes latched now (0: no trip). */
uint32_t g4_hal_trip_cause(const hal_t *h);

/* Board temperature: one regular conversion (main loop); -1 on time-out. */
int32_t g4_hal_temp_counts(hal_t *h);
/* The board's linear model: deg C, or NaN when the voltage says the sensor is
 * open or shorted. */
double g4_hal_temp_c(const g4_board_t *b, int32_t counts);

#endif /* HAL_STM32G4_G4_HAL_H */
