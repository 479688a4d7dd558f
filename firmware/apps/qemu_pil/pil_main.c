/*
 * PIL test image: the firmware on the emulated Cortex-M4 (QEMU mps2-an386)
 * with the plant in the loop, run by the closed-loop engine of the host
 * simulator (firmware/apps/engine/sim_run.h, HAL port hal/qemu_mps2), then
 * compared with the host run of the same scenario (pil_data.c).
 *
 * Timer0 interrupt = one PWM period of plant time Ts = 1/fs: sim_run_period
 * (scenario and metrics bookkeeping at the period start, ADC/encoder samples,
 * fw_isr, the plant through the period). fw_isr's own
 * hal_cycles (Timer1) timing is the only one the deadline check sees. The
 * main loop polls UART0 RX into the command interpreter (fw_link), kicks the
 * watchdog and adapts the Timer0 rate to the measured interrupt cost (plant
 * time does not depend on it: pil_common.h). The engine arms the drive with
 * the scenario's torque reference once it is calibrated, as on the host.
 *
 * Build-time selection (compile definitions):
 *   PIL_CTRL="bst"  controller (scenario from pil_data.c: thesis SPMSM,
 *                   750 r/min dynamometer, 1.8 N*m, 0.5 s after arm)
 *   PIL_OVERRUN=1   deadline test: from 0.02 s after arm, the controller's
 *                   step busy-waits 2 x the budget; the firmware must latch
 *                   the deadline fault and switch the gates off
 * Exit status: 0 pass; 1 metrics outside tolerance of the host run; 2 setup
 * error; 3 unexpected fault / plant failure; 4 deadline test failed.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "controller.h"
#include "fw_link.h"
#include "metrics.h"
#include "pil_cl.h"
#include "pil_common.h"
#include "pipeline.h"
#include "qemu_mps2.h"
#include "sim_run.h"

#ifndef PIL_CTRL
#define PIL_CTRL "bst"
#endif
#ifndef PIL_OVERRUN
#define PIL_OVERRUN 0
#endif

#define PIL_OVERRUN_AT_S 0.02

/* Everything the image keeps between interrupts, in one instance (pil below):
 * the Timer0 interrupt (pil_isr) and the wrapped controller step
 * (pil_slow_step) are called without an argument that could carry it, so on
 * bare metal it has to be reachable at file scope. Everything else takes it by
 * pointer. */
typedef struct {
    sim_run_t run;
    fw_link_t link;
    pil_timer_t timer;
    const pil_cl_t *sc;
    volatile bool done; /* written by the interrupt, read by the main loop */
    /* cost accounting (Timer1 ticks) */
    uint32_t pipe_max_running;
    uint64_t pipe_sum, pipe_n;
    uint8_t state_before;
    /* overrun test */
    bool overrun_on;
    uint32_t overrun_nops;
    uint32_t fault_period; /* ISR count at the fault */
    bool gates_at_fault;   /* plant gates still on in the faulted period */
    uint32_t overrun_start_period;
    const ctrl_desc_t *inner; /* the selected controller, wrapped by slow_desc */
    ctrl_desc_t slow_desc;
} pil_t;

static pil_t pil;

/* ---- deadline test: a controller that wraps the selected one ---- */

__attribute__((noinline)) static void pil_busy(uint32_t n)
{
    for (uint32_t i = 0; i < n; i++) {
        __asm__ volatile("nop" ::: "memory");
    }
}

static void pil_slow_step(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out)
{
    pil.inner->step(state, ctx, out);
    if (pil.overrun_on) {
        pil_busy(pil.overrun_nops);
    }
}

/* Right after fw_isr, before the plant goes through the period. */
static void pil_after_isr(void *ctx)
{
    pil_t *s = ctx;
    const fw_telemetry_t *tm = fw_telemetry(&s->run.fw);
    if (s->state_before == FW_STATE_RUNNING && tm->state == FW_STATE_RUNNING) {
        if (tm->cycles > s->pipe_max_running) {
            s->pipe_max_running = tm->cycles;
        }
        s->pipe_sum += tm->cycles;
        s->pipe_n++;
    }
    if (tm->state == FW_STATE_FAULT && s->fault_period == 0u) {
        s->fault_period = s->run.fw.period;
        /* hal_gate_enable(false) acts at once: the plant period that starts
         * now is integrated with all switches open. */
        s->gates_at_fault = engine_hal_gates_on(&s->run.hal);
    }
}

/* The PWM-period interrupt (Timer0). */
static void pil_isr(void)
{
    pil_t *s = &pil;
    if (s->done) {
        return;
    }
    const uint32_t t_enter = timer1_read();
    if (PIL_OVERRUN && s->run.armed && !s->overrun_on &&
        sim_run_time(&s->run) >= PIL_OVERRUN_AT_S) {
        s->overrun_on = true;
        s->overrun_start_period = s->run.fw.period + 1u;
    }
    s->state_before = (uint8_t)fw_state(&s->run.fw);
    /* The deadline test ends at the fault; elsewhere a fault fails the run
     * (and with the gates open the plant's RK4 path is slow). */
    if (sim_run_period(&s->run) != 0 || sim_run_done(&s->run) || s->fault_period != 0u) {
        s->done = true;
        timer0_stop();
        return;
    }
    pil_timer_account(&s->timer, timer1_read() - t_enter, pil_isr);
}

static void pil_print_num(const char *key, double host, double target, double tol)
{
    printf("  %-22s host %12.6g  qemu %12.6g  diff %10.3g  tol %9.3g\n", key, host, target,
           target - host, tol);
}

/* |target - host| <= tol; NaN on both sides counts as equal. */
static int pil_check(const char *key, double host, double target, double tol)
{
    if (isnan(host) && isnan(target)) {
        return 0;
    }
    if (!(fabs(target - host) <= tol)) {
        printf("FAIL %s: qemu %.9g host %.9g tolerance %.3g\n", key, target, host, tol);
        return 1;
    }
    return 0;
}

/* The engine configuration of the scenario (the host's, from pil_data.c). */
static void pil_config(const pil_cl_t *sc, const ctrl_desc_t *desc, sim_run_cfg_t *c)
{
    sim_run_config_default(c, &sc->plant, desc);
    c->ctrl_machine = sc->machine;
    c->fs_hz = sc->fs_hz;
    c->speed_rpm = sc->speed_rpm;
    c->torque_ref_nm = sc->torque_ref_nm;
    c->duration_s = sc->duration_s;
    c->win_start_s = sc->win_start_s;
    c->win_end_s = sc->win_end_s;
    c->calib_samples = sc->calib_samples;
    c->hal.timer_clock_hz = sc->timer_clock_hz;
    c->hal.adc_bits = sc->adc_bits;
    c->hal.i_fullscale_a = sc->i_fullscale_a;
    c->hal.vdc_fullscale_v = sc->vdc_fullscale_v;
    c->hal.adc_noise_counts = sc->adc_noise_counts;
    c->hal.enc_lines = sc->enc_lines;
    c->hal.enc_index = sc->enc_index != 0u;
    c->hal.trip_level_a = sc->trip_level_a;
    /* The interrupt and main loop of this image. */
    c->defer_start = true;
    c->kick_watchdog = false;
    c->after_isr = pil_after_isr;
    c->after_isr_ctx = &pil;
    /* No THD on the target: its Fourier sums over the Ts/10 samples cost
     * ~10^10 soft-float instructions (see README-pil.md). */
    c->skip_thd = true;
}

int main(void)
{
    pil_t *s = &pil;
    memset(s, 0, sizeof *s);
    (void)setvbuf(stdout, NULL, _IONBF, 0); /* UART output in order with uart_puts */
    for (size_t i = 0; i < pil_n_cl; i++) {
        if (pil_cl[i].ctrl_name != NULL && strcmp(pil_cl[i].ctrl_name, PIL_CTRL) == 0) {
            s->sc = &pil_cl[i];
        }
    }
    const ctrl_desc_t *desc = ctrl_find(PIL_CTRL);
    if (s->sc == NULL || desc == NULL) {
        printf("pil: controller %s: no scenario or not registered\n", PIL_CTRL);
        return 2;
    }
    const pil_cl_t *sc = s->sc;
    if (PIL_OVERRUN) {
        s->inner = desc;
        s->slow_desc = *desc;
        s->slow_desc.step = pil_slow_step;
        desc = &s->slow_desc;
    }
    static sim_run_cfg_t cfg;
    pil_config(sc, desc, &cfg);
    char err[256];
    if (sim_run_init(&s->run, &cfg, err, sizeof err) != 0) {
        printf("pil: %s\n", err);
        return 2;
    }
    hal_info_t info;
    hal_info_get(&s->run.hal, &info);
    /* Busy-wait of twice the budget (the loop costs >= 3 instructions per nop). */
    s->overrun_nops = 2u * (uint32_t)((uint64_t)PIL_CPU_HZ / info.pwm_freq_hz);
    printf("pil: %s on %s, fs %u Hz, %.0f r/min, %.2f N*m, %.2f s; Timer1 %u ticks/1000 instr; "
           "deadline budget %u instr (CPU %u Hz)\n",
           desc->name, sc->machine.name, (unsigned)sc->fs_hz, sc->speed_rpm, sc->torque_ref_nm,
           sc->duration_s, (unsigned)hal_qemu_ticks_per_kinstr(&s->run.hal),
           (unsigned)(PIL_CPU_HZ / info.pwm_freq_hz), (unsigned)PIL_CPU_HZ);
    fw_link_init(&s->link, &s->run.fw, pil_uart_write, NULL);
    hal_qemu_uart_rx_enable();

    const uint32_t t_start = timer1_read();
    pil_timer_start(&s->timer, pil_isr);
    while (!s->done) {
        pil_poll_uart(&s->link);
        fw_watchdog_kick(&s->run.fw);
        board_idle();
    }
    timer0_stop();
    const uint32_t virt_ticks = timer1_read() - t_start;
    const hal_t *hal = &s->run.hal;
    const uint32_t pipe_max_i = hal_qemu_ticks_to_instr(hal, s->pipe_max_running);
    const uint32_t pipe_mean_i =
        s->pipe_n > 0u ? hal_qemu_ticks_to_instr(hal, (uint32_t)(s->pipe_sum / s->pipe_n)) : 0u;
    printf("pil: %lu interrupts; pipeline (fw_isr, running) mean %u max %u instructions "
           "(budget %u); interrupt incl. plant mean %u max %u instructions; %.2f s virtual\n",
           (unsigned long)s->timer.isr_n, (unsigned)pipe_mean_i, (unsigned)pipe_max_i,
           (unsigned)(PIL_CPU_HZ / info.pwm_freq_hz),
           (unsigned)hal_qemu_ticks_to_instr(
               hal, s->timer.isr_n ? (uint32_t)(s->timer.isr_sum / s->timer.isr_n) : 0u),
           (unsigned)hal_qemu_ticks_to_instr(hal, s->timer.isr_max),
           (double)virt_ticks / (double)QEMU_MPS2_SYSCLK_HZ);
    printf("pil: state %s, fault %s\n", fw_state_name(fw_state(&s->run.fw)),
           fw_fault_name(fw_fault(&s->run.fw)));

    if (PIL_OVERRUN) {
        const fw_telemetry_t *tm = fw_telemetry(&s->run.fw);
        printf("pil: busy-wait (%u nop loop passes) in the controller step from ISR %u; fault "
               "%s at ISR %u after %u pipeline instructions (budget %u); plant gates %s\n",
               (unsigned)s->overrun_nops, (unsigned)s->overrun_start_period,
               fw_fault_name(fw_fault(&s->run.fw)), (unsigned)s->fault_period,
               (unsigned)hal_qemu_ticks_to_instr(hal, tm->cycles),
               (unsigned)(PIL_CPU_HZ / info.pwm_freq_hz), s->gates_at_fault ? "ON" : "off");
        const bool ok = s->overrun_on && fw_fault(&s->run.fw) == FW_FAULT_DEADLINE &&
                        fw_state(&s->run.fw) == FW_STATE_FAULT && !s->gates_at_fault &&
                        tm->gates == 0u && s->fault_period == s->overrun_start_period;
        printf("%s: deadline overrun -> fault %u, gates off in the same period\n",
               ok ? "PASS" : "FAIL", (unsigned)FW_FAULT_DEADLINE);
        return ok ? 0 : 4;
    }
    if (fw_state(&s->run.fw) != FW_STATE_RUNNING || s->run.plant_rc != PLANT_OK || !s->run.armed) {
        printf("FAIL: state %s, fault %s, plant %d\n", fw_state_name(fw_state(&s->run.fw)),
               fw_fault_name(fw_fault(&s->run.fw)), s->run.plant_rc);
        return 3;
    }
    metrics_result_t mp;
    metrics_result_t mc;
    if (sim_run_metrics(&s->run, &mp, &mc) != 0) {
        printf("FAIL: metrics\n");
        return 3;
    }
    const pil_metrics_t *h = &sc->host;
    printf("pil: metrics, window %.3f..%.3f s (*_ctrl: true plant signals at the control "
           "instants)\n",
           sc->win_start_s, sc->win_end_s);
    const struct {
        const char *key;
        double host, qemu, tol;
    } rows[] = {
        {"torque_mean_nm", h->torque_mean_nm, mp.torque_mean_nm, sc->tol.torque_mean_nm},
        {"torque_ripple_nm", h->torque_ripple_nm, mp.torque_ripple_nm, sc->tol.torque_ripple_nm},
        {"flux_mean_wb", h->flux_mean_wb, mp.flux_mean_wb, sc->tol.flux_mean_wb},
        {"flux_ripple_wb", h->flux_ripple_wb, mp.flux_ripple_wb, sc->tol.flux_ripple_wb},
        {"torque_sse_nm", h->torque_sse_nm, mp.torque_sse_nm, sc->tol.torque_sse_nm},
        {"f_av_hz", h->f_av_hz, mc.f_av_hz, sc->tol.f_av_hz},
        {"torque_mean_ctrl_nm", h->torque_mean_ctrl_nm, mc.torque_mean_nm,
         sc->tol.torque_mean_ctrl_nm},
        {"torque_ripple_ctrl_nm", h->torque_ripple_ctrl_nm, mc.torque_ripple_nm,
         sc->tol.torque_ripple_ctrl_nm},
        {"flux_mean_ctrl_wb", h->flux_mean_ctrl_wb, mc.flux_mean_wb, sc->tol.flux_mean_ctrl_wb},
        {"flux_ripple_ctrl_wb", h->flux_ripple_ctrl_wb, mc.flux_ripple_wb,
         sc->tol.flux_ripple_ctrl_wb},
        {"torque_sse_ctrl_nm", h->torque_sse_ctrl_nm, mc.torque_sse_nm, sc->tol.torque_sse_ctrl_nm},
    };
    int fail = 0;
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
        pil_print_num(rows[i].key, rows[i].host, rows[i].qemu, rows[i].tol);
    }
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
        fail += pil_check(rows[i].key, rows[i].host, rows[i].qemu, rows[i].tol);
    }
    /* Same leg-transition count and every metric within 1e-9 relative: the
     * same switching sequence as on the host (informative; the pass criterion
     * is the tolerance above). */
    const double rel =
        fabs(mc.torque_mean_nm - h->torque_mean_ctrl_nm) / (fabs(h->torque_mean_ctrl_nm) + 1e-300);
    printf("pil: switching sequence %s the host's (f_av %s, torque mean rel. diff %.2g)\n",
           (mc.f_av_hz == h->f_av_hz && rel < 1e-9) ? "IDENTICAL to" : "differs from",
           mc.f_av_hz == h->f_av_hz ? "equal" : "differs", rel);
    sim_run_free(&s->run);
    printf("%s: %s closed loop in QEMU vs host\n", fail == 0 ? "PASS" : "FAIL", PIL_CTRL);
    return fail == 0 ? 0 : 1;
}
