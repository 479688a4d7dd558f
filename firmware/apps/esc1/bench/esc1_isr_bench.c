/*
 * Instruction count of the B-G431B-ESC1's control interrupt, on the emulated
 * Cortex-M4 (QEMU mps2-an386, tools/bench_fw/bench_esc1.py).
 *
 * The code counted is the board image's: esc1_control_isr (esc1_isr.c) with
 * the G4 back-end of hal.h (g4_hal.c) and the firmware, built with the same
 * compiler and flags; only the peripheral base addresses differ: they are
 * arrays here (G4_MEM_ARRAYS), link-time constants like the chip's addresses,
 * so every register access compiles to the same instructions.
 *
 * A bench recording (tools/bench, bench_blob.h: a host closed loop's raw
 * inputs and compare values per period) is replayed: before each interrupt
 * the recorded samples are put where the hardware would put them (ADC
 * injected data registers, mirrored as the ESC1's inverting amplifier
 * delivers them; the TIM4 counter; an index capture), after it the compare
 * values TIM1_CCRx and the state are checked against the recording. The HAL
 * reports the recording's hal_info (period counts, gains) and applies no
 * compare limit, so the firmware computes exactly what it did on the PC.
 * Markers as in bench_cm4.c: bench_mark_begin / _end_empty / _end_boot /
 * _end_run around each call, _end_mid around the medium-rate task which the
 * interrupt pended (PendSV_Handler's fw_medium; the counting plugin,
 * bench_plugin.c).
 *
 * UART0: one summary line; exit 0 when every period matched the recording.
 */
#include <stdint.h>
#include <string.h>

#include "bench_blob.h"
#include "board_esc1.h"
#include "controller.h"
#include "esc1_app.h"
#include "g4_regs.h"
#include "qemu_mps2.h"

#define G4_DEFINE_ARRAY(N, n, addr, bytes) uint32_t g4_mem_##n[(bytes) / 4u];
G4_PERIPHS(G4_DEFINE_ARRAY)
#undef G4_DEFINE_ARRAY

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

static esc1_t s;
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

    /* The ESC1's back-end as g4_hal_init leaves it (ranks: U ADC1 JDR1, V
     * ADC2 JDR1, W ADC1 JDR2, Vbus ADC2 JDR2; ADC2 raises the interrupt),
     * with the recording's scales. */
    hal_t *hal = &s.hal;
    memset(hal, 0, sizeof *hal);
    hal->board = &g4_board_esc1;
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
    hal->mirror = 0xFFFu;
    hal->jdr[0] = G4_ADC1 + G4_ADC_JDR1;
    hal->jdr[1] = G4_ADC2 + G4_ADC_JDR1;
    hal->jdr[2] = G4_ADC1 + G4_ADC_JDR2;
    hal->jdr[3] = G4_ADC2 + G4_ADC_JDR2;
    hal->irq_adc = G4_ADC2;
    hal->other_adc = G4_ADC1;

    fw_config_default(&s.fc, &machine, desc);
    s.fc.calib_samples = h->calib_samples;
    s.fc.sensorless = h->sensorless != 0u; /* as recorded (tools/bench --esc1 --sensorless) */
    if (fw_init(&s.fw, hal, &s.fc) != FW_OK) {
        uart_puts("bench: fw_init failed\n");
        return 3;
    }
    fw_link_init(&s.link, &s.fw, NULL, NULL);

    for (int i = 0; i < 4; i++) {
        bench_mark_begin();
        bench_mark_end_empty();
    }
    uint32_t differs = 0u, running = 0u, last_index = 0u;
    bool index_was_seen = false;
    for (uint32_t k = 0; k < h->n; k++) {
        const bench_rec_t *r = &rec[k];
        put(G4_ADC1 + G4_ADC_JDR1, r->adc[0] ^ 0xFFFu);
        put(G4_ADC2 + G4_ADC_JDR1, r->adc[1] ^ 0xFFFu);
        put(G4_ADC1 + G4_ADC_JDR2, r->adc[2] ^ 0xFFFu);
        put(G4_ADC2 + G4_ADC_JDR2, r->adc[3]);
        put(G4_ADC2 + G4_ADC_ISR, G4_ADC_ISR_JEOS | G4_ADC_ISR_JEOC);
        put(G4_TIM4 + G4_TIM_CNT, r->enc_count & 0xFFFFu);
        if (r->index_seen != 0u && (!index_was_seen || r->index_count != last_index)) {
            put(G4_TIM4 + G4_TIM_CCR3, r->index_count & 0xFFFFu);
            put(G4_TIM4 + G4_TIM_SR, G4_TIM_SR_CC3IF);
            index_was_seen = true;
            last_index = r->index_count;
        }
        put(G4_TIM1 + G4_TIM_SR, r->trip != 0u ? G4_TIM_SR_BIF : 0u);
        if ((r->cmd & BENCH_CMD_TORQUE) != 0u) {
            fw_set_torque_ref(&s.fw, h->torque_ref_q24);
        }
        if ((r->cmd & BENCH_CMD_ARM) != 0u) {
            fw_cmd_arm(&s.fw);
        }
        if (k >= h->arm_index && r->state_after == (uint8_t)FW_STATE_RUNNING) {
            bench_mark_begin();
            esc1_control_isr(&s);
            bench_mark_end_run();
            running++;
        } else {
            bench_mark_begin();
            esc1_control_isr(&s);
            bench_mark_end_boot();
        }
        if (s.fw.mid_done != s.fw.mid_req) {
            /* PendSV pended (in a register array here): the medium-rate task */
            bench_mark_begin();
            fw_medium(&s.fw);
            bench_mark_end_mid();
        }
        /* Reading CCR3 clears CC3IF in the hardware. */
        put(G4_TIM4 + G4_TIM_SR, 0u);
        fw_watchdog_kick(&s.fw);
        if (get(G4_TIM1 + G4_TIM_CCR1) != r->cmp[0] || get(G4_TIM1 + G4_TIM_CCR2) != r->cmp[1] ||
            get(G4_TIM1 + G4_TIM_CCR3) != r->cmp[2] ||
            (uint32_t)fw_state(&s.fw) != r->state_after) {
            differs++;
        }
    }
    uart_puts("bench: esc1 ctrl ");
    uart_puts(desc->name);
    say(" speed ", h->speed_rpm);
    say(" periods ", h->n);
    say(" running ", running);
    say(" differs ", differs);
    say(" fs ", h->pwm_freq_hz);
    uart_puts("\n");
    return differs == 0u ? 0 : 1;
}
