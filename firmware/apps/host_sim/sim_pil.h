/*
 * The PC's side of processor in the loop over a link (pil_frame.h): the
 * simulator's engine (sim_run.h) keeps the plant and its sensor models and
 * runs the host's firmware in lockstep; the target runs the same firmware on
 * its own processor. Each period the target gets the samples and the main
 * loop's commands, and its compare values and gate request drive the plant
 * (sim_link_t). The host's firmware is the observer of the quantities the
 * metrics and traces need (torque reference, estimate) and the check: the
 * target's state, fault and telemetry digest must equal it every period,
 * else the run stops with the link fault "target diverged" (gates off).
 *
 * Targets:
 *   qemu          qemu-system-arm (mps2-an386, -icount) with the image
 *                 pil_target.elf; transport semihosting (two FIFOs in a
 *                 temporary folder, read and written by SYS_READ/SYS_WRITE)
 *                 or socket (CMSDK UART0 on a chardev socket)
 *   board:DEVICE  a board running the PIL image over its serial port
 *                 (B-G431B-ESC1: pmsm-esc1-pil.elf, ST-LINK virtual COM port)
 *   exec:PROGRAM  a host process speaking the link on stdin/stdout (tests)
 * Time-out: a frame not received within timeout_ms is the link fault
 * "time-out" (also the target's exit while a frame is awaited: "closed").
 */
#ifndef FIRMWARE_APPS_HOST_SIM_PIL_H
#define FIRMWARE_APPS_HOST_SIM_PIL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "sim_run.h"

typedef struct {
    const char *target;     /* "qemu", "board:DEVICE" or "exec:PROGRAM" */
    const char *qemu_image; /* --target qemu: the ELF */
    const char *transport;  /* --target qemu: "semihosting" (default) or "socket" */
    uint32_t timeout_ms;    /* per frame (0: 2000) */
    uint32_t baud;          /* board: serial rate (0: 921600) */
} sim_pil_opts_t;

typedef struct sim_pil sim_pil_t;

/* Start / open the target. Returns NULL with a message. */
sim_pil_t *sim_pil_open(const sim_pil_opts_t *o, char *err, size_t errlen);
/* The hooks for sim_run_cfg_t.link. */
const sim_link_t *sim_pil_link(sim_pil_t *p);
/* The target's figures (periods, fw_isr cycles against the budget, wall
 * time per simulated second) on one line. */
void sim_pil_report(const sim_pil_t *p, FILE *f);
/* STOP, close, wait for the emulator; returns 0 or -1 (the target's exit
 * was not clean). */
int sim_pil_close(sim_pil_t *p);

#endif /* FIRMWARE_APPS_HOST_SIM_PIL_H */
