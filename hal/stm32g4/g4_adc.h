/*
 * ADC1/ADC2 of the STM32G4 (RM0440 ADC chapter): power-up, calibration,
 * injected sequences triggered by a timer, regular single conversions.
 *
 * Clock: synchronous, HCLK / 4 (ADC12_CCR.CKMODE = 11): 42.5 MHz at 170 MHz,
 * below the 60 MHz maximum of the datasheet (DS12589, f_ADC), and with a
 * fixed trigger-to-sampling latency.
 * Conversion of one channel, 12 bits: (SMP + 12.5) ADC clock cycles, SMP the
 * sampling time of the channel (2.5, 6.5, 12.5, 24.5, 47.5, 92.5, 247.5,
 * 640.5 cycles; ADC_SMPRx codes 0..7). Injected ranks convert one after the
 * other from the trigger.
 */
#ifndef HAL_STM32G4_G4_ADC_H
#define HAL_STM32G4_G4_ADC_H

#include <stdint.h>

#define G4_ADC_FULL_SCALE 4095u /* 12-bit: V = VREF+ x code / 4095 (RM0440) */

/* ADC_SMPRx code for a sampling time given in half cycles (5 = 2.5 cycles,
 * 13 = 6.5, ...). G4_OK or G4_E_CONFIG if it is not one of the eight. */
int g4_adc_smp_code(uint32_t smp_half_cycles, uint32_t *code);
/* Sampling time in half cycles of an SMP code. */
uint32_t g4_adc_smp_half_cycles(uint32_t code);

/* ADC_JSQR for n = 1..4 injected ranks (channels ch[0..n-1]), external
 * trigger jextsel on the rising edge. */
uint32_t g4_adc_jsqr(const uint8_t *ch, unsigned n, uint32_t jextsel);

/* Start and end of the sampling phase of injected rank `rank` (1-based) after
 * the trigger, in ADC clock half cycles: the ranks before it take
 * (SMP + 12.5) cycles each; latency_half = trigger-to-sampling latency. */
void g4_adc_sample_window(const uint32_t *smp_half, unsigned rank, uint32_t latency_half,
                          uint32_t *start_half, uint32_t *end_half);

/* ADC1/ADC2 common clock: synchronous HCLK / 4 (both ADCs disabled). */
void g4_adc12_clock_init(void);
/* Exit deep power-down, regulator on and its start-up time (20 us,
 * t_ADCVREG_STUP), single-ended calibration (ADCAL) with time-out, >= 4 ADC
 * clock cycles, then enable (ADEN) and wait for ADRDY (RM0440 "ADC
 * on-off control", "Calibration"). f_cpu_hz for the waits. */
int g4_adc_power_up(uintptr_t adc, uint32_t f_cpu_hz);
/* Sampling time code of one channel (ADC_SMPR1/2). */
void g4_adc_set_smp(uintptr_t adc, uint32_t channel, uint32_t code);
/* Injected sequence with its external trigger, then JADSTART (the ADC waits
 * for the trigger). */
void g4_adc_injected_start(uintptr_t adc, uint32_t jsqr);
/* One regular conversion of `channel` started by software, waited for
 * (time-out in core cycles). Returns the 12-bit result or -1. Injected
 * conversions triggered meanwhile take precedence (the regular one restarts). */
int32_t g4_adc_convert(uintptr_t adc, uint32_t channel, uint32_t timeout_cycles);

#endif /* HAL_STM32G4_G4_ADC_H */
