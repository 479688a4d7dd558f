/*
 * Timers of the STM32F405/407 (RM0090 sec. 17 "Advanced-control timers
 * (TIM1 and TIM8)" and sec. 18 "General-purpose timers (TIM2 to TIM5)"):
 * TIM1 as a three-phase complementary PWM, a TIM2..5 as a quadrature encoder
 * counter with an index capture, a TIM2..5 measuring a servo pulse train.
 * The time base, dead-time and filter arithmetic is hal/stm32/stm32_calc.h.
 *
 * What differs from the G4's TIM1 (hal/stm32g4/g4_tim.h): OCxM has three
 * bits, there is no TRGO2 (TRGO = update event triggers the ADCs), no break
 * filter and no internal comparator inputs: the break input is the BKIN pin
 * (PA6 or PB12, AF1), and the clock security system's HSE failure
 * (RM0090 sec. 17.3.14).
 */
#ifndef HAL_STM32F4_F4_TIM_H
#define HAL_STM32F4_F4_TIM_H

#include <stdbool.h>
#include <stdint.h>

#include "stm32_calc.h"

/* TIM1 as the inverter's PWM. */
typedef struct {
    stm32_pwm_timing_t timing;
    uint8_t dtg;      /* stm32_dtg_encode */
    bool break_input; /* BKIN pin wired to a hardware over-current signal */
    bool break_active_low;
} f4_tim1_cfg_t;

/* Configures TIM1 with the outputs safe and the counter stopped (RM0090
 * sec. 17.3): centre-aligned mode 1, ARR preload, PWM mode 1 on CH1..3 with
 * compare preload (new values act at the next update event), complementary
 * outputs with dead time, active high (CCxP = CCxNP = 0: the only gate
 * inputs f4_hal_describe accepts), idle state inactive (OISx = OISxN = 0, OSSI = OSSR
 * = 1: with MOE = 0 all six outputs are driven to their inactive level, both
 * switches of every leg off), break from the BKIN pin when the board wires
 * one (BKE, its polarity, BIE; AOE = 0: after a break the gates stay off
 * until software sets MOE), TRGO = update event (the ADC trigger),
 * repetition counter RCR = 1 written before the counter starts: one update
 * event per PWM period, at the counter peak (overflow). MOE stays 0.
 * Compare values 0. The core halted by a debugger stops TIM1 with its
 * outputs disabled (DBGMCU_APB2_FZ.DBG_TIM1_STOP). */
void f4_tim1_pwm_init(const f4_tim1_cfg_t *c);
/* Starts the counter; waits for an update event and checks that it fell at
 * the counter peak (TIMx_CR1.DIR = 1, counting down, right after it).
 * F4_OK or F4_E_TIM (then the counter is stopped again). */
int f4_tim1_start(const stm32_pwm_timing_t *t, uint32_t f_cpu_hz);
/* MOE: the outputs follow the compare values (on) / inactive (off, at once). */
void f4_tim1_outputs(bool on);
/* Gates off from any context, fault handlers included: a software break
 * (TIMx_EGR.BG clears MOE in hardware), then MOE cleared. */
void f4_tim1_gates_off_now(void);

/* The general-purpose timers TIM2..TIM5 (TIM2 and TIM5 count 32 bits). */
uintptr_t f4_gptim_base(uint32_t n);
/* Its clock on (RCC_APB1ENR.TIMxEN). */
void f4_gptim_enable(uint32_t n);

/* TIMn (2 or 5, the 32-bit ones) free-running at 1 MHz (PSC = f_tim / 1 MHz
 * - 1, ARR = 0xFFFF_FFFF): the main loop's microsecond clock. The DWT cycle
 * counter times the short waits; this one the main loop's periods, and it
 * also runs in QEMU's STM32F405 model, which has no DWT. */
void f4_ticks_init(uint32_t n, uint32_t f_tim_hz);
/* Its count, microseconds modulo 2^32. */
uint32_t f4_ticks(uint32_t n);

/* TIMn (2..5) as quadrature counter (encoder mode 3: x4, counts on both edges
 * of both channels, CH1/CH2 inputs), free-running over its 16 low bits
 * (ARR = 0xFFFF), input filter `icf`; channel `index_ch` (3 or 4; 0: none)
 * captures the counter on the index's rising edge. */
void f4_encoder_init(uint32_t n, uint32_t icf, uint32_t index_ch);

/* Servo pulse train on channel `ch` (1..4) of TIMn (2..5): the channel
 * captures the rising edges (CCxS = 01), its partner of the pair (1-2, 3-4)
 * the falling edges of the same input (CCyS = 10), the counter free-running
 * at f_tim / (psc + 1); input filter `icf`. */
void f4_capture_init(uint32_t n, uint32_t ch, uint32_t psc, uint32_t icf);

/* Pulses from the two captures: at each new rising edge, the width of the
 * pulse before it (its falling capture - the previous rising one) and the
 * period (rising - previous rising), in counter ticks modulo the counter's
 * width (16 bits on TIM3/4: frames up to 65.5 ms at 1 MHz). */
typedef struct {
    uint32_t n, ch;  /* timer, rising-edge channel */
    uint32_t mask;   /* counter width: 0xFFFF or 0xFFFFFFFF */
    uint32_t rise;   /* the last rising capture */
    bool primed;     /* rise holds one */
    uint32_t missed; /* samples dropped because a capture was overwritten */
} f4_capture_t;
void f4_capture_start(f4_capture_t *c, uint32_t n, uint32_t ch);
/* A rising edge has been captured since the last call: true with *width and
 * *period of the pulse that ended there. False if none, for the first edge,
 * or when a capture was overwritten since the previous one (an overcapture,
 * CCxOF: the pair would mix two pulses; counted in missed). */
bool f4_capture_read(f4_capture_t *c, uint32_t *width, uint32_t *period);

#endif /* HAL_STM32F4_F4_TIM_H */
