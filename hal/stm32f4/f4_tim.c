/* Timers: TIM1 PWM, encoder counter, servo capture (f4_tim.h). */
#include "f4_tim.h"

#include "f4_core.h"
#include "f4_regs.h"

void f4_tim1_pwm_init(const f4_tim1_cfg_t *c)
{
    const uintptr_t t = F4_TIM1;
    f4_rcc_enable(F4_RCC_APB2ENR, F4_RCC_APB2ENR_TIM1EN);
    /* Counter stopped, outputs off before anything else. */
    f4_wr(t + F4_TIM_CR1, 0u);
    f4_clr(t + F4_TIM_BDTR, F4_TIM_BDTR_MOE);
    f4_wr(t + F4_TIM_CR1, F4_TIM_CR1_CMS_CENTER1 | F4_TIM_CR1_ARPE);
    f4_wr(t + F4_TIM_PSC, c->timing.psc);
    f4_wr(t + F4_TIM_ARR, c->timing.arr);
    /* RCR = 1 before the counter starts: the update event (compare preload
     * transfer, TRGO) on every second counter event, the overflow (peak). */
    f4_wr(t + F4_TIM_RCR, 1u);
    f4_wr(t + F4_TIM_CCMR1, F4_TIM_CCMR_OC_PWM1_PE(0u) | F4_TIM_CCMR_OC_PWM1_PE(1u));
    f4_wr(t + F4_TIM_CCMR2, F4_TIM_CCMR_OC_PWM1_PE(0u));
    for (uint32_t ch = 1u; ch <= 3u; ch++) {
        f4_wr(t + F4_TIM_CCR(ch), 0u);
    }
    uint32_t ccer = 0u;
    for (uint32_t ch = 1u; ch <= 3u; ch++) {
        ccer |= F4_TIM_CCER_CCE(ch) | F4_TIM_CCER_CCNE(ch);
    }
    f4_wr(t + F4_TIM_CCER, ccer);
    /* Idle levels 0 (OISx = OISxN = 0 = inactive), TRGO on update. */
    f4_wr(t + F4_TIM_CR2, F4_TIM_CR2_MMS_UPDATE);
    /* One write with MOE = 0: dead time, off-state selection, the break
     * input when wired (BKP = 1: active high), no automatic re-enable, no
     * lock. */
    uint32_t bdtr = (uint32_t)c->dtg | F4_TIM_BDTR_OSSI | F4_TIM_BDTR_OSSR;
    if (c->break_input) {
        bdtr |= F4_TIM_BDTR_BKE | (c->break_active_low ? 0u : F4_TIM_BDTR_BKP);
    }
    f4_wr(t + F4_TIM_BDTR, bdtr);
    /* Load the preload registers (PSC, ARR, RCR, CCRx) into the shadows. */
    f4_wr(t + F4_TIM_EGR, F4_TIM_EGR_UG);
    f4_wr(t + F4_TIM_SR, 0u);
    f4_wr(t + F4_TIM_DIER, c->break_input ? F4_TIM_DIER_BIE : 0u);
    f4_set(F4_DBGMCU + F4_DBGMCU_APB2_FZ, F4_DBGMCU_APB2_FZ_TIM1_STOP);
}

int f4_tim1_start(const stm32_pwm_timing_t *t, uint32_t f_cpu_hz)
{
    const uintptr_t b = F4_TIM1;
    /* Two PWM periods in core cycles as time-out. */
    const uint32_t timeout = (uint32_t)(2ull * f_cpu_hz / t->fs_hz);
    /* TIMx_SR is rc_w0: writing ~flag clears that flag alone. */
    f4_wr(b + F4_TIM_SR, ~F4_TIM_SR_UIF);
    f4_set(b + F4_TIM_CR1, F4_TIM_CR1_CEN);
    if (!f4_wait_bits(b + F4_TIM_SR, F4_TIM_SR_UIF, F4_TIM_SR_UIF, timeout) ||
        (f4_rd(b + F4_TIM_CR1) & F4_TIM_CR1_DIR) == 0u) {
        f4_clr(b + F4_TIM_CR1, F4_TIM_CR1_CEN);
        return F4_E_TIM;
    }
    f4_wr(b + F4_TIM_SR, ~F4_TIM_SR_UIF);
    return F4_OK;
}

void f4_tim1_outputs(bool on)
{
    if (on) {
        f4_set(F4_TIM1 + F4_TIM_BDTR, F4_TIM_BDTR_MOE);
    } else {
        f4_clr(F4_TIM1 + F4_TIM_BDTR, F4_TIM_BDTR_MOE);
    }
}

void f4_tim1_gates_off_now(void)
{
    f4_wr(F4_TIM1 + F4_TIM_EGR, F4_TIM_EGR_BG);
    f4_clr(F4_TIM1 + F4_TIM_BDTR, F4_TIM_BDTR_MOE);
}

uintptr_t f4_gptim_base(uint32_t n)
{
    switch (n) {
    case 2u:
        return F4_TIM2;
    case 3u:
        return F4_TIM3;
    case 4u:
        return F4_TIM4;
    default:
        return F4_TIM5;
    }
}

void f4_gptim_enable(uint32_t n)
{
    f4_rcc_enable(F4_RCC_APB1ENR, F4_RCC_APB1ENR_TIM2EN << (n - 2u));
}

void f4_ticks_init(uint32_t n, uint32_t f_tim_hz)
{
    const uintptr_t t = f4_gptim_base(n);
    f4_gptim_enable(n);
    f4_wr(t + F4_TIM_CR1, 0u);
    f4_wr(t + F4_TIM_PSC, f_tim_hz / 1000000u - 1u);
    f4_wr(t + F4_TIM_ARR, 0xFFFFFFFFu);
    f4_wr(t + F4_TIM_EGR, F4_TIM_EGR_UG); /* the prescaler loaded */
    f4_wr(t + F4_TIM_CR1, F4_TIM_CR1_CEN);
}

uint32_t f4_ticks(uint32_t n)
{
    return f4_rd(f4_gptim_base(n) + F4_TIM_CNT);
}

/* CCMRx of channel ch, and its place (0, 1) in that register. */
static uintptr_t f4_ccmr(uintptr_t t, uint32_t ch)
{
    return t + (ch <= 2u ? F4_TIM_CCMR1 : F4_TIM_CCMR2);
}

void f4_encoder_init(uint32_t n, uint32_t icf, uint32_t index_ch)
{
    const uintptr_t t = f4_gptim_base(n);
    f4_gptim_enable(n);
    f4_wr(t + F4_TIM_CR1, 0u);
    f4_wr(t + F4_TIM_CCMR1, F4_TIM_CCMR_IC(0u, 1u, icf) | F4_TIM_CCMR_IC(1u, 1u, icf));
    f4_wr(t + F4_TIM_CCMR2, index_ch >= 3u ? F4_TIM_CCMR_IC(index_ch - 3u, 1u, icf) : 0u);
    /* CC1P = CC2P = 0: non-inverted; the index channel captures its rising
     * edge. */
    f4_wr(t + F4_TIM_CCER, index_ch >= 3u ? F4_TIM_CCER_CCE(index_ch) : 0u);
    f4_wr(t + F4_TIM_SMCR, F4_TIM_SMCR_SMS_ENCODER3);
    f4_wr(t + F4_TIM_PSC, 0u);
    f4_wr(t + F4_TIM_ARR, 0xFFFFu);
    f4_wr(t + F4_TIM_EGR, F4_TIM_EGR_UG);
    f4_wr(t + F4_TIM_CNT, 0u);
    f4_wr(t + F4_TIM_SR, 0u);
    f4_wr(t + F4_TIM_CR1, F4_TIM_CR1_CEN);
}

/* The other channel of ch's pair: 1 <-> 2, 3 <-> 4. */
static uint32_t f4_partner(uint32_t ch)
{
    return ((ch - 1u) ^ 1u) + 1u;
}

void f4_capture_init(uint32_t n, uint32_t ch, uint32_t psc, uint32_t icf)
{
    const uintptr_t t = f4_gptim_base(n);
    const uint32_t p = f4_partner(ch);
    f4_gptim_enable(n);
    f4_wr(t + F4_TIM_CR1, 0u);
    /* ch on its own input (CCxS 01), its partner on the same input (10):
     * both in the CCMR of the pair. */
    f4_wr(f4_ccmr(t, ch),
          F4_TIM_CCMR_IC((ch - 1u) % 2u, 1u, icf) | F4_TIM_CCMR_IC((p - 1u) % 2u, 2u, icf));
    /* ch on the rising edge, the partner on the falling one (CCyP). */
    f4_wr(t + F4_TIM_CCER, F4_TIM_CCER_CCE(ch) | F4_TIM_CCER_CCE(p) | F4_TIM_CCER_CCP(p));
    f4_wr(t + F4_TIM_SMCR, 0u);
    f4_wr(t + F4_TIM_PSC, psc);
    f4_wr(t + F4_TIM_ARR, 0xFFFFFFFFu); /* the 16-bit timers keep 0xFFFF */
    f4_wr(t + F4_TIM_EGR, F4_TIM_EGR_UG);
    f4_wr(t + F4_TIM_SR, 0u);
    f4_wr(t + F4_TIM_CR1, F4_TIM_CR1_CEN);
}

void f4_capture_start(f4_capture_t *c, uint32_t n, uint32_t ch)
{
    c->n = n;
    c->ch = ch;
    c->mask = (n == 2u || n == 5u) ? 0xFFFFFFFFu : 0xFFFFu;
    c->rise = 0u;
    c->primed = false;
    c->missed = 0u;
}

bool f4_capture_read(f4_capture_t *c, uint32_t *width, uint32_t *period)
{
    const uintptr_t t = f4_gptim_base(c->n);
    const uint32_t p = f4_partner(c->ch);
    const uint32_t sr0 = f4_rd(t + F4_TIM_SR);
    if ((sr0 & F4_TIM_SR_CCIF(c->ch)) == 0u) {
        return false;
    }
    /* The falling edge first, then the rising one (reading CCRx clears
     * CCxIF); the flags again after: an edge captured meanwhile over an
     * unread one sets its overcapture flag. */
    const uint32_t fall = f4_rd(t + F4_TIM_CCR(p));
    const uint32_t rise = f4_rd(t + F4_TIM_CCR(c->ch));
    const uint32_t sr1 = f4_rd(t + F4_TIM_SR);
    const uint32_t of = F4_TIM_SR_CCOF(c->ch) | F4_TIM_SR_CCOF(p);
    const bool fell = (sr0 & F4_TIM_SR_CCIF(p)) != 0u;
    const bool overrun = ((sr0 | sr1) & of) != 0u;
    f4_wr(t + F4_TIM_SR, ~of); /* rc_w0: those flags alone */
    const bool ok = c->primed && fell && !overrun;
    const uint32_t prev = c->rise;
    c->rise = rise;
    c->primed = true;
    if (!ok) {
        if (overrun) {
            c->missed++;
        }
        return false;
    }
    *width = (fall - prev) & c->mask;
    *period = (rise - prev) & c->mask;
    return true;
}
