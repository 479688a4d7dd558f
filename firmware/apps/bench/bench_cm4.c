/*
 * Cortex-M4 (QEMU mps2-an386) image of the interrupt-cost benchmark; built as
 * bench_cm0 for ARMv6-M (QEMU microbit, BENCH_MICROBIT).
 *
 * QEMU's `-device loader` puts a recording (bench_blob.h) at BENCH_BLOB_ADDR;
 * this image replays it through fw_isr_fast and fw_medium (the two rates,
 * pipeline.h) with the replay HAL and brackets every call with marker
 * functions. The counting plugin (bench_plugin.c) watches the
 * first instruction of each marker and writes the number of instructions
 * executed between bench_mark_begin and the following bench_mark_end_*:
 *   end_empty  begin/end with nothing in between (call overhead, subtracted)
 *   end_boot   fw_isr_fast not running (boot, calibration, ready, fault)
 *   end_run    fw_isr_fast of a running period (from the arm on, state running
 *              after the ISR; a period in which the drive faults is "boot")
 *   end_est    ctrl_estimator_update alone, on a copy of the pre-ISR state
 *   end_step   the controller's step alone, on a copy of the pre-ISR state
 *   end_mid    fw_medium, in the periods whose interrupt triggered it
 * The split (est, step) repeats exactly what fw_isr computed in that period
 * (its leg duties are compared with the ISR's), so its parts add up to the ISR's
 * estimator and controller cost.
 *
 * UART0 prints one summary line; the exit status is 0 when the replay matched
 * the PC's recording in every period.
 */
#include <stdbool.h>
#include <stdint.h>
#include <string.h>

#include "bench_replay.h"
#include "controller.h"
#include "estimator.h"
#include "plan.h"
#if defined(BENCH_MICROBIT)
#include "qemu_microbit.h" /* bench_cm0: the same image on ARMv6-M */
#else
#include "qemu_mps2.h"
#endif

/* Markers: distinct (the image is built with -fno-ipa-icf), never inlined. */
#define BENCH_MARK(name)                                                                           \
    __attribute__((noinline, used)) void name(void);                                               \
    __attribute__((noinline, used)) void name(void)                                                \
    {                                                                                              \
        __asm__ volatile("" ::: "memory");                                                         \
    }
BENCH_MARK(bench_mark_begin)
BENCH_MARK(bench_mark_end_empty)
BENCH_MARK(bench_mark_end_boot)
BENCH_MARK(bench_mark_end_run)
BENCH_MARK(bench_mark_end_est)
BENCH_MARK(bench_mark_end_step)
BENCH_MARK(bench_mark_end_mid)

static fw_t fw;
static hal_t hal;
static bench_replay_t rep;
static ctrl_estimator_t est_saved;
static ctrl_legs_t applied_saved;
static union {
    max_align_t align;
    unsigned char bytes[CTRL_STATE_MAX];
} state_saved;

/* The medium task where the interrupt triggered it, counted apart. */
static void bench_medium(bool due)
{
    if (due) {
        bench_mark_begin();
        fw_medium(&fw);
        bench_mark_end_mid();
    }
}

static int legs_equal(const ctrl_legs_t *a, const ctrl_legs_t *b)
{
    return a->duty[0] == b->duty[0] && a->duty[1] == b->duty[1] && a->duty[2] == b->duty[2];
}

/* Estimator and controller step of period k alone, from the saved state. */
static uint32_t bench_split(const ctrl_desc_t *desc)
{
    const fw_telemetry_t *tm = fw_telemetry(&fw);
    ctrl_meas_t m;
    m.i_a = tm->i_a;
    m.i_b = tm->i_b;
    m.vdc = tm->vdc;
    m.theta_e = tm->theta_e;
    if (fw.cfg.sensorless) {
        /* what the interrupt handed the sensorless angle before its estimate
         * (pipeline.c, fw_sl_inputs) */
        const ctrl_angle_sl_t *live = ctrl_estimator_angle_state(&fw.est);
        ctrl_angle_sl_t *saved = ctrl_estimator_angle_state(&est_saved);
        saved->speed_ref = live->speed_ref;
        saved->torque_est = live->torque_est;
    }
    ctrl_estimate_t est;
    bench_mark_begin();
    ctrl_estimator_update(&est_saved, &fw.params, &m, &applied_saved, &est);
    bench_mark_end_est();
    const ctrl_refs_t refs = fw.refs;
    const ctrl_ctx_t ctx = {&fw.params, &est, &refs};
    ctrl_out_t out;
    out.plan.n_seg = 0u;
    bench_mark_begin();
    desc->step(state_saved.bytes, &ctx, &out); /* leg duties included */
    bench_mark_end_step();
    return legs_equal(&out.legs, &fw.applied) ? 0u : 1u;
}

int main(void)
{
    const char *e = bench_replay_open(&rep, (const void *)BENCH_BLOB_ADDR, BENCH_BLOB_MAX);
    if (e != NULL) {
        uart_puts("bench: ");
        uart_puts(e);
        uart_puts("\n");
        return 2;
    }
    const ctrl_desc_t *desc = rep.desc;
    if (desc->state_size > sizeof state_saved.bytes) {
        uart_puts("bench: controller state too large\n");
        return 2;
    }
    if (bench_replay_init(&rep, &fw, &hal) != FW_OK) {
        uart_puts("bench: fw_init failed\n");
        return 3;
    }
    for (int i = 0; i < 4; i++) {
        bench_mark_begin();
        bench_mark_end_empty();
    }
    const uint32_t n = rep.hdr->n, arm = rep.hdr->arm_index;
    uint32_t differs = 0u, split_bad = 0u, not_running = 0u, split_n = 0u;
    for (uint32_t k = 0; k < arm; k++) {
        bench_replay_input(&rep, &fw, &hal, k);
        bench_mark_begin();
        const bool due = fw_isr_fast(&fw);
        bench_mark_end_boot();
        bench_medium(due);
        fw_watchdog_kick(&fw);
        differs += (uint32_t)bench_replay_differs(&rep, &fw, &hal, k);
    }
    for (uint32_t k = arm; k < n; k++) {
        bench_replay_input(&rep, &fw, &hal, k);
        est_saved = fw.est;
        applied_saved = fw.applied;
        memcpy(state_saved.bytes, fw.ctrl_state.bytes, desc->state_size);
        /* Running periods (state after the ISR, as recorded) are counted
         * apart from the others (after a fault the gates are off). */
        bool due;
        if (rep.rec[k].state_after == (uint8_t)FW_STATE_RUNNING) {
            bench_mark_begin();
            due = fw_isr_fast(&fw);
            bench_mark_end_run();
        } else {
            bench_mark_begin();
            due = fw_isr_fast(&fw);
            bench_mark_end_boot();
        }
        bench_medium(due);
        fw_watchdog_kick(&fw);
        differs += (uint32_t)bench_replay_differs(&rep, &fw, &hal, k);
        const ctrl_angle_sl_t *sl = fw.cfg.sensorless ? ctrl_estimator_angle_state(&fw.est) : NULL;
        if (fw_state(&fw) != FW_STATE_RUNNING) {
            not_running++;
        } else if (k > arm && (sl == NULL || sl->out.mode != CTRL_SL_DETECT)) {
            /* (the sensorless start's voltage pulses replace the controller's
             * output: no step to repeat) */
            /* The arming period resets the state inside the ISR: not split. */
            split_bad += bench_split(desc);
            split_n++;
        }
    }
    uart_puts("bench: ctrl ");
    uart_puts(desc->name);
    uart_puts(" speed ");
    uart_put_u32(rep.hdr->speed_rpm);
    uart_puts(" periods ");
    uart_put_u32(n);
    uart_puts(" running ");
    uart_put_u32(n - arm - not_running);
    uart_puts(" split ");
    uart_put_u32(split_n);
    uart_puts(" differs ");
    uart_put_u32(differs);
    uart_puts(" split_mismatch ");
    uart_put_u32(split_bad);
    uart_puts(" not_running ");
    uart_put_u32(not_running);
    uart_puts(" fs ");
    uart_put_u32(rep.hdr->pwm_freq_hz);
    uart_puts(" state_bytes ");
    uart_put_u32((uint32_t)desc->state_size);
    uart_puts("\n");
    return (differs == 0u && split_bad == 0u) ? 0 : 1;
}
