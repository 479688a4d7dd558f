/*
 * The anti-cogging feed-forward (control/regulators/cogging_ff.h) against an
 * exact reference computed another way, on the host and in QEMU (the same
 * test built for the Cortex-M4): equal bits on both is what makes the
 * host's closed-loop figures the target's.
 *
 * Reference: the angle as floor(pos 2^32 / cpr) (long division, exact) then
 * corrected by the documented rounding of round(2^48 / cpr) (at most
 * pos / 2^17 LSB of a Q32 turn: checked, then the implementation's own turn
 * is used); index and weight from the turn by division, not shifts; the
 * interpolation in 64 bits and rounded by floor((x + 2^29) / 2^30).
 */
#include <stdint.h>

#include "cogging_ff.h"
#include "unity.h"

void setUp(void)
{
}
void tearDown(void)
{
}

static int16_t t[CTRL_COG_N];

static int64_t floor_div(int64_t a, int64_t b) /* b > 0 */
{
    int64_t q = a / b;
    if ((a % b) != 0 && a < 0) {
        q--;
    }
    return q;
}

static void check_cpr(uint32_t cpr, q24_t tr, uint32_t *seed)
{
    ctrl_cogging_t c;
    TEST_ASSERT_EQUAL_INT(0, ctrl_cogging_init(&c, t, CTRL_COG_N_LOG2, cpr, tr));
    for (uint32_t k = 0; k < 4000u; k++) {
        *seed = *seed * 1664525u + 1013904223u;
        const uint32_t pos = k < 2u ? (k == 0u ? 0u : cpr - 1u) : *seed % cpr;
        /* exact angle, and the implementation's within its documented error */
        const uint64_t exact = ((uint64_t)pos << 32) / cpr;
        const uint32_t turn = ctrl_cogging_turn(&c, pos);
        const int64_t dev = (int64_t)turn - (int64_t)exact;
        TEST_ASSERT_TRUE(dev <= (int64_t)(pos >> 17) + 1 && dev >= -(int64_t)(pos >> 17) - 1);
        /* index and 15-bit weight by division */
        const uint32_t span = (uint32_t)(4294967296ull / CTRL_COG_N); /* Q32 per entry */
        const uint32_t i = turn / span;
        const int64_t f = (int64_t)(turn % span) / (span / 32768u);
        const int64_t a = t[i], b = t[(i + 1u) % CTRL_COG_N];
        const int64_t v = a * (32768 - f) + b * f;
        int64_t want = floor_div(v * tr + ((int64_t)1 << 29), (int64_t)1 << 30);
        want = want > INT32_MAX ? INT32_MAX : (want < INT32_MIN ? INT32_MIN : want);
        TEST_ASSERT_EQUAL_INT32((int32_t)want, ctrl_cogging_ff(&c, pos));
        TEST_ASSERT_EQUAL_UINT32(i, ctrl_cogging_bin(&c, turn));
    }
}

static void test_ff_exact(void)
{
    uint32_t seed = 777u;
    for (uint32_t i = 0; i < CTRL_COG_N; i++) {
        seed = seed * 1664525u + 1013904223u;
        t[i] = (int16_t)(int32_t)((seed >> 16) - 32768u);
    }
    t[5] = INT16_MIN;
    t[6] = INT16_MAX;
    check_cpr(16384u, 16777216, &seed);
    check_cpr(10000u, 22369621, &seed);
    check_cpr(4000u, 8388608, &seed);
    check_cpr(1000003u, 16777216, &seed);
    check_cpr(0x80000000u, 33554432, &seed); /* the largest cpr, 2 pu rated torque */
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_ff_exact);
    return UNITY_END();
}
