/* hal.h on an STM32G4 motor board (g4_hal.h): the calls of the control
 * interrupt and the trip latch (the set-up is in g4_hal_setup.c). */
#include "g4_hal.h"

#include <math.h>
#include <string.h>

#include "g4_adc.h"
#include "g4_analog.h"
#include "g4_clock.h"
#include "g4_core.h"
#include "g4_regs.h"

void g4_hal_adc_irq_ack(hal_t *h)
{
    g4_wr(h->irq_adc + G4_ADC_ISR, G4_ADC_ISR_JEOC | G4_ADC_ISR_JEOS);
    g4_wr(h->other_adc + G4_ADC_ISR, G4_ADC_ISR_JEOC | G4_ADC_ISR_JEOS);
}

void g4_hal_break_irq(hal_t *h)
{
    /* Gates off first (the hardware has cleared MOE; this makes sure), by
     * clearing MOE, not by a software break: EGR.BG would set BIF before SR
     * is read below, and every break, a system break too, would count as an
     * over-current. */
    g4_tim1_outputs(false);
    const uint32_t flags = G4_TIM_SR_BIF | G4_TIM_SR_B2IF | G4_TIM_SR_SBIF;
    const uint32_t sr = g4_rd(G4_TIM1 + G4_TIM_SR);
    if ((sr & (G4_TIM_SR_BIF | G4_TIM_SR_B2IF)) != 0u) {
        h->break_n++;
    }
    if ((sr & G4_TIM_SR_SBIF) != 0u) {
        h->system_n++;
    }
    g4_wr(G4_TIM1 + G4_TIM_SR, ~flags);
    /* RM0440 TIM1 break: a flag cannot be cleared while its input is still
     * active, and the interrupt would be taken again at once, for as long as
     * a comparator stays high. Masked until g4_hal_break_rearm finds the
     * inputs released (DIER holds BIE only: written whole, no
     * read-modify-write). The break just counted stays latched meanwhile. */
    if ((g4_rd(G4_TIM1 + G4_TIM_SR) & flags) != 0u) {
        g4_wr(G4_TIM1 + G4_TIM_DIER, 0u);
    }
}

/* Any comparator output high (a break input still active). */
static bool g4_hal_comp_high(const hal_t *h)
{
    for (unsigned x = 0; x < 3u; x++) {
        if (g4_comp_value(h->board->phase[x].comp)) {
            return true;
        }
    }
    return false;
}

bool g4_hal_break_rearm(hal_t *h)
{
    /* The main loop and the control interrupt (hal_trip_clear) both call
     * this: check, clear and enable as one step, or a main loop preempted
     * after its check could clear a flag the other caller's enable had let
     * pend, uncounted. */
    const uint32_t primask = g4_irq_lock();
    bool enabled = (g4_rd(G4_TIM1 + G4_TIM_DIER) & G4_TIM_DIER_BIE) != 0u;
    if (!enabled && !g4_hal_comp_high(h)) {
        /* Masked only by the interrupt, right after it counted a break that
         * no clear has acknowledged yet: the flags cleared here belong to
         * that latched break, and so does any short break merged into them
         * (one flag cannot tell two apart). From the enable on, a break is
         * taken and counted. */
        g4_wr(G4_TIM1 + G4_TIM_SR, ~(G4_TIM_SR_BIF | G4_TIM_SR_B2IF));
        g4_wr(G4_TIM1 + G4_TIM_DIER, G4_TIM_DIER_BIE);
    }
    g4_irq_unlock(primask);
    return enabled;
}

void g4_hal_trip_board(hal_t *h, bool on)
{
    /* The latch first: a control interrupt in between no longer enables the
     * gates. MOE cleared without a software break (EGR.BG would raise BIF and
     * read as an over-current). */
    h->board_trip = on;
    if (on) {
        g4_tim1_outputs(false);
    }
}

uint32_t g4_hal_trip_cause(const hal_t *h)
{
    const uint32_t sr = g4_rd(G4_TIM1 + G4_TIM_SR);
    uint32_t t = 0u;
    if (h->break_n != h->break_acked || (sr & (G4_TIM_SR_BIF | G4_TIM_SR_B2IF)) != 0u) {
        t |= G4_TRIP_BREAK;
    }
    if (h->system_n != 0u || (sr & G4_TIM_SR_SBIF) != 0u) {
        t |= G4_TRIP_SYSTEM;
    }
    if (h->board_trip) {
        t |= G4_TRIP_BOARD;
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
     * so that the counts rise with the phase current, as hal.h expects. */
    raw->i_a = (uint16_t)((g4_rd(h->jdr[0]) ^ h->mirror) & 0xFFFu);
    raw->i_b = (uint16_t)((g4_rd(h->jdr[1]) ^ h->mirror) & 0xFFFu);
    raw->i_c = (uint16_t)((g4_rd(h->jdr[2]) ^ h->mirror) & 0xFFFu);
    raw->vdc = (uint16_t)(g4_rd(h->jdr[3]) & 0xFFFu);
}

void hal_encoder_read(hal_t *h, hal_encoder_raw_t *enc)
{
    const uint16_t cnt = (uint16_t)g4_rd(G4_TIM4 + G4_TIM_CNT);
    enc->count = g4_enc_extend(&h->enc, cnt);
    if ((g4_rd(G4_TIM4 + G4_TIM_SR) & G4_TIM_SR_CC3IF) != 0u) {
        /* Reading CCR3 clears CC3IF. */
        const uint16_t ccr = (uint16_t)g4_rd(G4_TIM4 + G4_TIM_CCR3);
        h->index_count = g4_enc_at_capture(&h->enc, cnt, ccr);
        h->index_seen = true;
    }
    enc->index_seen = h->index_seen;
    enc->index_count = h->index_count;
}

void hal_pwm_write(hal_t *h, const hal_pwm_t *pwm)
{
    const uint32_t m = h->cmp_max;
    g4_wr(G4_TIM1 + G4_TIM_CCR1, pwm->cmp[0] < m ? pwm->cmp[0] : m);
    g4_wr(G4_TIM1 + G4_TIM_CCR2, pwm->cmp[1] < m ? pwm->cmp[1] : m);
    g4_wr(G4_TIM1 + G4_TIM_CCR3, pwm->cmp[2] < m ? pwm->cmp[2] : m);
}

void hal_gate_enable(hal_t *h, bool enable)
{
    if (enable) {
        /* The trip's check and MOE's read-modify-write as one step with the
         * interrupts masked (g4_irq_lock): the break interrupt, which clears
         * MOE too, cannot run between the read and the write and have its
         * "gates off" undone by it; pending, it runs after the write, its
         * clear the last word. A break in hardware meanwhile clears MOE and
         * holds it clear while its input is active (RM0440 TIM1 break).
         * Called at an arm or a commissioning step's first period, never
         * every period: the lock costs nothing per period. */
        const uint32_t primask = g4_irq_lock();
        const bool on = !hal_trip_active(h);
        if (on) {
            g4_tim1_outputs(true);
        }
        g4_irq_unlock(primask);
        if (on) {
            return;
        }
    }
    g4_tim1_outputs(false);
}

bool hal_trip_active(const hal_t *h)
{
    /* Every period: one combined test, no branch per cause. */
    const uint32_t sr = g4_rd(G4_TIM1 + G4_TIM_SR);
    return ((h->break_n ^ h->break_acked) | h->system_n | (uint32_t)h->board_trip |
            (sr & (G4_TIM_SR_BIF | G4_TIM_SR_B2IF | G4_TIM_SR_SBIF))) != 0u;
}

void hal_trip_clear(hal_t *h)
{
    /* The breaks counted before the inputs are seen released are the ones
     * acknowledged: n is read first, so a break after it (even one that has
     * ended by the check below) leaves break_n past n, latched. */
    const uint32_t n = h->break_n;
    /* Stays latched while a comparator still sees over-current, and while
     * the interrupt is masked: then this call only re-arms it
     * (g4_hal_break_rearm, which the main loop also calls), because the
     * flags it clears could hold a short break no interrupt saw; the next
     * clear acknowledges. A flag the interrupt has not taken yet stays too.
     * The board cause (over-temperature) is the board's to clear
     * (g4_hal_trip_board). */
    if (g4_hal_comp_high(h) || !g4_hal_break_rearm(h) ||
        (g4_rd(G4_TIM1 + G4_TIM_SR) & (G4_TIM_SR_BIF | G4_TIM_SR_B2IF)) != 0u) {
        return;
    }
    h->break_acked = n;
}

uint32_t hal_cycles(const hal_t *h)
{
    (void)h;
    return g4_cycles();
}
