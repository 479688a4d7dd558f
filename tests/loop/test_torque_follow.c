/*
 * Torque supervision (firmware/isr/torque_follow.h) against its criterion:
 * the window from the rate, the tolerance max(5 % of the mean reference, 2 %
 * of rated) on both sides of its edge, the warning's set and clear, the
 * configurable fault, and the restart on an untrusted estimate. No plant:
 * host and QEMU.
 */
#include <stdbool.h>
#include <stdint.h>

#include "protect.h"
#include "torque_follow.h"
#include "unity.h"

void setUp(void)
{
}
void tearDown(void)
{
}

#define ONE ((q24_t)1 << 24)
#define RATED (ONE / 2) /* rated torque 0.5 pu */

static fw_torque_follow_t tf;

/* One whole window of constant reference and estimate; the last call's result. */
static uint32_t window(q24_t ref, q24_t est)
{
    uint32_t f = FW_FAULT_NONE;
    const uint32_t n = (uint32_t)1 << tf.cfg.shift;
    for (uint32_t k = 0; k < n; k++) {
        f = fw_torque_follow_step(&tf, ref, est, true);
        if (k + 1u < n) {
            TEST_ASSERT_EQUAL_UINT32(FW_FAULT_NONE, f); /* decided at the window's end only */
        }
    }
    return f;
}

static void setup(uint32_t fault_windows)
{
    fw_torque_follow_cfg_t c;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, fw_torque_follow_config(&c, 20000u, RATED, fault_windows));
    fw_torque_follow_init(&tf, &c);
}

static void test_config(void)
{
    fw_torque_follow_cfg_t c;
    /* 50 ms at 20 kHz = 1000 periods -> 1024; at 10 kHz 500 -> 512 */
    TEST_ASSERT_EQUAL_INT(CTRL_OK, fw_torque_follow_config(&c, 20000u, RATED, 0u));
    TEST_ASSERT_EQUAL_UINT8(10u, c.shift);
    TEST_ASSERT_EQUAL_INT32(RATED / 50, c.tol_rated);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, fw_torque_follow_config(&c, 10000u, RATED, 0u));
    TEST_ASSERT_EQUAL_UINT8(9u, c.shift);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, fw_torque_follow_config(&c, 4000000u, RATED, 0u));
    TEST_ASSERT_EQUAL_UINT8(15u, c.shift); /* capped: the sums stay below 2^47 */
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, fw_torque_follow_config(&c, 0u, RATED, 0u));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, fw_torque_follow_config(&c, 20000u, 0, 0u));
    TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, fw_torque_follow_config(NULL, 20000u, RATED, 0u));
}

/* Large reference: 5 % of it is the tolerance. */
static void test_relative_edge(void)
{
    setup(0u);
    const q24_t ref = RATED; /* 5 % = 0.025 pu > 2 % of rated = 0.01 pu */
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_NONE, window(ref, ref - ref / 20 + 2));
    TEST_ASSERT_EQUAL_UINT8(0u, tf.warn);
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_NONE, window(ref, ref - ref / 20 - 2));
    TEST_ASSERT_EQUAL_UINT8(1u, tf.warn);
    /* above the reference counts the same, and either sign of torque */
    setup(0u);
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_NONE, window(-ref, -ref - ref / 20 - 2));
    TEST_ASSERT_EQUAL_UINT8(1u, tf.warn);
    /* a window that meets clears the warning */
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_NONE, window(-ref, -ref));
    TEST_ASSERT_EQUAL_UINT8(0u, tf.warn);
}

/* Small reference: 2 % of rated is the floor. */
static void test_rated_floor(void)
{
    setup(0u);
    const q24_t tol = RATED / 50;
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_NONE, window(0, tol - 1));
    TEST_ASSERT_EQUAL_UINT8(0u, tf.warn);
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_NONE, window(0, tol + 1));
    TEST_ASSERT_EQUAL_UINT8(1u, tf.warn);
    /* the mean decides, not a single period: a ripple of +-4 tol around the reference */
    setup(0u);
    const uint32_t n = (uint32_t)1 << tf.cfg.shift;
    for (uint32_t k = 0; k < n; k++) {
        (void)fw_torque_follow_step(&tf, RATED / 10, RATED / 10 + ((k & 1u) ? 4 : -4) * tol, true);
    }
    TEST_ASSERT_EQUAL_UINT8(0u, tf.warn);
}

/* Fault after the configured number of consecutive missed windows. */
static void test_fault_windows(void)
{
    setup(3u);
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_NONE, window(RATED, 0));
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_NONE, window(RATED, 0));
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_NONE, window(RATED, RATED)); /* met: count restarts */
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_NONE, window(RATED, 0));
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_NONE, window(RATED, 0));
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_TORQUE_FOLLOW, window(RATED, 0));
    TEST_ASSERT_EQUAL_STRING("torque_follow", fw_fault_name(FW_FAULT_TORQUE_FOLLOW));
    /* warning only: never a fault */
    setup(0u);
    for (int w = 0; w < 20; w++) {
        TEST_ASSERT_EQUAL_UINT32(FW_FAULT_NONE, window(RATED, 0));
    }
    TEST_ASSERT_EQUAL_UINT8(1u, tf.warn);
    fw_torque_follow_reset(&tf);
    TEST_ASSERT_EQUAL_UINT8(0u, tf.warn);
}

/* An untrusted period restarts the window: what came before it does not count. */
static void test_invalid_restarts(void)
{
    setup(1u);
    const uint32_t n = (uint32_t)1 << tf.cfg.shift;
    for (uint32_t k = 0; k + 1u < n; k++) {
        TEST_ASSERT_EQUAL_UINT32(FW_FAULT_NONE, fw_torque_follow_step(&tf, RATED, 0, true));
    }
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_NONE, fw_torque_follow_step(&tf, RATED, 0, false));
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_NONE, window(RATED, RATED));
    TEST_ASSERT_EQUAL_UINT8(0u, tf.warn);
}

/* Extreme values: no overflow (UBSan), a full-scale miss detected. */
static void test_extremes(void)
{
    setup(1u);
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_TORQUE_FOLLOW, window(INT32_MAX, INT32_MIN));
    setup(1u);
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_NONE, window(INT32_MIN, INT32_MIN));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_config);
    RUN_TEST(test_relative_edge);
    RUN_TEST(test_rated_floor);
    RUN_TEST(test_fault_windows);
    RUN_TEST(test_invalid_restarts);
    RUN_TEST(test_extremes);
    return UNITY_END();
}
