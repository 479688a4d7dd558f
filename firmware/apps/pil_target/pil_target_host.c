/*
 * The PIL target as a host program (pil_target.h): the link on stdin and
 * stdout, for the tests of the link and of the engine's PIL path without an
 * emulator (./tools/sim --target exec:pil_target_host). No cycle counter
 * (the deadline check is off), a 2 s time-out between SAMPLE frames.
 * Exit status: 0 after STOP, else 10 + the link fault.
 */
#define _POSIX_C_SOURCE 200809L
#include <poll.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

#include "pil_target.h"

static int pil_host_read(void *ctx, uint8_t *buf, size_t cap)
{
    (void)ctx;
    struct pollfd pf = {0, POLLIN, 0};
    if (poll(&pf, 1, 10) <= 0) {
        return 0;
    }
    const ssize_t n = read(0, buf, cap);
    return n > 0 ? (int)n : -1;
}

static void pil_host_write(void *ctx, const uint8_t *buf, size_t n)
{
    (void)ctx;
    while (n > 0u) {
        const ssize_t w = write(1, buf, n);
        if (w <= 0) {
            return;
        }
        buf += w;
        n -= (size_t)w;
    }
}

static uint32_t pil_host_now_ms(void *ctx)
{
    (void)ctx;
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint32_t)((uint64_t)ts.tv_sec * 1000u + (uint64_t)ts.tv_nsec / 1000000u);
}

static pil_target_t t;
static unsigned long flip_at; /* 0: no injection */
static unsigned long isr_n;

/* hal_cycles: the first call of each fw_isr is its entry (pipeline.h). */
static uint32_t pil_host_cycles(void)
{
    static bool in_isr;
    in_isr = !in_isr;
    if (in_isr && ++isr_n == flip_at) {
        t.hal.adc.i_a ^= 1u;
    }
    return 0u;
}

int main(void)
{
    const char *f = getenv("PIL_TARGET_FLIP_ADC_AT");
    flip_at = f != NULL ? strtoul(f, NULL, 10) : 0u;
    const pil_port_t port = {
        NULL, pil_host_read, pil_host_write, pil_host_now_ms, 1000u, pil_host_cycles, 0u, 2000u};
    const int rc = pil_target_run(&t, &port);
    return rc == PIL_OK ? 0 : 10 + rc;
}
