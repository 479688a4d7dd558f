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
 * The look-ahead: the advance floor((omega lead + 2^23) / 2^24) clamped to
 * int32_t, added to the exact turn modulo 2^32 (64-bit arithmetic), must
 * give the same bits as the plain feed-forward at that turn.
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

/* The feed-forward at the turn pos's turn + the speed's advance. */
static void check_ahead(uint32_t cpr, q24_t tr, int32_t lead, uint32_t *seed)
{
    ctrl_cogging_t c;
    TEST_ASSERT_EQUAL_INT(0, ctrl_cogging_init(&c, t, CTRL_COG_N_LOG2, cpr, tr));
    TEST_ASSERT_EQUAL_INT32(0, c.lead); /* none until set */
    TEST_ASSERT_EQUAL_INT(-1, ctrl_cogging_set_lead(&c, -1, 1 << 24));
    TEST_ASSERT_EQUAL_INT(-1, ctrl_cogging_set_lead(&c, lead, 0));
    TEST_ASSERT_EQUAL_INT(-1, ctrl_cogging_set_lead(&c, lead, (1 << 24) + 1));
    TEST_ASSERT_EQUAL_INT(0, ctrl_cogging_set_lead(&c, lead, 1 << 24));
    for (uint32_t k = 0; k < 4000u; k++) {
        *seed = *seed * 1664525u + 1013904223u;
        const uint32_t pos = *seed % cpr;
        *seed = *seed * 1664525u + 1013904223u;
        /* speeds over the whole Q24 range, the extremes included */
        const int32_t w =
            k == 0u ? INT32_MAX : (k == 1u ? INT32_MIN : (int32_t)(*seed ^ 0x5a5a5a5au));
        int64_t adv = floor_div((int64_t)w * lead + ((int64_t)1 << 23), (int64_t)1 << 24);
        adv = adv > INT32_MAX ? INT32_MAX : (adv < INT32_MIN ? INT32_MIN : adv);
        const int64_t turn = ((int64_t)ctrl_cogging_turn(&c, pos) + adv) % 4294967296ll;
        const uint32_t want_turn = (uint32_t)(turn < 0 ? turn + 4294967296ll : turn);
        TEST_ASSERT_EQUAL_INT32(ctrl_cogging_ff_turn(&c, want_turn),
                                ctrl_cogging_ff_ahead(&c, pos, w));
    }
    /* no speed: the position's own entry */
    TEST_ASSERT_EQUAL_INT32(ctrl_cogging_ff(&c, 123u % cpr),
                            ctrl_cogging_ff_ahead(&c, 123u % cpr, 0));
}

/* The speed filter: y += k (x - y) in Q48, against the same in 64-bit
 * arithmetic by division; a step settles on its input, saturates nowhere. */
static void test_speed_filter(void)
{
    ctrl_cogging_t c;
    TEST_ASSERT_EQUAL_INT(0, ctrl_cogging_init(&c, t, CTRL_COG_N_LOG2, 16384u, 16777216));
    const int32_t k = 207000; /* 20 Hz at 10 kHz: 1 - exp(-2 pi 20 / 1e4) in Q24 */
    TEST_ASSERT_EQUAL_INT(0, ctrl_cogging_set_lead(&c, 1000, k));
    int64_t acc = 0;
    int32_t y = 0;
    uint32_t seed = 99u;
    for (uint32_t n = 0; n < 20000u; n++) {
        seed = seed * 1664525u + 1013904223u;
        const int32_t x = n < 10000u ? (int32_t)(seed ^ 0x12345678u) : INT32_MIN;
        int64_t e = (int64_t)x - y;
        e = e > INT32_MAX ? INT32_MAX : (e < INT32_MIN ? INT32_MIN : e);
        acc += e * k;
        int64_t r = floor_div(acc + ((int64_t)1 << 23), (int64_t)1 << 24);
        y = (int32_t)(r > INT32_MAX ? INT32_MAX : (r < INT32_MIN ? INT32_MIN : r));
        TEST_ASSERT_EQUAL_INT32(y, ctrl_cogging_speed(&c, x));
    }
    TEST_ASSERT_INT32_WITHIN(1, INT32_MIN, c.w); /* settled on the held input */
}

/* One period (ctrl_cogging_step): the speed filter every period, primed with
 * the speed after a restart; the table read ahead by the filtered speed when
 * the position has moved, and held while it has not, whatever the speed
 * does: the output changes no more often than the position (a reference that
 * changed every period with the speed's filter put FST in its step mode). */
static void test_step_holds(void)
{
    ctrl_cogging_t c;
    const uint32_t cpr = 16384u;
    TEST_ASSERT_EQUAL_INT(0, ctrl_cogging_init(&c, t, CTRL_COG_N_LOG2, cpr, 16777216));
    const int32_t k = 207000;
    const int32_t lead = 200000000; /* a large advance: every speed's change shows */
    TEST_ASSERT_EQUAL_INT(0, ctrl_cogging_set_lead(&c, lead, k));
    TEST_ASSERT_EQUAL_UINT32(CTRL_COG_NONE, c.pos_held);
    uint32_t seed = 4242u, pos = 100u;
    int64_t acc = 0;
    int32_t y = 0;
    uint32_t moves = 0u, changes = 0u;
    q24_t last = 0;
    for (uint32_t n = 0; n < 20000u; n++) {
        seed = seed * 1664525u + 1013904223u;
        const int32_t w = 150000 + (int32_t)(seed >> 20) * 64; /* noisy, positive */
        const uint32_t moved = (seed >> 7) % 3u == 0u ? 1u : 0u;
        pos = (pos + moved) % cpr;
        if (n == 0u) {
            acc = (int64_t)w << 24; /* primed */
            y = w;
        }
        acc += ((int64_t)w - y) * k;
        y = (int32_t)floor_div(acc + ((int64_t)1 << 23), (int64_t)1 << 24);
        const q24_t ff = ctrl_cogging_step(&c, pos, w);
        TEST_ASSERT_EQUAL_INT32(y, c.w);
        if (n == 0u || moved != 0u) {
            TEST_ASSERT_EQUAL_INT32(ctrl_cogging_ff_ahead(&c, pos, y), ff);
            moves += n > 0u ? 1u : 0u;
        } else {
            TEST_ASSERT_EQUAL_INT32(last, ff); /* held */
        }
        changes += n > 0u && ff != last ? 1u : 0u;
        last = ff;
    }
    TEST_ASSERT_TRUE(changes <= moves);
    TEST_ASSERT_TRUE(moves > 5000u);
    /* restarted (the drive armed again): primed anew from the speed */
    ctrl_cogging_restart(&c);
    TEST_ASSERT_EQUAL_UINT32(CTRL_COG_NONE, c.pos_held);
    const q24_t ff = ctrl_cogging_step(&c, pos, -300000);
    TEST_ASSERT_EQUAL_INT32(-300000, c.w);
    TEST_ASSERT_EQUAL_INT32(ctrl_cogging_ff_ahead(&c, pos, -300000), ff);
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
    /* a gimbal's lead (about 6e3) and the largest that fits (saturating) */
    check_ahead(16384u, 16777216, 6365, &seed);
    check_ahead(10000u, 22369621, 200000000, &seed);
    check_ahead(16384u, 16777216, INT32_MAX, &seed);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_ff_exact);
    RUN_TEST(test_speed_filter);
    RUN_TEST(test_step_holds);
    return UNITY_END();
}
