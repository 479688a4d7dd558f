/*
 * mps2-an386 peripherals used by the project: CMSDK UART0, CMSDK Timer0/Timer1,
 * the NVIC, and ARM semihosting. Addresses and bit fields: QEMU.md.
 */
#include <stddef.h>
#include <stdint.h>

#include "arm_semihost.h"
#include "qemu_mps2.h"

#define REG32(addr) (*(volatile uint32_t *)(addr))

/* CMSDK APB UART0 */
#define UART0_BASE 0x40004000u
#define UART_DATA REG32(UART0_BASE + 0x0u)
#define UART_STATE REG32(UART0_BASE + 0x4u)
#define UART_CTRL REG32(UART0_BASE + 0x8u)
#define UART_BAUDDIV REG32(UART0_BASE + 0x10u)
#define UART_STATE_TX_FULL 0x1u
#define UART_CTRL_TX_EN 0x1u

/* CMSDK APB timers (down-counters at the 25 MHz system clock) */
#define TIMER0_BASE 0x40000000u
#define TIMER1_BASE 0x40001000u
#define TIMER_CTRL(b) REG32((b) + 0x0u)
#define TIMER_VALUE(b) REG32((b) + 0x4u)
#define TIMER_RELOAD(b) REG32((b) + 0x8u)
#define TIMER_INTCLEAR(b) REG32((b) + 0xCu)
#define TIMER_CTRL_EN 0x1u
#define TIMER_CTRL_IRQ_EN 0x8u
#define TIMER0_IRQ 8u

/* NVIC */
#define NVIC_ISER0 REG32(0xE000E100u)
#define NVIC_ICER0 REG32(0xE000E180u)
#define NVIC_ICPR0 REG32(0xE000E280u)
#define NVIC_ISPR0 REG32(0xE000E200u) /* set-pending; reads 1 for a pending IRQ (B3.4.5) */
/* System control block: ICSR, SHPR3 (PendSV's priority in bits 23:16) */
#define SCB_ICSR REG32(0xE000ED04u)
#define SCB_ICSR_PENDSVSET (1u << 28)
#define SCB_SHPR3 REG32(0xE000ED20u)

void TIMER0_Handler(void);
void PendSV_Handler(void);

static pendsv_callback_t pendsv_callback;

static timer0_callback_t timer0_callback;
static uint32_t timer0_period;

void board_init(void)
{
    UART_BAUDDIV = 16u; /* minimum legal divider; QEMU does not model the baud rate */
    UART_CTRL = UART_CTRL_TX_EN;

    /* Timer1: free-running from 0xFFFFFFFF, no interrupt. */
    TIMER_CTRL(TIMER1_BASE) = 0u;
    TIMER_RELOAD(TIMER1_BASE) = 0xFFFFFFFFu;
    TIMER_VALUE(TIMER1_BASE) = 0xFFFFFFFFu;
    TIMER_CTRL(TIMER1_BASE) = TIMER_CTRL_EN;
}

void uart_putc(char c)
{
    while ((UART_STATE & UART_STATE_TX_FULL) != 0u) {
    }
    UART_DATA = (uint32_t)(unsigned char)c;
}

void uart_puts(const char *s)
{
    if (s == NULL) {
        return;
    }
    while (*s != '\0') {
        uart_putc(*s++);
    }
}

void uart_put_u32(uint32_t v)
{
    char buf[10];
    unsigned n = 0u;
    do {
        buf[n++] = (char)('0' + (char)(v % 10u));
        v /= 10u;
    } while (v != 0u);
    while (n > 0u) {
        uart_putc(buf[--n]);
    }
}

void semihost_write0(const char *s)
{
    if (s != NULL) {
        (void)arm_semihost_call(SYS_WRITE0, s);
    }
}

void semihost_exit(int code)
{
    arm_semihost_exit(code); /* QEMU exits with code & 0xFF */
}

int timer0_start(uint32_t hz, timer0_callback_t callback)
{
    if (hz == 0u || hz > 1000000u || callback == NULL) {
        return -1;
    }
    timer0_stop();
    timer0_callback = callback;
    timer0_period = QEMU_MPS2_SYSCLK_HZ / hz;
    TIMER_RELOAD(TIMER0_BASE) = timer0_period - 1u;
    TIMER_VALUE(TIMER0_BASE) = timer0_period - 1u;
    TIMER_INTCLEAR(TIMER0_BASE) = 1u;
    NVIC_ICPR0 = 1u << TIMER0_IRQ;
    NVIC_ISER0 = 1u << TIMER0_IRQ;
    TIMER_CTRL(TIMER0_BASE) = TIMER_CTRL_EN | TIMER_CTRL_IRQ_EN;
    return 0;
}

void timer0_realign(void)
{
    if (timer0_period != 0u && (NVIC_ISPR0 & (1u << TIMER0_IRQ)) != 0u) {
        TIMER_VALUE(TIMER0_BASE) = timer0_period - 1u; /* reload now (CMSDK timer VALUE) */
    }
}

void timer0_stop(void)
{
    TIMER_CTRL(TIMER0_BASE) = 0u;
    NVIC_ICER0 = 1u << TIMER0_IRQ;
    TIMER_INTCLEAR(TIMER0_BASE) = 1u;
    NVIC_ICPR0 = 1u << TIMER0_IRQ;
    timer0_period = 0u;
}

uint32_t timer0_period_ticks(void)
{
    return timer0_period;
}

void TIMER0_Handler(void)
{
    TIMER_INTCLEAR(TIMER0_BASE) = 1u;
    if (timer0_callback != NULL) {
        timer0_callback();
    }
}

void board_pendsv_set(pendsv_callback_t callback)
{
    pendsv_callback = callback;
    SCB_SHPR3 = (SCB_SHPR3 & ~(0xFFu << 16)) | (0xFFu << 16); /* lowest priority */
}

void board_pendsv_pend(void)
{
    SCB_ICSR = SCB_ICSR_PENDSVSET;
}

void PendSV_Handler(void)
{
    if (pendsv_callback != NULL) {
        pendsv_callback();
    }
}

uint32_t timer1_read(void)
{
    return 0xFFFFFFFFu - TIMER_VALUE(TIMER1_BASE);
}

/* Exactly 1000 instructions (plus the call), for the Timer1 calibration:
 * under -icount, Timer1 counts virtual time = instructions x 2^shift ns. */
__attribute__((noinline)) static void board_nops_1000(void)
{
    __asm__ volatile(".rept 1000\n\tnop\n\t.endr" ::: "memory");
}

__attribute__((noinline)) static void board_nops_0(void)
{
    __asm__ volatile("" ::: "memory");
}

uint32_t timer1_ticks_per_kinstr(void)
{
    uint32_t t0 = timer1_read();
    board_nops_0();
    uint32_t t1 = timer1_read();
    const uint32_t base = t1 - t0;
    t0 = timer1_read();
    board_nops_1000();
    t1 = timer1_read();
    const uint32_t d = (t1 - t0) - base;
    return d == 0u ? 1u : d;
}

void board_irq_disable(void)
{
    __asm__ volatile("cpsid i" ::: "memory");
}

void board_irq_enable(void)
{
    __asm__ volatile("cpsie i" ::: "memory");
}

bool board_timer0_irq_mask(void)
{
    const bool on = (NVIC_ISER0 & (1u << TIMER0_IRQ)) != 0u;
    NVIC_ICER0 = 1u << TIMER0_IRQ;
    __asm__ volatile("dsb\n\tisb" ::: "memory"); /* masked before the caller goes on */
    return on;
}

void board_timer0_irq_unmask(void)
{
    NVIC_ISER0 = 1u << TIMER0_IRQ;
}

void board_idle(void)
{
    __asm__ volatile("nop" ::: "memory");
}
