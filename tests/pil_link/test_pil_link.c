/*
 * The PIL link (firmware/protocol/pil_frame.h) and the target's side of it
 * (firmware/apps/pil_target): payload round trips, every single-bit error of
 * a frame detected, and the target's named faults with the gates off: a
 * corrupted frame (CRC), a frame out of sequence, a malformed one, and no
 * frame within the time-out (a fake clock). Runs on the host and in QEMU.
 */
#include <stddef.h>
#include <string.h>

#include "../plant/ini_machines.h"
#include "pil_frame.h"
#include "pil_shared.h"
#include "pil_target.h"
#include "unity.h"

void setUp(void)
{
}

void tearDown(void)
{
}

/* ---- a fake port: output captured, clock set by the test ---- */

typedef struct {
    uint8_t out[4096];
    size_t n;
    uint32_t now;
} fake_port_t;

static fake_port_t fp;

static int fake_read(void *ctx, uint8_t *buf, size_t cap)
{
    (void)ctx;
    (void)buf;
    (void)cap;
    return -1;
}

static void fake_write(void *ctx, const uint8_t *buf, size_t n)
{
    fake_port_t *f = ctx;
    TEST_ASSERT_TRUE(f->n + n <= sizeof f->out);
    memcpy(&f->out[f->n], buf, n);
    f->n += n;
}

static uint32_t fake_now(void *ctx)
{
    return ((fake_port_t *)ctx)->now;
}

static uint32_t fake_cycles(void)
{
    return 0u;
}

static const pil_port_t port = {&fp, fake_read, fake_write, fake_now, 1000u, fake_cycles, 0u, 50u};
static pil_target_t tgt;

/* The frames the target wrote since the last call, decoded in order. */
static size_t take_frames(pil_frame_t *f, size_t max)
{
    static pil_dec_t d;
    pil_dec_init(&d);
    size_t k = 0;
    for (size_t i = 0; i < fp.n; i++) {
        bool got = false;
        TEST_ASSERT_EQUAL_INT(PIL_OK,
                              pil_dec_feed(&d, fp.out[i], &f[k < max ? k : max - 1u], &got));
        k += got ? 1u : 0u;
    }
    fp.n = 0u;
    return k;
}

static void feed(const uint8_t *w, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        TEST_ASSERT_EQUAL_INT(0, pil_target_byte(&tgt, w[i]));
    }
}

static size_t wire_of(uint8_t type, uint16_t seq, const uint8_t *p, size_t n, uint8_t *w)
{
    const size_t len = pil_frame_encode(type, seq, p, n, w, PIL_WIRE_MAX);
    TEST_ASSERT_TRUE(len > 0u);
    return len;
}

/* The thesis SPMSM on a 12-bit ADC (hal/sim's defaults: 1.5 current_max
 * and 2 Vdc full scale), m2ptfc at 10 kHz, 4 calibration samples. */
static void setup_thesis(pil_setup_t *s)
{
    memset(s, 0, sizeof *s);
    (void)strcpy(s->ctrl, "m2ptfc");
    s->machine = ini_thesis_spmsm;
    s->calib_samples = 4u;
    s->psi_adapt = true;
    s->enc_direction = 1;
    s->info.pwm_freq_hz = 10000u;
    s->info.period_counts = 5000u;
    s->info.adc_bits = 12u;
    s->info.adc_current_a_per_count = 2.0 * 1.5 * 10.5 / 4096.0;
    s->info.adc_vdc_v_per_count = 2.0 * 220.0 / 4096.0;
    s->info.encoder_counts_per_rev = 10000u;
    s->info.has_i_c = true;
}

static void start_target(void)
{
    memset(&tgt, 0, sizeof tgt);
    tgt.port = &port;
    pil_dec_init(&tgt.dec);
    fp.n = 0u;
    fp.now = 1000u;
    static pil_setup_t s;
    setup_thesis(&s);
    static uint8_t p[PIL_BODY_MAX];
    static uint8_t w[PIL_WIRE_MAX];
    const size_t n = pil_setup_pack(&s, p, sizeof p);
    TEST_ASSERT_TRUE(n > 0u);
    feed(w, wire_of(PIL_T_SETUP, 0u, p, n, w));
    static pil_frame_t f[4];
    TEST_ASSERT_EQUAL_UINT(1u, take_frames(f, 4u));
    TEST_ASSERT_EQUAL_UINT(PIL_T_READY, f[0].type);
    pil_ready_t rd;
    TEST_ASSERT_EQUAL_INT(PIL_OK, pil_ready_unpack(f[0].payload, f[0].len, &rd));
    TEST_ASSERT_EQUAL_INT(0, rd.rc);
}

/* One period at rest: mid-scale currents, 220 V, encoder at 0. */
static size_t sample_wire(uint16_t seq, uint8_t cmd, uint8_t *w)
{
    pil_sample_t s;
    memset(&s, 0, sizeof s);
    s.adc.i_a = s.adc.i_b = s.adc.i_c = 2048u;
    s.adc.vdc = 2048u;
    s.cmd = cmd;
    s.torque_ref = 1 << 22; /* 0.25 pu */
    uint8_t p[64];
    const size_t n = pil_sample_pack(&s, p, sizeof p);
    return wire_of(PIL_T_SAMPLE, seq, p, n, w);
}

/* The target answers a SAMPLE with APPLY (seq echoed) or with FAULT (code). */
static pil_frame_t *period(uint16_t seq, uint8_t cmd)
{
    static uint8_t w[PIL_WIRE_MAX];
    static pil_frame_t f[4];
    feed(w, sample_wire(seq, cmd, w));
    TEST_ASSERT_EQUAL_UINT(1u, take_frames(f, 4u));
    return &f[0];
}

static bool gates_requested(void)
{
    hal_pwm_t pwm;
    bool written, gates, cleared;
    hal_pil_outputs(&tgt.hal, &pwm, &written, &gates, &cleared);
    return gates;
}

/* Calibrated and armed with 0.25 pu torque: the gates are requested on. */
static uint16_t run_to_gates_on(uint16_t seq)
{
    for (const uint16_t end = (uint16_t)(seq + 8u); seq < end; seq++) {
        TEST_ASSERT_EQUAL_UINT(PIL_T_APPLY, period(seq, PIL_CMD_KICK)->type);
    }
    TEST_ASSERT_EQUAL_UINT(PIL_T_APPLY,
                           period(seq++, PIL_CMD_ARM | PIL_CMD_TORQUE | PIL_CMD_KICK)->type);
    for (int k = 0; k < 4; k++) {
        const pil_frame_t *f = period(seq++, PIL_CMD_KICK);
        TEST_ASSERT_EQUAL_UINT(PIL_T_APPLY, f->type);
        TEST_ASSERT_EQUAL_UINT(seq - 1u, f->seq);
    }
    TEST_ASSERT_EQUAL_INT(FW_STATE_RUNNING, fw_state(&tgt.fw));
    TEST_ASSERT_TRUE(gates_requested());
    return seq;
}

static void assert_fault(const pil_frame_t *f, int code)
{
    TEST_ASSERT_EQUAL_UINT(PIL_T_FAULT, f->type);
    TEST_ASSERT_EQUAL_UINT(1u, f->len);
    TEST_ASSERT_EQUAL_INT(code, f->payload[0]);
    TEST_ASSERT_EQUAL_INT(code, tgt.fault);
    TEST_ASSERT_FALSE(gates_requested());
}

/* ---- tests ---- */

static void test_payload_round_trips(void)
{
    pil_sample_t s = {
        {1u, 4095u, 77u, 3000u}, {0xFFFFFFF0u, true, 123456u}, true, 0x3Fu, -(1 << 24), 0x7FFFFFFF};
    uint8_t p[PIL_BODY_MAX];
    size_t n = pil_sample_pack(&s, p, sizeof p);
    pil_sample_t s2;
    TEST_ASSERT_EQUAL_INT(PIL_OK, pil_sample_unpack(p, n, &s2));
    TEST_ASSERT_EQUAL_INT(s.torque_ref, s2.torque_ref);
    TEST_ASSERT_EQUAL_INT(s.speed_ref, s2.speed_ref);
    TEST_ASSERT_EQUAL_UINT(s.enc.count, s2.enc.count);
    TEST_ASSERT_EQUAL_UINT(s.adc.vdc, s2.adc.vdc);
    TEST_ASSERT_TRUE(s2.trip && s2.enc.index_seen);
    /* one byte short or long: a format error, never a guess */
    TEST_ASSERT_EQUAL_INT(PIL_E_FORMAT, pil_sample_unpack(p, n - 1u, &s2));
    TEST_ASSERT_EQUAL_INT(PIL_E_FORMAT, pil_sample_unpack(p, n + 1u, &s2));
    const pil_apply_t a = {{{1u, 2u, 4999u}}, PIL_OUT_PWM | PIL_OUT_GATES, 3u, 0u, 1234u, 0xBEEFu};
    n = pil_apply_pack(&a, p, sizeof p);
    pil_apply_t a2;
    TEST_ASSERT_EQUAL_INT(PIL_OK, pil_apply_unpack(p, n, &a2));
    TEST_ASSERT_EQUAL_UINT(4999u, a2.pwm.cmp[2]);
    TEST_ASSERT_EQUAL_UINT(0xBEEFu, a2.tm_digest);
    static pil_setup_t su, su2;
    setup_thesis(&su);
    su.n_sets = 2u;
    (void)strcpy(su.sets[1].name, "lambda");
    su.sets[1].value = -0.125;
    su.enc_direction = -1;
    n = pil_setup_pack(&su, p, sizeof p);
    TEST_ASSERT_EQUAL_INT(PIL_OK, pil_setup_unpack(p, n, &su2));
    TEST_ASSERT_EQUAL_STRING("m2ptfc", su2.ctrl);
    TEST_ASSERT_EQUAL_STRING("lambda", su2.sets[1].name);
    TEST_ASSERT_TRUE(su2.sets[1].value == -0.125);
    TEST_ASSERT_TRUE(su2.machine.psi_pm_wb == su.machine.psi_pm_wb);
    TEST_ASSERT_EQUAL_INT(-1, su2.enc_direction);
    TEST_ASSERT_EQUAL_UINT(su.info.period_counts, su2.info.period_counts);
    /* more tunables than a frame carries: refused on both sides */
    su.n_sets = PIL_SETS_MAX + 1u;
    TEST_ASSERT_EQUAL_UINT(0u, pil_setup_pack(&su, p, sizeof p));
}

/* Every single-bit error of a SAMPLE frame on the wire is reported (CRC or
 * format), never decoded as a frame. */
static void test_every_bit_flip_detected(void)
{
    uint8_t w[PIL_WIRE_MAX];
    const size_t n = sample_wire(77u, PIL_CMD_KICK, w);
    static pil_dec_t d;
    static pil_frame_t f;
    unsigned errors = 0u;
    for (size_t i = 0; i < n; i++) {
        for (int b = 0; b < 8; b++) {
            uint8_t c[PIL_WIRE_MAX];
            memcpy(c, w, n);
            c[i] ^= (uint8_t)(1u << b);
            pil_dec_init(&d);
            int bad = 0;
            for (size_t k = 0; k < n; k++) {
                bool got = false;
                bad += pil_dec_feed(&d, c[k], &f, &got) != PIL_OK;
                TEST_ASSERT_FALSE_MESSAGE(got, "a corrupted frame was accepted");
            }
            /* a flipped delimiter may leave the frame incomplete instead */
            TEST_ASSERT_TRUE(bad > 0 || pil_dec_busy(&d) || c[i] == 0u || w[i] == 0u);
            errors += bad > 0;
        }
    }
    TEST_ASSERT_TRUE(errors >= 8u * (n - 2u) - 16u);
}

static void test_target_period_and_digest(void)
{
    start_target();
    const pil_frame_t *f = period(1u, PIL_CMD_KICK);
    TEST_ASSERT_EQUAL_UINT(PIL_T_APPLY, f->type);
    TEST_ASSERT_EQUAL_UINT(1u, f->seq);
    pil_apply_t a;
    TEST_ASSERT_EQUAL_INT(PIL_OK, pil_apply_unpack(f->payload, f->len, &a));
    TEST_ASSERT_EQUAL_UINT(pil_tm_digest(fw_telemetry(&tgt.fw)), a.tm_digest);
    TEST_ASSERT_EQUAL_UINT(fw_state(&tgt.fw), a.state);
    TEST_ASSERT_EQUAL_UINT(0u, a.flags & PIL_OUT_GATES);
    run_to_gates_on(2u);
}

static void test_target_sequence_fault(void)
{
    start_target();
    const uint16_t seq = run_to_gates_on(1u);
    /* one SAMPLE lost: the next one's seq is one too far */
    assert_fault(period((uint16_t)(seq + 1u), PIL_CMD_KICK), PIL_E_SEQ);
    /* latched: the right seq afterwards gets FAULT too, gates stay off */
    assert_fault(period(seq, PIL_CMD_KICK), PIL_E_SEQ);
}

static void test_target_crc_fault(void)
{
    start_target();
    const uint16_t seq = run_to_gates_on(1u);
    uint8_t w[PIL_WIRE_MAX];
    const size_t n = sample_wire(seq, PIL_CMD_KICK, w);
    w[n / 2u] ^= 0x10u;
    if (w[n / 2u] == 0u) {
        w[n / 2u] = 0x55u;
    }
    feed(w, n);
    static pil_frame_t f[4];
    TEST_ASSERT_EQUAL_UINT(1u, take_frames(f, 4u));
    assert_fault(&f[0], PIL_E_CRC);
}

static void test_target_format_fault(void)
{
    start_target();
    const uint16_t seq = run_to_gates_on(1u);
    uint8_t p[8] = {0};
    uint8_t w[PIL_WIRE_MAX];
    feed(w, wire_of(PIL_T_SAMPLE, seq, p, sizeof p, w)); /* 8 bytes: too short */
    static pil_frame_t f[4];
    TEST_ASSERT_EQUAL_UINT(1u, take_frames(f, 4u));
    assert_fault(&f[0], PIL_E_FORMAT);
}

static void test_target_timeout_fault(void)
{
    start_target();
    const uint16_t seq = run_to_gates_on(1u);
    /* within the 50 ms time-out: nothing happens */
    fp.now += 50u;
    pil_target_poll_timeout(&tgt);
    TEST_ASSERT_EQUAL_UINT(0u, fp.n);
    TEST_ASSERT_TRUE(gates_requested());
    /* half a frame, then silence past the time-out: the frame is lost */
    uint8_t w[PIL_WIRE_MAX];
    const size_t n = sample_wire(seq, PIL_CMD_KICK, w);
    feed(w, n / 2u);
    fp.now += 51u;
    pil_target_poll_timeout(&tgt);
    static pil_frame_t f[4];
    TEST_ASSERT_EQUAL_UINT(1u, take_frames(f, 4u));
    assert_fault(&f[0], PIL_E_TIMEOUT);
    TEST_ASSERT_FALSE(pil_dec_busy(&tgt.dec));
}

static void test_target_refuses_setup(void)
{
    memset(&tgt, 0, sizeof tgt);
    tgt.port = &port;
    pil_dec_init(&tgt.dec);
    fp.n = 0u;
    static pil_setup_t s;
    setup_thesis(&s);
    (void)strcpy(s.ctrl, "no_such_controller");
    static uint8_t p[PIL_BODY_MAX];
    static uint8_t w[PIL_WIRE_MAX];
    feed(w, wire_of(PIL_T_SETUP, 0u, p, pil_setup_pack(&s, p, sizeof p), w));
    static pil_frame_t f[4];
    TEST_ASSERT_EQUAL_UINT(1u, take_frames(f, 4u));
    pil_ready_t rd;
    TEST_ASSERT_EQUAL_INT(PIL_OK, pil_ready_unpack(f[0].payload, f[0].len, &rd));
    TEST_ASSERT_TRUE(rd.rc != 0);
    /* not ready: a SAMPLE is a format fault */
    assert_fault(period(1u, PIL_CMD_KICK), PIL_E_FORMAT);
}

/* A port that returns STOP and the next SETUP in one read (a serial port
 * whose bytes arrived together): the run ends at the STOP, the next run
 * starts with the SETUP's bytes and answers READY; nothing is lost. */
static const uint8_t *chunk;
static size_t chunk_n;
static int chunk_read(void *ctx, uint8_t *buf, size_t cap)
{
    (void)ctx;
    if (chunk_n == 0u) {
        return -1;
    }
    const size_t n = chunk_n < cap ? chunk_n : cap;
    memcpy(buf, chunk, n);
    chunk += n;
    chunk_n -= n;
    return (int)n;
}

static void test_run_keeps_bytes_after_stop(void)
{
    static const pil_port_t cport = {&fp, chunk_read, fake_write, NULL, 1000u, fake_cycles, 0u, 0u};
    static pil_setup_t s;
    setup_thesis(&s);
    static uint8_t p[PIL_BODY_MAX];
    static uint8_t w[2u * PIL_WIRE_MAX];
    size_t n = wire_of(PIL_T_STOP, 0u, NULL, 0u, w);
    /* STOP, then the first bytes of SETUP in the same read of 64 bytes */
    TEST_ASSERT_TRUE(n < 32u);
    n += wire_of(PIL_T_SETUP, 0u, p, pil_setup_pack(&s, p, sizeof p), w + n);
    chunk = w;
    chunk_n = n;
    fp.n = 0u;
    memset(&tgt, 0, sizeof tgt);
    TEST_ASSERT_EQUAL_INT(PIL_OK, pil_target_run(&tgt, &cport));
    TEST_ASSERT_TRUE(tgt.carry_n > 0u);
    TEST_ASSERT_EQUAL_INT(PIL_E_CLOSED, pil_target_run(&tgt, &cport));
    static pil_frame_t f[4];
    TEST_ASSERT_EQUAL_UINT(1u, take_frames(f, 4u));
    TEST_ASSERT_EQUAL_UINT(PIL_T_READY, f[0].type);
    pil_ready_t rd;
    TEST_ASSERT_EQUAL_INT(PIL_OK, pil_ready_unpack(f[0].payload, f[0].len, &rd));
    TEST_ASSERT_EQUAL_INT(0, rd.rc);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_payload_round_trips);
    RUN_TEST(test_every_bit_flip_detected);
    RUN_TEST(test_target_period_and_digest);
    RUN_TEST(test_target_sequence_fault);
    RUN_TEST(test_target_crc_fault);
    RUN_TEST(test_target_format_fault);
    RUN_TEST(test_target_timeout_fault);
    RUN_TEST(test_target_refuses_setup);
    RUN_TEST(test_run_keeps_bytes_after_stop);
    return UNITY_END();
}
