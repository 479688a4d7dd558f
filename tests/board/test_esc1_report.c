/*
 * The B-G431B-ESC1's start-up report and serial writer on the register model
 * (g4_model.h): what reaches USART2_TDR with no interrupt enabled, the reset
 * cause from RCC_CSR, the boot option bytes against the BOOT0 pin's pull-up,
 * and the writer's wait for transmit space keeping the watchdog served.
 */
#include <string.h>

#include "board_esc1.h"
#include "esc1_report.h"
#include "esc1_uart.h"
#include "g4_boot.h"
#include "g4_clock.h"
#include "g4_core.h"
#include "g4_model.h"
#include "unity.h"

static esc1_uart_t uart;

void setUp(void)
{
    g4_model_reset();
    g4_cycle_counter_init();
    TEST_ASSERT_EQUAL_INT(G4_OK, esc1_uart_init(&uart, G4_HSI_HZ, 115200u));
}

void tearDown(void)
{
}

/* Characters written to USART2_TDR so far (the line), from the write log. */
static const char *line_out(void)
{
    static char text[1024];
    size_t n = 0u;
    for (uint32_t i = 0; i < g4_model.n_log && n + 1u < sizeof text; i++) {
        if (g4_model.log[i].reg == G4_USART2 + G4_USART_TDR) {
            text[n++] = (char)g4_model.log[i].value;
        }
    }
    text[n] = '\0';
    return text;
}

/* A clock failure at start-up: the report and the halt message reach the
 * line with the USART interrupt never enabled (NVIC_ISER1 bit 6 = IRQ 38). */
static void test_clock_failure_reaches_the_line_without_interrupts(void)
{
    const g4_boot_info_t bi = {G4_RCC_CSR_IWDGRSTF | G4_RCC_CSR_PINRSTF, 0xFBEFF8AAu};
    esc1_report_startup(&uart, &g4_board_esc1, &bi, G4_E_HSE);
    esc1_report_failure(&uart, "clock", g4_strerror(G4_E_HSE));
    TEST_ASSERT_EQUAL_HEX32(0u, g4_model_get(G4_NVIC + G4_NVIC_ISER(1u)) & G4_BIT(6));
    const char *out = line_out();
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(out, "esc1: reset: watchdog\r\n"), out);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(out, "esc1: clock failed: "), out);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(out, g4_strerror(G4_E_HSE)), out);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(out, "esc1: gates off, not armable\r\n"), out);
    TEST_ASSERT_NULL_MESSAGE(strstr(out, "boot:"), "shipped option bytes: no boot warning");
    TEST_ASSERT_EQUAL_UINT32(0u, uart.tx_dropped);
}

/* A transmitter that never becomes ready (TXE low): the polled writer gives
 * up after four character times per character instead of hanging start-up. */
static void test_polled_output_gives_up_without_txe(void)
{
    g4_model_put(G4_USART2 + G4_USART_ISR, 0u);
    esc1_uart_puts_polled(&uart, "abc");
    TEST_ASSERT_EQUAL_STRING("", line_out());
    TEST_ASSERT_EQUAL_UINT32(1u, uart.tx_dropped);
}

/* RCC_CSR flags -> cause, the specific flag before PINRSTF (set with every
 * internal reset). */
static void test_reset_cause(void)
{
    TEST_ASSERT_EQUAL_STRING("brown-out/power-on",
                             g4_reset_cause(G4_RCC_CSR_BORRSTF | G4_RCC_CSR_PINRSTF));
    TEST_ASSERT_EQUAL_STRING("watchdog", g4_reset_cause(G4_RCC_CSR_IWDGRSTF | G4_RCC_CSR_PINRSTF));
    TEST_ASSERT_EQUAL_STRING("window watchdog", g4_reset_cause(G4_RCC_CSR_WWDGRSTF));
    TEST_ASSERT_EQUAL_STRING("software", g4_reset_cause(G4_RCC_CSR_SFTRSTF | G4_RCC_CSR_PINRSTF));
    TEST_ASSERT_EQUAL_STRING("reset pin", g4_reset_cause(G4_RCC_CSR_PINRSTF));
    TEST_ASSERT_EQUAL_STRING("option-byte load", g4_reset_cause(G4_RCC_CSR_OBLRSTF));
    TEST_ASSERT_EQUAL_STRING("low-power", g4_reset_cause(G4_RCC_CSR_LPWRRSTF));
    TEST_ASSERT_EQUAL_STRING("unknown", g4_reset_cause(0u));
}

/* Boot option bytes (RM0440 table "Boot modes"): factory 0xFFEF_F8AA takes
 * BOOT0 from PB8 (nSWBOOT0 = 1), which this board pulls up: a risk; as ST
 * ships the ESC1 (nSWBOOT0 = 0, nBOOT0 = 1): none; nBOOT0 = 0: always. */
static void test_boot_option_bytes(void)
{
    const uint32_t factory = 0xFFEFF8AAu;
    const uint32_t shipped = factory & ~G4_FLASH_OPTR_nSWBOOT0;
    TEST_ASSERT_NOT_NULL(g4_boot_risk(factory, true));
    TEST_ASSERT_NULL(g4_boot_risk(factory, false));
    TEST_ASSERT_NULL(g4_boot_risk(shipped, true));
    TEST_ASSERT_NOT_NULL(g4_boot_risk(shipped & ~G4_FLASH_OPTR_nBOOT0, false));
    TEST_ASSERT_TRUE(g4_board_esc1.boot0_pulled_up);

    const g4_boot_info_t bi = {G4_RCC_CSR_PINRSTF, factory};
    esc1_report_startup(&uart, &g4_board_esc1, &bi, G4_OK);
    const char *out = line_out();
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(out, "esc1: boot: nSWBOOT0=1"), out);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(out, "docs/bringup.md step 1"), out);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(out, "esc1: clock: ok\r\n"), out);
}

/* g4_boot_read takes RCC_CSR and FLASH_OPTR as they are (model: power-on
 * flags, the shipped option bytes), then clears the flags (RMVF). */
static void test_boot_read(void)
{
    g4_boot_info_t bi;
    g4_boot_read(&bi);
    TEST_ASSERT_EQUAL_HEX32(G4_RCC_CSR_PINRSTF | G4_RCC_CSR_BORRSTF, bi.csr);
    TEST_ASSERT_EQUAL_HEX32(0xFBEFF8AAu, bi.optr);
    TEST_ASSERT_TRUE(g4_model_find(G4_RCC + G4_RCC_CSR, G4_RCC_CSR_RMVF, G4_RCC_CSR_RMVF, 0) >= 0);
}

/* The writer waiting for space in a full ring must keep serving the
 * watchdog (a full ring drains in 1024 x 10 / 115200 s = 89 ms, close to the
 * 100 ms independent watchdog); when the interrupt drains a byte meanwhile,
 * nothing is dropped. */
static unsigned idle_calls;
static bool idle_drains;

static void idle(void *ctx)
{
    esc1_uart_t *u = ctx;
    idle_calls++;
    if (idle_drains && idle_calls == 100u) {
        u->tx_tail++; /* the USART interrupt sent one byte */
    }
}

static void test_full_ring_wait_serves_the_watchdog(void)
{
    TEST_ASSERT_EQUAL_INT(G4_OK, esc1_uart_init(&uart, 170000000u, 115200u));
    uart.idle = idle;
    uart.idle_ctx = &uart;
    uart.tx_head = ESC1_UART_TX_SIZE; /* full */
    idle_calls = 0u;
    idle_drains = true;
    esc1_uart_puts(&uart, "x");
    TEST_ASSERT_EQUAL_UINT32(0u, uart.tx_dropped);
    TEST_ASSERT_EQUAL_UINT(100u, idle_calls);

    idle_calls = 0u;
    idle_drains = false;
    esc1_uart_puts(&uart, "yz");
    TEST_ASSERT_EQUAL_UINT32(2u, uart.tx_dropped);
    /* The model's cycle counter moves 16 per read: every wait of at most
     * tx_wait_cycles was spent calling idle. */
    TEST_ASSERT_TRUE(idle_calls >= uart.tx_wait_cycles / 64u);
}

/* The report after the start-up, through the transmit ring: the stack's
 * high-water mark and the longest firmware initialisation. */
static void test_stack_and_init_time_report(void)
{
    esc1_report_stack(&uart, 6124u, 12288u, 1520u);
    char text[128];
    const uint32_t n = uart.tx_head - uart.tx_tail;
    TEST_ASSERT_TRUE(n < sizeof text);
    memcpy(text, uart.tx, n);
    text[n] = '\0';
    TEST_ASSERT_EQUAL_STRING(
        "esc1: stack: 6124 of 12288 B used (high-water mark); fw_init 1520 us\r\n", text);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_clock_failure_reaches_the_line_without_interrupts);
    RUN_TEST(test_polled_output_gives_up_without_txe);
    RUN_TEST(test_reset_cause);
    RUN_TEST(test_boot_option_bytes);
    RUN_TEST(test_boot_read);
    RUN_TEST(test_full_ring_wait_serves_the_watchdog);
    RUN_TEST(test_stack_and_init_time_report);
    return UNITY_END();
}
