/*
 * The target's side of the processor-in-the-loop link (pil_frame.h): the
 * firmware pipeline (fw_init, fw_isr) behind hal/pil, driven frame by frame.
 * The same code runs on QEMU (pil_target_qemu.c: semihosting files or the
 * CMSDK UART) and on the B-G431B-ESC1 (firmware/apps/esc1_pil: USART2 to the
 * ST-LINK virtual COM port), and on the host in the link's tests.
 *
 * SETUP -> fw_init -> READY; then per SAMPLE: the commands (arm, references,
 * clear), the samples into hal_pil, fw_isr, the watchdog kick, APPLY with
 * the outputs and pil_tm_digest of the telemetry record. A bad frame (CRC,
 * format), a seq other than the next, or (on a port with a clock) no frame
 * within the time-out once running latches the link fault: gate request off
 * for good, a FAULT frame naming it, and a FAULT frame for every later
 * SAMPLE.
 */
#ifndef FIRMWARE_APPS_PIL_TARGET_H
#define FIRMWARE_APPS_PIL_TARGET_H

#include <stddef.h>
#include <stdint.h>

#include "hal_pil.h"
#include "pil_frame.h"
#include "pipeline.h"

/* The byte stream and clocks of one target. */
typedef struct {
    void *ctx;
    /* Bytes received so far into buf (0: none yet; may block), -1: closed. */
    int (*read)(void *ctx, uint8_t *buf, size_t cap);
    void (*write)(void *ctx, const uint8_t *buf, size_t n);
    /* Time for the link time-out, in ticks of now_hz; NULL: blocking reads,
     * the PC's time-out alone (QEMU: virtual time stands still while the
     * emulator waits for the PC). */
    uint32_t (*now)(void *ctx);
    uint32_t now_hz;
    uint32_t (*cycles)(void); /* hal_cycles, at cycle_clock_hz */
    uint32_t cycle_clock_hz;
    uint32_t timeout_ms; /* with now: the longest gap between SAMPLE frames */
} pil_port_t;

typedef struct {
    const pil_port_t *port;
    hal_t hal;
    fw_t fw;
    pil_dec_t dec;
    pil_frame_t rx;
    pil_setup_t setup;
    unsigned char ctrl_cfg[CTRL_CFG_MAX] __attribute__((aligned(16)));
    bool ready;
    uint16_t seq_next; /* the SAMPLE seq expected */
    int fault;         /* pil_err_t latched, PIL_OK while fine */
    uint32_t t_last;   /* port->now at the last good frame */
    uint32_t periods;
    /* Bytes read with a STOP but after it: the next run's first (a port may
     * return STOP and the next SETUP in one read). */
    uint8_t carry[64];
    uint8_t carry_n;
} pil_target_t;

/* Serve the link until STOP (returns PIL_OK) or until it closes (PIL_E_CLOSED,
 * or the fault latched before it closed). The bytes read after a STOP are
 * the next call's first (same t and port; t zeroed before the first call,
 * as a static object is). */
int pil_target_run(pil_target_t *t, const pil_port_t *port);

/* One received byte (the run loop's step; exposed for the tests). Returns
 * 1 after STOP, else 0. */
int pil_target_byte(pil_target_t *t, uint8_t byte);
/* The time-out check of a port with a clock (the run loop calls it when no
 * byte is pending). */
void pil_target_poll_timeout(pil_target_t *t);

#endif /* FIRMWARE_APPS_PIL_TARGET_H */
