/*
 * Instruction count of the STM32F405 board images' control interrupt, on
 * the emulated Cortex-M4 (QEMU mps2-an386, tools/bench --f405).
 *
 * The code counted is the board image's: f405_control_isr (f405_isr.c) with
 * the F4 back-end of hal.h (f4_hal.c) set up for the board by
 * f4_hal_describe (its ADC data registers, sense sign, rebuilt phase,
 * encoder timer), and the firmware, built with the same compiler and flags;
 * only the peripheral base addresses differ: they are arrays here
 * (F4_MEM_ARRAYS), link-time constants like the chip's addresses, so every
 * register access compiles to the same instructions.
 *
 * A bench recording (tools/bench, bench_blob.h) is replayed as for the
 * B-G431B-ESC1 (firmware/apps/esc1/bench/esc1_isr_bench.c): before each
 * interrupt the recorded samples are put where the hardware would put them
 * (the injected data registers, mirrored when the board's sense gain is
 * negative; on a board that rebuilds a phase from the other two (ODrive
 * v3.6: phase A), the two measured phases and, as the rebuild's constant,
 * the sum of the recorded three, so that the rebuilt phase is the recorded
 * one; nFAULT high; the encoder counter), after it the compare values
 * TIM1_CCRx and the state are checked against the recording. The HAL
 * reports the recording's hal_info and applies no compare limit.
 * Markers as in bench_cm4.c; UART0: one summary line; exit 0 when every
 * period matched the recording.
 */
#include <stdint.h>
#include <string.h>

#include "bench_blob.h"
#include "controller.h"
#include "f405_app.h"
#include "f4_core.h"
#include "f4_periph.h"
#include "f4_regs.h"
#include "qemu_mps2.h"
#include F405_BOARD_HEADER

#define F4_DEFINE_ARRAY(N, n, addr, bytes) uint32_t f4_mem_##n[(bytes) / 4u];
F4_PERIPHS(F4_DEFINE_ARRAY)
#undef F4_DEFINE_ARRAY

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
BENCH_MARK(bench_mark_end_est)  /* not used here: the sections' order as in bench_cm4.c */
BENCH_MARK(bench_mark_end_step) /* idem */
BENCH_MARK(bench_mark_end_mid)

static f405_t s;
static ctrl_machine_t machine;
static char ctrl_name[33], machine_name[33];

static void put(uintptr_t reg, uint32_t v)
{
    *(volatile uint32_t *)reg = v;
}

static uint32_t get(uintptr_t reg)
{
    return *(volatile uint32_t *)reg;
}

static void say(const char *k, uint32_t v)
{
    uart_puts(k);
    uart_put_u32(v);
}

int main(void)
{
    const bench_hdr_t *h = (const bench_hdr_t *)BENCH_BLOB_ADDR;
    if (h->magic != BENCH_MAGIC || h->version != BENCH_VERSION || h->n == 0u ||
        h->arm_index >= h->n || h->adc_bits != 12u) {
        uart_puts("bench: not a 12-bit bench recording\n");
        return 2;
    }
    const bench_rec_t *rec = (const bench_rec_t *)(const void *)(h + 1);
    memcpy(ctrl_name, h->ctrl_name, sizeof h->ctrl_name);
    memcpy(machine_name, h->machine_name, sizeof h->machine_name);
    const ctrl_desc_t *desc = ctrl_find(ctrl_name);
    if (desc == NULL) {
        uart_puts("bench: controller not in the registry\n");
        return 2;
    }
    machine.name = machine_name;
    machine.pole_pairs = h->pole_pairs;
    machine.rs_ohm = h->rs_ohm;
    machine.ld_h = h->ld_h;
    machine.lq_h = h->lq_h;
    machine.psi_pm_wb = h->psi_pm_wb;
    machine.vdc_v = h->vdc_v;
    machine.inertia_kgm2 = h->inertia_kgm2;
    machine.torque_rated_nm = h->torque_rated_nm;
    machine.speed_rated_rpm = h->speed_rated_rpm;
    machine.current_rated_a = h->current_rated_a;
    machine.current_max_a = h->current_max_a;
    machine.psi_ref_wb = h->psi_ref_wb;

    /* The board's back-end as f4_hal_init describes it at 168 MHz, with the
     * recording's scales. */
    const f4_clocks_t clk = {168000000u, 42000000u, 84000000u, 84000000u, 168000000u, true};
    const f4_hal_cfg_t cfg = {h->pwm_freq_hz, h->encoder_counts_per_rev};
    hal_t *hal = &s.hal;
    if (f4_hal_describe(hal, &F405_BOARD, &cfg, &clk) != F4_OK) {
        uart_puts("bench: the board's description refused\n");
        return 2;
    }
    hal->info.pwm_freq_hz = h->pwm_freq_hz;
    hal->info.period_counts = h->period_counts;
    hal->info.adc_bits = 12u;
    hal->info.adc_current_a_per_count = h->adc_current_a_per_count;
    hal->info.adc_vdc_v_per_count = h->adc_vdc_v_per_count;
    hal->info.encoder_counts_per_rev = h->encoder_counts_per_rev;
    hal->info.has_i_c = h->has_i_c != 0u;
    hal->info.cycle_clock_hz = h->cycle_clock_hz;
    hal->cmp_max = h->period_counts;
    hal->info.pwm_cmp_max = h->period_counts;
    /* nFAULT high (no driver fault), every other input as well */
    put(f4_gpio_base(F405_BOARD.nfault.port) + F4_GPIO_IDR, 0xFFFFu);

    fw_config_default(&s.app.fc, &machine, desc);
    s.app.fc.calib_samples = h->calib_samples;
    s.app.fc.sensorless = h->sensorless != 0u;
    if (fw_init(&s.app.fw, hal, &s.app.fc) != FW_OK) {
        uart_puts("bench: fw_init failed\n");
        return 3;
    }
    fw_link_init(&s.app.link, &s.app.fw, NULL, NULL);

    for (int i = 0; i < 4; i++) {
        bench_mark_begin();
        bench_mark_end_empty();
    }
    const uintptr_t enc = hal->enc_tim;
    const uint32_t ich = hal->enc_index_ch;
    uint32_t differs = 0u, running = 0u, last_index = 0u;
    bool index_was_seen = false;
    for (uint32_t k = 0; k < h->n; k++) {
        const bench_rec_t *r = &rec[k];
        for (unsigned x = 0; x < 3u; x++) {
            if (hal->jdr[x] != 0u) {
                put(hal->jdr[x], (uint32_t)r->adc[x] ^ hal->mirror);
            }
        }
        if (hal->rebuilt < 3u) {
            hal->rebuild_k = (uint32_t)r->adc[0] + r->adc[1] + r->adc[2];
        }
        put(hal->jdr[3], r->adc[3]);
        put(hal->irq_adc + F4_ADC_SR, F4_ADC_SR_JEOC | F4_ADC_SR_JSTRT);
        put(enc + F4_TIM_CNT, r->enc_count & 0xFFFFu);
        if (ich != 0u && r->index_seen != 0u && (!index_was_seen || r->index_count != last_index)) {
            put(enc + F4_TIM_CCR(ich), r->index_count & 0xFFFFu);
            put(enc + F4_TIM_SR, F4_TIM_SR_CCIF(ich));
            index_was_seen = true;
            last_index = r->index_count;
        }
        put(F4_TIM1 + F4_TIM_SR, r->trip != 0u ? F4_TIM_SR_BIF : 0u);
        if ((r->cmd & BENCH_CMD_TORQUE) != 0u) {
            fw_set_torque_ref(&s.app.fw, h->torque_ref_q24);
        }
        if ((r->cmd & BENCH_CMD_ARM) != 0u) {
            fw_cmd_arm(&s.app.fw);
        }
        if (k >= h->arm_index && r->state_after == (uint8_t)FW_STATE_RUNNING) {
            bench_mark_begin();
            f405_control_isr(&s);
            bench_mark_end_run();
            running++;
        } else {
            bench_mark_begin();
            f405_control_isr(&s);
            bench_mark_end_boot();
        }
        if (s.app.fw.mid_done != s.app.fw.mid_req) {
            /* PendSV pended (in a register array here): the medium-rate task */
            bench_mark_begin();
            fw_medium(&s.app.fw);
            bench_mark_end_mid();
        }
        /* Reading CCRx clears CCxIF in the hardware. */
        put(enc + F4_TIM_SR, 0u);
        fw_watchdog_kick(&s.app.fw);
        if (get(F4_TIM1 + F4_TIM_CCR(1u)) != r->cmp[0] ||
            get(F4_TIM1 + F4_TIM_CCR(2u)) != r->cmp[1] ||
            get(F4_TIM1 + F4_TIM_CCR(3u)) != r->cmp[2] ||
            (uint32_t)fw_state(&s.app.fw) != r->state_after) {
            differs++;
        }
    }
    uart_puts("bench: " F405_BOARD_TAG " ctrl ");
    uart_puts(desc->name);
    say(" speed ", h->speed_rpm);
    say(" periods ", h->n);
    say(" running ", running);
    say(" differs ", differs);
    say(" fs ", h->pwm_freq_hz);
    uart_puts("\n");
    return differs == 0u ? 0 : 1;
}
