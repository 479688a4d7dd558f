/*
 * The firmware on the emulated Cortex-M4 (QEMU mps2-an386) with the plant in
 * the loop (hal/qemu_mps2/hal_qemu.h, README-pil.md there).
 *
 * Timer0 interrupt = one PWM period k of plant time Ts = 1/fs:
 *   hal_qemu_period_end    plant through [t_{k-1}, t_k) (compare values of k-1)
 *   metrics bookkeeping    the same as the host simulator (sim_run.c): control
 *                          instants, Ts/10 observer in the window, transitions
 *   hal_qemu_period_begin  ADC / encoder samples at t_k
 *   fw_isr                 the pipeline; its own hal_cycles (Timer1) timing
 *                          is the only one the deadline check sees
 *   fw_link_isr            telemetry sample queue
 * The main loop polls UART0 RX into the command interpreter (fw_link) and runs
 * a compiled-in command script ("ref torque", "arm" once calibrated, "status"
 * at the end), kicks the watchdog and adapts the Timer0 rate to the measured
 * interrupt cost (plant time does not depend on it).
 *
 * Build-time selection (compile definitions):
 *   PIL_CTRL="bst"     controller (scenario from pil_data.c: thesis SPMSM,
 *                      750 r/min dynamometer, 1.8 N*m, 0.5 s after arm)
 *   PIL_CPU_HZ=100000000 modelled CPU clock for the deadline budget
 *   PIL_PLANT_GRID=1   Ts/10 plant-grid metrics as on the host (default)
 *   PIL_OVERRUN=1      deadline test: from 0.02 s after arm, the controller's
 *                      step busy-waits 2 x the budget; the firmware must latch
 *                      the deadline fault and switch the gates off
 * Exit status: 0 pass; 1 metrics outside tolerance of the host run; 2 setup
 * error; 3 unexpected fault / plant failure; 4 deadline test failed.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "controller.h"
#include "fw_link.h"
#include "hal_qemu.h"
#include "metrics.h"
#include "pil_data.h"
#include "pipeline.h"
#include "plant.h"
#include "qemu_mps2.h"

#ifndef PIL_CTRL
#define PIL_CTRL "bst"
#endif
/* The modelled CPU clock of the deadline budget: 100 MHz, the cycle clock of
 * hal/sim's default (so host and PIL runs have the same budget) and of a
 * typical motor-control Cortex-M4. The mps2's own 25 MHz would give 1250
 * instructions at 20 kHz, below the ~1.8k the switching-table pipeline needs. */
#ifndef PIL_CPU_HZ
#define PIL_CPU_HZ 100000000u
#endif
#ifndef PIL_OVERRUN
#define PIL_OVERRUN 0
#endif
/* 1: the Ts/10 plant observer of the host simulator in the metrics window
 * (plant-grid metrics; the plant is then split at exactly the host's instants,
 * so the run reproduces the host's to rounding); 0: control-instant metrics
 * only, ~3x faster, but the different splitting makes the trajectory diverge
 * from the host's (statistically equivalent). */
#ifndef PIL_PLANT_GRID
#define PIL_PLANT_GRID 1
#endif

#define PIL_PI 3.14159265358979323846
#define PIL_OBS_PER_PERIOD 10u
#define PIL_OVERRUN_AT_S 0.02

/* Everything the image keeps between interrupts, in one instance (pil below):
 * the Timer0 interrupt (pil_isr) and the wrapped controller step
 * (pil_slow_step) are called without an argument that could carry it, so on
 * bare metal it has to be reachable at file scope. Everything else takes it by
 * pointer. */
typedef struct {
    plant_t plant;
    hal_t hal;
    fw_t fw;
    fw_link_t link;
    /* closed loop */
    const pil_cl_t *sc;
    double ts, obs_dt, t_arm, speed_sum_rpm;
    uint64_t speed_n, tr_win_start;
    double t_win_start;
    volatile bool arm_cmd;     /* set by the main loop with the arm command */
    volatile bool armed, done; /* written by the interrupt, read by the main loop */
    bool win_started, win_done, obs_on;
    metrics_acc_t m_plant, m_ctrl;
    /* cost accounting (Timer1 ticks) */
    uint32_t isr_max, pipe_max, pipe_max_running;
    uint64_t pipe_sum, pipe_n, isr_sum, isr_n;
    uint32_t timer_period;
    uint32_t isr_last;
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

/* ---- UART output for the command interface ---- */
static void pil_write(void *ctx, const uint8_t *bytes, size_t len)
{
    (void)ctx;
    for (size_t i = 0; i < len; i++) {
        uart_putc((char)bytes[i]);
    }
}

static double pil_torque_ref_nm(const pil_t *s)
{
    return ctrl_q24_to_double(s->fw.refs.torque) * s->fw.bases.torque_nm;
}

/* Plant observer on the Ts/10 grid (sim_run.c's, without the trace). */
static void pil_observer(void *ctx, const plant_t *p)
{
    pil_t *s = (pil_t *)ctx;
    const double t = plant_time(p) - s->t_arm;
    if (t < 0.0) {
        return;
    }
    if (t >= s->sc->win_start_s && t <= s->sc->win_end_s) {
        double i_abc[3];
        plant_i_abc(p, i_abc);
        metrics_add(&s->m_plant, t, plant_torque(p), pil_torque_ref_nm(s), plant_psi_amp(p),
                    i_abc[0]);
        s->speed_sum_rpm += plant_omega_m(p) * 60.0 / (2.0 * PIL_PI);
        s->speed_n++;
    }
}

static void pil_count_transitions(pil_t *s, double t)
{
    const uint64_t n = plant_transitions(&s->plant) - s->tr_win_start;
    metrics_set_transitions(&s->m_plant, n, t - s->t_win_start);
    metrics_set_transitions(&s->m_ctrl, n, t - s->t_win_start);
}

/* sim_run_period's bookkeeping at the start of a period (scenario time t). */
static void pil_bookkeeping(pil_t *s, double t)
{
    const bool in_win = PIL_PLANT_GRID && t + s->ts >= s->sc->win_start_s && t <= s->sc->win_end_s;
    if (in_win != s->obs_on) {
        plant_set_observer(&s->plant, in_win ? pil_observer : NULL, s, in_win ? s->obs_dt : 0.0);
        s->obs_on = in_win;
    }
    if (t >= s->sc->win_start_s && !s->win_started) {
        s->win_started = true;
        s->tr_win_start = plant_transitions(&s->plant);
        s->t_win_start = t;
    }
    if (t >= s->sc->win_end_s && s->win_started && !s->win_done) {
        s->win_done = true;
        pil_count_transitions(s, t);
    }
    if (t >= s->sc->win_start_s && t <= s->sc->win_end_s) {
        double i_abc[3];
        plant_i_abc(&s->plant, i_abc);
        metrics_add(&s->m_ctrl, t, plant_torque(&s->plant), pil_torque_ref_nm(s),
                    plant_psi_amp(&s->plant), i_abc[0]);
    }
}

/* Timer0 rate, from the interrupt's own cost: period = cost x 1.25 (leaves
 * the main loop a fifth of the time), changed when the cost grows above the
 * period or falls below 2/3 of it (e.g. when the Ts/10 observer of the metrics
 * window switches on). Only wall time depends on it, never the result: plant
 * time advances by Ts per interrupt whatever the rate. */
static void pil_isr(void);

static void pil_adapt_timer(pil_t *s, uint32_t isr)
{
    const uint32_t want = isr + isr / 4u + 200u;
    if (want > s->timer_period || want + want / 2u < s->timer_period) {
        s->timer_period = want;
        uint32_t hz = QEMU_MPS2_SYSCLK_HZ / want;
        if (hz == 0u) {
            hz = 1u;
        }
        (void)timer0_start(hz, pil_isr);
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
    if (hal_qemu_period_end(&s->hal) != PLANT_OK) {
        s->done = true;
        timer0_stop();
        return;
    }
    if (s->arm_cmd && !s->armed) {
        /* The arm command was given after the previous period (as in sim_run_init). */
        s->armed = true;
        s->t_arm = plant_time(&s->plant);
    }
    if (s->armed) {
        const double t = plant_time(&s->plant) - s->t_arm;
        if (!(t + 0.5 * s->ts < s->sc->duration_s)) {
            s->done = true;
            timer0_stop();
            return;
        }
        pil_bookkeeping(s, t);
        if (PIL_OVERRUN && !s->overrun_on && t >= PIL_OVERRUN_AT_S) {
            s->overrun_on = true;
            s->overrun_start_period = s->fw.period + 1u;
        }
    }
    hal_qemu_period_begin(&s->hal);

    const uint8_t state_before = (uint8_t)fw_state(&s->fw);
    fw_isr(&s->fw);
    fw_link_isr(&s->link);

    const fw_telemetry_t *tm = fw_telemetry(&s->fw);
    const uint32_t pipe = tm->cycles;
    if (pipe > s->pipe_max) {
        s->pipe_max = pipe;
    }
    if (state_before == FW_STATE_RUNNING && tm->state == FW_STATE_RUNNING) {
        if (pipe > s->pipe_max_running) {
            s->pipe_max_running = pipe;
        }
        s->pipe_sum += pipe;
        s->pipe_n++;
    }
    if (tm->state == FW_STATE_FAULT && s->fault_period == 0u) {
        s->fault_period = s->fw.period;
        /* hal_gate_enable(false) acts at once: the plant period that starts
         * now is integrated with all switches open. */
        s->gates_at_fault = hal_qemu_plant_gates_on(hal_qemu_plant_models(&s->hal));
        /* The deadline test ends at the fault; elsewhere a fault fails the run
         * (and with the gates open the plant's RK4 path is slow). */
        s->done = true;
        timer0_stop();
    }
    const uint32_t isr = timer1_read() - t_enter;
    if (isr > s->isr_max) {
        s->isr_max = isr;
    }
    s->isr_sum += isr;
    s->isr_last = isr;
    s->isr_n++;
    if (!s->done) {
        pil_adapt_timer(s, isr);
    }
}

/* Feeds a command line to the interpreter with the interrupt masked, so that
 * it acts between two periods exactly (as the host simulator's calls do);
 * *mark (if not NULL) is set in the same masked section. */
static void pil_command(pil_t *s, const char *line, volatile bool *mark)
{
    uart_puts("> ");
    uart_puts(line);
    board_irq_disable();
    for (const char *c = line; *c != '\0'; c++) {
        fw_link_rx(&s->link, (uint8_t)*c);
    }
    if (mark != NULL) {
        *mark = true;
    }
    board_irq_enable();
    fw_link_poll(&s->link);
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
    s->ts = 1.0 / (double)sc->fs_hz;
    s->obs_dt = s->ts / (double)PIL_OBS_PER_PERIOD;

    plant_config_t pc;
    memset(&pc, 0, sizeof pc);
    pc.pole_pairs = sc->pole_pairs;
    pc.rs_ohm = sc->rs_ohm;
    pc.ld_h = sc->ld_h;
    pc.lq_h = sc->lq_h;
    pc.psi_pm_wb = sc->psi_pm_wb;
    pc.vdc_v = sc->vdc_v;
    pc.dc_cap_f = sc->dc_cap_f;
    pc.dc_src_r_ohm = sc->dc_src_r_ohm;
    pc.dead_time_s = sc->dead_time_s;
    pc.v_fwd_v = sc->v_fwd_v;
    pc.mech = PLANT_MECH_IMPOSED;
    pc.inertia_kgm2 = sc->inertia_kgm2;
    pc.friction_nms = sc->friction_nms;
    pc.speed0_rpm = sc->speed_rpm;
    if (plant_init(&s->plant, &pc) != PLANT_OK) {
        printf("pil: plant_init failed\n");
        return 2;
    }
    /* hal_sim_config_default + the scenario's values (noise off in PIL). */
    hal_qemu_plant_config_t hc;
    memset(&hc, 0, sizeof hc);
    hc.pwm_freq_hz = sc->fs_hz;
    hc.timer_clock_hz = sc->timer_clock_hz;
    hc.cycle_clock_hz = 100000000u; /* unused: hal_cycles is Timer1 */
    hc.cycles_per_read = 50u;
    hc.adc_bits = sc->adc_bits;
    hc.i_fullscale_a = sc->i_fullscale_a;
    hc.vdc_fullscale_v = sc->vdc_fullscale_v;
    hc.adc_noise_counts = sc->adc_noise_counts;
    hc.enc_lines = sc->enc_lines;
    hc.enc_index = sc->enc_index != 0u;
    hc.trip_level_a = sc->trip_level_a;
    hc.seed = 1u;
    hal_qemu_plant_t *models = hal_qemu_plant_init(&hc, &s->plant);
    if (models == NULL || hal_qemu_init(&s->hal, models, PIL_CPU_HZ) != HAL_QEMU_OK) {
        printf("pil: HAL init failed\n");
        return 2;
    }
    if (PIL_OVERRUN) {
        s->inner = desc;
        s->slow_desc = *desc;
        s->slow_desc.step = pil_slow_step;
        desc = &s->slow_desc;
    }
    fw_config_t fc;
    fw_config_default(&fc, &sc->machine, desc);
    fc.calib_samples = sc->calib_samples;
    const int frc = fw_init(&s->fw, &s->hal, &fc);
    if (frc != FW_OK) {
        printf("pil: fw_init: %s\n", fw_strerror(frc));
        return 2;
    }
    hal_info_t info;
    hal_info_get(&s->hal, &info);
    /* Busy-wait of twice the budget (the loop costs >= 3 instructions per nop). */
    s->overrun_nops = 2u * (uint32_t)((uint64_t)PIL_CPU_HZ / info.pwm_freq_hz);
    printf("pil: %s on %s, fs %u Hz, %.0f r/min, %.2f N*m, %.2f s; Timer1 %u ticks/1000 instr; "
           "deadline budget %u instr (CPU %u Hz)\n",
           desc->name, sc->machine.name, (unsigned)sc->fs_hz, sc->speed_rpm, sc->torque_ref_nm,
           sc->duration_s, (unsigned)hal_qemu_ticks_per_kinstr(&s->hal),
           (unsigned)(PIL_CPU_HZ / info.pwm_freq_hz), (unsigned)PIL_CPU_HZ);
    fw_link_init(&s->link, &s->fw, pil_write, NULL);
    hal_qemu_uart_rx_enable();
    /* No THD on the target: its Fourier sums over the Ts/10 samples cost ~10^10
     * soft-float instructions (see README-pil.md). */
    metrics_init(&s->m_plant, METRICS_SAMPLING_PLANT, 0.0);
    metrics_init(&s->m_ctrl, METRICS_SAMPLING_CONTROL, 0.0);

    const uint32_t t_start = timer1_read();
    s->timer_period = 20000u;
    (void)timer0_start(QEMU_MPS2_SYSCLK_HZ / s->timer_period, pil_isr);
    char script[64];
    (void)snprintf(script, sizeof script, "ref torque %.17g\n", sc->torque_ref_nm);
    bool sent = false;
    while (!s->done) {
        const int c = hal_qemu_uart_getc();
        if (c >= 0) {
            board_irq_disable();
            fw_link_rx(&s->link, (uint8_t)c);
            board_irq_enable();
        }
        if (!sent && fw_state(&s->fw) == FW_STATE_READY) {
            pil_command(s, script, NULL);
            pil_command(s, "arm\n", &s->arm_cmd);
            sent = true;
        }
        if (sent && !s->armed && fw_state(&s->fw) == FW_STATE_FAULT) {
            break;
        }
        fw_link_poll(&s->link);
        fw_watchdog_kick(&s->fw);
        board_idle();
    }
    timer0_stop();
    const uint32_t virt_ticks = timer1_read() - t_start;
    pil_command(s, "status\n", NULL);

    const uint32_t pipe_max_i = hal_qemu_ticks_to_instr(&s->hal, s->pipe_max_running);
    const uint32_t pipe_mean_i =
        s->pipe_n > 0u ? hal_qemu_ticks_to_instr(&s->hal, (uint32_t)(s->pipe_sum / s->pipe_n)) : 0u;
    printf("pil: %lu interrupts; pipeline (fw_isr, running) mean %u max %u instructions "
           "(budget %u); interrupt incl. plant mean %u max %u instructions; %.2f s virtual\n",
           (unsigned long)s->isr_n, (unsigned)pipe_mean_i, (unsigned)pipe_max_i,
           (unsigned)(PIL_CPU_HZ / info.pwm_freq_hz),
           (unsigned)hal_qemu_ticks_to_instr(&s->hal,
                                             s->isr_n ? (uint32_t)(s->isr_sum / s->isr_n) : 0u),
           (unsigned)hal_qemu_ticks_to_instr(&s->hal, s->isr_max),
           (double)virt_ticks / (double)QEMU_MPS2_SYSCLK_HZ);

    if (PIL_OVERRUN) {
        const fw_telemetry_t *tm = fw_telemetry(&s->fw);
        printf("pil: busy-wait (%u nop loop passes) in the controller step from ISR %u; fault "
               "%s at ISR %u after %u pipeline instructions (budget %u); state %s; plant "
               "gates %s\n",
               (unsigned)s->overrun_nops, (unsigned)s->overrun_start_period,
               fw_fault_name(fw_fault(&s->fw)), (unsigned)s->fault_period,
               (unsigned)hal_qemu_ticks_to_instr(&s->hal, tm->cycles),
               (unsigned)(PIL_CPU_HZ / info.pwm_freq_hz), fw_state_name(fw_state(&s->fw)),
               s->gates_at_fault ? "ON" : "off");
        const bool ok = s->overrun_on && fw_fault(&s->fw) == FW_FAULT_DEADLINE &&
                        fw_state(&s->fw) == FW_STATE_FAULT && !s->gates_at_fault &&
                        tm->gates == 0u && s->fault_period == s->overrun_start_period;
        printf("%s: deadline overrun -> fault %u, gates off in the same period\n",
               ok ? "PASS" : "FAIL", (unsigned)FW_FAULT_DEADLINE);
        return ok ? 0 : 4;
    }
    if (fw_state(&s->fw) != FW_STATE_RUNNING || s->hal.plant_rc != PLANT_OK || !s->armed) {
        printf("FAIL: state %s, fault %s, plant %d\n", fw_state_name(fw_state(&s->fw)),
               fw_fault_name(fw_fault(&s->fw)), s->hal.plant_rc);
        return 3;
    }
    if (!s->win_done && s->win_started) {
        pil_count_transitions(s, plant_time(&s->plant) - s->t_arm);
    }
    metrics_result_t mp, mc;
    memset(&mp, 0, sizeof mp);
    if ((PIL_PLANT_GRID && metrics_finish(&s->m_plant, &mp) != 0) ||
        metrics_finish(&s->m_ctrl, &mc) != 0) {
        printf("FAIL: metrics\n");
        return 3;
    }
    const pil_metrics_t *h = &sc->host;
    printf("pil: metrics, window %.3f..%.3f s (*_ctrl: true plant signals at the control "
           "instants)\n",
           sc->win_start_s, sc->win_end_s);
    if (PIL_PLANT_GRID) {
        pil_print_num("torque_mean_nm", h->torque_mean_nm, mp.torque_mean_nm,
                      sc->tol.torque_mean_nm);
        pil_print_num("torque_ripple_nm", h->torque_ripple_nm, mp.torque_ripple_nm,
                      sc->tol.torque_ripple_nm);
        pil_print_num("flux_mean_wb", h->flux_mean_wb, mp.flux_mean_wb, sc->tol.flux_mean_wb);
        pil_print_num("flux_ripple_wb", h->flux_ripple_wb, mp.flux_ripple_wb,
                      sc->tol.flux_ripple_wb);
        pil_print_num("torque_sse_nm", h->torque_sse_nm, mp.torque_sse_nm, sc->tol.torque_sse_nm);
    }
    pil_print_num("f_av_hz", h->f_av_hz, mc.f_av_hz, sc->tol.f_av_hz);
    pil_print_num("torque_mean_ctrl_nm", h->torque_mean_ctrl_nm, mc.torque_mean_nm,
                  sc->tol.torque_mean_ctrl_nm);
    pil_print_num("torque_ripple_ctrl_nm", h->torque_ripple_ctrl_nm, mc.torque_ripple_nm,
                  sc->tol.torque_ripple_ctrl_nm);
    pil_print_num("flux_mean_ctrl_wb", h->flux_mean_ctrl_wb, mc.flux_mean_wb,
                  sc->tol.flux_mean_ctrl_wb);
    pil_print_num("flux_ripple_ctrl_wb", h->flux_ripple_ctrl_wb, mc.flux_ripple_wb,
                  sc->tol.flux_ripple_ctrl_wb);
    pil_print_num("torque_sse_ctrl_nm", h->torque_sse_ctrl_nm, mc.torque_sse_nm,
                  sc->tol.torque_sse_ctrl_nm);
    int fail = 0;
    if (PIL_PLANT_GRID) {
        fail += pil_check("torque_mean_nm", h->torque_mean_nm, mp.torque_mean_nm,
                          sc->tol.torque_mean_nm);
        fail += pil_check("torque_ripple_nm", h->torque_ripple_nm, mp.torque_ripple_nm,
                          sc->tol.torque_ripple_nm);
        fail += pil_check("flux_mean_wb", h->flux_mean_wb, mp.flux_mean_wb, sc->tol.flux_mean_wb);
        fail += pil_check("flux_ripple_wb", h->flux_ripple_wb, mp.flux_ripple_wb,
                          sc->tol.flux_ripple_wb);
        fail +=
            pil_check("torque_sse_nm", h->torque_sse_nm, mp.torque_sse_nm, sc->tol.torque_sse_nm);
    }
    fail += pil_check("f_av_hz", h->f_av_hz, mc.f_av_hz, sc->tol.f_av_hz);
    fail += pil_check("torque_mean_ctrl_nm", h->torque_mean_ctrl_nm, mc.torque_mean_nm,
                      sc->tol.torque_mean_ctrl_nm);
    fail += pil_check("torque_ripple_ctrl_nm", h->torque_ripple_ctrl_nm, mc.torque_ripple_nm,
                      sc->tol.torque_ripple_ctrl_nm);
    fail += pil_check("flux_mean_ctrl_wb", h->flux_mean_ctrl_wb, mc.flux_mean_wb,
                      sc->tol.flux_mean_ctrl_wb);
    fail += pil_check("flux_ripple_ctrl_wb", h->flux_ripple_ctrl_wb, mc.flux_ripple_wb,
                      sc->tol.flux_ripple_ctrl_wb);
    fail += pil_check("torque_sse_ctrl_nm", h->torque_sse_ctrl_nm, mc.torque_sse_nm,
                      sc->tol.torque_sse_ctrl_nm);
    /* Same leg-transition count and every metric within 1e-9 relative: the
     * same switching sequence as on the host (informative; the pass criterion
     * is the tolerance above). */
    const double rel =
        fabs(mc.torque_mean_nm - h->torque_mean_ctrl_nm) / (fabs(h->torque_mean_ctrl_nm) + 1e-300);
    printf("pil: switching sequence %s the host's (f_av %s, torque mean rel. diff %.2g)\n",
           (mc.f_av_hz == h->f_av_hz && rel < 1e-9) ? "IDENTICAL to" : "differs from",
           mc.f_av_hz == h->f_av_hz ? "equal" : "differs", rel);
    metrics_free(&s->m_plant);
    metrics_free(&s->m_ctrl);
    printf("%s: %s closed loop in QEMU vs host\n", fail == 0 ? "PASS" : "FAIL", PIL_CTRL);
    return fail == 0 ? 0 : 1;
}
