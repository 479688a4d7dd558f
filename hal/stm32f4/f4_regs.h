/*
 * STM32F405/407 register map: the peripheral base addresses, register offsets
 * and bit fields this chip support uses, named as in ST's reference manual
 * RM0090 (register TIMx_BDTR, field MOE -> F4_TIM_BDTR, F4_TIM_BDTR_MOE).
 * Cortex-M4 core registers (SCB, NVIC, DWT) are named as in ARM's ARMv7-M
 * Architecture Reference Manual.
 *
 * Sources: RM0090 sec. 2.3 "Memory map" (table 1, register boundary
 * addresses) and every peripheral chapter's register map; every value here
 * is checked by tests/board/test_f4_facts against a list of facts written
 * from RM0090 and ST's CMSIS device header stm32f405xx.h
 * (STMicroelectronics/cmsis_device_f4: *_BASE, the *_TypeDef member order,
 * the *_Pos / *_Msk values): tests/board/f4_facts.txt.
 *
 * Register access goes through f4_rd/f4_wr only. Three builds, as for the G4
 * (hal/stm32g4/g4_regs.h):
 *   target (default)     base addresses are the chip's; plain volatile access
 *   F4_MEM_ARRAYS        base addresses are the addresses of arrays
 *                        f4_mem_<name>[] that the build provides (host tests,
 *                        the QEMU instruction-count image)
 *   F4_REG_TRACE         (with F4_MEM_ARRAYS) every access calls
 *                        f4_trace_read / f4_trace_write, which the register-image
 *                        test implements (write log, hardware model)
 */
#ifndef HAL_STM32F4_F4_REGS_H
#define HAL_STM32F4_F4_REGS_H

#include <stdint.h>

/* X(name, lower-case name, base address, bytes mapped in a host array).
 * Addresses: RM0090 table 1 (= stm32f405xx.h *_BASE); core: ARMv7-M System
 * Control Space. Host arrays cover the registers used. */
#define F4_PERIPHS(X)                                                                              \
    X(TIM2, tim2, 0x40000000u, 0x54u)                                                              \
    X(TIM3, tim3, 0x40000400u, 0x54u)                                                              \
    X(TIM4, tim4, 0x40000800u, 0x54u)                                                              \
    X(TIM5, tim5, 0x40000C00u, 0x54u)                                                              \
    X(IWDG, iwdg, 0x40003000u, 0x10u)                                                              \
    X(SPI2, spi2, 0x40003800u, 0x24u)                                                              \
    X(SPI3, spi3, 0x40003C00u, 0x24u)                                                              \
    X(USART2, usart2, 0x40004400u, 0x1Cu)                                                          \
    X(USART3, usart3, 0x40004800u, 0x1Cu)                                                          \
    X(UART4, uart4, 0x40004C00u, 0x1Cu)                                                            \
    X(PWR, pwr, 0x40007000u, 0x8u)                                                                 \
    X(TIM1, tim1, 0x40010000u, 0x54u)                                                              \
    X(USART1, usart1, 0x40011000u, 0x1Cu)                                                          \
    X(USART6, usart6, 0x40011400u, 0x1Cu)                                                          \
    X(ADC1, adc1, 0x40012000u, 0x50u)                                                              \
    X(ADC2, adc2, 0x40012100u, 0x50u)                                                              \
    X(ADC3, adc3, 0x40012200u, 0x50u)                                                              \
    X(ADC_COMMON, adc_common, 0x40012300u, 0xCu)                                                   \
    X(SPI1, spi1, 0x40013000u, 0x24u)                                                              \
    X(SYSCFG, syscfg, 0x40013800u, 0x24u)                                                          \
    X(EXTI, exti, 0x40013C00u, 0x18u)                                                              \
    X(GPIOA, gpioa, 0x40020000u, 0x28u)                                                            \
    X(GPIOB, gpiob, 0x40020400u, 0x28u)                                                            \
    X(GPIOC, gpioc, 0x40020800u, 0x28u)                                                            \
    X(GPIOD, gpiod, 0x40020C00u, 0x28u)                                                            \
    X(RCC, rcc, 0x40023800u, 0x88u)                                                                \
    X(FLASH, flash, 0x40023C00u, 0x18u)                                                            \
    X(DBGMCU, dbgmcu, 0xE0042000u, 0x10u)                                                          \
    X(DWT, dwt, 0xE0001000u, 0x10u)                                                                \
    X(NVIC, nvic, 0xE000E100u, 0x400u)                                                             \
    X(SCB, scb, 0xE000ED00u, 0x100u)

#if defined(F4_MEM_ARRAYS)
#define F4_DECLARE_ARRAY(N, n, addr, bytes) extern uint32_t f4_mem_##n[(bytes) / 4u];
F4_PERIPHS(F4_DECLARE_ARRAY)
#undef F4_DECLARE_ARRAY
#define F4_BASE(n, addr) ((uintptr_t)f4_mem_##n)
#else
#define F4_BASE(n, addr) ((uintptr_t)(addr))
#endif

#define F4_TIM2 F4_BASE(tim2, 0x40000000u)
#define F4_TIM3 F4_BASE(tim3, 0x40000400u)
#define F4_TIM4 F4_BASE(tim4, 0x40000800u)
#define F4_TIM5 F4_BASE(tim5, 0x40000C00u)
#define F4_IWDG F4_BASE(iwdg, 0x40003000u)
#define F4_SPI2 F4_BASE(spi2, 0x40003800u)
#define F4_SPI3 F4_BASE(spi3, 0x40003C00u)
#define F4_USART2 F4_BASE(usart2, 0x40004400u)
#define F4_USART3 F4_BASE(usart3, 0x40004800u)
#define F4_UART4 F4_BASE(uart4, 0x40004C00u)
#define F4_PWR F4_BASE(pwr, 0x40007000u)
#define F4_TIM1 F4_BASE(tim1, 0x40010000u)
#define F4_USART1 F4_BASE(usart1, 0x40011000u)
#define F4_USART6 F4_BASE(usart6, 0x40011400u)
#define F4_ADC1 F4_BASE(adc1, 0x40012000u)
#define F4_ADC2 F4_BASE(adc2, 0x40012100u)
#define F4_ADC3 F4_BASE(adc3, 0x40012200u)
#define F4_ADC_COMMON F4_BASE(adc_common, 0x40012300u)
#define F4_SPI1 F4_BASE(spi1, 0x40013000u)
#define F4_SYSCFG F4_BASE(syscfg, 0x40013800u)
#define F4_EXTI F4_BASE(exti, 0x40013C00u)
#define F4_GPIOA F4_BASE(gpioa, 0x40020000u)
#define F4_GPIOB F4_BASE(gpiob, 0x40020400u)
#define F4_GPIOC F4_BASE(gpioc, 0x40020800u)
#define F4_GPIOD F4_BASE(gpiod, 0x40020C00u)
#define F4_RCC F4_BASE(rcc, 0x40023800u)
#define F4_FLASH F4_BASE(flash, 0x40023C00u)
#define F4_DBGMCU F4_BASE(dbgmcu, 0xE0042000u)
#define F4_DWT F4_BASE(dwt, 0xE0001000u)
#define F4_NVIC F4_BASE(nvic, 0xE000E100u)
#define F4_SCB F4_BASE(scb, 0xE000ED00u)

/* ---- access ---- */
#if defined(F4_REG_TRACE)
uint32_t f4_trace_read(uintptr_t reg);
void f4_trace_write(uintptr_t reg, uint32_t value);
/* The register model's PRIMASK (f4_irq_lock / f4_irq_unlock). */
uint32_t f4_trace_irq_lock(void);
void f4_trace_irq_unlock(uint32_t primask);
static inline uint32_t f4_rd(uintptr_t reg)
{
    return f4_trace_read(reg);
}
static inline void f4_wr(uintptr_t reg, uint32_t value)
{
    f4_trace_write(reg, value);
}
#else
static inline uint32_t f4_rd(uintptr_t reg)
{
    return *(volatile uint32_t *)reg;
}
static inline void f4_wr(uintptr_t reg, uint32_t value)
{
    *(volatile uint32_t *)reg = value;
}
#endif
/* Read-modify-write of the bits in mask. */
static inline void f4_mod(uintptr_t reg, uint32_t mask, uint32_t value)
{
    f4_wr(reg, (f4_rd(reg) & ~mask) | (value & mask));
}
static inline void f4_set(uintptr_t reg, uint32_t bits)
{
    f4_wr(reg, f4_rd(reg) | bits);
}
static inline void f4_clr(uintptr_t reg, uint32_t bits)
{
    f4_wr(reg, f4_rd(reg) & ~bits);
}
/* A peripheral's clock on: bits of the RCC enable register at offset enr
 * (RCC_AHB1ENR, RCC_APB1ENR, RCC_APB2ENR), then that register read back.
 * ST erratum sheet ES0182 (STM32F405/407), "Delay after an RCC peripheral
 * clock enabling": a peripheral access within 2 AHB cycles (AHB peripheral)
 * or 1 + AHB/APB prescaler cycles (APB) of the enable is lost; the dummy
 * read of the RCC register is the erratum's workaround (and what ST's HAL
 * does in its clock-enable macros). Every clock enable goes through here. */
static inline void f4_rcc_enable(uint32_t enr, uint32_t bits)
{
    f4_set(F4_RCC + enr, bits);
    (void)f4_rd(F4_RCC + enr);
}

#define F4_BIT(n) (1u << (n))
#define F4_FIELD(v, pos) ((uint32_t)(v) << (pos))

/* ---- RCC (RM0090 sec. 7.3, RCC_TypeDef) ---- */
#define F4_RCC_CR 0x00u
#define F4_RCC_CR_HSION F4_BIT(0)
#define F4_RCC_CR_HSIRDY F4_BIT(1)
#define F4_RCC_CR_HSEON F4_BIT(16)
#define F4_RCC_CR_HSERDY F4_BIT(17)
#define F4_RCC_CR_CSSON F4_BIT(19)
#define F4_RCC_CR_PLLON F4_BIT(24)
#define F4_RCC_CR_PLLRDY F4_BIT(25)
#define F4_RCC_CR_RESET 0x00000083u /* HSION | HSIRDY | HSITRIM 10000 (sec. 7.3.1) */
#define F4_RCC_PLLCFGR 0x04u
#define F4_RCC_PLLCFGR_PLLM_POS 0u  /* [5:0] = M, 2..63 */
#define F4_RCC_PLLCFGR_PLLN_POS 6u  /* [14:6] = N */
#define F4_RCC_PLLCFGR_PLLP_POS 16u /* [17:16]: 00 /2, 01 /4, 10 /6, 11 /8 */
#define F4_RCC_PLLCFGR_PLLSRC_HSE F4_BIT(22)
#define F4_RCC_PLLCFGR_PLLQ_POS 24u      /* [27:24] = Q, 2..15 */
#define F4_RCC_PLLCFGR_RESET 0x24003010u /* sec. 7.3.2: Q 4, SRC HSI, P /2, N 192, M 16 */
#define F4_RCC_CFGR 0x08u
#define F4_RCC_CFGR_SW_MASK F4_FIELD(3u, 0)
#define F4_RCC_CFGR_SW_HSI F4_FIELD(0u, 0)
#define F4_RCC_CFGR_SW_PLL F4_FIELD(2u, 0)
#define F4_RCC_CFGR_SWS_MASK F4_FIELD(3u, 2)
#define F4_RCC_CFGR_SWS_HSI F4_FIELD(0u, 2)
#define F4_RCC_CFGR_SWS_PLL F4_FIELD(2u, 2)
#define F4_RCC_CFGR_HPRE_MASK F4_FIELD(0xFu, 4)
#define F4_RCC_CFGR_PPRE1_POS 10u /* [12:10]: 0xx /1, 100 /2, 101 /4, 110 /8, 111 /16 */
#define F4_RCC_CFGR_PPRE1_MASK F4_FIELD(7u, 10)
#define F4_RCC_CFGR_PPRE2_POS 13u
#define F4_RCC_CFGR_PPRE2_MASK F4_FIELD(7u, 13)
#define F4_RCC_AHB1ENR 0x30u /* GPIOxEN = bit x (A = 0) */
#define F4_RCC_APB1ENR 0x40u
#define F4_RCC_APB1ENR_TIM2EN F4_BIT(0) /* TIMxEN = bit x - 2 for TIM2..TIM5 */
#define F4_RCC_APB1ENR_SPI2EN F4_BIT(14)
#define F4_RCC_APB1ENR_SPI3EN F4_BIT(15)
#define F4_RCC_APB1ENR_USART2EN F4_BIT(17)
#define F4_RCC_APB1ENR_USART3EN F4_BIT(18)
#define F4_RCC_APB1ENR_UART4EN F4_BIT(19)
#define F4_RCC_APB1ENR_PWREN F4_BIT(28)
#define F4_RCC_APB2ENR 0x44u
#define F4_RCC_APB2ENR_TIM1EN F4_BIT(0)
#define F4_RCC_APB2ENR_USART1EN F4_BIT(4)
#define F4_RCC_APB2ENR_USART6EN F4_BIT(5)
#define F4_RCC_APB2ENR_ADC1EN F4_BIT(8) /* ADCxEN = bit 7 + x */
#define F4_RCC_APB2ENR_SPI1EN F4_BIT(12)
#define F4_RCC_APB2ENR_SYSCFGEN F4_BIT(14)
#define F4_RCC_CSR 0x74u
#define F4_RCC_CSR_LSION F4_BIT(0)
#define F4_RCC_CSR_LSIRDY F4_BIT(1)
#define F4_RCC_CSR_RMVF F4_BIT(24)
#define F4_RCC_CSR_BORRSTF F4_BIT(25)
#define F4_RCC_CSR_PINRSTF F4_BIT(26)
#define F4_RCC_CSR_PORRSTF F4_BIT(27)
#define F4_RCC_CSR_SFTRSTF F4_BIT(28)
#define F4_RCC_CSR_IWDGRSTF F4_BIT(29)
#define F4_RCC_CSR_WWDGRSTF F4_BIT(30)
#define F4_RCC_CSR_LPWRRSTF F4_BIT(31)

/* ---- PWR (RM0090 sec. 5.4) ---- */
#define F4_PWR_CR 0x00u
#define F4_PWR_CR_VOS F4_BIT(14) /* STM32F405/407: 1 = scale 1 mode (reset value) */

/* ---- FLASH interface (RM0090 sec. 3.9, FLASH_TypeDef) ---- */
#define F4_FLASH_ACR 0x00u
#define F4_FLASH_ACR_LATENCY_MASK 0x7u /* [2:0] wait states on the STM32F405/407 */
#define F4_FLASH_ACR_PRFTEN F4_BIT(8)
#define F4_FLASH_ACR_ICEN F4_BIT(9)
#define F4_FLASH_ACR_DCEN F4_BIT(10)
#define F4_FLASH_ACR_ICRST F4_BIT(11)
#define F4_FLASH_ACR_DCRST F4_BIT(12)
#define F4_FLASH_KEYR 0x04u
#define F4_FLASH_SR 0x0Cu
#define F4_FLASH_SR_EOP F4_BIT(0)
#define F4_FLASH_SR_OPERR F4_BIT(1) /* "SOP" in stm32f405xx.h */
#define F4_FLASH_SR_WRPERR F4_BIT(4)
#define F4_FLASH_SR_PGAERR F4_BIT(5)
#define F4_FLASH_SR_PGPERR F4_BIT(6)
#define F4_FLASH_SR_PGSERR F4_BIT(7)
#define F4_FLASH_SR_BSY F4_BIT(16)
#define F4_FLASH_CR 0x10u
#define F4_FLASH_CR_PG F4_BIT(0)
#define F4_FLASH_CR_SER F4_BIT(1)
#define F4_FLASH_CR_SNB_POS 3u /* [6:3] sector number (0..11) */
#define F4_FLASH_CR_SNB_MASK F4_FIELD(0xFu, 3)
#define F4_FLASH_CR_PSIZE_POS 8u /* [9:8]: 00 x8, 01 x16, 10 x32, 11 x64 */
#define F4_FLASH_CR_PSIZE_MASK F4_FIELD(3u, 8)
#define F4_FLASH_CR_STRT F4_BIT(16)
#define F4_FLASH_CR_LOCK F4_BIT(31)
#define F4_FLASH_CR_RESET 0x80000000u /* LOCK (sec. 3.9.5) */
#define F4_FLASH_KEY1 0x45670123u     /* sec. 3.5.1 (HAL: FLASH_KEY1) */
#define F4_FLASH_KEY2 0xCDEF89ABu

/* ---- SYSCFG, EXTI (RM0090 sec. 9.2, 12.3) ---- */
#define F4_SYSCFG_EXTICR(n) (0x08u + 4u * ((n) / 4u)) /* EXTICR1..4: 4 bits per line */
#define F4_SYSCFG_EXTICR_SHIFT(n) (4u * ((n) % 4u))   /* port code: A 0, B 1, ... */
#define F4_EXTI_IMR 0x00u
#define F4_EXTI_RTSR 0x08u
#define F4_EXTI_FTSR 0x0Cu
#define F4_EXTI_PR 0x14u /* rc_w1 */

/* ---- GPIO (RM0090 sec. 8.4; the same layout as the G4's) ---- */
#define F4_GPIO_MODER 0x00u /* 2 bits per pin: 00 input, 01 output, 10 AF, 11 analog */
#define F4_GPIO_OTYPER 0x04u
#define F4_GPIO_OSPEEDR 0x08u
#define F4_GPIO_PUPDR 0x0Cu
#define F4_GPIO_IDR 0x10u
#define F4_GPIO_ODR 0x14u
#define F4_GPIO_BSRR 0x18u
#define F4_GPIO_AFRL 0x20u
#define F4_GPIO_AFRH 0x24u
/* Reset values of the ports this support uses (sec. 8.4): PA13/14/15 and
 * PB3/PB4 start as the debug port's alternate functions. */
#define F4_GPIOA_MODER_RESET 0xA8000000u
#define F4_GPIOB_MODER_RESET 0x00000280u
#define F4_GPIOA_PUPDR_RESET 0x64000000u
#define F4_GPIOB_PUPDR_RESET 0x00000100u
#define F4_GPIOA_OSPEEDR_RESET 0x0C000000u
#define F4_GPIOB_OSPEEDR_RESET 0x000000C0u

/* ---- TIMx (RM0090 sec. 17.4 TIM1/TIM8, sec. 18.4 TIM2..TIM5) ---- */
#define F4_TIM_CR1 0x00u
#define F4_TIM_CR1_CEN F4_BIT(0)
#define F4_TIM_CR1_DIR F4_BIT(4)
#define F4_TIM_CR1_CMS_CENTER1 F4_FIELD(1u, 5)
#define F4_TIM_CR1_ARPE F4_BIT(7)
#define F4_TIM_CR2 0x04u
#define F4_TIM_CR2_MMS_UPDATE F4_FIELD(2u, 4) /* TRGO = update event */
#define F4_TIM_SMCR 0x08u
#define F4_TIM_SMCR_SMS_ENCODER3 F4_FIELD(3u, 0) /* x4: count on TI1FP1 and TI2FP2 edges */
#define F4_TIM_DIER 0x0Cu
#define F4_TIM_DIER_BIE F4_BIT(7)
#define F4_TIM_SR 0x10u
#define F4_TIM_SR_UIF F4_BIT(0)
#define F4_TIM_SR_CCIF(ch) F4_BIT(ch) /* CCxIF, ch 1..4 */
#define F4_TIM_SR_BIF F4_BIT(7)
#define F4_TIM_SR_CCOF(ch) F4_BIT(8u + (ch)) /* CCxOF, ch 1..4 */
#define F4_TIM_EGR 0x14u
#define F4_TIM_EGR_UG F4_BIT(0)
#define F4_TIM_EGR_BG F4_BIT(7)
#define F4_TIM_CCMR1 0x18u
#define F4_TIM_CCMR2 0x1Cu
/* Output compare channel 1 (bits 7:0) / 2 (15:8) of CCMR1, 3 / 4 of CCMR2:
 * CCxS 1:0, OCxPE 3, OCxM 6:4 (3 bits on the F4). PWM mode 1 = OCxM 110. */
#define F4_TIM_CCMR_OC_PWM1_PE(ch_in_reg)                                                          \
    (F4_FIELD(6u, 4u + 8u * (ch_in_reg)) | F4_BIT(3u + 8u * (ch_in_reg)))
/* Input capture: CCxS (01 = on its own input TIx, 10 = on the other input of
 * the pair, TI2 for IC1 / TI1 for IC2 / TI4 for IC3 / TI3 for IC4) and
 * ICxF (bits 7:4 of the channel's byte). */
#define F4_TIM_CCMR_IC(ch_in_reg, ccs, f)                                                          \
    (F4_FIELD((ccs), 8u * (ch_in_reg)) | F4_FIELD((f), 4u + 8u * (ch_in_reg)))
#define F4_TIM_CCER 0x20u
#define F4_TIM_CCER_CCE(ch) F4_BIT(4u * ((ch)-1u))       /* CCxE, ch 1..4 */
#define F4_TIM_CCER_CCP(ch) F4_BIT(4u * ((ch)-1u) + 1u)  /* CCxP */
#define F4_TIM_CCER_CCNE(ch) F4_BIT(4u * ((ch)-1u) + 2u) /* CCxNE, ch 1..3 */
#define F4_TIM_CCER_CCNP(ch) F4_BIT(4u * ((ch)-1u) + 3u) /* CCxNP */
#define F4_TIM_CNT 0x24u
#define F4_TIM_PSC 0x28u
#define F4_TIM_ARR 0x2Cu
#define F4_TIM_RCR 0x30u
#define F4_TIM_CCR(ch) (0x30u + 4u * (ch)) /* CCR1..4 at 0x34..0x40 */
#define F4_TIM_BDTR 0x44u
#define F4_TIM_BDTR_DTG_MASK 0xFFu
#define F4_TIM_BDTR_OSSI F4_BIT(10)
#define F4_TIM_BDTR_OSSR F4_BIT(11)
#define F4_TIM_BDTR_BKE F4_BIT(12)
#define F4_TIM_BDTR_BKP F4_BIT(13)
#define F4_TIM_BDTR_AOE F4_BIT(14)
#define F4_TIM_BDTR_MOE F4_BIT(15)

/* ---- ADC (RM0090 sec. 13.13) ---- */
#define F4_ADC_SR 0x00u
#define F4_ADC_SR_EOC F4_BIT(1)
#define F4_ADC_SR_JEOC F4_BIT(2)
#define F4_ADC_SR_JSTRT F4_BIT(3)
#define F4_ADC_SR_STRT F4_BIT(4)
#define F4_ADC_SR_OVR F4_BIT(5)
#define F4_ADC_CR1 0x04u
#define F4_ADC_CR1_JEOCIE F4_BIT(7)
#define F4_ADC_CR1_SCAN F4_BIT(8)
#define F4_ADC_CR2 0x08u
#define F4_ADC_CR2_ADON F4_BIT(0)
#define F4_ADC_CR2_JEXTSEL_POS 16u
#define F4_ADC_CR2_JEXTEN_RISING F4_FIELD(1u, 20)
#define F4_ADC_CR2_SWSTART F4_BIT(30)
#define F4_ADC_SMPR1 0x0Cu /* channels 10..18, 3 bits each */
#define F4_ADC_SMPR2 0x10u /* channels 0..9 */
#define F4_ADC_SQR1 0x2Cu  /* L [23:20] */
#define F4_ADC_SQR3 0x34u  /* SQ1 [4:0] */
#define F4_ADC_JSQR 0x38u
#define F4_ADC_JSQR_JL_POS 20u
#define F4_ADC_JDR(rank) (0x38u + 4u * (rank)) /* JDR1..4 at 0x3C..0x48 */
#define F4_ADC_DR 0x4Cu
/* Common registers (ADC_COMMON base). */
#define F4_ADC_CCR 0x04u
#define F4_ADC_CCR_ADCPRE_POS 16u /* [17:16]: PCLK2 / 2, 4, 6, 8 */
#define F4_ADC_CCR_ADCPRE_MASK F4_FIELD(3u, 16)
/* JEXTSEL of ADC1..3 (sec. 13.13.3, "External trigger for injected
 * channels"; HAL ADC_EXTERNALTRIGINJECCONV_T1_TRGO = ADC_CR2_JEXTSEL_0). */
#define F4_ADC_JEXT_TIM1_TRGO 1u

/* ---- SPI (RM0090 sec. 28.5) ---- */
#define F4_SPI_CR1 0x00u
#define F4_SPI_CR1_CPHA F4_BIT(0)
#define F4_SPI_CR1_CPOL F4_BIT(1)
#define F4_SPI_CR1_MSTR F4_BIT(2)
#define F4_SPI_CR1_BR_POS 3u /* [5:3]: f_PCLK / 2^(BR + 1) */
#define F4_SPI_CR1_SPE F4_BIT(6)
#define F4_SPI_CR1_SSI F4_BIT(8)
#define F4_SPI_CR1_SSM F4_BIT(9)
#define F4_SPI_CR1_DFF F4_BIT(11) /* 16-bit frames */
#define F4_SPI_SR 0x08u
#define F4_SPI_SR_RXNE F4_BIT(0)
#define F4_SPI_SR_TXE F4_BIT(1)
#define F4_SPI_SR_MODF F4_BIT(5)
#define F4_SPI_SR_OVR F4_BIT(6)
#define F4_SPI_SR_BSY F4_BIT(7)
#define F4_SPI_DR 0x0Cu

/* ---- USART (RM0090 sec. 30.6) ---- */
#define F4_USART_SR 0x00u
#define F4_USART_SR_FE F4_BIT(1)
#define F4_USART_SR_NF F4_BIT(2)
#define F4_USART_SR_ORE F4_BIT(3)
#define F4_USART_SR_RXNE F4_BIT(5)
#define F4_USART_SR_TXE F4_BIT(7)
#define F4_USART_DR 0x04u
#define F4_USART_BRR 0x08u
#define F4_USART_CR1 0x0Cu
#define F4_USART_CR1_RE F4_BIT(2)
#define F4_USART_CR1_TE F4_BIT(3)
#define F4_USART_CR1_RXNEIE F4_BIT(5)
#define F4_USART_CR1_TXEIE F4_BIT(7)
#define F4_USART_CR1_UE F4_BIT(13)

/* ---- IWDG (RM0090 sec. 21.4; the same registers as the G4's) ---- */
#define F4_IWDG_KR 0x00u
#define F4_IWDG_KR_START 0xCCCCu
#define F4_IWDG_KR_REFRESH 0xAAAAu
#define F4_IWDG_KR_UNLOCK 0x5555u
#define F4_IWDG_PR 0x04u
#define F4_IWDG_RLR 0x08u
#define F4_IWDG_SR 0x0Cu /* PVU 0, RVU 1: an update in progress */

/* ---- DBGMCU (RM0090 sec. 38.16) ---- */
#define F4_DBGMCU_APB1_FZ 0x08u
#define F4_DBGMCU_APB1_FZ_IWDG_STOP F4_BIT(12)
#define F4_DBGMCU_APB2_FZ 0x0Cu
#define F4_DBGMCU_APB2_FZ_TIM1_STOP F4_BIT(0)

/* ---- Cortex-M4 core (ARMv7-M ARM) ---- */
#define F4_DWT_CTRL 0x00u
#define F4_DWT_CTRL_CYCCNTENA F4_BIT(0)
#define F4_DWT_CYCCNT 0x04u
#define F4_SCB_ICSR 0x04u                /* B3.2.4 */
#define F4_SCB_ICSR_PENDSVSET F4_BIT(28) /* write 1: PendSV pending; 0s: no effect */
#define F4_SCB_AIRCR 0x0Cu               /* B3.2.6 */
#define F4_SCB_AIRCR_VECTKEY 0x05FA0000u /* bits 31:16, written with every write */
#define F4_SCB_AIRCR_SYSRESETREQ F4_BIT(2)
#define F4_SCB_CFSR 0x28u             /* B3.2.15 (MMFSR 7:0, BFSR 15:8, UFSR 31:16) */
#define F4_SCB_HFSR 0x2Cu             /* B3.2.16 */
#define F4_SCB_MMFAR 0x34u            /* B3.2.17 */
#define F4_SCB_BFAR 0x38u             /* B3.2.18 */
#define F4_SCB_SHPR3 0x20u            /* B3.2.12: PendSV priority in bits 23:16 */
#define F4_SCB_SHPR3_PENDSV_SHIFT 20u /* 4 priority bits implemented: 23:20 */
#define F4_SCB_DEMCR 0xFCu
#define F4_SCB_DEMCR_TRCENA F4_BIT(24)
#define F4_NVIC_ISER(n) (0x000u + 4u * (n))
#define F4_NVIC_ICER(n) (0x080u + 4u * (n))
/* Priority of an IRQ: byte (irq mod 4) of word IPR(irq / 4); 4 bits
 * implemented (7:4) on the STM32F4 (RM0090 sec. 10.1: 16 levels). */
#define F4_NVIC_IPR_WORD(irq) (0x300u + 4u * ((irq) / 4u))
#define F4_NVIC_IPR_SHIFT(irq) (8u * ((irq) % 4u) + 4u)

/* IRQ numbers (RM0090 table 61, stm32f405xx.h IRQn_Type). */
#define F4_IRQ_EXTI0 6u /* EXTI0..4: 6..10 */
#define F4_IRQ_ADC 18u  /* ADC1, ADC2 and ADC3 */
#define F4_IRQ_EXTI9_5 23u
#define F4_IRQ_TIM1_BRK_TIM9 24u
#define F4_IRQ_USART1 37u
#define F4_IRQ_USART2 38u
#define F4_IRQ_USART3 39u
#define F4_IRQ_EXTI15_10 40u
#define F4_IRQ_UART4 52u
#define F4_IRQ_USART6 71u
#define F4_NUM_IRQ 82u /* vector entries after the 16 system ones (FPU = 81) */

#endif /* HAL_STM32F4_F4_REGS_H */
