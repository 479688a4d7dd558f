/*
 * PC replay of the interrupt-cost benchmark (tools/bench), on recordings made
 * by bench_rec (bench_blob.h), with the replay HAL:
 *
 *   bench_host time [--reps R] FILE...
 *       Replays each recording R times through fw_isr; per repetition the
 *       wall time (CLOCK_MONOTONIC) of the running periods (from the arm to
 *       the first period not running) divided by their number; prints one JSON object per file with
 * the median over the repetitions (and min/max). bench_host replay FILE... Replays once; the
 * running periods' ISRs go through bench_isr_running() (for valgrind --tool=callgrind
 * --toggle-collect=bench_isr_running). Both report "differs": periods whose compare values or state
 * differ from the recording (0 expected: the replay is the recorded closed loop).
 */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_blob.h"
#include "bench_replay.h"
#include "controller.h"
#include "pipeline.h"

static int die(const char *msg, const char *arg)
{
    fprintf(stderr, "bench_host: %s%s\n", msg, arg != NULL ? arg : "");
    return 1;
}

/* ---- replay ------------------------------------------------------------ */

static unsigned char *load_file(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        return NULL;
    }
    unsigned char *buf = malloc(BENCH_BLOB_MAX);
    size_t n = buf != NULL ? fread(buf, 1u, BENCH_BLOB_MAX, f) : 0u;
    fclose(f);
    if (buf == NULL || n == 0u) {
        free(buf);
        return NULL;
    }
    *size = n;
    return buf;
}

/* The ISR of a running period: a separate, never inlined function so that
 * callgrind's --toggle-collect selects exactly these calls. */
__attribute__((noinline)) void bench_isr_running(fw_t *fw);
__attribute__((noinline)) void bench_isr_running(fw_t *fw)
{
    fw_isr(fw);
    __asm__ volatile("" ::: "memory");
}

static double now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e9 + (double)ts.tv_nsec;
}

/* One pass; returns the wall time of the running periods (ns), their number
 * in *calls, the number of differing periods in *diff (untimed pass only), or
 * a negative value on a setup error. */
static double replay_pass(bench_replay_t *r, int timed, uint32_t *diff, uint32_t *calls)
{
    static fw_t fw;
    static hal_t hal;
    if (bench_replay_init(r, &fw, &hal) != FW_OK) {
        return -1.0;
    }
    const uint32_t n = r->hdr->n, arm = r->hdr->arm_index;
    uint32_t bad = 0u;
    for (uint32_t k = 0; k < arm; k++) {
        bench_replay_input(r, &fw, &hal, k);
        fw_isr(&fw);
        fw_watchdog_kick(&fw);
        bad += (uint32_t)bench_replay_differs(r, &fw, &hal, k);
    }
    /* Running periods: from the arm to the first period that is not running
     * (a controller that trips its drive ends the timed stretch there). */
    uint32_t stop = arm;
    while (stop < n && r->rec[stop].state_after == (uint8_t)FW_STATE_RUNNING) {
        stop++;
    }
    double t = 0.0;
    if (timed) {
        /* Only the ISR and the replay HAL's input copy are in the loop. */
        const double t0 = now_ns();
        for (uint32_t k = arm; k < stop; k++) {
            bench_replay_input(r, &fw, &hal, k);
            fw_isr(&fw);
            fw_watchdog_kick(&fw);
        }
        t = now_ns() - t0;
    } else {
        for (uint32_t k = arm; k < stop; k++) {
            bench_replay_input(r, &fw, &hal, k);
            bench_isr_running(&fw);
            fw_watchdog_kick(&fw);
            bad += (uint32_t)bench_replay_differs(r, &fw, &hal, k);
        }
    }
    for (uint32_t k = stop; k < n; k++) {
        bench_replay_input(r, &fw, &hal, k);
        fw_isr(&fw);
        fw_watchdog_kick(&fw);
        bad += timed ? 0u : (uint32_t)bench_replay_differs(r, &fw, &hal, k);
    }
    *calls = stop - arm;
    *diff = bad;
    return t;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

#define BENCH_MAX_FILES 128

typedef struct {
    const char *path;
    unsigned char *blob;
    bench_replay_t r;
    uint32_t calls, differs;
    double *t; /* ns per call, per repetition */
} bench_file_t;

static int cmd_replay(int argc, char **argv, int timed)
{
    unsigned long reps = 41u;
    int i = 0;
    if (timed && argc >= 2 && strcmp(argv[0], "--reps") == 0) {
        char *end;
        reps = strtoul(argv[1], &end, 10);
        if (*end != '\0' || reps == 0u || reps > 100000u) {
            return die("--reps expects 1 .. 100000, got ", argv[1]);
        }
        i = 2;
    }
    const int nf = argc - i;
    if (nf <= 0 || nf > BENCH_MAX_FILES) {
        return die("expects 1 .. 128 recordings", NULL);
    }
    static bench_file_t files[BENCH_MAX_FILES];
    int rc = 0;
    for (int f = 0; f < nf && rc == 0; f++) {
        bench_file_t *b = &files[f];
        b->path = argv[i + f];
        size_t size = 0u;
        b->blob = load_file(b->path, &size);
        b->t = calloc(reps, sizeof *b->t);
        if (b->blob == NULL || b->t == NULL) {
            rc = die("cannot read ", b->path);
            break;
        }
        const char *e = bench_replay_open(&b->r, b->blob, size);
        if (e != NULL) {
            fprintf(stderr, "bench_host: %s: %s\n", b->path, e);
            rc = 1;
            break;
        }
        /* Untimed pass: warm-up, equivalence with the recording, callgrind. */
        if (replay_pass(&b->r, 0, &b->differs, &b->calls) < 0.0) {
            rc = die("fw_init failed for ", b->path);
        }
    }
    /* Repetitions outside, recordings inside: every controller sees the same
     * mix of machine load over the run (fair ratios on a shared machine). */
    for (unsigned long k = 0; timed && k < reps && rc == 0; k++) {
        for (int f = 0; f < nf && rc == 0; f++) {
            if (files[f].calls == 0u) {
                continue; /* no running period (faulted at once): nothing to time */
            }
            uint32_t d = 0u, c = 0u;
            const double ns = replay_pass(&files[f].r, 1, &d, &c);
            if (ns < 0.0) {
                rc = die("fw_init failed for ", files[f].path);
            }
            files[f].t[k] = ns / (double)files[f].calls;
        }
    }
    for (int f = 0; f < nf && rc == 0; f++) {
        bench_file_t *b = &files[f];
        printf("{\"file\": \"%s\", \"ctrl\": \"%s\", \"speed_rpm\": %u, \"calls\": %u, "
               "\"differs\": %u",
               b->path, b->r.desc->name, b->r.hdr->speed_rpm, b->calls, b->differs);
        if (timed && b->calls == 0u) {
            printf(", \"reps\": 0, \"ns_median\": null");
        } else if (timed) {
            qsort(b->t, reps, sizeof *b->t, cmp_double);
            printf(", \"reps\": %lu, \"ns_median\": %.2f, \"ns_min\": %.2f, \"ns_max\": %.2f", reps,
                   b->t[reps / 2u], b->t[0], b->t[reps - 1u]);
        }
        printf("}\n");
    }
    for (int f = 0; f < nf; f++) {
        free(files[f].blob);
        free(files[f].t);
    }
    return rc;
}

int main(int argc, char **argv)
{
    if (argc >= 2 && strcmp(argv[1], "time") == 0) {
        return cmd_replay(argc - 2, argv + 2, 1);
    }
    if (argc >= 2 && strcmp(argv[1], "replay") == 0) {
        return cmd_replay(argc - 2, argv + 2, 0);
    }
    return die("usage: bench_host time|replay ... (see bench_host.c)", NULL);
}
