/*
 * The main loop's watch on the control interrupt (board_isr_watch.h): a
 * 20 kHz interrupt counted, the main loop looking at uneven intervals (97 to
 * 397 us, as its passes vary), microsecond ticks started just before their
 * wrap. The bounds: a stop with the gates on is seen within the 2 ms limit
 * plus one main-loop pass (well inside the watchdog's shortest 68 ms); a
 * running interrupt, or a stopped one with the gates off, never is.
 */
#include "board_isr_watch.h"
#include "unity.h"

#define PERIOD_US 50u /* 20 kHz */

static board_isr_watch_t w;
static uint32_t now;   /* microsecond ticks */
static uint32_t count; /* interrupts so far */
static uint32_t next_isr;
static uint32_t step;

void setUp(void)
{
    w = (board_isr_watch_t){0};
    now = 0xFFFFF000u; /* wraps 4 ms in */
    count = 12345u;
    next_isr = now + PERIOD_US;
    step = 0u;
}

void tearDown(void)
{
}

/* Time passes until the main loop's next look; the interrupt runs when
 * `running`. */
static void pass(bool running)
{
    const uint32_t dt = 97u + (step++ * 53u) % 301u;
    for (uint32_t t = 0; t < dt; t++) {
        now++;
        if (running && now == next_isr) {
            count++;
            next_isr += PERIOD_US;
        }
    }
    if (!running) {
        next_isr = now + PERIOD_US;
    }
}

static void test_running_never_trips(void)
{
    for (unsigned k = 0; k < 5000u; k++) { /* about 1.2 s, across the wrap */
        pass(true);
        TEST_ASSERT_FALSE(board_isr_watch_check(&w, count, now, true, BOARD_ISR_WATCH_US));
    }
}

static void test_gates_off_never_trips(void)
{
    for (unsigned k = 0; k < 5000u; k++) {
        pass(false);
        TEST_ASSERT_FALSE(board_isr_watch_check(&w, count, now, false, BOARD_ISR_WATCH_US));
    }
}

static void test_stop_with_gates_on_is_seen(void)
{
    for (unsigned k = 0; k < 100u; k++) {
        pass(true);
        TEST_ASSERT_FALSE(board_isr_watch_check(&w, count, now, true, BOARD_ISR_WATCH_US));
    }
    const uint32_t last_isr = next_isr - PERIOD_US; /* the last period that ran */
    bool seen = false;
    uint32_t t_seen = 0u;
    for (unsigned k = 0; k < 100u && !seen; k++) {
        pass(false);
        seen = board_isr_watch_check(&w, count, now, true, BOARD_ISR_WATCH_US);
        t_seen = now;
    }
    TEST_ASSERT_TRUE(seen);
    /* not before the limit after the last look that saw it move, and within
     * the limit plus two passes (<= 397 us each) of the last period */
    TEST_ASSERT_TRUE(t_seen - last_isr >= BOARD_ISR_WATCH_US - 397u);
    TEST_ASSERT_TRUE(t_seen - last_isr <= BOARD_ISR_WATCH_US + 2u * 397u);
    /* it stays seen; gates off ends it, and on again the window restarts */
    pass(false);
    TEST_ASSERT_TRUE(board_isr_watch_check(&w, count, now, true, BOARD_ISR_WATCH_US));
    TEST_ASSERT_FALSE(board_isr_watch_check(&w, count, now, false, BOARD_ISR_WATCH_US));
    TEST_ASSERT_FALSE(board_isr_watch_check(&w, count, now, true, BOARD_ISR_WATCH_US));
    now += BOARD_ISR_WATCH_US - 1u;
    TEST_ASSERT_FALSE(board_isr_watch_check(&w, count, now, true, BOARD_ISR_WATCH_US));
    now += 1u;
    TEST_ASSERT_TRUE(board_isr_watch_check(&w, count, now, true, BOARD_ISR_WATCH_US));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_running_never_trips);
    RUN_TEST(test_gates_off_never_trips);
    RUN_TEST(test_stop_with_gates_on_is_seen);
    return UNITY_END();
}
