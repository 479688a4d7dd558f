/*
 * The PIL target image for QEMU mps2-an386 (pil_target.elf): the firmware
 * behind hal/pil, served by pil_target_run over one of two transports:
 *   semihosting  SYS_OPEN of "pil.in" / "pil.out" in QEMU's working folder
 *                (FIFOs the PC created), SYS_READ / SYS_WRITE of whole frames
 *   UART0        the CMSDK UART polled byte by byte (-serial chardev:...),
 *                when "pil.in" cannot be opened
 * No timer interrupt: one SAMPLE frame is one period. hal_cycles is Timer1,
 * its budget that of a Cortex-M4 running one instruction per cycle at
 * PIL_CPU_HZ (as the in-image PIL images: hal/qemu_mps2/README-pil.md).
 * Exit status: 0 after STOP, else 10 + the link fault (pil_frame.h).
 */
#include <stdint.h>
#include <string.h>

#include "arm_semihost.h"
#include "pil_target.h"
#include "qemu_mps2.h"

#ifndef PIL_CPU_HZ
#define PIL_CPU_HZ 100000000u
#endif

typedef struct {
    int fd_in, fd_out; /* semihosting handles, -1: UART0 */
} pil_qemu_t;

static pil_target_t pil_t;

static int pil_sh_open(const char *name, int mode)
{
    const uint32_t a[3] = {(uint32_t)(uintptr_t)name, (uint32_t)mode, (uint32_t)strlen(name)};
    return arm_semihost_call(SYS_OPEN, a);
}

/* CMSDK UART0 (hal_qemu.c's registers): DATA +0, STATE +4 (bit 1 RX full),
 * CTRL +8 (bit 1 RX enable). */
#define PIL_UART0_DATA (*(volatile uint32_t *)0x40004000u)
#define PIL_UART0_STATE (*(volatile uint32_t *)0x40004004u)
#define PIL_UART0_CTRL (*(volatile uint32_t *)0x40004008u)

static int pil_qemu_read(void *ctx, uint8_t *buf, size_t cap)
{
    pil_qemu_t *q = ctx;
    if (q->fd_in >= 0) {
        const uint32_t a[3] = {(uint32_t)q->fd_in, (uint32_t)(uintptr_t)buf, (uint32_t)cap};
        const int left = arm_semihost_call(SYS_READ, a); /* bytes NOT read */
        const int n = (int)cap - left;
        return n > 0 ? n : -1; /* nothing read: end of file (the PC closed) */
    }
    size_t n = 0u;
    while (n < cap && (PIL_UART0_STATE & 0x2u) != 0u) {
        buf[n++] = (uint8_t)(PIL_UART0_DATA & 0xFFu);
    }
    return (int)n;
}

static void pil_qemu_write(void *ctx, const uint8_t *buf, size_t n)
{
    pil_qemu_t *q = ctx;
    if (q->fd_out >= 0) {
        const uint32_t a[3] = {(uint32_t)q->fd_out, (uint32_t)(uintptr_t)buf, (uint32_t)n};
        (void)arm_semihost_call(SYS_WRITE, a);
        return;
    }
    for (size_t i = 0; i < n; i++) {
        uart_putc((char)buf[i]);
    }
}

static uint32_t pil_qemu_cycles(void)
{
    return timer1_read();
}

int main(void)
{
    static pil_qemu_t q;
    q.fd_in = pil_sh_open("pil.in", 1);   /* "rb" */
    q.fd_out = pil_sh_open("pil.out", 5); /* "wb" */
    if (q.fd_in < 0 || q.fd_out < 0) {
        q.fd_in = q.fd_out = -1;
        PIL_UART0_CTRL |= 0x2u;
    }
    /* Budget PIL_CPU_HZ / fs instructions in Timer1 ticks. */
    const uint64_t hz = (uint64_t)PIL_CPU_HZ * timer1_ticks_per_kinstr() / 1000u;
    static pil_port_t port;
    port.ctx = &q;
    port.read = pil_qemu_read;
    port.write = pil_qemu_write;
    port.now = NULL;
    port.cycles = pil_qemu_cycles;
    port.cycle_clock_hz = hz > 0xFFFFFFFFu ? 0xFFFFFFFFu : (uint32_t)hz;
    const int rc = pil_target_run(&pil_t, &port);
    return rc == PIL_OK ? 0 : 10 + rc;
}
