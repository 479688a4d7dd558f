/* hal.h on an STM32F405/407 board with a DRV8301 (f4_hal.h): the calls of the
 * control interrupt and the trip latch (the set-up is in f4_hal_setup.c). */
#include "f4_hal.h"

#include <stddef.h>

#include "f4_core.h"
#include "f4_regs.h"
#include "f4_tim.h"

void f4_hal_adc_irq_ack(hal_t *h)
{
    /* ADC_SR is rc_w0: JEOC and JSTRT cleared, the other flags kept. */
    for (uint32_t n = 1u; n <= 3u; n++) {
        if ((h->adc_mask & F4_BIT(n)) != 0u) {
            const uintptr_t adc = n == 1u ? F4_ADC1 : (n == 2u ? F4_ADC2 : F4_ADC3);
            f4_wr(adc + F4_ADC_SR, ~(F4_ADC_SR_JEOC | F4_ADC_SR_JSTRT));
        }
    }
}

void f4_hal_nfault_irq(hal_t *h)
{
    /* Gates off first: MOE cleared (the DRV8301 in latch mode has turned its
     * outputs off already when the cause is an over-current). */
    f4_tim1_outputs(false);
    h->fault_n++;
    f4_wr(F4_EXTI + F4_EXTI_PR, F4_BIT(h->nfault_line));
}

void f4_hal_break_irq(hal_t *h)
{
    f4_tim1_outputs(false);
    if ((f4_rd(F4_TIM1 + F4_TIM_SR) & F4_TIM_SR_BIF) != 0u) {
        h->break_n++;
    }
    f4_wr(F4_TIM1 + F4_TIM_SR, ~F4_TIM_SR_BIF);
    /* RM0090 sec. 17.3.14: BIF cannot be cleared while the input is active;
     * the interrupt is masked until f4_hal_drv_service sees it released
     * (DIER holds BIE only: written whole). */
    if ((f4_rd(F4_TIM1 + F4_TIM_SR) & F4_TIM_SR_BIF) != 0u) {
        f4_wr(F4_TIM1 + F4_TIM_DIER, 0u);
    }
}

void f4_hal_trip_board(hal_t *h, bool on)
{
    /* The latch first: a control interrupt in between no longer enables the
     * gates. */
    h->board_trip = on;
    if (on) {
        f4_tim1_outputs(false);
    }
}

bool f4_hal_nfault_low(const hal_t *h)
{
    return !f4_gpio_read(h->board->nfault);
}

uint32_t f4_hal_trip_cause(const hal_t *h)
{
    uint32_t t = 0u;
    if (h->fault_n != h->fault_acked || f4_hal_nfault_low(h)) {
        t |= F4_TRIP_DRIVER;
    }
    if (h->break_n != h->break_acked || (f4_rd(F4_TIM1 + F4_TIM_SR) & F4_TIM_SR_BIF) != 0u) {
        t |= F4_TRIP_BREAK;
    }
    if (h->board_trip) {
        t |= F4_TRIP_BOARD;
    }
    if (h->hold) {
        t |= F4_TRIP_HOLD;
    }
    if (h->cfg_lost) {
        t |= F4_TRIP_CONFIG;
    }
    return t;
}

/* ---- hal.h ---- */

void hal_info_get(const hal_t *h, hal_info_t *info)
{
    if (h != NULL && info != NULL) {
        *info = h->info;
    }
}

void hal_adc_read(hal_t *h, hal_adc_raw_t *raw)
{
    /* 12-bit codes; a negative sense gain is mirrored (4095 - x = x ^ 0xFFF)
     * so that the counts rise with the phase current, as hal.h expects. A
     * phase without an ADC (jdr 0) is rebuilt from the other two: in counts
     * i_x = k - i_y - i_z with k three zero-current codes, so that the
     * firmware's offset calibration of that channel measures
     * k - off_y - off_z and its current is exactly -(i_y + i_z); limited to
     * the 12-bit range, where the measured phases saturate too. */
    uint32_t c[3];
    for (unsigned x = 0; x < 3u; x++) {
        c[x] = h->jdr[x] != 0u ? ((f4_rd(h->jdr[x]) ^ h->mirror) & 0xFFFu) : 0u;
    }
    if (h->rebuilt < 3u) {
        const int32_t v = (int32_t)h->rebuild_k - (int32_t)(c[0] + c[1] + c[2]);
        c[h->rebuilt] = v < 0 ? 0u : (v > 0xFFF ? 0xFFFu : (uint32_t)v);
    }
    raw->i_a = (uint16_t)c[0];
    raw->i_b = (uint16_t)c[1];
    raw->i_c = (uint16_t)c[2];
    raw->vdc = (uint16_t)(f4_rd(h->jdr[3]) & 0xFFFu);
}

void hal_encoder_read(hal_t *h, hal_encoder_raw_t *enc)
{
    const uint16_t cnt = (uint16_t)f4_rd(h->enc_tim + F4_TIM_CNT);
    enc->count = stm32_enc_extend(&h->enc, cnt);
    if (h->enc_index_ch != 0u &&
        (f4_rd(h->enc_tim + F4_TIM_SR) & F4_TIM_SR_CCIF(h->enc_index_ch)) != 0u) {
        /* Reading CCRx clears CCxIF. */
        const uint16_t ccr = (uint16_t)f4_rd(h->enc_tim + F4_TIM_CCR(h->enc_index_ch));
        h->index_count = stm32_enc_at_capture(&h->enc, cnt, ccr);
        h->index_seen = true;
    }
    enc->index_seen = h->index_seen;
    enc->index_count = h->index_count;
}

void hal_pwm_write(hal_t *h, const hal_pwm_t *pwm)
{
    const uint32_t m = h->cmp_max;
    f4_wr(F4_TIM1 + F4_TIM_CCR(1u), pwm->cmp[0] < m ? pwm->cmp[0] : m);
    f4_wr(F4_TIM1 + F4_TIM_CCR(2u), pwm->cmp[1] < m ? pwm->cmp[1] : m);
    f4_wr(F4_TIM1 + F4_TIM_CCR(3u), pwm->cmp[2] < m ? pwm->cmp[2] : m);
}

/* The control interrupt is the ADCs' (the injected sequence's end). */
void hal_ctrl_hold(hal_t *h, bool hold)
{
    if (hold) {
        if (h->hold_depth++ == 0u) {
            h->hold_was_on = f4_nvic_enabled(F4_IRQ_ADC);
            f4_nvic_disable(F4_IRQ_ADC);
        }
    } else if (h->hold_depth != 0u && --h->hold_depth == 0u && h->hold_was_on) {
        f4_nvic_enable(F4_IRQ_ADC);
    }
}

void hal_gate_enable(hal_t *h, bool enable)
{
    if (enable) {
        /* The trip's check and MOE's read-modify-write as one step with the
         * interrupts masked (f4_irq_lock): the nFAULT and break interrupts,
         * which clear MOE too, cannot run between the read and the write and
         * have their "gates off" undone by it; pending, they run after the
         * write, their clear the last word. A break in hardware meanwhile
         * clears MOE and holds it clear while its input is active (RM0090
         * sec. 17.3.14). Called at an arm or a commissioning step's first
         * period, never every period: the lock costs nothing per period. */
        const uint32_t primask = f4_irq_lock();
        const bool on = !hal_trip_active(h);
        if (on) {
            f4_tim1_outputs(true);
        }
        f4_irq_unlock(primask);
        if (on) {
            return;
        }
    }
    f4_tim1_outputs(false);
}

bool hal_trip_active(const hal_t *h)
{
    /* Every period: one combined test. nFAULT's level too, so that a fault
     * whose edge came before its interrupt was enabled still counts. */
    const uint32_t sr = f4_rd(F4_TIM1 + F4_TIM_SR);
    const uint32_t low = f4_hal_nfault_low(h) ? 1u : 0u;
    return ((h->fault_n ^ h->fault_acked) | (h->break_n ^ h->break_acked) |
            (uint32_t)h->board_trip | (uint32_t)h->cfg_lost | (uint32_t)h->hold | low |
            (sr & F4_TIM_SR_BIF)) != 0u;
}

void hal_trip_clear(hal_t *h)
{
    /* The faults counted before the cause is seen gone are the ones
     * acknowledged (n read first: a fault after it stays latched). The
     * driver's own latch is reset by the main loop (f4_hal_drv_service);
     * until then nFAULT stays low and so does the trip. The board, hold and
     * configuration causes are the main loop's to release. */
    const uint32_t n = h->fault_n;
    const uint32_t b = h->break_n;
    if (!f4_hal_nfault_low(h)) {
        h->fault_acked = n;
    }
    if ((f4_rd(F4_TIM1 + F4_TIM_SR) & F4_TIM_SR_BIF) == 0u) {
        h->break_acked = b;
    }
}

uint32_t hal_cycles(const hal_t *h)
{
    (void)h;
    return f4_cycles();
}
