/*
 * The minimal firmware of the memory-footprint images (tools/bench): the
 * pipeline (fw_init with the registry's first controller, fw_isr from the
 * Timer0 interrupt) on the replay HAL. Identical in every image; only the
 * registry (bench_size_registry.c) differs, so the size difference to the
 * baseline (empty registry) is what one controller adds.
 */
#include <stddef.h>

#include "hal_replay.h"
#include "pipeline.h"
#include "qemu_mps2.h"

static fw_t fw;
static hal_t hal;
static pil_in_t in;

static void bench_size_tick(void)
{
    hal_replay_set_input(&hal, &in);
    fw_isr(&fw);
    fw_watchdog_kick(&fw);
}

int main(void)
{
    static const ctrl_machine_t machine = {
        "thesis_spmsm", 4,   0.901,  6.552e-3, 6.552e-3, 0.09427, 220.0,
        1.2e-4,         2.4, 3000.0, 4.2,      10.5,     0.0,     0.0};
    /* zero current at mid-scale, its tolerance the default (hal.h) */
    const hal_info_t info = {
        10000u, 2500u, 12u, 15.75 / 2048.0, 440.0 / 4096.0, 10000u, false, 25000000u, 0u, 0u, 0u};
    const ctrl_desc_t *desc = ctrl_at(0);
    if (desc == NULL) {
        return 0;
    }
    hal_replay_init(&hal, &info);
    fw_config_t fc;
    fw_config_default(&fc, &machine, desc);
    if (fw_init(&fw, &hal, &fc) != FW_OK) {
        return 1;
    }
    fw_set_torque_ref(&fw, 0);
    fw_cmd_arm(&fw);
    if (timer0_start(info.pwm_freq_hz, bench_size_tick) != 0) {
        return 1;
    }
    for (;;) {
        board_idle();
    }
}
