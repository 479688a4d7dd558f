/*
 * The interrupt's fast forms against the straightforward forms they replace,
 * kept here as the oracles (no plant, runs on the host and in QEMU):
 *  - ctrl_plan_legs (plan.h) against the plain per-segment sum for every
 *    vector pair (and bad indices), every n_seg and random, edge and
 *    out-of-range durations;
 *  - fw_pwm_compare8 (one UMULL) against the 64-bit rounding of compare values;
 *  - fw_legs_limit (the board's duty cap) against its properties;
 *  - fw_protect_current against the saturating |i_a|, |i_b|,
 *    |-(i_a + i_b)| > i_max test for every limit fw_protect_init takes (and
 *    the refusal of the others);
 *  - fw_protect_encoder (jump test without 64-bit arithmetic, rate without a
 *    division) against the original per-move Q16.16 rate and 64-bit jump test,
 *    on random count sequences (steady, stops, jumps, the 2^32 wrap).
 * The references below are the pre-optimisation code, kept verbatim in logic.
 */
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "fw_pwm.h"
#include "plan.h"
#include "protect.h"
#include "unity.h"

void setUp(void)
{
}

void tearDown(void)
{
}

/* xorshift32: deterministic pseudo-random inputs. */
static uint32_t rng = 0x9E3779B9u;
static uint32_t rnd(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 17;
    rng ^= rng << 5;
    return rng;
}

static int32_t rnd_i32(void)
{
    return fx_u2i(rnd());
}

/* A duration: in range, at the edges or far outside. */
static q24_t rnd_dur(void)
{
    static const q24_t edge[] = {0,  1,         FX_ONE - 1, FX_ONE,    FX_ONE + 1,
                                 -1, INT32_MIN, INT32_MAX,  FX_ONE / 2};
    const uint32_t k = rnd() % 4u;
    if (k == 0u) {
        return edge[rnd() % (sizeof edge / sizeof edge[0])];
    }
    if (k == 1u) {
        return rnd_i32();
    }
    return (q24_t)(rnd() % ((uint32_t)FX_ONE + 1u));
}

/* The oracle: each on-time clamped to [0, FX_ONE], summed per leg over the
 * segments whose vector has that leg high (Table 4.2; indices > 7: no leg),
 * at most CTRL_PLAN_MAX_SEG segments, each sum capped at FX_ONE. */
static void ref_plan_to_legs(const ctrl_plan_t *p, ctrl_legs_t *legs)
{
    static const uint8_t mask[8] = {0u, 1u, 3u, 2u, 6u, 4u, 5u, 7u};
    int32_t acc[3] = {0, 0, 0};
    const unsigned n = p->n_seg < CTRL_PLAN_MAX_SEG ? p->n_seg : CTRL_PLAN_MAX_SEG;
    for (unsigned i = 0u; i < n; i++) {
        const q24_t dur = fx_clamp(p->dur[i], 0, FX_ONE);
        const unsigned m = p->vec[i] <= 7u ? mask[p->vec[i]] : 0u;
        for (unsigned x = 0u; x < 3u; x++) {
            acc[x] += ((m >> x) & 1u) != 0u ? dur : 0;
        }
    }
    for (unsigned x = 0u; x < 3u; x++) {
        legs->duty[x] = fx_min(acc[x], FX_ONE);
    }
}

static void legs_check(const ctrl_plan_t *p)
{
    ctrl_legs_t want;
    ctrl_legs_t got;
    ref_plan_to_legs(p, &want);
    memset(&got, 0x5A, sizeof got);
    ctrl_plan_legs(p, &got);
    for (int x = 0; x < 3; x++) {
        if (want.duty[x] != got.duty[x]) {
            char msg[160];
            snprintf(msg, sizeof msg, "n_seg %u vec %u,%u dur %ld,%ld leg %d", (unsigned)p->n_seg,
                     (unsigned)p->vec[0], (unsigned)p->vec[1], (long)p->dur[0], (long)p->dur[1], x);
            TEST_ASSERT_EQUAL_INT32_MESSAGE(want.duty[x], got.duty[x], msg);
        }
    }
}

static void test_legs_every_pair(void)
{
    static const uint8_t vecs[] = {0u, 1u, 2u, 3u, 4u, 5u, 6u, 7u, 8u, 9u, 200u, 255u};
    const size_t nv = sizeof vecs / sizeof vecs[0];
    for (size_t a = 0; a < nv; a++) {
        for (size_t b = 0; b < nv; b++) {
            for (uint8_t n = 0u; n <= 5u; n++) {
                for (int r = 0; r < 40; r++) {
                    ctrl_plan_t p;
                    p.n_seg = n;
                    p.vec[0] = vecs[a];
                    p.vec[1] = vecs[b];
                    p.vec[2] = (uint8_t)(rnd() % 9u);
                    p.vec[3] = (uint8_t)(rnd() % 9u);
                    for (int s = 0; s < 4; s++) {
                        /* Half the plans with every on-time in range (fast form). */
                        p.dur[s] =
                            (r & 1) != 0 ? (q24_t)(rnd() % ((uint32_t)FX_ONE + 1u)) : rnd_dur();
                    }
                    legs_check(&p);
                }
            }
        }
    }
}

/* Plans as the helpers build them: exact complements, every active vector. */
static void test_legs_helper_plans(void)
{
    for (uint8_t v = 0u; v <= 7u; v++) {
        for (int r = 0; r < 2000; r++) {
            ctrl_plan_t p;
            const q24_t d = r < 3 ? (q24_t)(r * (FX_ONE / 2)) : (q24_t)(rnd() % (FX_ONE + 1u));
            ctrl_plan_active_zero(&p, v, d);
            legs_check(&p);
            ctrl_plan_single(&p, v);
            legs_check(&p);
            /* Two active vectors and a zero vector (SVM-like). */
            const q24_t d2 = (q24_t)(rnd() % ((uint32_t)(FX_ONE - d) + 1u));
            p.n_seg = 3u;
            p.vec[0] = v;
            p.dur[0] = d;
            p.vec[1] = (uint8_t)(1u + rnd() % 6u);
            p.dur[1] = d2;
            p.vec[2] = ctrl_zero_after(v);
            p.dur[2] = FX_ONE - d - d2;
            legs_check(&p);
        }
    }
}

/* ---- compare values: the 2^8-scaled form against the 64-bit rounding ---- */
static void test_pwm_compare(void)
{
    static const uint32_t ns[] = {1u,    2u,     3u,     255u,     4200u,
                                  8399u, 65535u, 65536u, 1000003u, (1u << 24) - 1u};
    for (size_t i = 0; i < sizeof ns / sizeof ns[0]; i++) {
        const uint32_t n = ns[i];
        for (uint32_t k = 0; k < 60000u; k++) {
            /* Edges, ties (d n = (2j + 1) 2^23 when possible) and random. */
            uint32_t d;
            if (k < 3u) {
                d = k == 0u ? 0u : (k == 1u ? 1u : (uint32_t)FX_ONE);
            } else if (k % 3u == 0u) {
                d = rnd() % ((uint32_t)FX_ONE + 1u);
            } else {
                d = (k * 2797u) % ((uint32_t)FX_ONE + 1u);
            }
            const uint64_t exact = ((uint64_t)d * n + (1u << 23)) >> 24;
            TEST_ASSERT_EQUAL_UINT32((uint32_t)exact, fw_pwm_compare(d, n));
            TEST_ASSERT_EQUAL_UINT32((uint32_t)exact, fw_pwm_compare8(d, n << 8));
            TEST_ASSERT_TRUE(exact <= n);
        }
        /* Exact ties: d n = 2^23 (mod 2^24) rounds up. */
        if (n % 2u == 1u) {
            const uint32_t d = 1u << 23;
            TEST_ASSERT_EQUAL_UINT32((n + 1u) / 2u, fw_pwm_compare8(d, n << 8));
        }
    }
}

/* ---- over-current ---- */
static uint32_t ref_current(q24_t lim, q24_t i_a, q24_t i_b)
{
    const q24_t i_c = fx_neg(fx_add(i_a, i_b));
    return fx_abs(i_a) > lim || fx_abs(i_b) > lim || fx_abs(i_c) > lim ? FW_FAULT_OVERCURRENT
                                                                       : FW_FAULT_NONE;
}

static q24_t near(q24_t lim)
{
    /* Values around +-lim, +-2 lim and the int32_t ends. */
    const int64_t base[] = {lim,       -(int64_t)lim, 2 * (int64_t)lim, -2 * (int64_t)lim, 0,
                            INT32_MAX, INT32_MIN,     (int64_t)lim / 2, -(int64_t)lim / 2};
    const int64_t v = base[rnd() % (sizeof base / sizeof base[0])] + (int64_t)(rnd() % 5u) - 2;
    return v > INT32_MAX ? INT32_MAX : (v < INT32_MIN ? INT32_MIN : (q24_t)v);
}

static void test_current_fast(void)
{
    static const q24_t bad[] = {(1 << 30) + 1, INT32_MAX - 1, INT32_MAX, -1, INT32_MIN};
    for (size_t l = 0; l < sizeof bad / sizeof bad[0]; l++) {
        fw_protect_cfg_t cfg = {bad[l], FX_ONE, 0, 5, 8, 65536, 0u, 0u};
        fw_protect_t p;
        TEST_ASSERT_EQUAL_INT(CTRL_EINVAL, fw_protect_init(&p, &cfg));
    }
    static const q24_t lims[] = {0, 1, FX_ONE / 2, FX_ONE * 3, 1 << 30, 123456789};
    for (size_t l = 0; l < sizeof lims / sizeof lims[0]; l++) {
        fw_protect_cfg_t cfg = {lims[l], FX_ONE, 0, 5, 8, 65536, 0u, 0u};
        fw_protect_t p;
        TEST_ASSERT_EQUAL_INT(CTRL_OK, fw_protect_init(&p, &cfg));
        for (int r = 0; r < 20000; r++) {
            const q24_t a = (r & 1) != 0 ? near(lims[l]) : rnd_i32();
            const q24_t b = (r & 2) != 0 ? near(lims[l]) : rnd_i32();
            const uint32_t want = ref_current(lims[l], a, b);
            if (fw_protect_current(&p, a, b) != want) {
                char msg[120];
                snprintf(msg, sizeof msg, "lim %ld i_a %ld i_b %ld", (long)lims[l], (long)a,
                         (long)b);
                TEST_FAIL_MESSAGE(msg);
            }
        }
    }
}

/* ---- encoder: the original check (per-move Q16.16 rate, 64-bit jump) ---- */
typedef struct {
    uint32_t last;
    int32_t last_delta;
    uint32_t still;
    int32_t rate_q16;
    int32_t move; /* the last move's counts (0: none since priming) */
    uint8_t primed;
} ref_enc_t;

static uint32_t ref_encoder(ref_enc_t *p, const fw_protect_cfg_t *cfg, uint32_t count)
{
    if (p->primed == 0u) {
        p->last = count;
        p->primed = 1u;
        return FW_FAULT_NONE;
    }
    const uint32_t du = count - p->last;
    const int32_t delta = du <= (uint32_t)INT32_MAX ? (int32_t)du : -(int32_t)(UINT32_MAX - du) - 1;
    p->last = count;
    uint32_t fault = FW_FAULT_NONE;
    if (p->primed == 1u) {
        p->primed = 2u;
        p->last_delta = delta;
        p->rate_q16 = 0;
        return FW_FAULT_NONE;
    }
    if (delta != 0) {
        const int64_t dd = (int64_t)delta - p->last_delta;
        if (dd > cfg->enc_jump_max || dd < -(int64_t)cfg->enc_jump_max) {
            fault = FW_FAULT_ENC_JUMP;
        }
        /* The counts surely travelled: |delta| after a move the same way,
         * |delta| - 1 after a reversal or none; over still + 2 periods. */
        const int64_t mag = delta < 0 ? -(int64_t)delta : (int64_t)delta;
        const bool same = (delta > 0 && p->move > 0) || (delta < 0 && p->move < 0);
        const int64_t rate = (same ? mag : mag - 1) * 65536 / ((int64_t)p->still + 2);
        p->move = delta;
        p->rate_q16 = rate > INT32_MAX ? INT32_MAX : (int32_t)rate;
        p->still = 0u;
    } else {
        if (p->still < UINT32_MAX) {
            p->still++;
        }
        if (p->still >= cfg->enc_stuck_periods && p->rate_q16 >= cfg->enc_rate_min_q16) {
            fault = FW_FAULT_ENC_STUCK;
        }
    }
    p->last_delta = delta;
    return fault;
}

/* Next counter value: mostly a steady rate with noise, sometimes a stop,
 * a glitch or a huge step. */
static uint32_t next_count(uint32_t c, int32_t *rate)
{
    const uint32_t k = rnd() % 100u;
    if (k < 3u) {
        *rate = (int32_t)(rnd() % 7u) - 3;
    } else if (k < 5u) {
        *rate = 0;
    } else if (k < 6u) {
        return c + rnd(); /* anything, incl. |delta| >= 2^15 and 2^31 */
    } else if (k < 8u) {
        return c + (uint32_t)(int32_t)((int32_t)(rnd() % 41u) - 20);
    } else if (k < 9u) {
        *rate = fx_u2i(rnd()) / 65536 * 2; /* |rate| up to 2^16 */
    }
    const int32_t noise = (rnd() % 4u == 0u) ? (int32_t)(rnd() % 3u) - 1 : 0;
    return c + (uint32_t)(*rate + noise);
}

static void test_encoder_fast(void)
{
    static const int32_t jumps[] = {5, 0, 1, 40, -3, INT32_MAX, 100000};
    static const int32_t rmins[] = {65536, 1, 0, -5, 3 * 65536 + 7, INT32_MAX, 20000};
    static const uint32_t stucks[] = {8u, 1u, 0u, 3u, 50u};
    for (size_t j = 0; j < sizeof jumps / sizeof jumps[0]; j++) {
        for (size_t r = 0; r < sizeof rmins / sizeof rmins[0]; r++) {
            for (size_t s = 0; s < sizeof stucks / sizeof stucks[0]; s++) {
                fw_protect_cfg_t cfg = {FX_ONE, FX_ONE, 0, jumps[j], stucks[s], rmins[r], 0u, 0u};
                fw_protect_t p;
                TEST_ASSERT_EQUAL_INT(CTRL_OK, fw_protect_init(&p, &cfg));
                ref_enc_t ref;
                memset(&ref, 0, sizeof ref);
                uint32_t c = rnd();
                int32_t rate = 3;
                for (int k = 0; k < 3000; k++) {
                    if (k % 1000 == 999) {
                        fw_protect_reset(&p);
                        memset(&ref, 0, sizeof ref);
                    }
                    const uint32_t want = ref_encoder(&ref, &cfg, c);
                    const uint32_t got = fw_protect_encoder(&p, c);
                    if (want != got) {
                        char msg[160];
                        snprintf(msg, sizeof msg,
                                 "jump %ld rate_min %ld stuck %lu k %d: %lu vs %lu", (long)jumps[j],
                                 (long)rmins[r], (unsigned long)stucks[s], k, (unsigned long)want,
                                 (unsigned long)got);
                        TEST_FAIL_MESSAGE(msg);
                    }
                    c = next_count(c, &rate);
                }
            }
        }
    }
}

/* Deadline and watchdog: 0 disables the check; otherwise the fault is above
 * the limit, up to the largest values. */
static void test_deadline_watchdog_limits(void)
{
    static const uint32_t lims[] = {0u, 1u, 1000u, UINT32_MAX - 1u, UINT32_MAX};
    for (size_t l = 0; l < sizeof lims / sizeof lims[0]; l++) {
        fw_protect_cfg_t cfg = {FX_ONE, FX_ONE, 0, 5, 8, 65536, lims[l], lims[l]};
        fw_protect_t p;
        TEST_ASSERT_EQUAL_INT(CTRL_OK, fw_protect_init(&p, &cfg));
        static const uint32_t el[] = {0u, 1u, 2u, 999u, 1000u, 1001u, UINT32_MAX - 1u, UINT32_MAX};
        for (size_t e = 0; e < sizeof el / sizeof el[0]; e++) {
            const uint32_t want =
                lims[l] != 0u && el[e] > lims[l] ? FW_FAULT_DEADLINE : FW_FAULT_NONE;
            TEST_ASSERT_EQUAL_UINT32(want, fw_protect_deadline(&p, el[e]));
            /* Watchdog: the periods since the last kick */
            TEST_ASSERT_EQUAL_UINT32(lims[l] != 0u && el[e] > lims[l] ? FW_FAULT_WATCHDOG
                                                                      : FW_FAULT_NONE,
                                     fw_protect_watchdog_tick(&p, el[e]));
        }
    }
}

/* fw_legs_limit: every leg within [0, dmax]; unchanged below the cap; the
 * line voltages kept exactly where max - min <= dmax; otherwise the lowest
 * leg at 0 and each leg min(d - min, dmax) (the least volt-seconds cut). */
static void check_limit(const int32_t in[3], int32_t dmax)
{
    int32_t d[3] = {in[0], in[1], in[2]};
    fw_legs_limit(d, dmax);
    int32_t hi = in[0], lo = in[0];
    for (int x = 1; x < 3; x++) {
        hi = in[x] > hi ? in[x] : hi;
        lo = in[x] < lo ? in[x] : lo;
    }
    char msg[120];
    snprintf(msg, sizeof msg, "in %ld %ld %ld dmax %ld -> %ld %ld %ld", (long)in[0], (long)in[1],
             (long)in[2], (long)dmax, (long)d[0], (long)d[1], (long)d[2]);
    for (int x = 0; x < 3; x++) {
        TEST_ASSERT_TRUE_MESSAGE(d[x] >= 0 && d[x] <= dmax, msg);
        if (hi <= dmax) {
            TEST_ASSERT_EQUAL_INT32_MESSAGE(in[x], d[x], msg);
        } else if (hi - lo <= dmax) {
            TEST_ASSERT_EQUAL_INT32_MESSAGE(in[x] - in[(x + 1) % 3], d[x] - d[(x + 1) % 3], msg);
        } else {
            const int32_t want = in[x] - lo < dmax ? in[x] - lo : dmax;
            TEST_ASSERT_EQUAL_INT32_MESSAGE(want, d[x], msg);
        }
    }
}

static void test_legs_limit(void)
{
    const int32_t one = 1 << 24;
    const int32_t esc1 = (int32_t)(((int64_t)3910 << 24) / 4250); /* B-G431B-ESC1, 20 kHz */
    const int32_t dmaxes[] = {one, esc1, one - 1, 1, one / 2};
    const int32_t edges[][3] = {{one, one, one},    {one, 0, 0},       {one, one, 0},
                                {0, 0, 0},          {one, one - 1, 1}, {esc1, esc1, esc1},
                                {esc1 + 1, 0, esc1}};
    for (size_t k = 0; k < sizeof dmaxes / sizeof dmaxes[0]; k++) {
        for (size_t e = 0; e < sizeof edges / sizeof edges[0]; e++) {
            check_limit(edges[e], dmaxes[k]);
        }
        for (int i = 0; i < 20000; i++) {
            const int32_t in[3] = {(int32_t)(rnd() % (uint32_t)(one + 1)),
                                   (int32_t)(rnd() % (uint32_t)(one + 1)),
                                   (int32_t)(rnd() % (uint32_t)(one + 1))};
            check_limit(in, dmaxes[k]);
        }
    }
    /* An active vector with V7 as its zero vector, below the cap's reach:
     * the same line voltages with V0 instead. */
    int32_t v7[3] = {one, one - one / 4, one - one / 4};
    fw_legs_limit(v7, esc1);
    TEST_ASSERT_EQUAL_INT32(one / 4, v7[0] - v7[1]);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_legs_every_pair);
    RUN_TEST(test_legs_helper_plans);
    RUN_TEST(test_pwm_compare);
    RUN_TEST(test_legs_limit);
    RUN_TEST(test_current_fast);
    RUN_TEST(test_encoder_fast);
    RUN_TEST(test_deadline_watchdog_limits);
    return UNITY_END();
}
