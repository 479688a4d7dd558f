/*
 * UART0 output and semihosting exit on QEMU's microbit machine. UART register
 * offsets from the nRF51 Series Reference Manual v3.0, §29.10 (UART registers):
 * TASKS_STARTTX 0x008, EVENTS_TXDRDY 0x11C, ENABLE 0x500 (4 = enabled), TXD 0x51C.
 */
#include <stddef.h>

#include "arm_semihost.h"
#include "qemu_microbit.h"

#define UART0_BASE 0x40002000u
#define UART_REG(off) (*(volatile uint32_t *)(UART0_BASE + (off)))
#define UART_TASKS_STARTTX 0x008u
#define UART_EVENTS_TXDRDY 0x11Cu
#define UART_ENABLE 0x500u
#define UART_TXD 0x51Cu

static int uart_started;

static void uart_putc(char c)
{
    if (!uart_started) {
        UART_REG(UART_ENABLE) = 4u;
        UART_REG(UART_TASKS_STARTTX) = 1u;
        uart_started = 1;
    }
    UART_REG(UART_EVENTS_TXDRDY) = 0u;
    UART_REG(UART_TXD) = (uint8_t)c;
    while (UART_REG(UART_EVENTS_TXDRDY) == 0u) {
    }
}

void uart_puts(const char *s)
{
    while (*s != '\0') {
        uart_putc(*s++);
    }
}

void uart_put_u32(uint32_t v)
{
    char buf[11];
    size_t n = 0;
    do {
        buf[n++] = (char)('0' + v % 10u);
        v /= 10u;
    } while (v != 0u);
    while (n > 0u) {
        uart_putc(buf[--n]);
    }
}

void semihost_exit(int code)
{
    arm_semihost_exit(code);
}
