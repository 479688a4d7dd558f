/*
 * The firmware on an STM32F405 board with a DRV8301 (f405_app.h).
 *
 * Start-up, in this order:
 *   1. the gates safe before anything else: EN_GATE low (the DRV8301 holds
 *      every gate low), the six gate inputs and the board's held pins at
 *      their levels (f4_hal_gate_pins_safe); the cycle counter; the
 *      independent watchdog with its start-up window (F405_IWDG_BOOT_MS;
 *      its LSI not running: the gates held off for good);
 *   2. the fault record the previous run left, the reset cause; the clock (8 MHz crystal -> PLL 168
 * MHz; on a failure HSI 16 MHz, the gates then held off for good);
 *   3. the console (the board's USART at the clock that runs) and the
 *      start-up report by polled output;
 *   4. the board HAL (f4_hal_init: the DRV8301 reset, configured and read
 *      back; then, on the PLL's clock only, ADCs, TIM1, injected
 *      conversions, encoder, nFAULT's interrupt, TIM1 started and its phase
 *      checked), its result said; any failure holds the gates off
 *      (fw_link_set_hold with the reason) while the console stays up;
 *   5. the firmware on the compiled-in machine, the command link, the
 *      throttle capture, the interrupts, the settings record;
 *   6. the watchdog's run window (F405_IWDG_RUN_MS); the stack's
 *      high-water mark so far (the start-up's deepest path, the settings
 *      record's fw_init, is behind it).
 *
 * Interrupts (priority: lower number first):
 *   0 EXTI (nFAULT), TIM1_BRK   gates off first, then the cause latched
 *   1 ADC                        end of the injected sequence: fw_isr_fast
 *   2 USART / UART (console)     byte rings
 *   3 PendSV                     the medium-rate task (fw_medium)
 * Main loop: received bytes -> command interpreter, telemetry out, the
 * shared service (firmware watchdog kick; the independent watchdog
 * refreshed while the control interrupt runs, or, when the gates are held
 * off for good and no control interrupt runs, by the main loop), every
 * 100 ms the DRV8301's status and configuration (a new fault named), the
 * power stage's temperature, the LEDs.
 */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "controller.h"
#include "drv8301.h"
#include "f405_app.h"
#include "f4_boot.h"
#include "f4_core.h"
#include "f4_regs.h"
#include "f4_startup.h"
#include "f4_tim.h"
#include "fw_stack.h"
#include "stm32_startup.h"
#include F405_BOARD_HEADER

_Static_assert(offsetof(f405_t, app) == 0, "the link's context is the f405_t");

const char f405_tag[] = F405_BOARD_TAG ": ";

/* The compiled-in machine, generated from its machine file at build time
 * (CMake cache PMSM_F405_MACHINE_INI). */
extern const ctrl_machine_t f405_default_machine;

/* Everything lives in one instance; the interrupt handlers take no argument. */
static f405_t f405;

/* The main stack (stm32f405xg.ld), painted at start-up (fw_stack.h). */
extern uint32_t __stack_bottom__[], __stack_top__[];

void ADC_IRQHandler(void);
void PendSV_Handler(void);
void TIM1_BRK_TIM9_IRQHandler(void);
void EXTI0_IRQHandler(void);
void EXTI1_IRQHandler(void);
void EXTI2_IRQHandler(void);
void EXTI3_IRQHandler(void);
void EXTI4_IRQHandler(void);
void EXTI9_5_IRQHandler(void);
void EXTI15_10_IRQHandler(void);
void USART1_IRQHandler(void);
void USART2_IRQHandler(void);
void USART3_IRQHandler(void);
void UART4_IRQHandler(void);
void USART6_IRQHandler(void);

void ADC_IRQHandler(void)
{
    f405_control_isr(&f405);
}

void PendSV_Handler(void)
{
    fw_medium(&f405.app.fw);
}

void TIM1_BRK_TIM9_IRQHandler(void)
{
    f4_hal_break_irq(&f405.hal); /* gates off first, then the cause */
}

/* nFAULT's line: gates off first, then counted. Every EXTI vector comes
 * here; only nFAULT's line is enabled (f4_exti_falling). */
static void f405_exti(void)
{
    if (f4_exti_pending(f405.hal.nfault_line)) {
        f4_hal_nfault_irq(&f405.hal);
    } else {
        f4_tim1_outputs(false); /* an unexpected line: gates off all the same */
        f4_wr(F4_EXTI + F4_EXTI_PR, 0xFFFFu);
    }
}
void EXTI0_IRQHandler(void)
{
    f405_exti();
}
void EXTI1_IRQHandler(void)
{
    f405_exti();
}
void EXTI2_IRQHandler(void)
{
    f405_exti();
}
void EXTI3_IRQHandler(void)
{
    f405_exti();
}
void EXTI4_IRQHandler(void)
{
    f405_exti();
}
void EXTI9_5_IRQHandler(void)
{
    f405_exti();
}
void EXTI15_10_IRQHandler(void)
{
    f405_exti();
}

/* The console's USART, whichever the board uses (only its vector is
 * enabled). */
void USART1_IRQHandler(void)
{
    f405_uart_irq(&f405.app.uart, &f405.usart);
}
void USART2_IRQHandler(void)
{
    f405_uart_irq(&f405.app.uart, &f405.usart);
}
void USART3_IRQHandler(void)
{
    f405_uart_irq(&f405.app.uart, &f405.usart);
}
void UART4_IRQHandler(void)
{
    f405_uart_irq(&f405.app.uart, &f405.usart);
}
void USART6_IRQHandler(void)
{
    f405_uart_irq(&f405.app.uart, &f405.usart);
}

/* After the gates are off in a fault handler: EN_GATE low, the gate pins as
 * outputs at their inactive level (in case TIM1 itself is misconfigured). */
void f4_board_fault_hook(void)
{
    f4_hal_gate_pins_safe(&F405_BOARD);
}

/* ---- the board's part of the shared application ---- */

static void f405_control_irq(bool on)
{
    if (on) {
        f4_nvic_enable(F4_IRQ_ADC);
    } else {
        f4_nvic_disable(F4_IRQ_ADC);
    }
}

static double f405_dead_time_s(const board_app_t *a)
{
    const f405_t *s = (const f405_t *)a;
    uint8_t dtg = 0;
    if (stm32_dtg_encode(s->clk.tim_apb2_hz, s->board->dead_time_ns, &dtg) != STM32_OK) {
        return 0.0; /* refused by f4_hal_init as well: held off */
    }
    return (double)stm32_dtg_ticks(dtg) / (double)s->clk.tim_apb2_hz;
}

static bool f405_throttle_read(board_app_t *a, uint32_t *width_us, uint32_t *period_us)
{
    return f4_capture_read(&((f405_t *)a)->throttle, width_us, period_us);
}

static uint32_t f405_ticks(void)
{
    return f4_ticks(F405_BOARD.tick_tim);
}

/* Around the firmware's re-initialisation (0.76 M instructions, 4.5 ..
 * 6.8 ms at 168 MHz: docs/f405.md; a margin whatever the machine data) the
 * erase's window, then the run window. */
static void f405_watchdog_long(const board_app_t *a, bool on)
{
    f405_watchdog_set((const f405_t *)a, on ? F405_IWDG_ERASE_MS : F405_IWDG_RUN_MS);
}

static bool f405_gates_on(void)
{
    return (f4_rd(F4_TIM1 + F4_TIM_BDTR) & F4_TIM_BDTR_MOE) != 0u;
}

/* The control interrupt stopped with the gates on: off at once (break
 * event, MOE cleared, EN_GATE low), held off for good with the reason. */
static void f405_isr_stalled(board_app_t *a)
{
    f405_t *s = (f405_t *)a;
    f4_tim1_gates_off_now();
    s->hal.hold = true;
    f4_hal_gate_pins_safe(s->board);
    if (a->link.hold == NULL) {
        (void)snprintf(s->hold_why, sizeof s->hold_why,
                       "gates held off: control interrupt stopped (no period for %u ms)",
                       (unsigned)(BOARD_ISR_WATCH_US / 1000u));
        f405_report_line(s, s->hold_why, "", "");
        fw_link_set_hold(&a->link, s->hold_why);
    }
}

static const board_app_port_t f405_port = {
    .tag = f405_tag,
    .machine = &f405_default_machine,
    .ctrl = F405_CTRL,
    .encoder_cpr = F405_ENCODER_CPR,
    .control_irq = f405_control_irq,
    .dead_time_s = f405_dead_time_s,
    .set_trip = NULL, /* the DRV8301's VDS level is the board's, not the machine's */
    .throttle_read = f405_throttle_read,
    .watchdog_refresh = f4_iwdg_refresh,
    .watchdog_long = f405_watchdog_long,
    .gates_on = f405_gates_on,
    .isr_stalled = f405_isr_stalled,
    .ticks = f405_ticks,
    .ticks_hz = 1000000u,
};

/* The watchdog for a time-out: F4_OK, or F4_E_LSI when its clock does not
 * run (then there is no independent watchdog: the gates are held off). */
static int f405_watchdog(const f405_t *s, uint32_t ms)
{
    uint32_t pr, rlr;
    if (stm32_iwdg_config(ms, F4_LSI_TYP_HZ, &pr, &rlr) != STM32_OK) {
        return F4_E_CONFIG;
    }
    return f4_iwdg_start(pr, rlr, s->clk.sysclk_hz);
}

/* Why the gates are held off, in one sentence (the detail of a refused
 * "arm"): the power stage's reason first, then a missing watchdog, then the
 * clock's fall-back; and its start-up line. */
static void f405_hold(f405_t *s)
{
    const int rc = s->hal_rc;
    char stage[112];
    char why[96];
    stage[0] = '\0';
    if (rc == F4_E_DRIVER) {
        (void)drv8301_explain(&s->hal.drv, why, sizeof why);
        (void)snprintf(stage, sizeof stage, "DRV8301 %s", why);
    } else if (rc != F4_OK && rc != F4_E_CLOCK) {
        (void)snprintf(stage, sizeof stage, "power stage: %s", f4_strerror(rc));
    }
    /* short: "err 8 state <this>" fits one response line (CMD_OUT_MAX); the
     * start-up lines before it say each in full */
    (void)snprintf(s->hold_why, sizeof s->hold_why, "gates held off: %s%s%s%s%s", stage,
                   stage[0] != '\0' && s->wdg_rc != F4_OK ? "; " : "",
                   s->wdg_rc != F4_OK ? "no watchdog" : "",
                   (stage[0] != '\0' || s->wdg_rc != F4_OK) && s->clock_rc != F4_OK ? "; " : "",
                   s->clock_rc != F4_OK ? "clock on HSI" : "");
    f405_report_line(s, s->hold_why, "", "");
    fw_link_set_hold(&s->app.link, s->hold_why);
}

/* Every 100 ms: the DRV8301's status (a new fault named once) and its
 * configuration, the temperature, the LEDs. */
static void f405_slow(f405_t *s)
{
    board_app_t *a = &s->app;
    const fw_state_id_t st = fw_state(&a->fw);
    const bool stopped = !fw_gates_on_or_pending(&a->fw);
    if (f4_hal_drv_service(&s->hal, stopped)) {
        char names[96];
        (void)drv8301_fault_names(s->hal.drv.status[0], s->hal.drv.status[1], names, sizeof names);
        board_uart_puts(&a->uart, f405_tag);
        board_uart_puts(&a->uart, "DRV8301 fault: ");
        board_uart_puts(&a->uart, names);
        board_uart_puts(&a->uart, stopped ? "; gates off, driver reset\r\n" : "; gates off\r\n");
    }
    if (s->hal_rc == F4_OK) {
        const bool was = a->temp_trip;
        const int32_t counts = f4_hal_temp_counts(&s->hal);
        const bool trip =
            board_app_temperature(a, f4_hal_temp_c(s->board, counts), s->board->temp.trip_c);
        f4_hal_trip_board(&s->hal, trip);
        if (trip && !was) {
            char line[80];
            if (isnan(a->temp_c)) {
                (void)snprintf(line, sizeof line, "sensor open or shorted (%ld counts)",
                               (long)counts);
            } else {
                (void)snprintf(line, sizeof line, "%g C above %g C", a->temp_c,
                               s->board->temp.trip_c);
            }
            board_uart_puts(&a->uart, f405_tag);
            board_uart_puts(&a->uart, "temperature: ");
            board_uart_puts(&a->uart, line);
            board_uart_puts(&a->uart, "; gates off\r\n");
        }
    }
    static bool blink;
    blink = !blink;
    f4_gpio_write(s->board->led, st == FW_STATE_RUNNING);
    f4_gpio_write(s->board->led_fault, (st == FW_STATE_FAULT || a->link.hold != NULL) && blink);
}

int main(void)
{
    /* The stack below this frame painted: its high-water mark since reset in
     * "status" and the start-up report (fw_stack.h). 16 words left for the
     * painting's own call. */
    fw_stack_paint(__stack_bottom__, stm32_sp() - 16u);
    f405_t *s = &f405;
    board_app_t *a = &s->app;
    s->board = &F405_BOARD;
    const f4_board_t *b = s->board;
    /* 1. */
    f4_hal_gate_pins_safe(b);
    f4_cycle_counter_init();
    f4_clocks_hsi(&s->clk);
    s->wdg_rc = f405_watchdog(s, F405_IWDG_BOOT_MS);
    /* 2. */
    s->had_fault = f4_fault_take(&s->fault);
    const uint32_t csr = f4_boot_read_csr();
    a->reset_flags = csr >> 24;
    s->clock_rc = f4_clock_init(b->hse_hz, b->sysclk_hz, &s->clk);
    f4_ticks_init(b->tick_tim, s->clk.tim_apb1_hz);
    /* 3. */
    (void)f405_uart_init(&a->uart, &s->usart, b, &s->clk, b->baud);
    f405_report_startup(s, csr);
    /* 4. */
    const f4_hal_cfg_t hc = {F405_FS_HZ, F405_ENCODER_CPR};
    s->hal_rc = f4_hal_init(&s->hal, b, &hc, &s->clk);
    f4_iwdg_refresh(); /* between the start-up's long steps */
    if (s->hal.drv_rc == DRV8301_OK) {
        char line[96];
        (void)snprintf(line, sizeof line, "DRV8301 configured (control 1 0x%x, control 2 0x%x)",
                       (unsigned)s->hal.drv.want[0], (unsigned)s->hal.drv.want[1]);
        f405_report_line(s, "gate driver: ", line, "");
    }
    /* 5. */
    const int frc = board_app_start(a, &f405_port, &s->hal);
    fw_link_set_stack(&a->link, __stack_bottom__, __stack_top__);
    f4_iwdg_refresh();
    if (frc != FW_OK) {
        f405_report_line(s, "fw_init failed: ", fw_strerror(frc), "");
        if (s->hal_rc == F4_OK) {
            s->hal_rc = F4_E_CONFIG;
        }
    }
    if (s->hal_rc != F4_OK || s->wdg_rc != F4_OK) {
        f405_hold(s);
    }
    f4_gpio_config(b->led, F4_PIN_OUTPUT, 0u);
    f4_gpio_config(b->led_fault, F4_PIN_OUTPUT, 0u);
    f4_gpio_config(b->throttle, F4_PIN_AF, 2u); /* pulled down: an open pad has no edges */
    f4_capture_init(b->throttle_tim, b->throttle_ch, s->clk.tim_apb1_hz / 1000000u - 1u,
                    b->throttle_filter);
    f4_capture_start(&s->throttle, b->throttle_tim, b->throttle_ch);

    f4_nvic_set_priority(f4_exti_irq(b->nfault.pin), 0u);
    f4_nvic_set_priority(F4_IRQ_TIM1_BRK_TIM9, 0u);
    f4_nvic_set_priority(F4_IRQ_ADC, 1u);
    f4_nvic_set_priority(s->usart.irq, 2u);
    f4_pendsv_set_priority(3u);
    f4_nvic_enable(s->usart.irq);
    if (!board_uart_check_tx(&a->uart, (const uint8_t *)"\r\n", 2u)) {
        f405_report_line(s,
                         "console: transmit interrupt silent (an emulator without one); "
                         "polled output",
                         "", "");
    }
    if (s->hal_rc == F4_OK) {
        f4_nvic_enable(f4_exti_irq(b->nfault.pin));
        if (f4_pin_used(b->break_in)) {
            f4_nvic_enable(F4_IRQ_TIM1_BRK_TIM9);
        }
        f4_nvic_enable(F4_IRQ_ADC);
    }
    f405_settings_start(s);
    /* 6. (a watchdog that did not start at step 1 is already reported) */
    const int wrc = f405_watchdog(s, F405_IWDG_RUN_MS);
    if (wrc != F4_OK && s->wdg_rc == F4_OK) {
        s->wdg_rc = wrc;
        f405_report_line(s, "watchdog: ", f4_strerror(wrc), "");
        f405_hold(s);
    }
    f405_report_stack(s, fw_stack_used(__stack_bottom__, __stack_top__),
                      (uint32_t)((uintptr_t)__stack_top__ - (uintptr_t)__stack_bottom__));

    a->last_isr = a->isr_count;
    a->uart.idle = board_app_service;
    a->uart.idle_ctx = a;
    uint32_t t_slow = a->now_ms;
    for (;;) {
        board_app_console(a, f405_uart_next);
        fw_link_poll(&a->link);
        board_app_service(a);
        board_app_messages(a);
        if (a->now_ms - t_slow >= 100u) {
            t_slow += 100u;
            f405_slow(s);
        }
    }
}
