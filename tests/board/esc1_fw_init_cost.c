/*
 * The firmware's initialisation (fw_init) against the B-G431B-ESC1's
 * independent watchdog, counted on the Cortex-M4 in QEMU (cm4 build only).
 *
 * A reconfiguration on the board ("config default",
 * "param set m.*", "ident apply", a settings record applied at start-up)
 * runs fw_init in the main loop with the control interrupt held off, and
 * nothing refreshes the watchdog meanwhile; a refused one runs it twice (the
 * previous data restored). Its running window is ESC1_IWDG_MS (100 ms) at the
 * LSI's nominal 32 kHz, 94.1 ms at the LSI's fastest 34 kHz (DS12589).
 *
 * Counted: the instructions of fw_init for the image's compiled-in machine
 * (PMSM_ESC1_MACHINE_INI) with each controller of the image (foc, m2ptfc,
 * drr, fst), encoder and sensorless. QEMU counts instructions, not cycles:
 * under -icount shift=7 one instruction is 128 ns of virtual time, Timer1
 * (25 MHz) is read around the call and converted with the measured ticks per
 * 1000 instructions (timer1_ticks_per_kinstr).
 *
 * Asserted: two runs at 3 cycles per instruction at 170 MHz take at most a
 * third of the shortest window (CPI 3 is twice the bench's upper 1.5: the
 * configuration code runs from flash with 4 wait states and its soft-float
 * calls are not the interrupt's cached loops), i.e. at most 888 889
 * instructions per run; measured about 0.61 .. 0.70 M (10.8 .. 12.3 ms at
 * CPI 3, half that at the bench's CPI 1.5). Before the MTPA table was built
 * in integer arithmetic, fw_init took about 13.5 M instructions
 * (pil_replay_qemu.elf's machine; 24.9 M in an earlier review's build of the
 * QEMU image): 238 ms for one run at CPI 3, a watchdog reset.
 */
#include <stdio.h>
#include <string.h>

#include "board_esc1.h"
#include "controller.h"
#include "hal_replay.h"
#include "pipeline.h"
#include "qemu_mps2.h"
#include "unity.h"

extern const ctrl_machine_t esc1_default_machine;

#define F_CPU_HZ 170e6
#define CPI 3.0
#define WINDOW_S (0.100 * 32000.0 / 34000.0) /* ESC1_IWDG_MS at the LSI's fastest */
#define SHARE (1.0 / 3.0)
#define RUNS 2.0 /* a refused reconfiguration and its restore */

static fw_t fw;
static hal_t hal;

void setUp(void)
{
}
void tearDown(void)
{
}

/* The ESC1's hal.h description as g4_hal_init gives it (g4_hal_setup.c). */
static void esc1_info(hal_info_t *info)
{
    const g4_board_t *b = &g4_board_esc1;
    memset(info, 0, sizeof *info);
    info->pwm_freq_hz = 20000u;  /* ESC1_FS_HZ */
    info->period_counts = 4250u; /* 170 MHz / (2 x 20 kHz), centre-aligned */
    info->pwm_cmp_max = 4250u;
    info->adc_bits = 12u;
    info->adc_current_a_per_count = b->vref / 4095.0 / (-b->sense_gain * b->shunt_ohm);
    info->adc_vdc_v_per_count = b->vref / 4095.0 / b->vbus_ratio;
    info->encoder_counts_per_rev = 4096u; /* ESC1_ENCODER_CPR */
    info->has_i_c = true;
    info->cycle_clock_hz = 170000000u;
}

static void test_fw_init_within_the_watchdog(void)
{
    const uint32_t kinstr = timer1_ticks_per_kinstr();
    TEST_ASSERT_TRUE(kinstr >= 1000u); /* shift >= 7: counts exact to an instruction */
    const double limit = SHARE * WINDOW_S * F_CPU_HZ / (CPI * RUNS);
    const char *names[] = {"foc", "m2ptfc", "drr", "fst"};
    hal_info_t info;
    esc1_info(&info);
    uint32_t worst = 0u;
    for (size_t k = 0; k < sizeof names / sizeof names[0]; k++) {
        for (int sl = 0; sl <= 1; sl++) {
            fw_config_t fc;
            fw_config_default(&fc, &esc1_default_machine, ctrl_find(names[k]));
            fc.sensorless = sl != 0;
            hal_replay_init(&hal, &info);
            const uint32_t t0 = timer1_read();
            const int rc = fw_init(&fw, &hal, &fc);
            const uint32_t t1 = timer1_read();
            const uint32_t n = (uint32_t)(((uint64_t)(t1 - t0) * 1000u + kinstr / 2u) / kinstr);
            printf("fw_init %-6s %-10s %7u instructions, %.2f ms at CPI %.0f, 170 MHz\n", names[k],
                   sl ? "sensorless" : "encoder", (unsigned)n, n * CPI / F_CPU_HZ * 1e3, CPI);
            TEST_ASSERT_EQUAL_INT_MESSAGE(FW_OK, rc, names[k]);
            worst = n > worst ? n : worst;
        }
    }
    printf("fw_init worst %u instructions; limit %.0f (%.0f %% of %.1f ms for %.0f runs at CPI "
           "%.0f)\n",
           (unsigned)worst, limit, SHARE * 100.0, WINDOW_S * 1e3, RUNS, CPI);
    TEST_ASSERT_TRUE_MESSAGE(worst <= (uint32_t)limit, "fw_init too long for the watchdog");
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_fw_init_within_the_watchdog);
    return UNITY_END();
}
