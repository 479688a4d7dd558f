/*
 * Timers of the STM32G4 (RM0440 chapter 29 "Advanced-control timers
 * (TIM1/TIM8/TIM20)" and the general-purpose TIM2/TIM3/TIM4/TIM5 chapter):
 * the PWM time base, the dead-time and filter encodings, TIM1 as a
 * three-phase complementary PWM with break input, TIM4 as a quadrature
 * encoder counter.
 */
#ifndef HAL_STM32G4_G4_TIM_H
#define HAL_STM32G4_G4_TIM_H

#include <stdbool.h>
#include <stdint.h>

#include "g4_core.h"
#include "stm32_calc.h"

_Static_assert(G4_OK == STM32_OK && G4_E_CONFIG == STM32_E_CONFIG, "shared return codes");

/* The time base, dead-time encoding and filter codes are the same arithmetic
 * as the other STM32 families' (hal/stm32/stm32_calc.h); the G4 names of
 * them follow. */
typedef stm32_pwm_timing_t g4_pwm_timing_t;
static inline int g4_pwm_timing(uint32_t f_tim_hz, uint32_t fs_hz, g4_pwm_timing_t *t)
{
    return stm32_pwm_timing(f_tim_hz, fs_hz, t);
}
static inline int g4_dtg_encode(uint32_t f_dts_hz, uint32_t dead_ns, uint8_t *dtg)
{
    return stm32_dtg_encode(f_dts_hz, dead_ns, dtg);
}
static inline uint32_t g4_dtg_ticks(uint8_t dtg)
{
    return stm32_dtg_ticks(dtg);
}
static inline uint32_t g4_filter_cycles(uint32_t code)
{
    return stm32_filter_cycles(code);
}

/* TIM1 as the inverter's PWM. */
typedef struct {
    g4_pwm_timing_t timing;
    uint8_t dtg;         /* g4_dtg_encode */
    uint8_t bkf;         /* break filter code */
    uint8_t break_comps; /* bit n (1..4): COMPn output drives the break input */
    bool active_low;     /* gate-driver inputs active low (CCxP = CCxNP = 1) */
} g4_tim1_cfg_t;

/* Configures TIM1 with the outputs safe and the counter stopped (RM0440
 * chapter 29): centre-aligned mode 1, ARR preload, PWM mode 1 on CH1..3 with
 * compare preload (new values act at the next update event), complementary
 * outputs with dead time, idle state inactive (OISx = OISxN = 0, OSSI = OSSR
 * = 1: with MOE = 0 all six outputs are driven to their inactive level, both
 * switches of every leg off), break input from the comparators, filtered,
 * active high, not automatic (AOE = 0: after a break the gates stay off until
 * software sets MOE), TRGO2 = update event (the ADC trigger), repetition
 * counter RCR = 1 written before the counter starts: one update event per PWM
 * period, at the counter peak (overflow). MOE stays 0. Compare values 0. */
void g4_tim1_pwm_init(const g4_tim1_cfg_t *c);
/* Starts the counter; waits for an update event and checks that it fell at
 * the counter peak (TIMx_CR1.DIR = 1, counting down, right after it).
 * G4_OK or G4_E_TIM (then the counter is stopped again). */
int g4_tim1_start(const g4_pwm_timing_t *t, uint32_t f_cpu_hz);
/* MOE: the outputs follow the compare values (on) / inactive (off, at once). */
void g4_tim1_outputs(bool on);
/* Gates off from any context, fault handlers included: a software break
 * (TIMx_EGR.BG clears MOE in hardware), then MOE cleared. */
void g4_tim1_gates_off_now(void);

/* TIM4 as quadrature counter (encoder mode 3: x4, counts on both edges of
 * both channels), 16 bits free-running (ARR = 0xFFFF), input filter code
 * `icf` on CH1/CH2; CH3 (index) captures the counter on its rising edge
 * when `index` is set. */
void g4_tim4_encoder_init(uint32_t icf, bool index);

/* TIM2 measuring a pulse train on CH1 (RM0440 TIM2/3/4/5, "PWM input
 * mode"): IC1 on TI1 rising edges, IC2 on TI1 falling edges, the rising edge
 * resets the counter (slave reset mode on TI1FP1): CCR1 = period, CCR2 =
 * width, in ticks of f_tim / (psc + 1); 32-bit counter; input filter `icf`. */
void g4_tim2_capture_init(uint32_t psc, uint32_t icf);
/* A period has ended since the last call (CC1IF): its pulse's width (CCR2)
 * and the period (CCR1), ticks, one period's pair; false if not, and false
 * when the reads cannot be sure of the pair: a rising edge during them, or
 * the next pulse's falling edge already captured (a read later than the
 * pulse's width after the period's end). */
bool g4_tim2_capture_read(uint32_t *width, uint32_t *period);

/* The 16-bit encoder counter extended to the 32-bit count of hal.h
 * (stm32_calc.h). */
typedef stm32_enc_ext_t g4_enc_ext_t;
static inline uint32_t g4_enc_extend(g4_enc_ext_t *e, uint16_t cnt)
{
    return stm32_enc_extend(e, cnt);
}
static inline uint32_t g4_enc_at_capture(const g4_enc_ext_t *e, uint16_t cnt, uint16_t ccr)
{
    return stm32_enc_at_capture(e, cnt, ccr);
}

#endif /* HAL_STM32G4_G4_TIM_H */
