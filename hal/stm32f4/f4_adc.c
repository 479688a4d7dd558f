/* ADC1..3: injected and regular conversions (f4_adc.h). */
#include "f4_adc.h"

#include "f4_core.h"
#include "f4_regs.h"

static const uint16_t f4_smp_cycles[8] = {3u, 15u, 28u, 56u, 84u, 112u, 144u, 480u};

uintptr_t f4_adc_base(uint32_t n)
{
    switch (n) {
    case 1u:
        return F4_ADC1;
    case 2u:
        return F4_ADC2;
    default:
        return F4_ADC3;
    }
}

int f4_adc_smp_code(uint32_t smp_cycles, uint32_t *code)
{
    for (uint32_t i = 0; i < 8u; i++) {
        if (f4_smp_cycles[i] == smp_cycles) {
            *code = i;
            return F4_OK;
        }
    }
    return F4_E_CONFIG;
}

uint32_t f4_adc_smp_cycles(uint32_t code)
{
    return f4_smp_cycles[code & 7u];
}

uint32_t f4_adc_jsqr(const uint8_t *ch, unsigned n)
{
    uint32_t v = F4_FIELD(n - 1u, F4_ADC_JSQR_JL_POS);
    for (unsigned r = 1u; r <= n; r++) {
        v |= F4_FIELD(ch[r - 1u] & 0x1Fu, 5u * (r + 3u - n));
    }
    return v;
}

uint32_t f4_adc_sample_end(const uint32_t *smp_cycles, unsigned rank, uint32_t latency)
{
    uint32_t t = latency;
    for (unsigned r = 1u; r < rank; r++) {
        t += smp_cycles[r - 1u] + 12u;
    }
    return t + smp_cycles[rank - 1u];
}

void f4_adc_clock_init(void)
{
    f4_rcc_enable(F4_RCC_APB2ENR, F4_RCC_APB2ENR_ADC1EN | (F4_RCC_APB2ENR_ADC1EN << 1) |
                                      (F4_RCC_APB2ENR_ADC1EN << 2));
    /* ADCPRE = 01: PCLK2 / 4; MULTI = 0: the three ADCs independent, each
     * triggered by TIM1_TRGO itself. */
    f4_mod(F4_ADC_COMMON + F4_ADC_CCR, F4_ADC_CCR_ADCPRE_MASK, F4_FIELD(1u, F4_ADC_CCR_ADCPRE_POS));
}

void f4_adc_power_up(uintptr_t adc, uint32_t f_cpu_hz)
{
    f4_wr(adc + F4_ADC_CR1, 0u); /* 12 bits, no scan of the regular group */
    f4_wr(adc + F4_ADC_CR2, F4_ADC_CR2_ADON);
    f4_delay_cycles(3u * (f_cpu_hz / 1000000u + 1u));
}

void f4_adc_set_smp(uintptr_t adc, uint32_t channel, uint32_t code)
{
    const uintptr_t reg = adc + (channel >= 10u ? F4_ADC_SMPR1 : F4_ADC_SMPR2);
    const uint32_t sh = 3u * (channel % 10u);
    f4_mod(reg, 7u << sh, code << sh);
}

void f4_adc_injected_start(uintptr_t adc, uint32_t jsqr, bool irq)
{
    f4_wr(adc + F4_ADC_JSQR, jsqr);
    /* ADC_SR is rc_w0: the injected flags cleared. */
    f4_wr(adc + F4_ADC_SR, ~(F4_ADC_SR_JEOC | F4_ADC_SR_JSTRT));
    /* SCAN: every rank of the injected sequence converts at each trigger
     * (sec. 13.3.5: without it only the first one would). */
    f4_wr(adc + F4_ADC_CR1, F4_ADC_CR1_SCAN | (irq ? F4_ADC_CR1_JEOCIE : 0u));
    f4_wr(adc + F4_ADC_CR2, F4_ADC_CR2_ADON |
                                F4_FIELD(F4_ADC_JEXT_TIM1_TRGO, F4_ADC_CR2_JEXTSEL_POS) |
                                F4_ADC_CR2_JEXTEN_RISING);
}

int32_t f4_adc_convert(uintptr_t adc, uint32_t channel, uint32_t timeout_cycles)
{
    /* SQR1.L = 0 (one conversion), SQ1 = channel. */
    f4_wr(adc + F4_ADC_SQR1, 0u);
    f4_wr(adc + F4_ADC_SQR3, channel & 0x1Fu);
    f4_wr(adc + F4_ADC_SR, ~(F4_ADC_SR_EOC | F4_ADC_SR_OVR | F4_ADC_SR_STRT));
    f4_set(adc + F4_ADC_CR2, F4_ADC_CR2_SWSTART);
    if (!f4_wait_bits(adc + F4_ADC_SR, F4_ADC_SR_EOC, F4_ADC_SR_EOC, timeout_cycles)) {
        return -1;
    }
    return (int32_t)(f4_rd(adc + F4_ADC_DR) & 0xFFFu);
}
