/*
 * Processor in the loop on an STM32F405 board (VESC 6, ODrive v3.6:
 * pmsm-<board>-pil.elf): the firmware pipeline at the board's own clock
 * against the PC's simulated motor, over the board's console USART, served
 * by the same pil_target.c as the QEMU and B-G431B-ESC1 images
 * (hal/qemu_mps2/README-pil.md; ./tools/sim --target board:DEV).
 *
 * The power stage is never used: EN_GATE is held low (the DRV8301 holds
 * every gate low and is never configured), the six gate inputs and the
 * board's held pins at their inactive levels from the first instruction
 * on (f4_hal_gate_pins_safe); TIM1 is not started; the ADCs stay at reset.
 * The firmware's gate requests go to the PC's plant only. The hal.h
 * back-end of hal/stm32f4 (f4_hal.c) is not linked: hal/pil is this
 * image's.
 *
 * Start-up: the cycle counter (hal_cycles), the clock (8 MHz crystal -> PLL
 * 168 MHz; on a failure the HSI's 16 MHz, reported in READY as the cycle
 * clock), the board's tick timer (the byte rings' waits), the console USART
 * at F405_PIL_BAUD with the shared byte rings (f405_uart.c; polled output
 * when its transmit interrupt is silent, as in QEMU). Then the link,
 * forever: pil_target_run until STOP, and again. fw_isr runs in the main
 * loop when a SAMPLE has arrived. The link's time-out counts core cycles
 * (DWT), as the B-G431B-ESC1's PIL image does.
 *
 * In QEMU's netduinoplus2 (tests/board: the PIL link over a pty) DWT's
 * cycle counter reads 0: the cycles reported are 0 there and only the PC's
 * time-out applies (QEMU's TIM2 counts at its own 1 GHz base, no clock to
 * time a link by). The independent watchdog is not started: the PC paces
 * this image.
 */
#include <stdint.h>

#include "f405_uart.h"
#include "f4_board.h"
#include "f4_clock.h"
#include "f4_core.h"
#include "f4_periph.h"
#include "f4_startup.h"
#include "f4_tim.h"
#include "pil_target.h"
#include F405_BOARD_HEADER

#ifndef F405_PIL_BAUD
#define F405_PIL_BAUD 921600u
#endif
#ifndef F405_PIL_TIMEOUT_MS
#define F405_PIL_TIMEOUT_MS 1000u
#endif

static board_uart_t uart;
static f4_usart_t usart;
static pil_target_t target;

void USART1_IRQHandler(void);
void USART2_IRQHandler(void);
void USART3_IRQHandler(void);
void UART4_IRQHandler(void);
void USART6_IRQHandler(void);

/* The console's USART, whichever the board uses (only its vector is
 * enabled). */
void USART1_IRQHandler(void)
{
    f405_uart_irq(&uart, &usart);
}
void USART2_IRQHandler(void)
{
    f405_uart_irq(&uart, &usart);
}
void USART3_IRQHandler(void)
{
    f405_uart_irq(&uart, &usart);
}
void UART4_IRQHandler(void)
{
    f405_uart_irq(&uart, &usart);
}
void USART6_IRQHandler(void)
{
    f405_uart_irq(&uart, &usart);
}

/* The fault handlers' last step (f4_startup.c): the pins are safe already,
 * and stay so. */
void f4_board_fault_hook(void)
{
    f4_hal_gate_pins_safe(&F405_BOARD);
}

static int f405_pil_read(void *ctx, uint8_t *buf, size_t cap)
{
    size_t n = 0u;
    int c;
    while (n < cap && (c = board_uart_getc((board_uart_t *)ctx)) >= 0) {
        buf[n++] = (uint8_t)c;
    }
    return (int)n;
}

static void f405_pil_write(void *ctx, const uint8_t *buf, size_t n)
{
    board_uart_write((board_uart_t *)ctx, buf, n);
}

static uint32_t f405_pil_now(void *ctx)
{
    (void)ctx;
    return f4_cycles();
}

static uint32_t f405_pil_cycles(void)
{
    return f4_cycles();
}

int main(void)
{
    const f4_board_t *b = &F405_BOARD;
    f4_hal_gate_pins_safe(b);
    f4_cycle_counter_init();
    f4_clocks_t clk;
    if (f4_clock_init(b->hse_hz, b->sysclk_hz, &clk) != F4_OK) {
        f4_clocks_hsi(&clk);
    }
    f4_ticks_init(b->tick_tim, clk.tim_apb1_hz);
    if (f405_uart_init(&uart, &usart, b, &clk, F405_PIL_BAUD) != F4_OK) {
        f4_fault_halt();
    }
    f4_nvic_set_priority(usart.irq, 2u);
    f4_nvic_enable(usart.irq);
    /* the probe: one frame delimiter (0x00), which the PC's frame decoder
     * skips (an empty chunk between delimiters, pil_frame.h) */
    static const uint8_t delimiter = 0u;
    (void)board_uart_check_tx(&uart, &delimiter, 1u);
    static pil_port_t port;
    port.ctx = &uart;
    port.read = f405_pil_read;
    port.write = f405_pil_write;
    port.now = f405_pil_now;
    port.now_hz = clk.sysclk_hz;
    port.cycles = f405_pil_cycles;
    port.cycle_clock_hz = clk.sysclk_hz;
    port.timeout_ms = F405_PIL_TIMEOUT_MS;
    for (;;) {
        (void)pil_target_run(&target, &port);
    }
}
