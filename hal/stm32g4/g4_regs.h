/*
 * STM32G4 register map: the peripheral base addresses, register offsets and
 * bit fields this HAL uses, named as in ST's reference manual RM0440 (register
 * TIMx_BDTR, field MOE -> G4_TIM_BDTR, G4_TIM_BDTR_MOE). Cortex-M4 core
 * registers (SCB, NVIC, DWT) are named as in ARM's Cortex-M4 Technical
 * Reference Manual / ARMv7-M Architecture Reference Manual.
 *
 * Sources: RM0440 "Memory map" (section 2.2) and every peripheral chapter's
 * register map; checked against ST's CMSIS device header stm32g431xx.h
 * (STMicroelectronics/cmsis_device_g4), which carries the same offsets and bit
 * positions.
 *
 * Register access goes through g4_rd/g4_wr only. Three builds:
 *   target (default)     base addresses are the chip's; plain volatile access
 *   G4_MEM_ARRAYS        base addresses are the addresses of arrays
 *                        g4_mem_<name>[] that the build provides (host tests,
 *                        the QEMU instruction-count image): the code is the
 *                        same, every base is still a link-time constant
 *   G4_REG_TRACE         (with G4_MEM_ARRAYS) every access calls
 *                        g4_trace_read / g4_trace_write, which the register-image
 *                        test implements (write log, hardware model)
 */
#ifndef HAL_STM32G4_G4_REGS_H
#define HAL_STM32G4_G4_REGS_H

#include <stdint.h>

/* X(name, lower-case name, base address, bytes mapped in a host array).
 * Addresses: RM0440 "Memory map" table of peripheral register boundary
 * addresses (= stm32g431xx.h *_BASE); core: ARMv7-M System Control Space. */
#define G4_PERIPHS(X)                                                                              \
    X(TIM2, tim2, 0x40000000u, 0x400u)                                                             \
    X(TIM4, tim4, 0x40000800u, 0x400u)                                                             \
    X(IWDG, iwdg, 0x40003000u, 0x400u)                                                             \
    X(USART2, usart2, 0x40004400u, 0x400u)                                                         \
    X(PWR, pwr, 0x40007000u, 0x400u)                                                               \
    X(SYSCFG, syscfg, 0x40010000u, 0x30u)                                                          \
    X(COMP, comp, 0x40010200u, 0x10u)                                                              \
    X(OPAMP, opamp, 0x40010300u, 0x20u)                                                            \
    X(TIM1, tim1, 0x40012C00u, 0x400u)                                                             \
    X(RCC, rcc, 0x40021000u, 0x400u)                                                               \
    X(FLASH, flash, 0x40022000u, 0x400u)                                                           \
    X(GPIOA, gpioa, 0x48000000u, 0x400u)                                                           \
    X(GPIOB, gpiob, 0x48000400u, 0x400u)                                                           \
    X(GPIOC, gpioc, 0x48000800u, 0x400u)                                                           \
    X(ADC1, adc1, 0x50000000u, 0x100u)                                                             \
    X(ADC2, adc2, 0x50000100u, 0x100u)                                                             \
    X(ADC12, adc12, 0x50000300u, 0x10u)                                                            \
    X(DAC3, dac3, 0x50001000u, 0x400u)                                                             \
    X(DBGMCU, dbgmcu, 0xE0042000u, 0x14u)                                                          \
    X(DWT, dwt, 0xE0001000u, 0x10u)                                                                \
    X(NVIC, nvic, 0xE000E100u, 0x400u)                                                             \
    X(SCB, scb, 0xE000ED00u, 0x100u)

#if defined(G4_MEM_ARRAYS)
#define G4_DECLARE_ARRAY(N, n, addr, bytes) extern uint32_t g4_mem_##n[(bytes) / 4u];
G4_PERIPHS(G4_DECLARE_ARRAY)
#undef G4_DECLARE_ARRAY
#define G4_BASE(n, addr) ((uintptr_t)g4_mem_##n)
#else
#define G4_BASE(n, addr) ((uintptr_t)(addr))
#endif

#define G4_TIM2 G4_BASE(tim2, 0x40000000u)
#define G4_TIM4 G4_BASE(tim4, 0x40000800u)
#define G4_IWDG G4_BASE(iwdg, 0x40003000u)
#define G4_USART2 G4_BASE(usart2, 0x40004400u)
#define G4_PWR G4_BASE(pwr, 0x40007000u)
#define G4_SYSCFG G4_BASE(syscfg, 0x40010000u)
#define G4_COMP G4_BASE(comp, 0x40010200u)
#define G4_OPAMP G4_BASE(opamp, 0x40010300u)
#define G4_TIM1 G4_BASE(tim1, 0x40012C00u)
#define G4_RCC G4_BASE(rcc, 0x40021000u)
#define G4_FLASH G4_BASE(flash, 0x40022000u)
#define G4_GPIOA G4_BASE(gpioa, 0x48000000u)
#define G4_GPIOB G4_BASE(gpiob, 0x48000400u)
#define G4_GPIOC G4_BASE(gpioc, 0x48000800u)
#define G4_ADC1 G4_BASE(adc1, 0x50000000u)
#define G4_ADC2 G4_BASE(adc2, 0x50000100u)
#define G4_ADC12 G4_BASE(adc12, 0x50000300u)
#define G4_DAC3 G4_BASE(dac3, 0x50001000u)
#define G4_DBGMCU G4_BASE(dbgmcu, 0xE0042000u)
#define G4_DWT G4_BASE(dwt, 0xE0001000u)
#define G4_NVIC G4_BASE(nvic, 0xE000E100u)
#define G4_SCB G4_BASE(scb, 0xE000ED00u)

/* ---- access ---- */
#if defined(G4_REG_TRACE)
uint32_t g4_trace_read(uintptr_t reg);
void g4_trace_write(uintptr_t reg, uint32_t value);
/* PRIMASK in the model (g4_irq_lock / g4_irq_unlock, g4_core.h). */
uint32_t g4_trace_irq_lock(void);
void g4_trace_irq_unlock(uint32_t primask);
static inline uint32_t g4_rd(uintptr_t reg)
{
    return g4_trace_read(reg);
}
static inline void g4_wr(uintptr_t reg, uint32_t value)
{
    g4_trace_write(reg, value);
}
#else
static inline uint32_t g4_rd(uintptr_t reg)
{
    return *(volatile uint32_t *)reg;
}
static inline void g4_wr(uintptr_t reg, uint32_t value)
{
    *(volatile uint32_t *)reg = value;
}
#endif
/* Read-modify-write of the bits in mask. */
static inline void g4_mod(uintptr_t reg, uint32_t mask, uint32_t value)
{
    g4_wr(reg, (g4_rd(reg) & ~mask) | (value & mask));
}
static inline void g4_set(uintptr_t reg, uint32_t bits)
{
    g4_wr(reg, g4_rd(reg) | bits);
}
static inline void g4_clr(uintptr_t reg, uint32_t bits)
{
    g4_wr(reg, g4_rd(reg) & ~bits);
}

#define G4_BIT(n) (1u << (n))
#define G4_FIELD(v, pos) ((uint32_t)(v) << (pos))

/* ---- FLASH (RM0440 FLASH chapter, FLASH_ACR) ---- */
#define G4_FLASH_ACR 0x00u
#define G4_FLASH_ACR_LATENCY_MASK 0xFu /* [3:0] wait states */
#define G4_FLASH_ACR_PRFTEN G4_BIT(8)
#define G4_FLASH_ACR_ICEN G4_BIT(9)
#define G4_FLASH_ACR_DCEN G4_BIT(10)
#define G4_FLASH_ACR_DBG_SWEN G4_BIT(18) /* debugger access; reset value 1 */
#define G4_FLASH_ACR_RESET 0x00040600u   /* DBG_SWEN | DCEN | ICEN */
/* FLASH_OPTR: loaded from the option bytes at reset (RM0440 FLASH_OPTR,
 * table "Boot modes"): nSWBOOT0 = 0 takes BOOT0 from nBOOT0, = 1 from the
 * BOOT0 pin (PB8); BOOT0 = 1 with nBOOT1 = 1 starts the ROM bootloader. */
#define G4_FLASH_OPTR 0x20u
#define G4_FLASH_OPTR_nBOOT1 G4_BIT(23)
#define G4_FLASH_OPTR_nSWBOOT0 G4_BIT(26)
#define G4_FLASH_OPTR_nBOOT0 G4_BIT(27)

/* ---- PWR (RM0440 PWR chapter) ---- */
#define G4_PWR_CR1 0x00u
#define G4_PWR_CR1_VOS_MASK G4_FIELD(3u, 9)
#define G4_PWR_CR1_VOS_RANGE1 G4_FIELD(1u, 9)
#define G4_PWR_CR3 0x08u
#define G4_PWR_CR3_UCPD1_DBDIS G4_BIT(14) /* USB-C dead-battery pull-downs off */
#define G4_PWR_SR2 0x14u
#define G4_PWR_SR2_VOSF G4_BIT(10)
#define G4_PWR_CR5 0x80u
#define G4_PWR_CR5_R1MODE G4_BIT(8) /* 0 = range 1 boost mode (170 MHz) */

/* ---- RCC (RM0440 RCC chapter) ---- */
#define G4_RCC_CR 0x00u
#define G4_RCC_CR_HSION G4_BIT(8)
#define G4_RCC_CR_HSIRDY G4_BIT(10)
#define G4_RCC_CR_HSEON G4_BIT(16)
#define G4_RCC_CR_HSERDY G4_BIT(17)
#define G4_RCC_CR_HSEBYP G4_BIT(18)
#define G4_RCC_CR_CSSON G4_BIT(19)
#define G4_RCC_CR_PLLON G4_BIT(24)
#define G4_RCC_CR_PLLRDY G4_BIT(25)
#define G4_RCC_CFGR 0x08u
#define G4_RCC_CFGR_SW_MASK G4_FIELD(3u, 0)
#define G4_RCC_CFGR_SW_HSI G4_FIELD(1u, 0)
#define G4_RCC_CFGR_SW_PLL G4_FIELD(3u, 0)
#define G4_RCC_CFGR_SWS_MASK G4_FIELD(3u, 2)
#define G4_RCC_CFGR_SWS_HSI G4_FIELD(1u, 2)
#define G4_RCC_CFGR_SWS_PLL G4_FIELD(3u, 2)
#define G4_RCC_CFGR_HPRE_MASK G4_FIELD(0xFu, 4)
#define G4_RCC_CFGR_HPRE_DIV1 G4_FIELD(0u, 4)
#define G4_RCC_CFGR_HPRE_DIV2 G4_FIELD(8u, 4)
#define G4_RCC_CFGR_PPRE1_MASK G4_FIELD(7u, 8)
#define G4_RCC_CFGR_PPRE2_MASK G4_FIELD(7u, 11)
#define G4_RCC_PLLCFGR 0x0Cu
#define G4_RCC_PLLCFGR_PLLSRC_HSE G4_FIELD(3u, 0)
#define G4_RCC_PLLCFGR_PLLM_POS 4u /* [7:4] = M - 1 */
#define G4_RCC_PLLCFGR_PLLN_POS 8u /* [14:8] = N */
#define G4_RCC_PLLCFGR_PLLREN G4_BIT(24)
#define G4_RCC_PLLCFGR_PLLR_POS 25u /* [26:25]: 00 /2, 01 /4, 10 /6, 11 /8 */
#define G4_RCC_CIER 0x18u
#define G4_RCC_CIFR 0x1Cu
#define G4_RCC_CIFR_CSSF G4_BIT(8)
#define G4_RCC_CICR 0x20u
#define G4_RCC_CICR_CSSC G4_BIT(8)
#define G4_RCC_AHB1ENR 0x48u
#define G4_RCC_AHB2ENR 0x4Cu
#define G4_RCC_AHB2ENR_GPIOAEN G4_BIT(0)
#define G4_RCC_AHB2ENR_GPIOBEN G4_BIT(1)
#define G4_RCC_AHB2ENR_GPIOCEN G4_BIT(2)
#define G4_RCC_AHB2ENR_ADC12EN G4_BIT(13)
#define G4_RCC_AHB2ENR_DAC3EN G4_BIT(18)
#define G4_RCC_APB1ENR1 0x58u
#define G4_RCC_APB1ENR1_TIM2EN G4_BIT(0)
#define G4_RCC_APB1ENR1_TIM4EN G4_BIT(2)
#define G4_RCC_APB1ENR1_USART2EN G4_BIT(17)
#define G4_RCC_APB1ENR1_PWREN G4_BIT(28)
#define G4_RCC_APB2ENR 0x60u
#define G4_RCC_APB2ENR_SYSCFGEN G4_BIT(0)
#define G4_RCC_APB2ENR_TIM1EN G4_BIT(11)
#define G4_RCC_CCIPR 0x88u
#define G4_RCC_CCIPR_USART2SEL_MASK G4_FIELD(3u, 2) /* 00 = PCLK1 */
#define G4_RCC_CCIPR_ADC12SEL_MASK G4_FIELD(3u, 28) /* 00 = no clock: synchronous HCLK mode */
#define G4_RCC_CSR 0x94u
#define G4_RCC_CSR_LSION G4_BIT(0)
#define G4_RCC_CSR_LSIRDY G4_BIT(1)
#define G4_RCC_CSR_RMVF G4_BIT(23)
#define G4_RCC_CSR_OBLRSTF G4_BIT(25)
#define G4_RCC_CSR_PINRSTF G4_BIT(26)
#define G4_RCC_CSR_BORRSTF G4_BIT(27)
#define G4_RCC_CSR_SFTRSTF G4_BIT(28)
#define G4_RCC_CSR_IWDGRSTF G4_BIT(29)
#define G4_RCC_CSR_WWDGRSTF G4_BIT(30)
#define G4_RCC_CSR_LPWRRSTF G4_BIT(31)

/* ---- SYSCFG (RM0440 SYSCFG chapter) ---- */
#define G4_SYSCFG_CFGR2 0x1Cu
#define G4_SYSCFG_CFGR2_CLL G4_BIT(0) /* Cortex-M4 LOCKUP -> TIM1 system break */

/* ---- GPIO (RM0440 GPIO chapter) ---- */
#define G4_GPIO_MODER 0x00u /* 2 bits per pin: 00 input, 01 output, 10 AF, 11 analog */
#define G4_GPIO_OTYPER 0x04u
#define G4_GPIO_OSPEEDR 0x08u
#define G4_GPIO_PUPDR 0x0Cu
#define G4_GPIO_IDR 0x10u
#define G4_GPIO_ODR 0x14u
#define G4_GPIO_BSRR 0x18u
#define G4_GPIO_AFRL 0x20u
#define G4_GPIO_AFRH 0x24u
#define G4_GPIO_BRR 0x28u

/* ---- TIMx (RM0440 TIM1/TIM8/TIM20 and TIM2/3/4/5 chapters) ---- */
#define G4_TIM_CR1 0x00u
#define G4_TIM_CR1_CEN G4_BIT(0)
#define G4_TIM_CR1_URS G4_BIT(2)
#define G4_TIM_CR1_DIR G4_BIT(4)
#define G4_TIM_CR1_CMS_MASK G4_FIELD(3u, 5)
#define G4_TIM_CR1_CMS_CENTER1 G4_FIELD(1u, 5)
#define G4_TIM_CR1_ARPE G4_BIT(7)
#define G4_TIM_CR1_CKD_MASK G4_FIELD(3u, 8)
#define G4_TIM_CR2 0x04u
#define G4_TIM_CR2_CCPC G4_BIT(0)
/* MMS[2:0] at bits 6:4 and MMS[3] at bit 25 (RM0440 TIMx_CR2; ST's
 * stm32g431xx.h TIM_CR2_MMS_Msk 0x02000070) */
#define G4_TIM_CR2_MMS_MASK (G4_FIELD(7u, 4) | G4_BIT(25))
#define G4_TIM_CR2_OIS_MASK G4_FIELD(0x3Fu, 8) /* OIS1, OIS1N .. OIS3, OIS3N */
#define G4_TIM_CR2_MMS2_MASK G4_FIELD(0xFu, 20)
#define G4_TIM_CR2_MMS2_UPDATE G4_FIELD(2u, 20)
#define G4_TIM_SMCR 0x08u
#define G4_TIM_SMCR_SMS_ENCODER3 G4_FIELD(3u, 0) /* x4: count on TI1FP1 and TI2FP2 edges */
#define G4_TIM_SMCR_SMS_RESET G4_FIELD(4u, 0)    /* trigger edge resets the counter */
#define G4_TIM_SMCR_TS_TI1FP1 G4_FIELD(5u, 4)    /* TS[2:0] = 101 (TS[4:3] = 00) */
#define G4_TIM_DIER 0x0Cu
#define G4_TIM_DIER_BIE G4_BIT(7)
#define G4_TIM_SR 0x10u
#define G4_TIM_SR_UIF G4_BIT(0)
#define G4_TIM_SR_CC1IF G4_BIT(1)
#define G4_TIM_SR_CC2IF G4_BIT(2)
#define G4_TIM_SR_CC3IF G4_BIT(3)
#define G4_TIM_SR_BIF G4_BIT(7)
#define G4_TIM_SR_B2IF G4_BIT(8)
#define G4_TIM_SR_CC1OF G4_BIT(9)
#define G4_TIM_SR_CC2OF G4_BIT(10)
#define G4_TIM_SR_SBIF G4_BIT(13)
#define G4_TIM_EGR 0x14u
#define G4_TIM_EGR_UG G4_BIT(0)
#define G4_TIM_EGR_BG G4_BIT(7)
#define G4_TIM_CCMR1 0x18u
#define G4_TIM_CCMR2 0x1Cu
/* Output compare channel 1 (bits 7:0, OC1M[3] at 16) / 2 (15:8, OC2M[3] at 24);
 * CCMR2 the same for channels 3 and 4. PWM mode 1 = OCxM 0110. */
#define G4_TIM_CCMR_OC_PWM1_PE(ch_in_reg)                                                          \
    (G4_FIELD(6u, 4u + 8u * (ch_in_reg)) | G4_BIT(3u + 8u * (ch_in_reg)))
/* Input capture channel mapped on its own input (CCxS = 01) with filter f. */
#define G4_TIM_CCMR_IC_DIRECT(ch_in_reg, f)                                                        \
    (G4_FIELD(1u, 8u * (ch_in_reg)) | G4_FIELD((f), 4u + 8u * (ch_in_reg)))
#define G4_TIM_CCER 0x20u
#define G4_TIM_CCER_CCE(ch) G4_BIT(4u * ((ch)-1u))       /* CCxE, ch 1..4 */
#define G4_TIM_CCER_CCP(ch) G4_BIT(4u * ((ch)-1u) + 1u)  /* CCxP */
#define G4_TIM_CCER_CCNE(ch) G4_BIT(4u * ((ch)-1u) + 2u) /* CCxNE */
#define G4_TIM_CCER_CCNP(ch) G4_BIT(4u * ((ch)-1u) + 3u) /* CCxNP */
#define G4_TIM_CNT 0x24u
#define G4_TIM_PSC 0x28u
#define G4_TIM_ARR 0x2Cu
#define G4_TIM_RCR 0x30u
#define G4_TIM_CCR1 0x34u
#define G4_TIM_CCR2 0x38u
#define G4_TIM_CCR3 0x3Cu
#define G4_TIM_CCR4 0x40u
#define G4_TIM_BDTR 0x44u
#define G4_TIM_BDTR_DTG_MASK 0xFFu
#define G4_TIM_BDTR_LOCK_MASK G4_FIELD(3u, 8)
#define G4_TIM_BDTR_OSSI G4_BIT(10)
#define G4_TIM_BDTR_OSSR G4_BIT(11)
#define G4_TIM_BDTR_BKE G4_BIT(12)
#define G4_TIM_BDTR_BKP G4_BIT(13)
#define G4_TIM_BDTR_AOE G4_BIT(14)
#define G4_TIM_BDTR_MOE G4_BIT(15)
#define G4_TIM_BDTR_BKF_POS 16u
#define G4_TIM_BDTR_BKF_MASK G4_FIELD(0xFu, 16)
#define G4_TIM_AF1 0x60u
#define G4_TIM_AF1_BKINE G4_BIT(0)
#define G4_TIM_AF1_BKCMPE(n) G4_BIT(n)        /* BKCMPnE, n = 1..4 */
#define G4_TIM_AF1_BKCMPP(n) G4_BIT(9u + (n)) /* BKCMPnP, n = 1..4 */

/* ---- ADC (RM0440 ADC chapter) ---- */
#define G4_ADC_ISR 0x00u
#define G4_ADC_ISR_ADRDY G4_BIT(0)
#define G4_ADC_ISR_EOC G4_BIT(2)
#define G4_ADC_ISR_EOS G4_BIT(3)
#define G4_ADC_ISR_OVR G4_BIT(4)
#define G4_ADC_ISR_JEOC G4_BIT(5)
#define G4_ADC_ISR_JEOS G4_BIT(6)
#define G4_ADC_ISR_JQOVF G4_BIT(10)
#define G4_ADC_IER 0x04u
#define G4_ADC_IER_JEOSIE G4_BIT(6)
#define G4_ADC_CR 0x08u
#define G4_ADC_CR_ADEN G4_BIT(0)
#define G4_ADC_CR_ADDIS G4_BIT(1)
#define G4_ADC_CR_ADSTART G4_BIT(2)
#define G4_ADC_CR_JADSTART G4_BIT(3)
#define G4_ADC_CR_ADVREGEN G4_BIT(28)
#define G4_ADC_CR_DEEPPWD G4_BIT(29)
#define G4_ADC_CR_ADCALDIF G4_BIT(30)
#define G4_ADC_CR_ADCAL G4_BIT(31)
#define G4_ADC_CFGR 0x0Cu
#define G4_ADC_CFGR_JQDIS G4_BIT(31)
#define G4_ADC_SMPR1 0x14u /* channels 0..9, 3 bits each */
#define G4_ADC_SMPR2 0x18u /* channels 10..18 */
#define G4_ADC_SQR1 0x30u
#define G4_ADC_DR 0x40u
#define G4_ADC_JSQR 0x4Cu
#define G4_ADC_JSQR_JEXTSEL_POS 2u
#define G4_ADC_JSQR_JEXTEN_RISING G4_FIELD(1u, 7)
#define G4_ADC_JSQR_JSQ_POS(rank) (9u + 6u * ((rank)-1u)) /* JSQ1 at 9, JSQ2 at 15, ... */
#define G4_ADC_JDR1 0x80u
#define G4_ADC_JDR2 0x84u
#define G4_ADC_JDR3 0x88u
#define G4_ADC_DIFSEL 0xB0u
/* Common registers of ADC1/ADC2 (ADC12_CCR at base + 0x08). */
#define G4_ADC_CCR 0x08u
#define G4_ADC_CCR_CKMODE_HCLK_DIV4 G4_FIELD(3u, 16)
#define G4_ADC_CCR_CKMODE_MASK G4_FIELD(3u, 16)
/* JEXTSEL of ADC1/ADC2 (RM0440 table "ADC1 and ADC2 - External triggers for
 * injected channels"): TIM1_TRGO2 = 8. */
#define G4_ADC12_JEXT_TIM1_TRGO2 8u

/* ---- OPAMP (RM0440 OPAMP chapter, OPAMPx_CSR at 0x40010300 + 4 (x - 1)) ---- */
#define G4_OPAMP_CSR(x) (4u * ((x)-1u))
#define G4_OPAMP_CSR_OPAEN G4_BIT(0)
#define G4_OPAMP_CSR_VPSEL_POS 2u
#define G4_OPAMP_CSR_VMSEL_PGA G4_FIELD(2u, 5)
#define G4_OPAMP_CSR_OPAHSM G4_BIT(7)
#define G4_OPAMP_CSR_OPAINTOEN G4_BIT(8)
#define G4_OPAMP_CSR_PGA_GAIN_POS 14u

/* ---- COMP (RM0440 COMP chapter, COMPx_CSR at 0x40010200 + 4 (x - 1)) ---- */
#define G4_COMP_CSR(x) (4u * ((x)-1u))
#define G4_COMP_CSR_EN G4_BIT(0)
#define G4_COMP_CSR_INMSEL_POS 4u
#define G4_COMP_CSR_INMSEL_DAC3 4u   /* DAC3_CH1 for COMP1/3, DAC3_CH2 for COMP2/4 */
#define G4_COMP_CSR_INPSEL G4_BIT(8) /* 0 = INP IO1 (COMP1 PA1, COMP2 PA7, COMP4 PB0) */
#define G4_COMP_CSR_POLARITY G4_BIT(15)
#define G4_COMP_CSR_HYST_POS 16u
#define G4_COMP_CSR_VALUE G4_BIT(30)
#define G4_COMP_CSR_LOCK G4_BIT(31)

/* ---- DAC (RM0440 DAC chapter) ---- */
#define G4_DAC_CR 0x00u
#define G4_DAC_CR_EN1 G4_BIT(0)
#define G4_DAC_CR_EN2 G4_BIT(16)
#define G4_DAC_DHR12R1 0x08u
#define G4_DAC_DHR12R2 0x14u
#define G4_DAC_SR 0x34u
#define G4_DAC_SR_DAC1RDY G4_BIT(11)
#define G4_DAC_SR_DAC2RDY G4_BIT(27)
#define G4_DAC_MCR 0x3Cu
/* MODEx = 011: normal mode, buffer disabled, connected to on-chip peripherals
 * only (DAC3 has no output pin). HFSEL = 10: AHB clock above 160 MHz. */
#define G4_DAC_MCR_MODE1_INTERNAL G4_FIELD(3u, 0)
#define G4_DAC_MCR_MODE2_INTERNAL G4_FIELD(3u, 16)
#define G4_DAC_MCR_HFSEL_MASK G4_FIELD(3u, 14)
#define G4_DAC_MCR_HFSEL_160MHZ G4_FIELD(2u, 14)

/* ---- USART (RM0440 USART chapter) ---- */
#define G4_USART_CR1 0x00u
#define G4_USART_CR1_UE G4_BIT(0)
#define G4_USART_CR1_RE G4_BIT(2)
#define G4_USART_CR1_TE G4_BIT(3)
#define G4_USART_CR1_RXNEIE G4_BIT(5) /* RXFNEIE in FIFO mode */
#define G4_USART_CR1_TXEIE G4_BIT(7)  /* TXFNFIE in FIFO mode */
/* FIFO mode: an RXFIFO and a TXFIFO of 8 characters each (RM0440 USART,
 * "USART FIFOs and thresholds"; ST's stm32g4xx_hal_uart_ex.c RX_FIFO_DEPTH);
 * FIFOEN is written only with UE = 0 (RM0440 USART_CR1). */
#define G4_USART_CR1_FIFOEN G4_BIT(29)
#define G4_USART_FIFO_DEPTH 8u
#define G4_USART_BRR 0x0Cu
#define G4_USART_ISR 0x1Cu
#define G4_USART_ISR_FE G4_BIT(1)
#define G4_USART_ISR_NE G4_BIT(2)
#define G4_USART_ISR_ORE G4_BIT(3)
#define G4_USART_ISR_RXNE G4_BIT(5) /* RXFNE in FIFO mode: RDR holds the RXFIFO's oldest */
#define G4_USART_ISR_TC G4_BIT(6)
#define G4_USART_ISR_TXE G4_BIT(7) /* TXFNF in FIFO mode */
#define G4_USART_ISR_RXFF G4_BIT(24)
#define G4_USART_ICR 0x20u
#define G4_USART_ICR_FECF G4_BIT(1)
#define G4_USART_ICR_NECF G4_BIT(2)
#define G4_USART_ICR_ORECF G4_BIT(3)
#define G4_USART_RDR 0x24u
#define G4_USART_TDR 0x28u

/* ---- IWDG (RM0440 IWDG chapter) ---- */
#define G4_IWDG_KR 0x00u
#define G4_IWDG_KR_START 0xCCCCu
#define G4_IWDG_KR_REFRESH 0xAAAAu
#define G4_IWDG_KR_UNLOCK 0x5555u
#define G4_IWDG_PR 0x04u
#define G4_IWDG_RLR 0x08u
#define G4_IWDG_SR 0x0Cu

/* ---- DBGMCU (RM0440 Debug support chapter) ---- */
#define G4_DBGMCU_APB1FZR1 0x08u
#define G4_DBGMCU_APB1FZR1_IWDG_STOP G4_BIT(12)
#define G4_DBGMCU_APB2FZ 0x10u
#define G4_DBGMCU_APB2FZ_TIM1_STOP G4_BIT(11)

/* ---- Cortex-M4 core ---- */
#define G4_DWT_CTRL 0x00u
#define G4_DWT_CTRL_CYCCNTENA G4_BIT(0)
#define G4_DWT_CYCCNT 0x04u
#define G4_SCB_ICSR 0x04u                /* ICSR (0xE000ED04), ARMv7-M ARM B3.2.4 */
#define G4_SCB_ICSR_PENDSVSET G4_BIT(28) /* write 1: PendSV pending; 0s: no effect */
#define G4_SCB_VTOR 0x08u
#define G4_SCB_SHPR3 0x20u /* SHPR3 (0xE000ED20), B3.2.12: PendSV priority in bits 23:16 */
#define G4_SCB_SHPR3_PENDSV_SHIFT 20u /* 4 priority bits implemented: 23:20 */
#define G4_SCB_SHCSR 0x24u
#define G4_SCB_SHCSR_FAULTS_ENA (G4_BIT(16) | G4_BIT(17) | G4_BIT(18)) /* MEM, BUS, USG */
#define G4_SCB_CPACR 0x88u
#define G4_SCB_DEMCR 0xFCu /* DEMCR (0xE000EDFC) */
#define G4_SCB_DEMCR_TRCENA G4_BIT(24)
#define G4_NVIC_ISER(n) (0x000u + 4u * (n))
#define G4_NVIC_ICER(n) (0x080u + 4u * (n))
/* Priority of an IRQ: byte (irq mod 4) of word IPR(irq / 4); 4 bits implemented (7:4). */
#define G4_NVIC_IPR_WORD(irq) (0x300u + 4u * ((irq) / 4u))
#define G4_NVIC_IPR_SHIFT(irq) (8u * ((irq) % 4u) + 4u)

/* IRQ numbers (RM0440 NVIC chapter, vector table). */
#define G4_IRQ_ADC1_2 18u
#define G4_IRQ_TIM1_BRK_TIM15 24u
#define G4_IRQ_TIM1_UP_TIM16 25u
#define G4_IRQ_TIM4 30u
#define G4_IRQ_USART2 38u
#define G4_NUM_IRQ 102u /* vector entries after the 16 system ones (FMAC = 101) */

#endif /* HAL_STM32G4_G4_REGS_H */
