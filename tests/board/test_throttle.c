/*
 * The servo-style throttle decoder (firmware/throttle/throttle.h) fed by a
 * simulated pulse source: a sender at 50..490 Hz with a set width, jitter
 * (a fixed-seed generator, the same sequence on the host and in QEMU),
 * glitches (through a model of the board's TIM2 capture), an unplugged wire
 * and out-of-range pulses. The bounds come from
 * the rules the decoder implements (the ESC convention and the RC signal's
 * limits): arming after 1 s at the low end, never with the throttle high at
 * power-up; no valid pulse for 100 ms -> the reference ramps to zero over
 * 100 ms, then disarm with the cause.
 */
#include <stdbool.h>
#include <string.h>

#include "g4_model.h"
#include "g4_regs.h"
#include "g4_tim.h"
#include "throttle.h"
#include "unity.h"

static thr_t thr;
static uint32_t t_us;    /* simulated time */
static uint32_t next_us; /* next rising edge */
static uint32_t seed;
static uint32_t n_arm, n_disarm;
static uint32_t t_arm_ms, t_disarm_ms;
static thr_out_t last;

typedef struct {
    uint32_t period_us; /* 0: no pulses (wire unplugged) */
    uint32_t width_us;
    uint32_t jitter_us;    /* width +- jitter, uniform */
    uint32_t glitch_every; /* run_capture: every n-th period also carries a 30..300 us spike */
} sender_t;

/* The board's capture (TIM2 in PWM input mode, g4_tim2_capture_init; RM0440
 * TIM2/3/4/5 "PWM input mode", slave mode controller in reset mode), on the
 * register model (g4_model.c): on a rising edge of TI1, CCR1 takes the
 * counter (the period since the last rising edge), CC1IF is set and the
 * counter restarts from 0; on a falling edge CCR2 takes the counter (the
 * high time), CC2IF set. The main loop's read is the driver's own,
 * g4_tim2_capture_read (CC1IF, then CNT, CCR1, CCR2, CNT; it reports nothing
 * when the read comes later than the width after the period's end: not
 * reached here, reads every 20 us, widths from 30 us; test_g4_regimage
 * checks that case). 1 us counts; the 32-bit counter never wraps within
 * these runs. */
static uint32_t tim2_origin; /* time of the last counter reset, us */
/* The edges of the sender's period in progress: edge_at[edge_i..edge_n)
 * still to come (rising or falling: edge_rise). */
static uint32_t edge_at[4];
static bool edge_rise[4];
static unsigned edge_n, edge_i;

static uint32_t rnd(void)
{
    seed = seed * 1664525u + 1013904223u;
    return seed >> 8;
}

static void reset(uint8_t mode)
{
    thr_config_t c;
    thr_config_default(&c);
    c.mode = mode;
    TEST_ASSERT_EQUAL_INT(0, thr_config_check(&c));
    t_us = 0u;
    next_us = 3000u;
    seed = 12345u;
    n_arm = n_disarm = 0u;
    g4_model_reset();
    tim2_origin = 0u;
    edge_n = edge_i = 0u;
    thr_init(&thr, &c, 0u);
}

/* Runs the sender for ms milliseconds: a pulse is reported at its falling
 * edge with the period since the previous rising edge; thr_update every 1 ms
 * (the main loop). */
/* The main loop's decoder step at t_us, its arm and disarm events counted. */
static void update_and_count(void)
{
    last = thr_update(&thr, t_us / 1000u);
    if (last.event == THR_EV_ARM) {
        n_arm++;
        t_arm_ms = t_us / 1000u;
    } else if (last.event == THR_EV_DISARM) {
        n_disarm++;
        t_disarm_ms = t_us / 1000u;
    }
}

static void run(const sender_t *s, uint32_t ms)
{
    const uint32_t end = t_us + ms * 1000u;
    while (t_us < end) {
        t_us += 1000u;
        while (s->period_us != 0u && next_us + s->width_us <= t_us) {
            uint32_t w = s->width_us;
            if (s->jitter_us != 0u) {
                w = w - s->jitter_us + rnd() % (2u * s->jitter_us + 1u);
            }
            thr_pulse(&thr, w, s->period_us, (next_us + w) / 1000u);
            next_us += s->period_us;
        }
        if (s->period_us == 0u) {
            next_us = t_us + 3000u;
        }
        update_and_count();
    }
}

static void tim2_edge(uint32_t at_us, bool rising)
{
    const uint32_t cnt = at_us - tim2_origin;
    const uint32_t sr = g4_model_get(G4_TIM2 + G4_TIM_SR);
    if (rising) {
        g4_model_put(G4_TIM2 + G4_TIM_CCR1, cnt);
        g4_model_put(G4_TIM2 + G4_TIM_SR, sr | G4_TIM_SR_CC1IF);
        tim2_origin = at_us; /* reset mode: the trigger TI1FP1 clears the counter */
    } else {
        g4_model_put(G4_TIM2 + G4_TIM_CCR2, cnt);
        g4_model_put(G4_TIM2 + G4_TIM_SR, sr | G4_TIM_SR_CC2IF);
    }
}

static uint32_t n_rise, n_spike; /* rising edges of the sender, spikes, so far */

#define CAPTURE_POLL_US 20u /* a main-loop pass without a command line */

/* The sender's edges up to t_us into tim2. */
static void capture_edges(const sender_t *s, uint32_t spike_at_us)
{
    static uint32_t n_period;
    for (;;) {
        if (edge_i == edge_n) { /* the next period's edges */
            const uint32_t r = next_us;
            edge_n = edge_i = 0u;
            edge_at[edge_n] = r;
            edge_rise[edge_n++] = true;
            edge_at[edge_n] = r + s->width_us;
            edge_rise[edge_n++] = false;
            n_period++;
            if (s->glitch_every != 0u && n_period % s->glitch_every == 0u) {
                TEST_ASSERT_TRUE(spike_at_us > s->width_us && spike_at_us + 300u < s->period_us);
                edge_at[edge_n] = r + spike_at_us;
                edge_rise[edge_n++] = true;
                edge_at[edge_n] = r + spike_at_us + 30u + rnd() % 271u;
                edge_rise[edge_n++] = false;
            }
            next_us += s->period_us;
        }
        if (edge_at[edge_i] > t_us) {
            return;
        }
        tim2_edge(edge_at[edge_i], edge_rise[edge_i]);
        if (edge_rise[edge_i]) {
            if (edge_i == 0u) {
                n_rise++;
            } else {
                n_spike++;
            }
        }
        edge_i++;
    }
}

/* As run(), through the capture: the sender's edges in time order into
 * tim2, every n-th period (s->glitch_every) with a spike rising spike_at_us
 * after the period's rising edge (after the pulse's falling edge), 30..300 us
 * wide. The main loop reads the capture every CAPTURE_POLL_US, as
 * esc1_throttle_poll does on each pass, and hands it to thr_pulse; it steps
 * the decoder every 1 ms. A spike shorter than the main loop's pass can end
 * before the read, which then reports nothing for that period (not
 * modelled: these spikes outlast the pass). */
static void run_capture(const sender_t *s, uint32_t spike_at_us, uint32_t ms)
{
    const uint32_t end = t_us + ms * 1000u;
    while (t_us < end) {
        const uint32_t step_end = t_us + 1000u;
        while (t_us < step_end) {
            t_us += CAPTURE_POLL_US;
            capture_edges(s, spike_at_us);
            g4_model_put(G4_TIM2 + G4_TIM_CNT, t_us - tim2_origin);
            uint32_t w = 0u, per = 0u;
            if (g4_tim2_capture_read(&w, &per)) {
                thr_pulse(&thr, w, per, t_us / 1000u);
            }
        }
        update_and_count();
    }
}

/* Low end at 50 Hz with +-5 us jitter: armed after 1 s of it, not before.
 * The first pulse ends at 3.995..4.005 ms: arming 1 s after it, at most one
 * period plus one main-loop step later. */
static void test_arms_after_one_second_at_the_low_end(void)
{
    reset(THR_MODE_TORQUE);
    const sender_t low = {20000u, 1000u, 5u, 0u};
    run(&low, 1000u);
    TEST_ASSERT_EQUAL_UINT32(0u, n_arm);
    run(&low, 100u);
    TEST_ASSERT_EQUAL_UINT32(1u, n_arm);
    TEST_ASSERT_TRUE(t_arm_ms >= 1003u && t_arm_ms <= 1005u + 20u + 1u);
    TEST_ASSERT_EQUAL_INT32(0, last.ref);
    TEST_ASSERT_EQUAL_UINT8(THR_ARMED, thr.state);
}

/* Throttle high at power-up (490 Hz, 1600 us) for 5 s: never armed. Then
 * at the low end: armed 1 s after the first low pulse, not earlier. */
static void test_throttle_high_at_power_up_never_arms(void)
{
    reset(THR_MODE_TORQUE);
    const sender_t high = {2040u, 1600u, 3u, 0u};
    run(&high, 5000u);
    TEST_ASSERT_EQUAL_UINT32(0u, n_arm);
    TEST_ASSERT_TRUE(thr.n_valid > 2000u);
    const uint32_t t_low = t_us / 1000u;
    const sender_t low = {2040u, 1010u, 3u, 0u};
    run(&low, 990u);
    TEST_ASSERT_EQUAL_UINT32(0u, n_arm);
    run(&low, 30u);
    TEST_ASSERT_EQUAL_UINT32(1u, n_arm);
    /* the pulse in flight at the switch may end (low) up to 1 ms before it */
    TEST_ASSERT_TRUE(t_arm_ms + 1u >= t_low + 1000u);
}

/* A break in the low-end run restarts the second: 600 ms low, 200 ms at
 * 1400 us, then low: armed 1 s after the return, not 1 s after the start. */
static void test_arming_needs_an_unbroken_second(void)
{
    reset(THR_MODE_SPEED);
    const sender_t low = {20000u, 1000u, 0u, 0u};
    const sender_t mid = {20000u, 1400u, 0u, 0u};
    run(&low, 600u);
    run(&mid, 200u);
    const uint32_t t_back = t_us / 1000u;
    run(&low, 990u);
    TEST_ASSERT_EQUAL_UINT32(0u, n_arm);
    run(&low, 50u);
    TEST_ASSERT_EQUAL_UINT32(1u, n_arm);
    TEST_ASSERT_TRUE(t_arm_ms + 1u >= t_back + 1000u);
}

static void arm(void)
{
    const sender_t low = {4000u, 1000u, 0u, 0u};
    run(&low, 1100u);
    TEST_ASSERT_EQUAL_UINT32(1u, n_arm);
}

/* Reference: 0 up to low + dead band (1030 us), linear to 1 at 2000 us,
 * 1 above: (1515 - 1030) / (2000 - 1030) = 1/2 exactly. With +-4 us jitter
 * it stays within 4 / 970 of full scale of the value at the nominal width. */
static void test_reference_follows_the_width(void)
{
    reset(THR_MODE_TORQUE);
    arm();
    const uint32_t w[5] = {1000u, 1030u, 1515u, 2000u, 2150u};
    const q24_t want[5] = {0, 0, FX_ONE / 2, FX_ONE, FX_ONE};
    for (unsigned i = 0; i < 5u; i++) {
        const sender_t s = {4000u, w[i], 0u, 0u};
        run(&s, 20u);
        TEST_ASSERT_EQUAL_INT32(want[i], last.ref);
    }
    const sender_t jit = {4000u, 1515u, 4u, 0u};
    const int32_t bound = (int32_t)(((int64_t)4 << 24) / 970 + 1);
    for (unsigned k = 0; k < 200u; k++) {
        run(&jit, 1u);
        TEST_ASSERT_INT32_WITHIN(bound, FX_ONE / 2, last.ref);
    }
    TEST_ASSERT_EQUAL_UINT32(1u, n_arm);
    TEST_ASSERT_EQUAL_UINT32(0u, n_disarm);
}

/* A spike 2.5 ms after a rising edge (1 ms after the 1515 us pulse's
 * falling edge), every third period of 4 ms: the capture splits that period
 * in two, a pulse of 1515 us in a 2500 us "period" (valid: at least the
 * 2000 us of 500 Hz) and a spike's width in the 1500 us rest (invalid). So
 * every period still gives its valid pulse, each spike one invalid reading;
 * the reference and the arming are untouched. */
static void test_spike_late_in_the_period_splits_it(void)
{
    reset(THR_MODE_TORQUE);
    arm();
    const sender_t s = {4000u, 1515u, 0u, 3u};
    run_capture(&s, 2500u, 20u); /* the first reading spans the switch */
    const uint32_t v0 = thr.n_valid, i0 = thr.n_invalid, r0 = n_rise, k0 = n_spike;
    run_capture(&s, 2500u, 2000u);
    const uint32_t rises = n_rise - r0, spikes = n_spike - k0;
    TEST_ASSERT_UINT32_WITHIN(1u, 166u, spikes);
    TEST_ASSERT_UINT32_WITHIN(1u, rises, thr.n_valid - v0);
    TEST_ASSERT_UINT32_WITHIN(1u, spikes, thr.n_invalid - i0);
    TEST_ASSERT_EQUAL_INT32(FX_ONE / 2, last.ref);
    TEST_ASSERT_EQUAL_UINT32(0u, n_disarm);
    TEST_ASSERT_EQUAL_UINT8(THR_ARMED, thr.state);
}

/* A spike less than 2 ms after a rising edge (1.8 ms: 285 us after the
 * pulse's falling edge), every third period: the good pulse is read in a
 * 1800 us "period", shorter than 500 Hz allows, and is lost with the spike's
 * own reading, two invalid readings per spike and one valid pulse fewer per
 * spike. The pulses left (one every 12 ms, inside the 100 ms time-out) keep
 * the drive armed at the same reference. */
static void test_spike_early_in_the_period_invalidates_the_pulse(void)
{
    reset(THR_MODE_TORQUE);
    arm();
    const sender_t s = {4000u, 1515u, 0u, 3u};
    run_capture(&s, 1800u, 20u);
    const uint32_t v0 = thr.n_valid, i0 = thr.n_invalid, r0 = n_rise, k0 = n_spike;
    run_capture(&s, 1800u, 2000u);
    const uint32_t rises = n_rise - r0, spikes = n_spike - k0;
    TEST_ASSERT_UINT32_WITHIN(1u, 166u, spikes);
    TEST_ASSERT_UINT32_WITHIN(1u, rises - spikes, thr.n_valid - v0);
    TEST_ASSERT_UINT32_WITHIN(2u, 2u * spikes, thr.n_invalid - i0);
    TEST_ASSERT_EQUAL_INT32(FX_ONE / 2, last.ref);
    TEST_ASSERT_EQUAL_UINT32(0u, n_disarm);
    TEST_ASSERT_EQUAL_UINT8(THR_ARMED, thr.state);
}

/* The same spike in every period: no reading is valid, which is a lost
 * signal though pulses keep coming. The reference holds for the 100 ms
 * time-out after the last valid pulse, ramps to zero over 100 ms, and the
 * drive is disarmed with cause "invalid" (pulses, none valid). */
static void test_repeated_spikes_read_as_signal_loss(void)
{
    reset(THR_MODE_TORQUE);
    arm();
    const sender_t good = {4000u, 1515u, 0u, 0u};
    run_capture(&good, 0u, 100u);
    TEST_ASSERT_EQUAL_INT32(FX_ONE / 2, last.ref);
    const uint32_t v0 = thr.n_valid;
    const sender_t s = {4000u, 1515u, 0u, 1u};
    run_capture(&s, 1800u, 400u);
    TEST_ASSERT_TRUE(thr.n_valid - v0 <= 1u); /* the period before the first spike */
    const uint32_t t_last = thr.t_valid_ms;
    TEST_ASSERT_EQUAL_UINT32(1u, n_disarm);
    TEST_ASSERT_EQUAL_UINT8(THR_CAUSE_INVALID, thr.cause);
    TEST_ASSERT_TRUE(t_disarm_ms >= t_last + THR_TIMEOUT_MS + THR_RAMP_MS &&
                     t_disarm_ms <= t_last + THR_TIMEOUT_MS + THR_RAMP_MS + 2u);
    TEST_ASSERT_EQUAL_INT32(0, last.ref);
    TEST_ASSERT_TRUE(thr.n_invalid > 150u);
}

/* Wire unplugged at full throttle: the reference holds for the 100 ms
 * time-out after the last pulse, then falls linearly to zero over 100 ms
 * (half way at 50 ms), then the drive is disarmed with cause "no pulse".
 * Pulses coming back high do not re-arm it; 1 s at the low end does. */
static void test_unplugged_wire_ramps_down_and_disarms(void)
{
    reset(THR_MODE_TORQUE);
    arm();
    const sender_t full = {4000u, 2000u, 0u, 0u};
    run(&full, 100u);
    const uint32_t t_last = thr.t_valid_ms;
    const sender_t none = {0u, 0u, 0u, 0u};
    run(&none, t_last + 100u - t_us / 1000u);
    TEST_ASSERT_EQUAL_INT32(FX_ONE, last.ref); /* still within the time-out */
    run(&none, 51u);
    TEST_ASSERT_EQUAL_UINT8(THR_RAMP_DOWN, thr.state);
    TEST_ASSERT_INT32_WITHIN(FX_ONE / 50, FX_ONE / 2, last.ref);
    TEST_ASSERT_INT32_WITHIN(FX_ONE / 50, FX_ONE / 2, last.ramp);
    q24_t prev = last.ref;
    for (unsigned k = 0; k < 60u && n_disarm == 0u; k++) {
        run(&none, 1u);
        TEST_ASSERT_TRUE(last.ref <= prev);
        prev = last.ref;
    }
    TEST_ASSERT_EQUAL_UINT32(1u, n_disarm);
    TEST_ASSERT_TRUE(t_disarm_ms >= t_last + 200u && t_disarm_ms <= t_last + 202u);
    TEST_ASSERT_EQUAL_INT32(0, last.ref);
    TEST_ASSERT_EQUAL_UINT8(THR_CAUSE_NO_PULSE, thr.cause);

    run(&full, 3000u);
    TEST_ASSERT_EQUAL_UINT32(1u, n_arm);
    TEST_ASSERT_EQUAL_INT32(0, last.ref);
    const sender_t low = {4000u, 1000u, 0u, 0u};
    run(&low, 1100u);
    TEST_ASSERT_EQUAL_UINT32(2u, n_arm);
    TEST_ASSERT_EQUAL_UINT8(THR_CAUSE_NONE, thr.cause);
}

/* Pulses that keep coming but are out of range (2500 us; or 1500 us at
 * 600 Hz, a period below 490 Hz's): no valid pulse, so the same loss, with
 * cause "invalid". Pulses at 800 and 2200 us are still valid. */
static void test_out_of_range_pulses_are_a_loss(void)
{
    const sender_t bad[2] = {{4000u, 2500u, 0u, 0u}, {1667u, 1500u, 0u, 0u}};
    for (unsigned i = 0; i < 2u; i++) {
        reset(THR_MODE_TORQUE);
        arm();
        run(&bad[i], 250u);
        TEST_ASSERT_EQUAL_UINT32(1u, n_disarm);
        TEST_ASSERT_EQUAL_UINT8(THR_CAUSE_INVALID, thr.cause);
        TEST_ASSERT_EQUAL_UINT8(THR_WAIT_LOW, thr.state);
    }
    reset(THR_MODE_TORQUE);
    arm();
    const sender_t edge[2] = {{20000u, 800u, 0u, 0u}, {20000u, 2200u, 0u, 0u}};
    run(&edge[0], 500u);
    run(&edge[1], 500u);
    TEST_ASSERT_EQUAL_UINT32(0u, n_disarm);
    TEST_ASSERT_EQUAL_INT32(FX_ONE, last.ref);
}

/* Settings outside their ranges are refused, naming which. */
static void test_config_check(void)
{
    thr_config_t c;
    thr_config_default(&c);
    TEST_ASSERT_EQUAL_INT(0, thr_config_check(&c));
    c.mode = 3u;
    TEST_ASSERT_EQUAL_INT(1, thr_config_check(&c));
    thr_config_default(&c);
    c.low_us = 799u;
    TEST_ASSERT_EQUAL_INT(2, thr_config_check(&c));
    thr_config_default(&c);
    c.high_us = 2201u;
    TEST_ASSERT_EQUAL_INT(3, thr_config_check(&c));
    thr_config_default(&c);
    c.deadband_us = 500u;
    TEST_ASSERT_EQUAL_INT(4, thr_config_check(&c));
    /* a restart with the settings in force (c pointing into the state) */
    thr_config_default(&c);
    c.low_us = 1100u;
    thr_init(&thr, &c, 0u);
    thr_init(&thr, &thr.cfg, 5u);
    TEST_ASSERT_EQUAL_UINT16(1100u, thr.cfg.low_us);
}

void setUp(void)
{
}

void tearDown(void)
{
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_arms_after_one_second_at_the_low_end);
    RUN_TEST(test_throttle_high_at_power_up_never_arms);
    RUN_TEST(test_arming_needs_an_unbroken_second);
    RUN_TEST(test_reference_follows_the_width);
    RUN_TEST(test_spike_late_in_the_period_splits_it);
    RUN_TEST(test_spike_early_in_the_period_invalidates_the_pulse);
    RUN_TEST(test_repeated_spikes_read_as_signal_loss);
    RUN_TEST(test_unplugged_wire_ramps_down_and_disarms);
    RUN_TEST(test_out_of_range_pulses_are_a_loss);
    RUN_TEST(test_config_check);
    return UNITY_END();
}
