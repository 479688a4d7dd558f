/*
 * Configuration arithmetic shared by the STM32 chip supports (hal/stm32g4,
 * hal/stm32f4): register values worked out from a requested quantity, no
 * register access. What the families share here is the same in ST's
 * reference manuals for both (RM0440 for the G4, RM0090 for the F405/407):
 *   - the centre-aligned time base of the timers (PSC, ARR),
 *   - the dead-time generator's DTG[7:0] encoding of TIMx_BDTR (RM0440
 *     sec. 29.6.21, RM0090 sec. 17.4.18, the same four ranges),
 *   - the digital input filter codes of TIMx_CCMRx.ICxF / BDTR.BKF,
 *   - the extension of a 16-bit encoder counter to 32 bits,
 *   - the USART baud-rate register with 16x oversampling (RM0440 "USART
 *     baud rate generation", RM0090 sec. 30.3.4: USARTDIV = f_CK / baud, the
 *     BRR value is USARTDIV x 16 / 16 = round(f_CK / baud) either way),
 *   - the independent watchdog's prescaler and reload (RM0440 / RM0090
 *     IWDG chapters: divider 4 x 2^PR, PR 0..6, 12-bit RLR).
 * The chip supports keep their own register maps and access layers.
 */
#ifndef HAL_STM32_STM32_CALC_H
#define HAL_STM32_STM32_CALC_H

#include <stdbool.h>
#include <stdint.h>

#define STM32_OK 0
#define STM32_E_CONFIG (-1) /* a requested value has no register encoding */

/* Centre-aligned time base: the counter runs 0 -> ARR -> 0, so one PWM
 * period is 2 ARR (PSC + 1) timer clocks: f_PWM = f_TIM / (2 ARR (PSC + 1)). */
typedef struct {
    uint32_t psc;   /* TIMx_PSC (divider - 1) */
    uint32_t arr;   /* TIMx_ARR = compare value for 100 % duty */
    uint32_t fs_hz; /* f_PWM, exactly the requested one */
} stm32_pwm_timing_t;

/* PSC = 0 when ARR fits 16 bits, else the smallest prescaler; the period must
 * be a whole number of timer clocks (f_TIM divisible by 2 fs (PSC + 1)),
 * otherwise STM32_E_CONFIG (the control period would not be 1/fs exactly). */
int stm32_pwm_timing(uint32_t f_tim_hz, uint32_t fs_hz, stm32_pwm_timing_t *t);

/* Dead time, TIMx_BDTR.DTG[7:0] (t_DTS = 1/f_DTS, CKD = 0 so f_DTS = f_TIM):
 *   DTG[7:5] = 0xx:  DT = DTG[7:0] x t_DTS                      0 .. 127 t_DTS
 *   DTG[7:5] = 10x:  DT = (64 + DTG[5:0]) x 2 t_DTS            128 .. 254 t_DTS
 *   DTG[7:5] = 110:  DT = (32 + DTG[4:0]) x 8 t_DTS            256 .. 504 t_DTS
 *   DTG[7:5] = 111:  DT = (32 + DTG[4:0]) x 16 t_DTS           512 .. 1008 t_DTS
 * The encoding never gives less than the requested time (rounded up to the
 * range's step). STM32_OK, or STM32_E_CONFIG above 1008 t_DTS. */
int stm32_dtg_encode(uint32_t f_dts_hz, uint32_t dead_ns, uint8_t *dtg);
/* Dead time of a DTG code, in t_DTS. */
uint32_t stm32_dtg_ticks(uint8_t dtg);

/* Digital filter codes (TIMx_BDTR.BKF, TIMx_CCMRx.ICxF, same table): the
 * delay of a code in f_DTS cycles (sampling divider x N events), e.g.
 * 0011 = f_CK_INT, N = 8 -> 8; 1010 = f_DTS/16, N = 5 -> 80. */
uint32_t stm32_filter_cycles(uint32_t code);

/* 16-bit hardware counter extended to a 32-bit count: the signed 16-bit
 * difference since the last read is added (valid while the encoder moves
 * less than 32768 counts between two reads, i.e. below 32768 fs / cpr
 * revolutions per second). The first read is sign-extended. */
typedef struct {
    uint32_t count; /* extended count */
    uint16_t last;  /* last hardware value */
    bool primed;
} stm32_enc_ext_t;
uint32_t stm32_enc_extend(stm32_enc_ext_t *e, uint16_t cnt);
/* Extended count at a capture taken by the hardware at `ccr` (16 bits), given
 * the extended count at the present hardware value `cnt`. */
uint32_t stm32_enc_at_capture(const stm32_enc_ext_t *e, uint16_t cnt, uint16_t ccr);

/* USART baud-rate register, oversampling by 16: BRR = round(f_ck / baud);
 * the achieved rate is f_ck / BRR. STM32_E_CONFIG if BRR < 16 or > 0xFFFF. */
int stm32_usart_brr(uint32_t f_ck_hz, uint32_t baud, uint32_t *brr);

/* IWDG: divider 4 x 2^PR (PR 0..6), down-counter from RLR (12 bits):
 * time-out = (RLR + 1) x divider / f_LSI. The smallest divider that reaches
 * timeout_ms at f_lsi_hz (rounded up: never shorter). STM32_E_CONFIG if it
 * cannot be reached. */
int stm32_iwdg_config(uint32_t timeout_ms, uint32_t f_lsi_hz, uint32_t *pr, uint32_t *rlr);
/* The time-out of PR, RLR at f_lsi_hz, ms (rounded down). */
uint32_t stm32_iwdg_timeout_ms(uint32_t pr, uint32_t rlr, uint32_t f_lsi_hz);

#endif /* HAL_STM32_STM32_CALC_H */
