/*
 * What the QEMU images with the plant in the loop share (pil_main.c, the PIL
 * test images; pil_interactive.c, the console image): the Timer0 rate and
 * the UART side of the command interface.
 *
 * Timer0 fires once per PWM period; each firing advances the plant by exactly
 * one Ts of plant time, whatever the real rate, so the rate only sets the wall
 * time. It follows the interrupt's own cost: period = cost x 1.25 (leaves the
 * main loop a fifth of the time), changed when the cost grows above the period
 * or falls below 2/3 of it (e.g. when the Ts/10 observer of a metrics window
 * switches on).
 */
#ifndef FIRMWARE_APPS_QEMU_PIL_COMMON_H
#define FIRMWARE_APPS_QEMU_PIL_COMMON_H

#include <stddef.h>
#include <stdint.h>

#include "fw_link.h"

/* The modelled CPU clock of the deadline budget (engine_port_qemu.c). */
#define PIL_CPU_HZ 100000000u

typedef struct {
    uint32_t period;            /* Timer0 period, Timer1 ticks */
    uint32_t isr_max, isr_last; /* interrupt cost, Timer1 ticks */
    uint64_t isr_sum, isr_n;
} pil_timer_t;

void pil_timer_start(pil_timer_t *t, void (*isr)(void));
/* After each interrupt: its cost (Timer1 ticks); adapts the rate. */
void pil_timer_account(pil_timer_t *t, uint32_t isr_ticks, void (*isr)(void));

/* fw_link's output: bytes to UART0. */
void pil_uart_write(void *ctx, const uint8_t *bytes, size_t len);
/* Main loop: received UART0 bytes into the command interpreter (with the
 * Timer0 interrupt masked, so a command acts between two periods), then the
 * queued responses and telemetry frames out. */
void pil_poll_uart(fw_link_t *link);

#endif /* FIRMWARE_APPS_QEMU_PIL_COMMON_H */
