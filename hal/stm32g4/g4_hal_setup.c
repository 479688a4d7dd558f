/* hal.h on an STM32G4 motor board (g4_hal.h): its set-up, run at boot and from
 * the main loop (clocks, pins, ADC, comparators, timers, the trip level, the
 * temperature). Outside the control interrupt: built for size (CMakeLists.txt);
 * the interrupt's calls are in g4_hal.c. */
#include "g4_hal.h"

#include <math.h>
#include <string.h>

#include "g4_adc.h"
#include "g4_analog.h"
#include "g4_clock.h"
#include "g4_core.h"
#include "g4_regs.h"

/* Injected trigger to start of sampling, upper bound in ADC half cycles
 * (synchronous clock mode: a fixed latency of a few ADC cycles). */
#define G4_HAL_ADC_LATENCY_HALF 6u
/* Zero-current level of the comparator inputs: average of this many
 * conversions; plausible range (the plus input sits at a small bias above
 * ground): 0 .. 1/4 of VREF+. */
#define G4_HAL_ZERO_SAMPLES 64u
#define G4_HAL_ZERO_MAX_COUNTS (G4_ADC_FULL_SCALE / 4u)

static uintptr_t g4_hal_adc_base(uint8_t adc)
{
    return adc == 1u ? G4_ADC1 : G4_ADC2;
}

static uintptr_t g4_hal_jdr(uint8_t adc, uint8_t rank)
{
    return g4_hal_adc_base(adc) + G4_ADC_JDR1 + 4u * (uint32_t)(rank - 1u);
}

/* ADC clock: HCLK / 4 (g4_adc12_clock_init). */
static uint32_t g4_hal_f_adc(const g4_board_t *b)
{
    return b->sysclk_hz / 4u;
}

/* Sampling times (half cycles) of the injected ranks of one ADC, in rank
 * order; returns the number of ranks and fills the channel list. */
static unsigned g4_hal_ranks(const g4_board_t *b, uint8_t adc, uint8_t ch[4], uint32_t smp[4],
                             bool currents_only)
{
    unsigned n = 0u;
    for (uint8_t r = 1u; r <= 4u; r++) {
        for (unsigned x = 0; x < 3u; x++) {
            if (b->phase[x].adc == adc && b->phase[x].adc_rank == r) {
                ch[n] = b->phase[x].adc_channel;
                smp[n] = b->current_smp_half;
                n++;
            }
        }
        if (!currents_only && b->vbus_adc == adc && b->vbus_rank == r) {
            ch[n] = b->vbus_channel;
            smp[n] = b->vbus_smp_half;
            n++;
        }
    }
    return n;
}

/* End of the last sampling phase of the ranks of one ADC after the trigger,
 * ns (currents only: the DC link needs no zero vector). */
static uint32_t g4_hal_sample_end_ns(const g4_board_t *b, uint8_t adc, bool currents_only)
{
    uint8_t ch[4];
    uint32_t smp[4];
    const unsigned n = g4_hal_ranks(b, adc, ch, smp, currents_only);
    if (n == 0u) {
        return 0u;
    }
    uint32_t s0, s1;
    g4_adc_sample_window(smp, n, G4_HAL_ADC_LATENCY_HALF, &s0, &s1);
    return (uint32_t)(((uint64_t)s1 * 1000000000u + 2u * g4_hal_f_adc(b) - 1u) /
                      (2u * (uint64_t)g4_hal_f_adc(b)));
}

int g4_hal_cmp_max(const g4_board_t *b, const g4_pwm_timing_t *t, uint32_t *cmp_max)
{
    /* Timer counts per second (f_TIM = SYSCLK, divided by PSC + 1). */
    const uint64_t f_cnt = b->sysclk_hz / (t->psc + 1u);
    const uint64_t before_ns = (uint64_t)b->dead_time_ns + b->sense_settle_ns;
    uint64_t after_ns = g4_hal_sample_end_ns(b, 1u, true);
    const uint64_t a2 = g4_hal_sample_end_ns(b, 2u, true);
    if (a2 > after_ns) {
        after_ns = a2;
    }
    const uint64_t need_ns = before_ns > after_ns ? before_ns : after_ns;
    const uint64_t guard = (need_ns * f_cnt + 999999999u) / 1000000000u;
    if (guard * 4u > t->arr) {
        return G4_E_CONFIG;
    }
    *cmp_max = t->arr - (uint32_t)guard;
    return G4_OK;
}

int g4_hal_trip_codes(const g4_board_t *b, const uint16_t vinp_zero[3], double trip_a,
                      uint32_t code[2])
{
    if (!(trip_a > 0.0) || !(trip_a <= b->current_peak_a)) {
        return G4_E_CONFIG;
    }
    code[0] = code[1] = 0xFFFu;
    bool used[2] = {false, false};
    for (unsigned x = 0; x < 3u; x++) {
        const g4_phase_sense_t *p = &b->phase[x];
        const double v_zero = (double)vinp_zero[x] * b->vref / (double)G4_ADC_FULL_SCALE;
        const double v_th =
            v_zero + fabs(b->sense_gain) / b->opamp_pga_gain * b->shunt_ohm * trip_a;
        uint32_t c;
        if (g4_dac_code(v_th, b->vref, &c) != G4_OK || p->dac_channel < 1u || p->dac_channel > 2u) {
            return G4_E_CONFIG;
        }
        const unsigned i = p->dac_channel - 1u;
        if (!used[i] || c < code[i]) {
            code[i] = c;
            used[i] = true;
        }
    }
    return G4_OK;
}

int g4_hal_set_trip_current(hal_t *h, double trip_a)
{
    uint32_t code[2];
    const int rc = g4_hal_trip_codes(h->board, h->vinp_zero, trip_a, code);
    if (rc != G4_OK) {
        return rc;
    }
    g4_dac3_set(code[0], code[1]);
    h->dac_code[0] = code[0];
    h->dac_code[1] = code[1];
    h->trip_current_a = trip_a;
    return G4_OK;
}

static int g4_hal_check(const g4_board_t *b, const g4_hal_cfg_t *c)
{
    if (c->fs_hz < G4_HAL_FS_MIN_HZ || c->fs_hz > G4_HAL_FS_MAX_HZ || c->encoder_cpr < 4u ||
        c->encoder_cpr > 0xFFFFu || !(c->trip_current_a > 0.0) ||
        !(c->trip_current_a <= b->current_peak_a)) {
        return G4_E_CONFIG;
    }
    return G4_OK;
}

void g4_hal_gate_pins_safe(const g4_board_t *b)
{
    for (unsigned x = 0; x < 3u; x++) {
        g4_gpio_write(b->pwm_high[x], b->gate_active_low);
        g4_gpio_write(b->pwm_low[x], b->gate_active_low);
        g4_gpio_config(b->pwm_high[x], G4_PIN_OUTPUT, 2u);
        g4_gpio_config(b->pwm_low[x], G4_PIN_OUTPUT, 2u);
    }
}

/* Zero-current level of each comparator plus input (gates off). */
static int g4_hal_measure_zero(hal_t *h)
{
    const g4_board_t *b = h->board;
    const uint32_t timeout = b->sysclk_hz / 10000u; /* 100 us */
    for (unsigned x = 0; x < 3u; x++) {
        const g4_phase_sense_t *p = &b->phase[x];
        const uintptr_t adc = g4_hal_adc_base(p->adc);
        uint32_t sum = 0u;
        for (unsigned i = 0; i < G4_HAL_ZERO_SAMPLES; i++) {
            const int32_t v = g4_adc_convert(adc, p->vinp_channel, timeout);
            if (v < 0) {
                return G4_E_ADC_RDY;
            }
            sum += (uint32_t)v;
        }
        const uint32_t avg = (sum + G4_HAL_ZERO_SAMPLES / 2u) / G4_HAL_ZERO_SAMPLES;
        if (avg > G4_HAL_ZERO_MAX_COUNTS) {
            return G4_E_RANGE;
        }
        h->vinp_zero[x] = (uint16_t)avg;
    }
    return G4_OK;
}

int g4_hal_init(hal_t *h, const g4_board_t *b, const g4_hal_cfg_t *c)
{
    if (h == NULL || b == NULL || c == NULL) {
        return G4_E_CONFIG;
    }
    memset(h, 0, sizeof *h);
    h->board = b;
    int rc = g4_hal_check(b, c);
    if (rc != G4_OK) {
        return rc;
    }
    g4_tim1_cfg_t tc;
    memset(&tc, 0, sizeof tc);
    rc = g4_pwm_timing(b->sysclk_hz, c->fs_hz, &tc.timing);
    if (rc == G4_OK) {
        rc = g4_dtg_encode(b->sysclk_hz, b->dead_time_ns, &tc.dtg);
    }
    if (rc == G4_OK) {
        rc = g4_hal_cmp_max(b, &tc.timing, &h->cmp_max);
    }
    if (rc != G4_OK) {
        return rc;
    }
    h->timing = tc.timing;
    tc.bkf = b->break_filter;
    tc.active_low = b->gate_active_low;
    for (unsigned x = 0; x < 3u; x++) {
        tc.break_comps = (uint8_t)(tc.break_comps | (1u << b->phase[x].comp));
    }

    /* 1. Gates: pins driven inactive before anything else. */
    g4_hal_gate_pins_safe(b);
    if (b->ucpd_dead_battery_off) {
        g4_set(G4_RCC + G4_RCC_APB1ENR1, G4_RCC_APB1ENR1_PWREN);
        g4_set(G4_PWR + G4_PWR_CR3, G4_PWR_CR3_UCPD1_DBDIS);
    }

    /* 2. Analog pins, op-amps (configured, then enabled). */
    for (unsigned x = 0; x < 3u; x++) {
        const g4_phase_sense_t *p = &b->phase[x];
        g4_gpio_config(p->vinp, G4_PIN_ANALOG, 0u);
        g4_gpio_config(p->vinm, G4_PIN_ANALOG, 0u);
        g4_gpio_config(p->vout, G4_PIN_ANALOG, 0u);
        g4_opamp_init(p->opamp, g4_opamp_csr(p->opamp_vpsel, b->opamp_pga_code, true));
    }
    g4_gpio_config(b->vbus_pin, G4_PIN_ANALOG, 0u);
    g4_gpio_config(b->temp_pin, G4_PIN_ANALOG, 0u);

    /* 3. ADC1/ADC2: clock, regulator, calibration, enable. */
    g4_adc12_clock_init();
    rc = g4_adc_power_up(G4_ADC1, b->sysclk_hz);
    if (rc == G4_OK) {
        rc = g4_adc_power_up(G4_ADC2, b->sysclk_hz);
    }
    if (rc != G4_OK) {
        return rc;
    }
    uint32_t code;
    if (g4_adc_smp_code(b->current_smp_half, &code) != G4_OK) {
        return G4_E_CONFIG;
    }
    for (unsigned x = 0; x < 3u; x++) {
        const uintptr_t adc = g4_hal_adc_base(b->phase[x].adc);
        g4_adc_set_smp(adc, b->phase[x].adc_channel, code);
        g4_adc_set_smp(adc, b->phase[x].vinp_channel, code);
    }
    if (g4_adc_smp_code(b->vbus_smp_half, &code) != G4_OK) {
        return G4_E_CONFIG;
    }
    g4_adc_set_smp(g4_hal_adc_base(b->vbus_adc), b->vbus_channel, code);
    if (g4_adc_smp_code(b->temp_smp_half, &code) != G4_OK) {
        return G4_E_CONFIG;
    }
    g4_adc_set_smp(g4_hal_adc_base(b->temp_adc), b->temp_channel, code);

    /* 4. Over-current thresholds from the zero-current levels; DAC3, then
     * the comparators (their outputs settle before TIM1 listens to them). */
    rc = g4_hal_measure_zero(h);
    if (rc != G4_OK) {
        return rc;
    }
    uint32_t dac[2];
    rc = g4_hal_trip_codes(b, h->vinp_zero, c->trip_current_a, dac);
    if (rc == G4_OK) {
        rc = g4_dac3_init(dac[0], dac[1], b->sysclk_hz);
    }
    if (rc != G4_OK) {
        return rc;
    }
    h->dac_code[0] = dac[0];
    h->dac_code[1] = dac[1];
    h->trip_current_a = c->trip_current_a;
    for (unsigned x = 0; x < 3u; x++) {
        g4_comp_init(b->phase[x].comp, g4_comp_csr_dac3(0u), b->sysclk_hz);
    }

    /* 5. TIM1: outputs safe, break from the comparators, MOE = 0. */
    g4_tim1_pwm_init(&tc);

    /* 6. Injected sequences on TIM1_TRGO2; the ADC that finishes last raises
     * the interrupt. */
    uint32_t end[2] = {0u, 0u};
    for (uint8_t adc = 1u; adc <= 2u; adc++) {
        uint8_t ch[4];
        uint32_t smp[4];
        const unsigned n = g4_hal_ranks(b, adc, ch, smp, false);
        if (n == 0u) {
            continue;
        }
        end[adc - 1u] = g4_hal_sample_end_ns(b, adc, false);
        g4_adc_injected_start(g4_hal_adc_base(adc), g4_adc_jsqr(ch, n, G4_ADC12_JEXT_TIM1_TRGO2));
    }
    h->irq_adc = end[1] > end[0] ? G4_ADC2 : G4_ADC1;
    h->other_adc = end[1] > end[0] ? G4_ADC1 : G4_ADC2;
    g4_wr(h->irq_adc + G4_ADC_IER, G4_ADC_IER_JEOSIE);
    for (unsigned x = 0; x < 3u; x++) {
        h->jdr[x] = g4_hal_jdr(b->phase[x].adc, b->phase[x].adc_rank);
    }
    h->jdr[3] = g4_hal_jdr(b->vbus_adc, b->vbus_rank);
    h->mirror = b->sense_gain < 0.0 ? G4_ADC_FULL_SCALE : 0u;

    /* 7. PWM pins to TIM1 (which drives them inactive: MOE = 0, OSSI = 1). */
    for (unsigned x = 0; x < 3u; x++) {
        g4_gpio_config(b->pwm_high[x], G4_PIN_AF, 2u);
        g4_gpio_config(b->pwm_low[x], G4_PIN_AF, 2u);
    }

    /* 8. Encoder. */
    g4_gpio_config(b->enc_a, G4_PIN_AF, 0u);
    g4_gpio_config(b->enc_b, G4_PIN_AF, 0u);
    if (b->enc_has_index) {
        g4_gpio_config(b->enc_index, G4_PIN_AF, 0u);
    }
    g4_tim4_encoder_init(b->enc_filter, b->enc_has_index);

    /* 9. hal.h description. */
    h->info.pwm_freq_hz = c->fs_hz;
    h->info.period_counts = tc.timing.arr;
    h->info.adc_bits = 12u;
    h->info.adc_current_a_per_count =
        b->vref / (double)G4_ADC_FULL_SCALE / (fabs(b->sense_gain) * b->shunt_ohm);
    h->info.adc_vdc_v_per_count = b->vref / (double)G4_ADC_FULL_SCALE / b->vbus_ratio;
    h->info.encoder_counts_per_rev = c->encoder_cpr;
    h->info.has_i_c = true;
    h->info.cycle_clock_hz = b->sysclk_hz;
    h->info.pwm_cmp_max = h->cmp_max;
    g4_sense_zero(b, &h->info.adc_current_zero, &h->info.adc_current_zero_tol);

    /* 10. Counter on; the update event must fall on the counter peak. Flags
     * raised while the comparators settled are cleared (before any MOE). */
    rc = g4_tim1_start(&tc.timing, b->sysclk_hz);
    if (rc != G4_OK) {
        return rc;
    }
    g4_wr(G4_TIM1 + G4_TIM_SR, ~(G4_TIM_SR_BIF | G4_TIM_SR_B2IF | G4_TIM_SR_SBIF));
    return G4_OK;
}

int32_t g4_hal_temp_counts(hal_t *h)
{
    const g4_board_t *b = h->board;
    return g4_adc_convert(g4_hal_adc_base(b->temp_adc), b->temp_channel, b->sysclk_hz / 10000u);
}

double g4_hal_temp_c(const g4_board_t *b, int32_t counts)
{
    const double v = (double)counts * b->vref / (double)G4_ADC_FULL_SCALE;
    if (counts < 0 || v < b->temp_v_min || v > b->temp_v_max) {
        return NAN;
    }
    return b->temp_t0_c + (v - b->temp_v0) / b->temp_dv_dt;
}

/* The control interrupt is ADC1_2's (the injected sequence's end). */
void hal_ctrl_hold(hal_t *h, bool hold)
{
    if (hold) {
        if (h->hold_depth++ == 0u) {
            h->hold_was_on = g4_nvic_enabled(G4_IRQ_ADC1_2);
            g4_nvic_disable(G4_IRQ_ADC1_2);
        }
    } else if (h->hold_depth != 0u && --h->hold_depth == 0u && h->hold_was_on) {
        g4_nvic_enable(G4_IRQ_ADC1_2);
    }
}
