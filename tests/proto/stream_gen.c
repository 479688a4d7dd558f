/*
 * Writes a recorded telemetry stream made by the C encoder (tel_t producer:
 * a META frame, samples, text responses between frames, some frames damaged
 * by a dropped or flipped byte) and a description of what it contains, for
 * the Python decoder test (tools/console_test.py).
 *
 * usage: proto_stream_gen STREAM.bin EXPECT.txt
 * EXPECT lines:  M seq mask fs every damaged scale_bits...   (hex scale bits)
 *                S seq tick mask damaged value...
 *                T text                                      (a text line)
 *                N index name unit                           (signal table)
 */
#include <stdio.h>
#include <string.h>

#include "telemetry.h"

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: %s STREAM.bin EXPECT.txt\n", argv[0]);
        return 2;
    }
    FILE *fb = fopen(argv[1], "wb");
    FILE *fe = fopen(argv[2], "w");
    if (fb == NULL || fe == NULL) {
        perror("fopen");
        return 2;
    }
    for (size_t i = 0; i < (size_t)TEL_SIG_COUNT; i++) {
        const tel_signal_t *sig = tel_signal_at(i);
        fprintf(fe, "N %u %s %s\n", (unsigned)i, sig->name, sig->unit[0] ? sig->unit : "-");
    }
    tel_t t;
    tel_init(&t);
    const uint32_t mask = (1u << TEL_SIG_I_A) | (1u << TEL_SIG_I_B) | (1u << TEL_SIG_TORQUE) |
                          (1u << TEL_SIG_SPEED) | (1u << TEL_SIG_VECTOR) | (1u << TEL_SIG_DUTY);
    const char *ok = "ok tel mask=0x00000543 every=4 bytes=39\r\n";
    fputs(ok, fb);
    fprintf(fe, "T %.*s\n", (int)(strlen(ok) - 2u), ok);
    if (tel_start(&t, mask, 4u) != 0) {
        return 1;
    }
    ctrl_bases_t b;
    memset(&b, 0, sizeof b);
    b.i_a = 14.388;
    b.torque_nm = 8.138;
    b.w_rad_s = 2333.7;
    b.v_v = 220.0;
    b.psi_wb = 0.09427;
    uint8_t w[TEL_WIRE_MAX];
    size_t n = tel_encode_meta(&t, 20000u, &b, 4, w, sizeof w);
    fwrite(w, 1, n, fb);
    {
        uint8_t p[TEL_PAYLOAD_MAX];
        tel_frame_t f;
        size_t pn = 0;
        /* read the scales back from the frame itself */
        (void)tel_cobs_decode(&w[1], n - 2u, p, sizeof p, &pn);
        (void)tel_frame_parse(p, pn, &f);
        fprintf(fe, "M %u %lu %lu %lu 0", (unsigned)f.seq, (unsigned long)f.mask,
                (unsigned long)f.fs_hz, (unsigned long)f.every);
        for (unsigned i = 0; i < f.n; i++) {
            uint32_t bits;
            memcpy(&bits, &f.scale[i], 4);
            fprintf(fe, " %08lx", (unsigned long)bits);
        }
        fputc('\n', fe);
    }
    uint32_t s = 2024u;
    unsigned k_frame = 0;
    for (uint32_t k = 0; k < 2000u; k++) {
        if (!tel_active(&t) || k % t.every != 0u) {
            continue; /* one sample in `every` periods, the first at k = 0 */
        }
        tel_sample_t smp;
        memset(&smp, 0, sizeof smp);
        smp.tick = k;
        s = s * 1664525u + 1013904223u;
        smp.i_a = (int32_t)(s >> 4) - (1 << 27);
        smp.i_b = -smp.i_a / 2;
        smp.torque = (k % 50u == 0u) ? 0 : (int32_t)(s >> 8);
        smp.speed = (k % 64u == 0u) ? INT32_MIN : -(int32_t)(s >> 3);
        smp.vector = (int32_t)(k % 8u);
        smp.duty = (int32_t)((s >> 8) & 0xFFFFFFu);
        n = tel_encode_sample(&t, &smp, w, sizeof w);
        int damaged = 0;
        if (k_frame % 9u == 4u) {
            /* drop one byte from the middle */
            const size_t pos = 1u + (s >> 5) % (n - 2u);
            memmove(&w[pos], &w[pos + 1u], n - pos - 1u);
            n--;
            damaged = 1;
        } else if (k_frame % 13u == 7u) {
            const size_t pos = 1u + (s >> 7) % (n - 2u);
            w[pos] ^= (uint8_t)(1u + (s >> 12) % 255u);
            damaged = 1;
        }
        fwrite(w, 1, n, fb);
        fprintf(fe, "S %u %lu %lu %d %ld %ld %ld %ld %ld %ld\n", (unsigned)(t.seq - 1u),
                (unsigned long)smp.tick, (unsigned long)mask, damaged, (long)smp.i_a, (long)smp.i_b,
                (long)smp.torque, (long)smp.speed, (long)smp.vector, (long)smp.duty);
        if (k_frame % 17u == 5u) {
            const char *txt = "ok ref torque 1.5\r\n";
            fputs(txt, fb);
            fprintf(fe, "T %.*s\n", (int)(strlen(txt) - 2u), txt);
        }
        k_frame++;
    }
    fclose(fb);
    fclose(fe);
    return 0;
}
