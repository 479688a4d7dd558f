/*
 * The firmware on the ST B-G431B-ESC1 (esc1_app.h).
 *
 * Start-up: DWT cycle counter, core lockup -> TIM1 break, reset flags and
 * option bytes read, clock (HSE 8 MHz -> PLL 170 MHz, boost mode), USART2,
 * the start-up report by polled output (reset cause, boot option bytes,
 * clock result: esc1_report.h); on a clock failure (as on any start-up
 * failure: esc1_halt) the gates are never enabled, the reason is said on
 * USART2 once a second, and the watchdog resets the chip within its start-up
 * time-out, which says it again. Then
 * the board HAL (gates off, op-amps, ADCs calibrated, comparator thresholds,
 * TIM1 with break, encoder, TIM1 started and its phase checked), fw_init with
 * the compiled-in machine, the command link, the interrupts, the settings,
 * the independent watchdog's running time-out (it runs from the reset
 * handler's first instruction with a longer one, refreshed between these
 * steps).
 *
 * Interrupts (priority: lower number first):
 *   0 TIM1_BRK_TIM15  break: the hardware has cleared MOE; latch the cause
 *   1 ADC1_2          end of the injected sequence: fw_isr_fast
 *   2 USART2          byte rings
 *   3 PendSV          the medium-rate task (fw_medium), pended by fw_isr_fast
 * Main loop (esc1_loop.c): one received command line at a time, telemetry
 * frames out, the firmware watchdog's kick and the independent watchdog
 * (refreshed only while the control interrupt keeps running; also while a
 * reply waits for transmit space: esc1_service) after every line, the break
 * interrupt re-armed after a long break, the board temperature every 100 ms.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "board_esc1.h"
#include "controller.h"
#include "esc1_app.h"
#include "esc1_report.h"
#include "fw_stack.h"
#include "g4_boot.h"
#include "g4_clock.h"
#include "g4_core.h"
#include "g4_periph.h"
#include "g4_regs.h"
#include "g4_startup.h"
#include "stm32_startup.h"

/* Everything lives in one instance; the interrupt handlers take no argument,
 * so it is reachable at file scope. */
static esc1_t esc1;

/* The main stack (stm32g431cb.ld). */
extern uint32_t __stack_bottom__[], __stack_top__[];

void ADC1_2_IRQHandler(void);
void TIM1_BRK_TIM15_IRQHandler(void);
void USART2_IRQHandler(void);
void PendSV_Handler(void);

void ADC1_2_IRQHandler(void)
{
    esc1_control_isr(&esc1);
}

void TIM1_BRK_TIM15_IRQHandler(void)
{
    g4_hal_break_irq(&esc1.hal); /* gates off first, then the cause */
}

void USART2_IRQHandler(void)
{
    esc1_uart_irq(&esc1.uart);
}

void PendSV_Handler(void)
{
    fw_medium(&esc1.fw);
}

/* After the gates are off in a fault handler: the PWM pins as outputs at
 * their inactive level as well (in case TIM1 itself is misconfigured). */
void g4_board_fault_hook(void)
{
    g4_hal_gate_pins_safe(&g4_board_esc1);
}

static void esc1_write(void *ctx, const uint8_t *bytes, size_t len)
{
    esc1_uart_write((esc1_uart_t *)ctx, bytes, len);
}

/* Start-up failed: gates off for good, the reason on the serial link by
 * polled output (the USART interrupt may not be enabled; it is masked so
 * that the ring does not interleave). The watchdog, running since the reset
 * handler's first instruction, is never refreshed here: the chip resets
 * within its start-up time-out (0.48 .. 0.56 s) and says it again at every
 * start, the report's first line "reset: watchdog"; a halted board is not
 * kept looking alive. */
static void esc1_halt(esc1_t *s, const char *what, const char *why, uint32_t f_cpu_hz)
{
    g4_tim1_gates_off_now();
    g4_nvic_disable(G4_IRQ_USART2);
    for (;;) {
        esc1_report_failure(&s->uart, what, why);
        g4_delay_cycles(f_cpu_hz);
    }
}

int main(void)
{
    /* The stack below this frame painted: its high-water mark since reset in
     * "status" and the start-up report (fw_stack.h). 16 words left for the
     * painting's own call. */
    fw_stack_paint(__stack_bottom__, stm32_sp() - 16u);
    esc1_t *s = &esc1;
    const g4_board_t *b = &g4_board_esc1;
    g4_cycle_counter_init();
    /* A core lockup (fault inside a fault handler) breaks TIM1 in hardware. */
    g4_set(G4_RCC + G4_RCC_APB2ENR, G4_RCC_APB2ENR_SYSCFGEN);
    g4_set(G4_SYSCFG + G4_SYSCFG_CFGR2, G4_SYSCFG_CFGR2_CLL);

    g4_boot_info_t boot;
    g4_boot_read(&boot);
    s->reset_csr = boot.csr;
    const int clk = g4_clock_init(b->hse_hz, b->sysclk_hz);
    const uint32_t f_cpu = clk == G4_OK ? b->sysclk_hz : G4_HSI_HZ;
    (void)esc1_uart_init(&s->uart, f_cpu, b->baud);
    esc1_report_startup(&s->uart, b, &boot, clk);
    /* The watchdog runs from reset with its start-up time-out (g4_startup.c):
     * refreshed after each step of the start-up, each far shorter. */
    g4_iwdg_refresh();
    if (clk != G4_OK) {
        esc1_halt(s, "clock", g4_strerror(clk), f_cpu);
    }
    g4_gpio_config(b->led, G4_PIN_OUTPUT, 0u);

    s->machine = esc1_default_machine;
    s->encoder_cpr = ESC1_ENCODER_CPR;
    s->temp_check = true;
    s->temp_c = NAN;
    s->hc.fs_hz = ESC1_FS_HZ;
    s->hc.encoder_cpr = s->encoder_cpr;
    s->hc.trip_current_a = esc1_hw_trip_a(b, &s->machine);
    const int hrc = g4_hal_init(&s->hal, b, &s->hc);
    g4_iwdg_refresh();
    if (hrc != G4_OK) {
        esc1_halt(s, "board init", g4_strerror(hrc), f_cpu);
    }
    esc1_config_default(&s->fc, b, &s->machine, ctrl_find(ESC1_CTRL));
    const uint32_t t_init = g4_cycles();
    const int frc = fw_init(&s->fw, &s->hal, &s->fc);
    esc1_init_time(s, t_init);
    g4_iwdg_refresh();
    if (frc != FW_OK) {
        esc1_halt(s, "fw_init", fw_strerror(frc), f_cpu);
    }
    fw_link_init(&s->link, &s->fw, esc1_write, &s->uart);
    fw_link_set_stack(&s->link, __stack_bottom__, __stack_top__);
    esc1_params_attach(s);
    esc1_throttle_init(s, f_cpu);

    g4_nvic_set_priority(G4_IRQ_TIM1_BRK_TIM15, 0u);
    g4_nvic_set_priority(G4_IRQ_ADC1_2, 1u);
    g4_nvic_set_priority(G4_IRQ_USART2, 2u);
    g4_pendsv_set_priority(3u);
    g4_nvic_enable(G4_IRQ_TIM1_BRK_TIM15);
    g4_nvic_enable(G4_IRQ_USART2);
    g4_nvic_enable(G4_IRQ_ADC1_2);
#if defined(ESC1_SETTINGS)
    /* the saved settings (or the defaults), said on the link */
    esc1_settings_start(s);
    g4_iwdg_refresh();
#endif
    esc1_report_stack(&s->uart, fw_stack_used(__stack_bottom__, __stack_top__),
                      (uint32_t)((uintptr_t)__stack_top__ - (uintptr_t)__stack_bottom__),
                      s->init_cycles / (f_cpu / 1000000u));

    uint32_t pr, rlr;
    if (g4_iwdg_config(ESC1_IWDG_MS, 32000u, &pr, &rlr) != G4_OK ||
        g4_iwdg_start(pr, rlr, f_cpu) != G4_OK) {
        esc1_halt(s, "watchdog", "LSI not ready", f_cpu);
    }

    s->ms_cycles = f_cpu / 1000u;
    s->ms_cycle = g4_cycles();
    s->last_isr = s->isr_count;
    s->uart.idle = esc1_service;
    s->uart.idle_ctx = s;
    s->t_temp = g4_cycles();
    s->temp_period = f_cpu / 10u;
    for (;;) {
        esc1_loop_once(s);
    }
}
