/*
 * QEMU mps2-an386 smoke test of the board support (cm4 build only):
 * Timer0 interrupts at the configured rate, counted against Timer1 over a fixed
 * simulated time; FPU enabled by the start-up code; newlib printf and heap.
 * Expected interrupt counts follow from the 25 MHz timer clock alone:
 * N = T * f, with one interrupt of tolerance for the phase of the last period.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "qemu_mps2.h"
#include "unity.h"

static volatile uint32_t isr_count;

static void count_isr(void)
{
    isr_count++;
}

void setUp(void)
{
    timer0_stop();
    isr_count = 0u;
}

void tearDown(void)
{
    timer0_stop();
}

/* Runs Timer0 at hz for `ticks` Timer1 ticks (25 MHz) of simulated time, busy-waiting. */
static uint32_t count_interrupts(uint32_t hz, uint32_t ticks)
{
    TEST_ASSERT_EQUAL_INT(0, timer0_start(hz, count_isr));
    const uint32_t t0 = timer1_read();
    while (timer1_read() - t0 < ticks) {
        board_idle();
    }
    timer0_stop();
    return isr_count;
}

static void report(const char *what, uint32_t hz, uint32_t ticks, uint32_t n)
{
    uart_puts("INFO ");
    uart_puts(what);
    uart_puts(": ");
    uart_put_u32(n);
    uart_puts(" Timer0 interrupts at ");
    uart_put_u32(hz);
    uart_puts(" Hz in ");
    uart_put_u32(ticks / (QEMU_MPS2_SYSCLK_HZ / 1000000u));
    uart_puts(" us of simulated time (Timer1)\n");
}

static void test_timer0_20khz_for_100ms(void)
{
    const uint32_t ticks = QEMU_MPS2_SYSCLK_HZ / 10u; /* 0.1 s */
    const uint32_t n = count_interrupts(20000u, ticks);
    report("20 kHz", 20000u, ticks, n);
    TEST_ASSERT_UINT32_WITHIN(1u, 2000u, n); /* 0.1 s * 20 kHz */
}

static void test_timer0_rate_is_configurable(void)
{
    const uint32_t ticks = QEMU_MPS2_SYSCLK_HZ / 20u; /* 0.05 s */
    const uint32_t n = count_interrupts(10000u, ticks);
    report("10 kHz", 10000u, ticks, n);
    TEST_ASSERT_UINT32_WITHIN(1u, 500u, n); /* 0.05 s * 10 kHz */
}

static void test_timer0_period_register(void)
{
    TEST_ASSERT_EQUAL_INT(0, timer0_start(20000u, count_isr));
    TEST_ASSERT_EQUAL_UINT32(1250u, timer0_period_ticks()); /* 25 MHz / 20 kHz */
    timer0_stop();
    TEST_ASSERT_EQUAL_UINT32(0u, timer0_period_ticks());
}

static void test_timer0_rejects_bad_arguments(void)
{
    TEST_ASSERT_EQUAL_INT(-1, timer0_start(0u, count_isr));
    TEST_ASSERT_EQUAL_INT(-1, timer0_start(2000000u, count_isr));
    TEST_ASSERT_EQUAL_INT(-1, timer0_start(20000u, NULL));
}

static void test_timer1_counts_up(void)
{
    const uint32_t a = timer1_read();
    for (volatile int i = 0; i < 1000; i++) {
    }
    const uint32_t b = timer1_read();
    TEST_ASSERT_GREATER_THAN_UINT32(0u, b - a);
}

static void test_fpu_enabled(void)
{
    /* Runs VFP instructions: a NOCP fault would end the run with status 127. */
    volatile float x = 1.5f;
    volatile float y = x * x + 0.25f;
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 2.5, (double)y);
}

static void test_newlib_printf_and_heap(void)
{
    static const char expected[] = "INFO printf through _write to UART0: 42 2.50\n";
    int n = printf("INFO printf through _write to UART0: %d %.2f\n", 42, 2.5);
    (void)fflush(stdout);
    TEST_ASSERT_EQUAL_INT((int)strlen(expected), n);
    void *p = malloc(64u * 1024u);
    TEST_ASSERT_NOT_NULL(p);
    free(p);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_timer0_20khz_for_100ms);
    RUN_TEST(test_timer0_rate_is_configurable);
    RUN_TEST(test_timer0_period_register);
    RUN_TEST(test_timer0_rejects_bad_arguments);
    RUN_TEST(test_timer1_counts_up);
    RUN_TEST(test_fpu_enabled);
    RUN_TEST(test_newlib_printf_and_heap);
    return UNITY_END();
}
