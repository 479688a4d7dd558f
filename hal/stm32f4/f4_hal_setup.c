/* hal.h on an STM32F405/407 board with a DRV8301 (f4_hal.h): its set-up, run
 * at boot and from the main loop (gate driver, ADCs, timers, temperature).
 * Outside the control interrupt: built for size (CMakeLists.txt); the
 * interrupt's calls are in f4_hal.c. */
#include "f4_hal.h"

#include <math.h>
#include <string.h>

#include "f4_adc.h"
#include "f4_core.h"
#include "f4_regs.h"
#include "f4_tim.h"

/* Injected trigger to start of sampling, upper bound in ADC cycles (RM0090
 * sec. 13.3.9 / DS8626: the trigger is synchronised to ADCCLK: two cycles). */
#define F4_HAL_ADC_LATENCY 2u
/* nSCS high between two DRV8301 frames: its minimum is 400 ns (data sheet
 * "SPI timing", t_HI_nSCS); ODrive's driver waits 1 us. */
#define F4_HAL_DRV_CS_HIGH_NS 1000u

static uint32_t f4_hal_f_adc(const f4_clocks_t *clk)
{
    return clk->pclk2_hz / F4_ADC_PRESCALER;
}

/* The channels and sampling times of one ADC's injected ranks, in rank
 * order; currents_only leaves the DC link out. Returns the number of ranks. */
static unsigned f4_hal_ranks(const f4_board_t *b, uint32_t adc, uint8_t ch[4], uint32_t smp[4],
                             bool currents_only)
{
    unsigned n = 0u;
    for (uint8_t r = 1u; r <= 4u; r++) {
        for (unsigned x = 0; x < 3u; x++) {
            if (b->phase[x].adc == adc && b->phase[x].rank == r) {
                ch[n] = b->phase[x].channel;
                smp[n] = b->current_smp_cycles;
                n++;
            }
        }
        if (!currents_only && b->vbus.adc == adc && b->vbus.rank == r) {
            ch[n] = b->vbus.channel;
            smp[n] = b->vbus_smp_cycles;
            n++;
        }
    }
    return n;
}

/* End of the last sampling phase of one ADC's ranks after the trigger, ns. */
static uint32_t f4_hal_sample_end_ns(const f4_board_t *b, uint32_t adc, uint32_t f_adc,
                                     bool currents_only)
{
    uint8_t ch[4];
    uint32_t smp[4];
    const unsigned n = f4_hal_ranks(b, adc, ch, smp, currents_only);
    if (n == 0u || f_adc == 0u) {
        return 0u;
    }
    const uint32_t cyc = f4_adc_sample_end(smp, n, F4_HAL_ADC_LATENCY);
    return (uint32_t)(((uint64_t)cyc * 1000000000u + f_adc - 1u) / f_adc);
}

int f4_hal_cmp_max(const f4_board_t *b, const stm32_pwm_timing_t *t, uint32_t f_tim_hz,
                   uint32_t f_adc_hz, uint32_t *cmp_max)
{
    const uint64_t f_cnt = f_tim_hz / (t->psc + 1u);
    const uint64_t before_ns = (uint64_t)b->dead_time_ns + b->sense_settle_ns;
    uint64_t after_ns = 0u;
    for (uint32_t adc = 1u; adc <= 3u; adc++) {
        const uint64_t a = f4_hal_sample_end_ns(b, adc, f_adc_hz, true);
        after_ns = a > after_ns ? a : after_ns;
    }
    const uint64_t need_ns = before_ns > after_ns ? before_ns : after_ns;
    const uint64_t guard = (need_ns * f_cnt + 999999999u) / 1000000000u;
    if (guard * 4u > t->arr) {
        return F4_E_CONFIG;
    }
    *cmp_max = t->arr - (uint32_t)guard;
    return F4_OK;
}

void f4_hal_current_zero(const f4_board_t *b, uint16_t *zero, uint16_t *tol)
{
    double z = b->sense.zero_v / b->vref * (double)F4_ADC_FULL_SCALE;
    if (b->sense.gain < 0.0) {
        z = (double)F4_ADC_FULL_SCALE - z;
    }
    const double t = ceil(b->sense.zero_tol_v / b->vref * (double)F4_ADC_FULL_SCALE);
    *zero = (uint16_t)lround(z);
    *tol = (uint16_t)t;
}

static uintptr_t f4_hal_jdr(uint32_t adc, uint32_t rank)
{
    return f4_adc_base(adc) + F4_ADC_JDR(rank);
}

int f4_hal_describe(hal_t *h, const f4_board_t *b, const f4_hal_cfg_t *c, const f4_clocks_t *clk)
{
    if (h == NULL || b == NULL || c == NULL || clk == NULL) {
        return F4_E_CONFIG;
    }
    memset(h, 0, sizeof *h);
    h->board = b;
    h->clk = *clk;
    if (c->fs_hz < F4_HAL_FS_MIN_HZ || c->fs_hz > F4_HAL_FS_MAX_HZ || c->encoder_cpr < 4u ||
        c->encoder_cpr > 0xFFFFu) {
        return F4_E_CONFIG;
    }
    /* TIM1's outputs idle at 0 with MOE cleared (OISx = OISxN = 0,
     * f4_tim.h): an active-low gate input would sit at its active level. */
    if (b->gate_active_low) {
        return F4_E_CONFIG;
    }
    /* The DRV8301's amplifiers as the sense: the gain currents are scaled by
     * must be the one written to it (a mismatch mis-scales every current). */
    if (b->sense.drv_amp &&
        (b->drv.gain > 3u || fabs(b->sense.gain) != (double)drv8301_gain(b->drv.gain))) {
        return F4_E_CONFIG;
    }
    uint8_t dtg;
    int rc = stm32_pwm_timing(clk->tim_apb2_hz, c->fs_hz, &h->timing);
    if (rc == F4_OK) {
        rc = stm32_dtg_encode(clk->tim_apb2_hz, b->dead_time_ns, &dtg);
    }
    if (rc == F4_OK) {
        rc = f4_hal_cmp_max(b, &h->timing, clk->tim_apb2_hz, f4_hal_f_adc(clk), &h->cmp_max);
    }
    if (rc != F4_OK) {
        return F4_E_CONFIG;
    }
    /* The sampled phases, the rebuilt one, the interrupting ADC (the one
     * whose sequence ends last). */
    h->rebuilt = 3u;
    uint32_t latest = 0u;
    for (unsigned x = 0; x < 3u; x++) {
        const f4_sample_t *p = &b->phase[x];
        if (p->adc == 0u) {
            if (h->rebuilt != 3u) {
                return F4_E_CONFIG; /* two phases are needed */
            }
            h->rebuilt = x;
        } else {
            h->jdr[x] = f4_hal_jdr(p->adc, p->rank);
            h->adc_mask |= F4_BIT(p->adc);
        }
    }
    h->jdr[3] = f4_hal_jdr(b->vbus.adc, b->vbus.rank);
    h->adc_mask |= F4_BIT(b->vbus.adc);
    for (uint32_t adc = 1u; adc <= 3u; adc++) {
        const uint32_t end = f4_hal_sample_end_ns(b, adc, f4_hal_f_adc(clk), false);
        if ((h->adc_mask & F4_BIT(adc)) != 0u && end >= latest) {
            latest = end;
            h->irq_adc = f4_adc_base(adc);
        }
    }
    h->mirror = b->sense.gain < 0.0 ? F4_ADC_FULL_SCALE : 0u;
    h->enc_tim = f4_gptim_base(b->enc_tim);
    h->enc_index_ch = b->enc_index_ch;
    h->nfault_line = b->nfault.pin;

    hal_info_t *i = &h->info;
    i->pwm_freq_hz = c->fs_hz;
    i->period_counts = h->timing.arr;
    i->adc_bits = 12u;
    i->adc_current_a_per_count =
        b->vref / (double)F4_ADC_FULL_SCALE / (fabs(b->sense.gain) * b->sense.shunt_ohm);
    i->adc_vdc_v_per_count = b->vref / (double)F4_ADC_FULL_SCALE / b->vbus_ratio;
    i->encoder_counts_per_rev = c->encoder_cpr;
    i->has_i_c = true;
    i->cycle_clock_hz = clk->sysclk_hz;
    i->pwm_cmp_max = h->cmp_max;
    f4_hal_current_zero(b, &i->adc_current_zero, &i->adc_current_zero_tol);
    h->rebuild_k = 3u * i->adc_current_zero;
    return F4_OK;
}

/* One DRV8301 frame: nSCS low, the frame, nSCS high and its high time. */
static int f4_hal_drv_xfer(void *ctx, uint16_t out, uint16_t *in)
{
    hal_t *h = ctx;
    const f4_board_t *b = h->board;
    f4_gpio_write(b->drv_cs, false);
    const int rc = f4_spi_xfer16(&h->spi, out, in, h->spi_timeout);
    f4_gpio_write(b->drv_cs, true);
    f4_delay_cycles((uint32_t)((uint64_t)h->clk.sysclk_hz * F4_HAL_DRV_CS_HIGH_NS / 1000000000u));
    return rc == F4_OK ? 0 : -1;
}

/* Step 3 of f4_hal_init: the gate driver reset, configured, read back. */
static int f4_hal_drv_start(hal_t *h)
{
    const f4_board_t *b = h->board;
    const uint32_t us = h->clk.sysclk_hz / 1000000u;
    f4_gpio_config(b->nfault, F4_PIN_INPUT, 1u); /* open drain: pulled up */
    f4_gpio_config(b->noctw, F4_PIN_INPUT, 1u);
    f4_gpio_output(b->drv_cs, true, 0u);
    f4_gpio_config(b->drv_sck, F4_PIN_AF, 0u);
    f4_gpio_config(b->drv_miso, F4_PIN_AF, 1u);
    f4_gpio_config(b->drv_mosi, F4_PIN_AF, 0u);
    uint32_t br, sck;
    const uint32_t pclk = h->spi.apb == 2u ? h->clk.pclk2_hz : h->clk.pclk1_hz;
    if (f4_spi_br(pclk, b->drv_spi_max_hz, &br, &sck) != F4_OK) {
        return F4_E_CONFIG;
    }
    /* A frame takes 16 SCLK periods; 100 frames' time as the time-out. */
    h->spi_timeout = (uint32_t)(100ull * 16u * h->clk.sysclk_hz / sck);
    f4_spi_init(&h->spi, br, false, true); /* mode 1: CPOL 0, CPHA 1 */
    /* EN_GATE low > 20 us: the driver reset (its registers to 0, latched
     * faults cleared), high, then SPI ready within 10 ms. */
    f4_gpio_write(b->en_gate, false);
    f4_delay_cycles(DRV8301_RESET_US * us);
    f4_gpio_write(b->en_gate, true);
    f4_delay_cycles(DRV8301_SPI_READY_US * us);
    h->drv.port.xfer = f4_hal_drv_xfer;
    h->drv.port.ctx = h;
    h->drv_rc = drv8301_configure(&h->drv, &b->drv);
    if (h->drv_rc == DRV8301_OK && f4_hal_nfault_low(h)) {
        /* Configured and no status bit, yet nFAULT is held low: named as a
         * fault of the driver all the same. */
        h->drv.err = h->drv_rc = DRV8301_E_FAULT;
        h->drv.status[0] = DRV8301_S1_FAULT;
    }
    if (h->drv_rc != DRV8301_OK) {
        f4_gpio_write(b->en_gate, false);
        return F4_E_DRIVER;
    }
    return F4_OK;
}

/* Step 4 of f4_hal_init: the power stage's peripherals, TIM1 started. */
static int f4_hal_power_start(hal_t *h)
{
    const f4_board_t *b = h->board;
    const uint32_t f_cpu = h->clk.sysclk_hz;
    /* Analog pins, ADC clocks and sampling times. */
    f4_adc_clock_init();
    for (unsigned x = 0; x < 3u; x++) {
        f4_gpio_config(b->phase[x].pin, F4_PIN_ANALOG, 0u);
    }
    f4_gpio_config(b->vbus.pin, F4_PIN_ANALOG, 0u);
    f4_gpio_config(b->temp.pin, F4_PIN_ANALOG, 0u);
    uint32_t code_i, code_v, code_t;
    if (f4_adc_smp_code(b->current_smp_cycles, &code_i) != F4_OK ||
        f4_adc_smp_code(b->vbus_smp_cycles, &code_v) != F4_OK ||
        f4_adc_smp_code(b->temp.smp_cycles, &code_t) != F4_OK) {
        return F4_E_CONFIG;
    }
    for (uint32_t adc = 1u; adc <= 3u; adc++) {
        if ((h->adc_mask & F4_BIT(adc)) != 0u || b->temp.adc == adc) {
            f4_adc_power_up(f4_adc_base(adc), f_cpu);
        }
    }
    for (unsigned x = 0; x < 3u; x++) {
        if (b->phase[x].adc != 0u) {
            f4_adc_set_smp(f4_adc_base(b->phase[x].adc), b->phase[x].channel, code_i);
        }
    }
    f4_adc_set_smp(f4_adc_base(b->vbus.adc), b->vbus.channel, code_v);
    f4_adc_set_smp(f4_adc_base(b->temp.adc), b->temp.channel, code_t);

    /* TIM1, outputs safe (MOE = 0). */
    f4_tim1_cfg_t tc;
    memset(&tc, 0, sizeof tc);
    tc.timing = h->timing;
    if (stm32_dtg_encode(h->clk.tim_apb2_hz, b->dead_time_ns, &tc.dtg) != F4_OK) {
        return F4_E_CONFIG;
    }
    tc.break_input = f4_pin_used(b->break_in);
    tc.break_active_low = b->break_active_low;
    f4_tim1_pwm_init(&tc);

    /* Injected sequences on TIM1_TRGO; the ADC that finishes last
     * interrupts. */
    for (uint32_t adc = 1u; adc <= 3u; adc++) {
        uint8_t ch[4];
        uint32_t smp[4];
        const unsigned n = f4_hal_ranks(b, adc, ch, smp, false);
        if (n != 0u) {
            const uintptr_t base = f4_adc_base(adc);
            f4_adc_injected_start(base, f4_adc_jsqr(ch, n), base == h->irq_adc);
        }
    }

    /* PWM pins to TIM1 (which drives them inactive: MOE = 0, OSSI = 1), the
     * break input, the encoder, nFAULT's interrupt line. */
    for (unsigned x = 0; x < 3u; x++) {
        f4_gpio_config(b->pwm_high[x], F4_PIN_AF, 2u);
        f4_gpio_config(b->pwm_low[x], F4_PIN_AF, 2u);
    }
    f4_gpio_config(b->break_in, F4_PIN_AF, 0u);
    f4_gpio_config(b->enc_a, F4_PIN_AF, 0u);
    f4_gpio_config(b->enc_b, F4_PIN_AF, 0u);
    f4_gpio_config(b->enc_index, F4_PIN_AF, 0u);
    f4_encoder_init(b->enc_tim, b->enc_filter, b->enc_index_ch);
    (void)f4_exti_falling(b->nfault);

    /* Counter on; the update event must fall on the counter peak. */
    const int rc = f4_tim1_start(&h->timing, f_cpu);
    if (rc != F4_OK) {
        return rc;
    }
    f4_wr(F4_TIM1 + F4_TIM_SR, ~F4_TIM_SR_BIF);
    return F4_OK;
}

int f4_hal_init(hal_t *h, const f4_board_t *b, const f4_hal_cfg_t *c, const f4_clocks_t *clk)
{
    int rc = f4_hal_describe(h, b, c, clk);
    if (rc == F4_OK) {
        rc = f4_spi_find(b->drv_spi, &h->spi);
    }
    /* From here on the gates stay held off unless every step passes. */
    h->hold = true;
    f4_hal_gate_pins_safe(b);
    if (rc == F4_OK) {
        rc = f4_hal_drv_start(h);
    }
    if (rc == F4_OK && !clk->pll) {
        rc = F4_E_CLOCK;
    }
    if (rc == F4_OK) {
        rc = f4_hal_power_start(h);
    }
    if (rc != F4_OK) {
        /* Held off: MOE cleared, EN_GATE low (the driver holds every gate
         * low), the pins inactive. */
        f4_tim1_gates_off_now();
        f4_hal_gate_pins_safe(b);
        return rc;
    }
    h->faults_seen = h->fault_n;
    h->hold = false;
    return F4_OK;
}

bool f4_hal_drv_service(hal_t *h, bool stopped)
{
    if (h->drv_rc != DRV8301_OK || h->hold) {
        /* Never configured, or a later start-up step failed: held off for
         * good with EN_GATE low, the driver reset and its SPI silent (its
         * read-back would fail every time and be written again forever). */
        return false;
    }
    const uint32_t n = h->fault_n;
    bool report = n != h->faults_seen;
    h->faults_seen = n;
    /* Status and control registers: what latched, and whether the
     * configuration survived. */
    const int rc = drv8301_check(&h->drv);
    if (rc == DRV8301_E_READBACK || rc == DRV8301_E_SILENT || rc == DRV8301_E_SPI) {
        h->cfg_lost = true;
        f4_tim1_outputs(false);
    }
    /* Status 2 carries the device ID beside its one fault bit. */
    const uint16_t s1 = h->drv.status[0];
    const uint16_t s2 = (uint16_t)(h->drv.status[1] & DRV8301_S2_GVDD_OV);
    if (s1 != h->reported[0] || s2 != h->reported[1]) {
        report = report || s1 != 0u || s2 != 0u;
        h->reported[0] = s1;
        h->reported[1] = s2;
    }
    if (stopped) {
        if (h->cfg_lost) {
            /* Written again; released only when it reads back. */
            if (drv8301_configure(&h->drv, &h->board->drv) == DRV8301_OK) {
                h->cfg_lost = false;
            }
        } else if (f4_hal_nfault_low(h)) {
            (void)drv8301_gate_reset(&h->drv);
        }
    }
    /* A masked break interrupt back on once its input is released. */
    if (f4_pin_used(h->board->break_in) && (f4_rd(F4_TIM1 + F4_TIM_DIER) & F4_TIM_DIER_BIE) == 0u) {
        f4_wr(F4_TIM1 + F4_TIM_SR, ~F4_TIM_SR_BIF);
        if ((f4_rd(F4_TIM1 + F4_TIM_SR) & F4_TIM_SR_BIF) == 0u) {
            f4_wr(F4_TIM1 + F4_TIM_DIER, F4_TIM_DIER_BIE);
        }
    }
    return report;
}

int32_t f4_hal_temp_counts(hal_t *h)
{
    const f4_board_t *b = h->board;
    return f4_adc_convert(f4_adc_base(b->temp.adc), b->temp.channel, h->clk.sysclk_hz / 10000u);
}

double f4_hal_temp_c(const f4_board_t *b, int32_t counts)
{
    const double v = (double)counts * b->vref / (double)F4_ADC_FULL_SCALE;
    if (counts < 0 || v < 0.01 * b->vref || v > 0.99 * b->vref) {
        return NAN;
    }
    const f4_ntc_t *t = &b->temp;
    /* NTC to VREF (fixed resistor to ground): v = VREF R_f / (R_f + R);
     * else the reverse. */
    const double r =
        t->ntc_high ? t->r_fixed * (b->vref / v - 1.0) : t->r_fixed * v / (b->vref - v);
    return 1.0 / (log(r / t->r25) / t->beta + 1.0 / 298.15) - 273.15;
}
