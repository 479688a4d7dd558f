/*
 * A host stand-in for the firmware's serial side: the command interpreter
 * with the mock drive (cmd_mock.c) on stdin/stdout, and a telemetry stream of
 * synthetic signals (a 50 Hz current pair, a torque step) produced by the real
 * telemetry code. Used to test tools/console end to end without a board or
 * QEMU image:  tools/console --exec build/.../proto_fake_fw --cmd ...
 * Simulated time: 20 kHz control periods, 200 periods per 10 ms of wall time.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <poll.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "cmd.h"
#include "cmd_mock.h"
#include "telemetry.h"

static void write_all(const void *p, size_t n)
{
    const unsigned char *b = p;
    while (n > 0) {
        const ssize_t w = write(1, b, n);
        if (w <= 0) {
            return;
        }
        b += w;
        n -= (size_t)w;
    }
}

int main(void)
{
    static mock_t m;
    cmd_t c;
    tel_t t;
    mock_init(&m);
    cmd_ops_t ops = *mock_ops();
    cmd_init(&c, &ops, &m);
    tel_init(&t);
    ctrl_bases_t b;
    memset(&b, 0, sizeof b);
    b.i_a = 14.388;
    b.v_v = 220.0;
    b.psi_wb = 0.09427;
    b.torque_nm = 8.138;
    b.w_rad_s = 2333.7;
    const uint32_t fs = 20000u;
    uint32_t tick = 0;
    uint32_t tel_tick0 = 0; /* period of the first sample after tel start */
    uint32_t mask_prev = 0;
    uint32_t every_prev = 0;
    uint8_t w[TEL_WIRE_MAX];
    for (;;) {
        struct pollfd p = {0, POLLIN, 0};
        const int r = poll(&p, 1, 10);
        if (r > 0) {
            unsigned char in[256];
            const ssize_t n = read(0, in, sizeof in);
            if (n <= 0) {
                break; /* stdin closed: exit */
            }
            for (ssize_t i = 0; i < n; i++) {
                const size_t before = m.out_len;
                cmd_feed_byte(&c, in[i]);
                if (m.out_len != before) {
                    write_all(&m.out[before], m.out_len - before);
                    mock_clear_out(&m);
                }
                /* the mock stores what "tel start/stop" asked for */
                if (m.st.tel_mask != mask_prev || m.st.tel_every != every_prev) {
                    mask_prev = m.st.tel_mask;
                    every_prev = m.st.tel_every;
                    if (mask_prev == 0u) {
                        tel_stop(&t);
                    } else if (tel_start(&t, mask_prev, every_prev) == 0) {
                        tel_tick0 = tick; /* the first sample is the next period's */
                        const size_t k = tel_encode_meta(&t, fs, &b, 4, w, sizeof w);
                        write_all(w, k);
                    }
                }
            }
        }
        /* 10 ms of control periods */
        for (int k = 0; k < 200; k++, tick++) {
            if (!tel_active(&t) || (tick - tel_tick0) % t.every != 0u) {
                continue;
            }
            const double time = (double)tick / fs;
            const double ang = 2.0 * 3.141592653589793 * 50.0 * time;
            tel_sample_t s;
            memset(&s, 0, sizeof s);
            s.tick = tick;
            s.i_a = (int32_t)(0.2 * 16777216.0 * cos(ang));
            s.i_b = (int32_t)(0.2 * 16777216.0 * cos(ang - 2.0943951023931953));
            s.torque_ref = (int32_t)(m.st.torque_ref / b.torque_nm * 16777216.0);
            s.torque = s.torque_ref + (int32_t)(0.01 * 16777216.0 * sin(7.0 * ang));
            s.speed =
                (int32_t)(1500.0 / 60.0 * 2.0 * 3.141592653589793 * 4.0 / b.w_rad_s * 16777216.0);
            s.vector = (int32_t)(1u + (tick / 7u) % 6u);
            s.duty = 16777216 / 2;
            s.vdc = 16777216;
            s.state = m.st.armed ? 3 : 2;
            const size_t n = tel_encode_sample(&t, &s, w, sizeof w);
            write_all(w, n);
        }
    }
    return 0;
}
