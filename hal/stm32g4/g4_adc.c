/* ADC1/ADC2: calibration, injected and regular conversions (g4_adc.h). */
#include "g4_adc.h"

#include "g4_core.h"
#include "g4_regs.h"

static const uint16_t g4_smp_half[8] = {5u, 13u, 25u, 49u, 95u, 185u, 495u, 1281u};

int g4_adc_smp_code(uint32_t smp_half_cycles, uint32_t *code)
{
    for (uint32_t i = 0; i < 8u; i++) {
        if (g4_smp_half[i] == smp_half_cycles) {
            *code = i;
            return G4_OK;
        }
    }
    return G4_E_CONFIG;
}

uint32_t g4_adc_smp_half_cycles(uint32_t code)
{
    return g4_smp_half[code & 7u];
}

uint32_t g4_adc_jsqr(const uint8_t *ch, unsigned n, uint32_t jextsel)
{
    uint32_t v = (uint32_t)(n - 1u) | G4_FIELD(jextsel & 0x1Fu, G4_ADC_JSQR_JEXTSEL_POS) |
                 G4_ADC_JSQR_JEXTEN_RISING;
    for (unsigned r = 1u; r <= n; r++) {
        v |= G4_FIELD(ch[r - 1u] & 0x1Fu, G4_ADC_JSQR_JSQ_POS(r));
    }
    return v;
}

void g4_adc_sample_window(const uint32_t *smp_half, unsigned rank, uint32_t latency_half,
                          uint32_t *start_half, uint32_t *end_half)
{
    uint32_t t = latency_half;
    for (unsigned r = 1u; r < rank; r++) {
        t += smp_half[r - 1u] + 25u; /* + 12.5 cycles of conversion */
    }
    *start_half = t;
    *end_half = t + smp_half[rank - 1u];
}

void g4_adc12_clock_init(void)
{
    g4_set(G4_RCC + G4_RCC_AHB2ENR, G4_RCC_AHB2ENR_ADC12EN);
    g4_mod(G4_ADC12 + G4_ADC_CCR, G4_ADC_CCR_CKMODE_MASK, G4_ADC_CCR_CKMODE_HCLK_DIV4);
}

int g4_adc_power_up(uintptr_t adc, uint32_t f_cpu_hz)
{
    const uint32_t us = f_cpu_hz / 1000000u;
    /* ADC_CR: the bits other than the one being changed are written 0 (its
     * bits are rs: writing 1 to ADCAL/ADEN/... starts an action). */
    g4_wr(adc + G4_ADC_CR, 0u); /* DEEPPWD = 0 */
    g4_wr(adc + G4_ADC_CR, G4_ADC_CR_ADVREGEN);
    g4_delay_cycles(20u * us); /* t_ADCVREG_STUP */
    /* ADCALDIF = 0: single-ended calibration. */
    g4_wr(adc + G4_ADC_CR, G4_ADC_CR_ADVREGEN | G4_ADC_CR_ADCAL);
    if (!g4_wait_bits(adc + G4_ADC_CR, G4_ADC_CR_ADCAL, 0u, 10000u * us)) {
        return G4_E_ADC_CAL;
    }
    /* >= 4 ADC clock cycles (16 HCLK cycles at HCLK / 4) after calibration. */
    g4_delay_cycles(64u);
    g4_wr(adc + G4_ADC_ISR, G4_ADC_ISR_ADRDY); /* w1c */
    g4_wr(adc + G4_ADC_CR, G4_ADC_CR_ADVREGEN | G4_ADC_CR_ADEN);
    if (!g4_wait_bits(adc + G4_ADC_ISR, G4_ADC_ISR_ADRDY, G4_ADC_ISR_ADRDY, 1000u * us)) {
        return G4_E_ADC_RDY;
    }
    return G4_OK;
}

void g4_adc_set_smp(uintptr_t adc, uint32_t channel, uint32_t code)
{
    const uintptr_t reg = adc + (channel < 10u ? G4_ADC_SMPR1 : G4_ADC_SMPR2);
    const uint32_t sh = 3u * (channel % 10u);
    g4_mod(reg, 7u << sh, code << sh);
}

void g4_adc_injected_start(uintptr_t adc, uint32_t jsqr)
{
    g4_wr(adc + G4_ADC_JSQR, jsqr);
    g4_wr(adc + G4_ADC_ISR, G4_ADC_ISR_JEOC | G4_ADC_ISR_JEOS | G4_ADC_ISR_JQOVF);
    /* JADSTART alone among the rs bits (written 0: no effect), ADVREGEN kept:
     * ADEN may be written 1 only with every other ADC_CR bit 0 (RM0440
     * ADC_CR; ST's LL_ADC_INJ_StartConversion writes the rs bits likewise). */
    g4_wr(adc + G4_ADC_CR, G4_ADC_CR_ADVREGEN | G4_ADC_CR_JADSTART);
}

int32_t g4_adc_convert(uintptr_t adc, uint32_t channel, uint32_t timeout_cycles)
{
    /* SQR1: L = 0 (one conversion), SQ1 = channel. */
    g4_wr(adc + G4_ADC_SQR1, G4_FIELD(channel & 0x1Fu, 6u));
    g4_wr(adc + G4_ADC_ISR, G4_ADC_ISR_EOC | G4_ADC_ISR_EOS | G4_ADC_ISR_OVR);
    /* ADSTART alone among the rs bits (written 0: no effect; ADEN stays set
     * and is not written 1 again while JADSTART is set), ADVREGEN kept: as
     * ST's LL_ADC_REG_StartConversion. */
    g4_wr(adc + G4_ADC_CR, G4_ADC_CR_ADVREGEN | G4_ADC_CR_ADSTART);
    if (!g4_wait_bits(adc + G4_ADC_ISR, G4_ADC_ISR_EOC, G4_ADC_ISR_EOC, timeout_cycles)) {
        return -1;
    }
    return (int32_t)(g4_rd(adc + G4_ADC_DR) & 0xFFFFu);
}
