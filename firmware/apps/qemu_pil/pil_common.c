/* Timer0 rate and UART side of the QEMU images (pil_common.h). */
#include "pil_common.h"

#include "hal_qemu.h"
#include "qemu_mps2.h"

static void pil_timer_set(pil_timer_t *t, uint32_t period, void (*isr)(void))
{
    t->period = period;
    uint32_t hz = QEMU_MPS2_SYSCLK_HZ / period;
    if (hz == 0u) {
        hz = 1u;
    }
    (void)timer0_start(hz, isr);
}

void pil_timer_start(pil_timer_t *t, void (*isr)(void))
{
    pil_timer_set(t, 20000u, isr);
}

void pil_timer_account(pil_timer_t *t, uint32_t isr_ticks, void (*isr)(void))
{
    if (isr_ticks > t->isr_max) {
        t->isr_max = isr_ticks;
    }
    t->isr_sum += isr_ticks;
    t->isr_last = isr_ticks;
    t->isr_n++;
    const uint32_t want = isr_ticks + isr_ticks / 4u + 200u;
    if (want > t->period || want + want / 2u < t->period) {
        pil_timer_set(t, want, isr);
    }
}

void pil_uart_write(void *ctx, const uint8_t *bytes, size_t len)
{
    (void)ctx;
    for (size_t i = 0; i < len; i++) {
        uart_putc((char)bytes[i]);
    }
}

void pil_poll_uart(fw_link_t *link)
{
    for (int c = hal_qemu_uart_getc(); c >= 0; c = hal_qemu_uart_getc()) {
        board_irq_disable();
        fw_link_rx(link, (uint8_t)c);
        /* A command runs masked (the engine's state is the interrupt's), a
         * long one (a listing: thousands of instructions) past a tick: that
         * period's interrupt comes late, and without the realignment the
         * next tick cuts short its medium task (PendSV) - a deadline fault
         * while running, the Timer0 period being only the interrupt's cost
         * and a quarter (pil_timer_account). */
        timer0_realign();
        board_irq_enable();
    }
    fw_link_poll(link);
}
