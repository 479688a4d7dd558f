/* Timers: TIM1 PWM, TIM4 encoder, TIM2 capture (g4_tim.h). */
#include "g4_tim.h"

#include "g4_core.h"
#include "g4_regs.h"

void g4_tim1_pwm_init(const g4_tim1_cfg_t *c)
{
    const uintptr_t t = G4_TIM1;
    g4_set(G4_RCC + G4_RCC_APB2ENR, G4_RCC_APB2ENR_TIM1EN);
    /* Counter stopped, outputs off before anything else. */
    g4_wr(t + G4_TIM_CR1, 0u);
    g4_clr(t + G4_TIM_BDTR, G4_TIM_BDTR_MOE);
    g4_wr(t + G4_TIM_CR1, G4_TIM_CR1_CMS_CENTER1 | G4_TIM_CR1_ARPE);
    g4_wr(t + G4_TIM_PSC, c->timing.psc);
    g4_wr(t + G4_TIM_ARR, c->timing.arr);
    /* RCR = 1 before the counter starts: the update event (compare preload
     * transfer, TRGO2) on every second counter event, the overflow (peak). */
    g4_wr(t + G4_TIM_RCR, 1u);
    g4_wr(t + G4_TIM_CCMR1, G4_TIM_CCMR_OC_PWM1_PE(0u) | G4_TIM_CCMR_OC_PWM1_PE(1u));
    g4_wr(t + G4_TIM_CCMR2, G4_TIM_CCMR_OC_PWM1_PE(0u));
    g4_wr(t + G4_TIM_CCR1, 0u);
    g4_wr(t + G4_TIM_CCR2, 0u);
    g4_wr(t + G4_TIM_CCR3, 0u);
    uint32_t ccer = 0u;
    for (uint32_t ch = 1u; ch <= 3u; ch++) {
        ccer |= G4_TIM_CCER_CCE(ch) | G4_TIM_CCER_CCNE(ch);
        if (c->active_low) {
            ccer |= G4_TIM_CCER_CCP(ch) | G4_TIM_CCER_CCNP(ch);
        }
    }
    g4_wr(t + G4_TIM_CCER, ccer);
    /* Idle levels 0 (OISx = OISxN = 0 = inactive), TRGO2 on update. */
    g4_wr(t + G4_TIM_CR2, G4_TIM_CR2_MMS2_UPDATE);
    /* Break: comparators only (no BKIN pin), polarity as is (BKCMPxP = 0). */
    uint32_t af1 = 0u;
    for (uint32_t n = 1u; n <= 4u; n++) {
        if ((c->break_comps & (1u << n)) != 0u) {
            af1 |= G4_TIM_AF1_BKCMPE(n);
        }
    }
    g4_wr(t + G4_TIM_AF1, af1);
    /* One write with MOE = 0: dead time, off-state selection, break enabled,
     * active high, filtered, no automatic re-enable, no lock. */
    g4_wr(t + G4_TIM_BDTR, (uint32_t)c->dtg | G4_TIM_BDTR_OSSI | G4_TIM_BDTR_OSSR |
                               (af1 != 0u ? G4_TIM_BDTR_BKE : 0u) | G4_TIM_BDTR_BKP |
                               G4_FIELD(c->bkf & 0xFu, G4_TIM_BDTR_BKF_POS));
    /* Load the preload registers (PSC, ARR, RCR, CCRx) into the shadows. */
    g4_wr(t + G4_TIM_EGR, G4_TIM_EGR_UG);
    g4_wr(t + G4_TIM_SR, 0u);
    g4_wr(t + G4_TIM_DIER, G4_TIM_DIER_BIE);
    /* Core halted by a debugger: counter stopped, outputs disabled as by a
     * break (RM0440 chapter 29, "Debug mode"). */
    g4_set(G4_DBGMCU + G4_DBGMCU_APB2FZ, G4_DBGMCU_APB2FZ_TIM1_STOP);
}

int g4_tim1_start(const g4_pwm_timing_t *t, uint32_t f_cpu_hz)
{
    const uintptr_t b = G4_TIM1;
    /* Two PWM periods in core cycles as time-out. */
    const uint32_t timeout = (uint32_t)(2ull * f_cpu_hz / t->fs_hz);
    /* TIMx_SR is rc_w0: writing ~flag clears that flag alone (a read-modify-
     * write could clear a break flag raised in between). */
    g4_wr(b + G4_TIM_SR, ~G4_TIM_SR_UIF);
    g4_set(b + G4_TIM_CR1, G4_TIM_CR1_CEN);
    if (!g4_wait_bits(b + G4_TIM_SR, G4_TIM_SR_UIF, G4_TIM_SR_UIF, timeout) ||
        (g4_rd(b + G4_TIM_CR1) & G4_TIM_CR1_DIR) == 0u) {
        g4_clr(b + G4_TIM_CR1, G4_TIM_CR1_CEN);
        return G4_E_TIM;
    }
    g4_wr(b + G4_TIM_SR, ~G4_TIM_SR_UIF);
    return G4_OK;
}

void g4_tim1_outputs(bool on)
{
    if (on) {
        g4_set(G4_TIM1 + G4_TIM_BDTR, G4_TIM_BDTR_MOE);
    } else {
        g4_clr(G4_TIM1 + G4_TIM_BDTR, G4_TIM_BDTR_MOE);
    }
}

void g4_tim1_gates_off_now(void)
{
    g4_wr(G4_TIM1 + G4_TIM_EGR, G4_TIM_EGR_BG);
    g4_clr(G4_TIM1 + G4_TIM_BDTR, G4_TIM_BDTR_MOE);
}

void g4_tim4_encoder_init(uint32_t icf, bool index)
{
    const uintptr_t t = G4_TIM4;
    g4_set(G4_RCC + G4_RCC_APB1ENR1, G4_RCC_APB1ENR1_TIM4EN);
    g4_wr(t + G4_TIM_CR1, 0u);
    g4_wr(t + G4_TIM_CCMR1, G4_TIM_CCMR_IC_DIRECT(0u, icf) | G4_TIM_CCMR_IC_DIRECT(1u, icf));
    g4_wr(t + G4_TIM_CCMR2, index ? G4_TIM_CCMR_IC_DIRECT(0u, icf) : 0u);
    /* CC1P = CC2P = 0: non-inverted; CC3E: capture on the index's rising edge. */
    g4_wr(t + G4_TIM_CCER, index ? G4_TIM_CCER_CCE(3u) : 0u);
    g4_wr(t + G4_TIM_SMCR, G4_TIM_SMCR_SMS_ENCODER3);
    g4_wr(t + G4_TIM_PSC, 0u);
    g4_wr(t + G4_TIM_ARR, 0xFFFFu);
    g4_wr(t + G4_TIM_EGR, G4_TIM_EGR_UG);
    g4_wr(t + G4_TIM_CNT, 0u);
    g4_wr(t + G4_TIM_SR, 0u);
    g4_wr(t + G4_TIM_CR1, G4_TIM_CR1_CEN);
}

void g4_tim2_capture_init(uint32_t psc, uint32_t icf)
{
    const uintptr_t t = G4_TIM2;
    g4_set(G4_RCC + G4_RCC_APB1ENR1, G4_RCC_APB1ENR1_TIM2EN);
    g4_wr(t + G4_TIM_CR1, 0u);
    /* CC1S = 01 (TI1), CC2S = 10 (TI1 as well), both filtered. */
    g4_wr(t + G4_TIM_CCMR1, G4_TIM_CCMR_IC_DIRECT(0u, icf) | G4_FIELD(2u, 8) | G4_FIELD(icf, 12));
    /* CC1 on the rising edge, CC2 on the falling edge (CC2P). */
    g4_wr(t + G4_TIM_CCER, G4_TIM_CCER_CCE(1u) | G4_TIM_CCER_CCE(2u) | G4_TIM_CCER_CCP(2u));
    g4_wr(t + G4_TIM_SMCR, G4_TIM_SMCR_TS_TI1FP1 | G4_TIM_SMCR_SMS_RESET);
    g4_wr(t + G4_TIM_PSC, psc);
    g4_wr(t + G4_TIM_ARR, 0xFFFFFFFFu);
    g4_wr(t + G4_TIM_EGR, G4_TIM_EGR_UG);
    g4_wr(t + G4_TIM_SR, 0u);
    g4_wr(t + G4_TIM_CR1, G4_TIM_CR1_CEN);
}

bool g4_tim2_capture_read(uint32_t *width, uint32_t *period)
{
    /* PWM input mode (RM0440 TIM2/3/4/5): the rising edge that ends a period
     * captures it in CCR1 and restarts the counter; CCR2 keeps the width of
     * the period's own pulse until the next pulse's falling edge overwrites
     * it. Reading CCR1 clears CC1IF, reading CCR2 clears CC2IF (RM0440
     * TIMx_SR), so no flag of a capture that lands meanwhile is written
     * away. */
    if ((g4_rd(G4_TIM2 + G4_TIM_SR) & G4_TIM_SR_CC1IF) == 0u) {
        return false;
    }
    const uint32_t c0 = g4_rd(G4_TIM2 + G4_TIM_CNT);
    const uint32_t p = g4_rd(G4_TIM2 + G4_TIM_CCR1);
    const uint32_t w = g4_rd(G4_TIM2 + G4_TIM_CCR2);
    const uint32_t c1 = g4_rd(G4_TIM2 + G4_TIM_CNT); /* microseconds since the period ended */
    /* A rising edge during the reads restarted the counter (c1 < c0): CCR1
     * may hold the next period. A width not above the counter may be the
     * next pulse's, captured since the period ended (the read came later
     * than the pulse's width). Either way the pair is not one period's: the
     * period is not reported (the next one is). */
    if (c1 < c0 || w <= c1) {
        return false;
    }
    *width = w;
    *period = p;
    return true;
}
