/*
 * Bit-exact host/target equivalence: replays every recording of pil_data.c
 * (one per registered controller, recorded on the host) through fw_isr and
 * compares the outputs bit for bit. Built for the host (test
 * test_pil_replay_host) and for QEMU (test_pil_replay_qemu) from the same
 * sources. Exit status 0 when every controller matches; otherwise the first
 * mismatching period and field of each failing controller are printed.
 */
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "controller.h"
#include "pil_replay.h"

static fw_t replay_fw;
static hal_t replay_hal;

int main(void)
{
    int fails = 0;
    size_t checked = 0u;
    for (size_t i = 0; i < pil_n_recs; i++) {
        const pil_rec_t *rec = &pil_recs[i];
        const char *mode = rec->sensorless != 0u ? "sensorless" : "encoder";
        pil_mismatch_t mm;
        const int rc = pil_replay_run(rec, &replay_fw, &replay_hal, &mm);
        if (rc == 0) {
            printf("PASS %-8s %-10s %u periods bit-identical (pwm compare, gates, telemetry)\n",
                   rec->name, mode, (unsigned)rec->n);
        } else if (rc > 0) {
            printf("FAIL %-8s %-10s period %u (of %u) field %s: recorded %lld, replayed %lld\n",
                   rec->name, mode, (unsigned)mm.period, (unsigned)rec->n, mm.field,
                   (long long)mm.want, (long long)mm.got);
            fails++;
        } else {
            printf("FAIL %-8s %-10s setup: %s\n", rec->name, mode,
                   mm.field != NULL ? mm.field : "?");
            fails++;
        }
        checked++;
    }
    /* Every registered controller must have a recording. */
    for (size_t c = 0; c < ctrl_count(); c++) {
        bool found = false;
        for (size_t i = 0; i < pil_n_recs; i++) {
            found = found || strcmp(pil_recs[i].name, ctrl_at(c)->name) == 0;
        }
        if (!found) {
            printf("FAIL %-8s registered but not recorded (regenerate pil_data.c)\n",
                   ctrl_at(c)->name);
            fails++;
        }
    }
    printf("%s: %u of %u recordings bit-identical (every controller with the encoder, some "
           "sensorless)\n",
           fails == 0 ? "PASS" : "FAIL", (unsigned)(checked - (size_t)fails), (unsigned)checked);
    return fails == 0 ? 0 : 1;
}
