/* Op-amps, comparators, DAC3 (g4_analog.h). */
#include "g4_analog.h"

#include "g4_adc.h"
#include "g4_core.h"
#include "g4_regs.h"

uint32_t g4_opamp_csr(uint32_t vpsel, uint32_t pga_gain_code, bool high_speed)
{
    return G4_FIELD(vpsel & 3u, G4_OPAMP_CSR_VPSEL_POS) | G4_OPAMP_CSR_VMSEL_PGA |
           (high_speed ? G4_OPAMP_CSR_OPAHSM : 0u) |
           G4_FIELD(pga_gain_code & 0x1Fu, G4_OPAMP_CSR_PGA_GAIN_POS);
}

void g4_opamp_init(uint32_t x, uint32_t csr)
{
    g4_set(G4_RCC + G4_RCC_APB2ENR, G4_RCC_APB2ENR_SYSCFGEN);
    g4_wr(G4_OPAMP + G4_OPAMP_CSR(x), csr & ~G4_OPAMP_CSR_OPAEN);
    g4_wr(G4_OPAMP + G4_OPAMP_CSR(x), csr | G4_OPAMP_CSR_OPAEN);
}

int g4_dac_code(double v, double vref, uint32_t *code)
{
    if (!(vref > 0.0) || !(v >= 0.0) || !(v < vref)) {
        return G4_E_CONFIG;
    }
    *code = (uint32_t)(v / vref * (double)G4_DAC_STEPS);
    return G4_OK;
}

int g4_dac3_init(uint32_t code1, uint32_t code2, uint32_t f_cpu_hz)
{
    g4_set(G4_RCC + G4_RCC_AHB2ENR, G4_RCC_AHB2ENR_DAC3EN);
    g4_wr(G4_DAC3 + G4_DAC_CR, 0u);
    g4_wr(G4_DAC3 + G4_DAC_MCR, G4_DAC_MCR_MODE1_INTERNAL | G4_DAC_MCR_MODE2_INTERNAL |
                                    (f_cpu_hz > 160000000u ? G4_DAC_MCR_HFSEL_160MHZ : 0u));
    g4_wr(G4_DAC3 + G4_DAC_DHR12R1, code1 & 0xFFFu);
    g4_wr(G4_DAC3 + G4_DAC_DHR12R2, code2 & 0xFFFu);
    g4_wr(G4_DAC3 + G4_DAC_CR, G4_DAC_CR_EN1 | G4_DAC_CR_EN2);
    const uint32_t rdy = G4_DAC_SR_DAC1RDY | G4_DAC_SR_DAC2RDY;
    if (!g4_wait_bits(G4_DAC3 + G4_DAC_SR, rdy, rdy, 100u * (f_cpu_hz / 1000000u))) {
        return G4_E_DAC;
    }
    return G4_OK;
}

void g4_dac3_set(uint32_t code1, uint32_t code2)
{
    g4_wr(G4_DAC3 + G4_DAC_DHR12R1, code1 & 0xFFFu);
    g4_wr(G4_DAC3 + G4_DAC_DHR12R2, code2 & 0xFFFu);
}

uint32_t g4_comp_csr_dac3(uint32_t hyst)
{
    return G4_FIELD(G4_COMP_CSR_INMSEL_DAC3, G4_COMP_CSR_INMSEL_POS) |
           G4_FIELD(hyst & 7u, G4_COMP_CSR_HYST_POS);
}

void g4_comp_init(uint32_t x, uint32_t csr, uint32_t f_cpu_hz)
{
    g4_set(G4_RCC + G4_RCC_APB2ENR, G4_RCC_APB2ENR_SYSCFGEN);
    g4_wr(G4_COMP + G4_COMP_CSR(x), csr & ~G4_COMP_CSR_EN);
    g4_wr(G4_COMP + G4_COMP_CSR(x), csr | G4_COMP_CSR_EN);
    g4_delay_cycles(5u * (f_cpu_hz / 1000000u));
}

bool g4_comp_value(uint32_t x)
{
    return (g4_rd(G4_COMP + G4_COMP_CSR(x)) & G4_COMP_CSR_VALUE) != 0u;
}

/* VINP's share of VDDA at zero current (g4_board_t: the bias divider). */
static float g4_bias_ratio(float r_gnd, float r_bias, float r_shunt)
{
    const float g_bias = 1.0f / r_bias;
    return g_bias / (1.0f / r_gnd + g_bias + 1.0f / r_shunt);
}

/* Single precision: a handful of FPU instructions on the Cortex-M4F (double
 * is library code there), and 24 bits are plenty for whole counts. */
void g4_sense_zero(const g4_board_t *b, uint16_t *zero, uint16_t *tol)
{
    *zero = 0u;
    *tol = 0u;
    const float rg = (float)b->sense_r_gnd, rb = (float)b->sense_r_bias;
    const float rs = (float)b->sense_r_shunt, e = (float)b->sense_r_tol;
    if (!(rb > 0.0f) || !(rg > 0.0f) || !(rs > 0.0f)) {
        return;
    }
    const float fs = (float)G4_ADC_FULL_SCALE;
    const float gain = (float)b->opamp_pga_gain;
    const float k = gain * fs; /* counts per unit of VINP / VDDA */
    const float nom = k * g4_bias_ratio(rg, rb, rs);
    /* The ratio rises with r_gnd and r_shunt and falls with r_bias. */
    const float top = k * g4_bias_ratio(rg * (1.0f + e), rb * (1.0f - e), rs * (1.0f + e));
    const float bot = k * g4_bias_ratio(rg * (1.0f - e), rb * (1.0f + e), rs * (1.0f - e));
    const float r_dev = top - nom > nom - bot ? top - nom : nom - bot;
    const float spread =
        r_dev + gain * (float)(b->opamp_vio_v / b->vref) * fs + (float)b->opamp_gain_err * nom;
    if (!(nom < fs) || !(spread >= 0.0f) || !(spread < fs)) {
        return;
    }
    const float raw = b->sense_gain < 0.0 ? fs - nom : nom; /* as hal_adc_read returns it */
    *zero = (uint16_t)(raw + 0.5f);
    const uint16_t t = (uint16_t)spread;
    *tol = (float)t < spread ? (uint16_t)(t + 1u) : t; /* rounded up */
}
