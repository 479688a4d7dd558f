/*
 * ADC1..ADC3 of the STM32F405/407 (RM0090 sec. 13): power-up, injected
 * sequences triggered by TIM1's TRGO, single regular conversions.
 *
 * Clock: ADCCLK = PCLK2 / 4 = 21 MHz at PCLK2 = 84 MHz (ADC_CCR.ADCPRE = 01),
 * below the 36 MHz maximum (DS8626 "ADC characteristics", f_ADC at VDDA >=
 * 2.4 V); VESC and ODrive use the same divider (ODrive Board/v3/Src/adc.c:
 * ADC_CLOCK_SYNC_PCLK_DIV4). Conversion of one channel, 12 bits: sampling
 * time + 12 ADCCLK cycles (sec. 13.6: T_conv = sampling + 12 cycles), the
 * sampling time 3, 15, 28, 56, 84, 112, 144 or 480 cycles (ADC_SMPRx codes
 * 0..7). Injected ranks convert one after the other from the trigger.
 *
 * The injected sequence is right-aligned in ADC_JSQR (sec. 13.13.12): with
 * JL + 1 = n conversions the ADC converts JSQ(4-n+1) .. JSQ4, and the result
 * of the r-th conversion lands in JDRr (ST's HAL: ADC_JSQR(channel, rank, n)
 * shifts the channel by 5 x (rank + 3 - n)).
 */
#ifndef HAL_STM32F4_F4_ADC_H
#define HAL_STM32F4_F4_ADC_H

#include <stdbool.h>
#include <stdint.h>

#define F4_ADC_FULL_SCALE 4095u /* 12-bit: V = VREF+ x code / 4095 */
#define F4_ADC_PRESCALER 4u     /* ADCCLK = PCLK2 / 4 */

uintptr_t f4_adc_base(uint32_t n); /* ADC1..ADC3 */

/* ADC_SMPRx code of a sampling time in ADC cycles (3, 15, .. 480), or
 * F4_E_CONFIG. */
int f4_adc_smp_code(uint32_t smp_cycles, uint32_t *code);
uint32_t f4_adc_smp_cycles(uint32_t code);

/* ADC_JSQR for n = 1..4 injected ranks of channels ch[0..n-1]. */
uint32_t f4_adc_jsqr(const uint8_t *ch, unsigned n);

/* End of the sampling phase of injected rank `rank` (1-based) after the
 * trigger, ADC cycles: the ranks before it take (SMP + 12) cycles each,
 * latency = trigger-to-sampling latency. */
uint32_t f4_adc_sample_end(const uint32_t *smp_cycles, unsigned rank, uint32_t latency);

/* Clocks of ADC1..3 on, the common prescaler PCLK2 / 4 (ADCs off). */
void f4_adc_clock_init(void);
/* ADON, then the stabilisation time t_STAB (3 us: DS8626; ST's HAL
 * ADC_STAB_DELAY_US). */
void f4_adc_power_up(uintptr_t adc, uint32_t f_cpu_hz);
void f4_adc_set_smp(uintptr_t adc, uint32_t channel, uint32_t code);
/* Injected sequence, JEOC interrupt when irq, trigger TIM1_TRGO on its rising
 * edge (JEXTEN = 01): the ADC converts at every trigger from then on. */
void f4_adc_injected_start(uintptr_t adc, uint32_t jsqr, bool irq);
/* One regular conversion of `channel` started by software (SWSTART), waited
 * for (EOC, time-out in core cycles). Returns the 12-bit result or -1.
 * Injected conversions triggered meanwhile interrupt it and it resumes
 * (sec. 13.3.9). */
int32_t f4_adc_convert(uintptr_t adc, uint32_t channel, uint32_t timeout_cycles);

#endif /* HAL_STM32F4_F4_ADC_H */
