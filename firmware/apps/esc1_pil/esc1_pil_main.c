/*
 * Processor in the loop on the ST B-G431B-ESC1 (pmsm-esc1-pil.elf): the
 * firmware pipeline at the board's own clock against the PC's simulated
 * motor, over USART2 (the ST-LINK virtual COM port), served by the same
 * pil_target.c as the QEMU image (hal/qemu_mps2/README-pil.md,
 * docs/bringup.md "PIL on the board").
 *
 * The power stage is never used: TIM1 is not started and the six gate pins
 * are held as GPIO outputs at their inactive level from the first
 * instruction on; the ADCs, op-amps and comparators stay at reset. The
 * firmware's gate requests go to the PC's plant only. hal/stm32g4's hal.h
 * back-end (g4_hal.c) is not linked: hal/pil is this image's.
 *
 * Start-up: DWT cycle counter (hal_cycles), clock (HSE 8 MHz -> PLL 170 MHz,
 * on a failure the HSI's 16 MHz, reported in READY as the cycle clock),
 * USART2 at ESC1_PIL_BAUD with interrupt-driven byte rings (esc1_uart.c, the
 * board application's). Then the link, forever: pil_target_run until STOP,
 * and again (the PC sends STOP before SETUP, so a board left in the middle
 * of a run starts afresh). fw_isr runs in the main loop when a SAMPLE has
 * arrived; the USART2 interrupt has nothing to move while it runs (the PC
 * waits for APPLY before the next SAMPLE), so its cycle count is the
 * pipeline's own. A SAMPLE later than ESC1_PIL_TIMEOUT_MS after the last
 * frame latches the link time-out.
 */
#include <stdint.h>

#include "board_esc1.h"
#include "esc1_uart.h"
#include "g4_clock.h"
#include "g4_core.h"
#include "g4_periph.h"
#include "g4_startup.h"
#include "pil_target.h"

#ifndef ESC1_PIL_BAUD
#define ESC1_PIL_BAUD 921600u
#endif
#ifndef ESC1_PIL_TIMEOUT_MS
#define ESC1_PIL_TIMEOUT_MS 1000u
#endif

static esc1_uart_t uart;
static pil_target_t target;

void USART2_IRQHandler(void);

void USART2_IRQHandler(void)
{
    esc1_uart_irq(&uart);
}

/* The six gate pins as GPIO outputs at their inactive level (both switches
 * of every leg off): g4_hal_gate_pins_safe's steps, which live in g4_hal.c
 * beside the hal.h back-end this image does not link. */
static void esc1_pil_gates_safe(const g4_board_t *b)
{
    for (unsigned x = 0; x < 3u; x++) {
        g4_gpio_write(b->pwm_high[x], b->gate_active_low);
        g4_gpio_write(b->pwm_low[x], b->gate_active_low);
        g4_gpio_config(b->pwm_high[x], G4_PIN_OUTPUT, 2u);
        g4_gpio_config(b->pwm_low[x], G4_PIN_OUTPUT, 2u);
    }
}

/* The fault handlers' last step (g4_startup.c): the pins are safe already,
 * and stay so. */
void g4_board_fault_hook(void)
{
    esc1_pil_gates_safe(&g4_board_esc1);
}

static int esc1_pil_read(void *ctx, uint8_t *buf, size_t cap)
{
    size_t n = 0u;
    int c;
    while (n < cap && (c = esc1_uart_getc((esc1_uart_t *)ctx)) >= 0) {
        buf[n++] = (uint8_t)c;
    }
    return (int)n;
}

static void esc1_pil_write(void *ctx, const uint8_t *buf, size_t n)
{
    esc1_uart_write((esc1_uart_t *)ctx, buf, n);
}

static uint32_t esc1_pil_now(void *ctx)
{
    (void)ctx;
    return g4_cycles();
}

static uint32_t esc1_pil_cycles(void)
{
    return g4_cycles();
}

int main(void)
{
    const g4_board_t *b = &g4_board_esc1;
    esc1_pil_gates_safe(b);
    g4_cycle_counter_init();
    const uint32_t f_cpu =
        g4_clock_init(b->hse_hz, b->sysclk_hz) == G4_OK ? b->sysclk_hz : G4_HSI_HZ;
    (void)esc1_uart_init(&uart, f_cpu, ESC1_PIL_BAUD);
    g4_nvic_set_priority(G4_IRQ_USART2, 2u);
    g4_nvic_enable(G4_IRQ_USART2);
    static pil_port_t port;
    port.ctx = &uart;
    port.read = esc1_pil_read;
    port.write = esc1_pil_write;
    port.now = esc1_pil_now;
    port.now_hz = f_cpu;
    port.cycles = esc1_pil_cycles;
    port.cycle_clock_hz = f_cpu;
    port.timeout_ms = ESC1_PIL_TIMEOUT_MS;
    for (;;) {
        (void)pil_target_run(&target, &port);
    }
}
