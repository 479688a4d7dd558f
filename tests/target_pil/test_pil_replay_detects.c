/*
 * The equivalence check must be able to fail: corrupt one recorded output bit
 * (and, separately, one recorded input count) of the first recording and
 * require pil_replay_run to report the first mismatching period and field.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pil_replay.h"

static fw_t det_fw;
static hal_t det_hal;

int main(void)
{
    if (pil_n_recs == 0u) {
        printf("FAIL: no recordings\n");
        return 1;
    }
    const pil_rec_t *rec = &pil_recs[0];
    const uint32_t k = rec->n - 100u; /* a running period */
    pil_out_t *out = malloc(rec->n * sizeof *out);
    pil_in_t *in = malloc(rec->n * sizeof *in);
    if (out == NULL || in == NULL) {
        free(out);
        free(in);
        printf("FAIL: out of memory\n");
        return 1;
    }
    int fails = 0;
    pil_mismatch_t mm;

    /* 1. One output bit: the least significant bit of theta_e at period k. */
    memcpy(out, rec->out, rec->n * sizeof *out);
    out[k].theta_e ^= 1u;
    pil_rec_t bad = *rec;
    bad.out = out;
    int rc = pil_replay_run(&bad, &det_fw, &det_hal, &mm);
    if (rc != 1 || mm.period != k || strcmp(mm.field, "tm.theta_e") != 0 ||
        mm.want != (int64_t)out[k].theta_e || mm.got != (int64_t)rec->out[k].theta_e) {
        printf("FAIL: flipped output bit not reported (rc %d, period %u, field %s)\n", rc,
               (unsigned)mm.period, mm.field != NULL ? mm.field : "-");
        fails++;
    } else {
        printf("PASS: flipped bit of tm.theta_e at period %u reported\n", (unsigned)k);
    }

    /* 2. One input count: phase a's ADC sample at period k, +1 count. */
    memcpy(in, rec->in, rec->n * sizeof *in);
    in[k].adc[0] = (uint16_t)(in[k].adc[0] + 1u);
    bad = *rec;
    bad.in = in;
    rc = pil_replay_run(&bad, &det_fw, &det_hal, &mm);
    if (rc != 1 || mm.period != k || strcmp(mm.field, "tm.i_a") != 0) {
        printf("FAIL: changed ADC count not reported at its period (rc %d, period %u, field %s)\n",
               rc, (unsigned)mm.period, mm.field != NULL ? mm.field : "-");
        fails++;
    } else {
        printf("PASS: +1 count on i_a at period %u reported as %s\n", (unsigned)k, mm.field);
    }
    free(out);
    free(in);
    return fails == 0 ? 0 : 1;
}
