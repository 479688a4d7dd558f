/*
 * Interactive image: the firmware on the emulated Cortex-M4 (QEMU
 * mps2-an386) with the thesis SPMSM in the loop, driven only by the commands
 * it receives on UART0 (firmware/PROTOCOL.md; tools/console --qemu). It has no
 * script and no end: it runs until QEMU is stopped.
 *
 * Plant: free rotor (J of the machine file) with a passive load of
 * PIL_APP_LOAD_NM on the shaft (it opposes the rotation and never drives it),
 * at rest at power-up: the demo rig's, given to the plant as the machine's
 * [mechanics] load (load_kind = passive), the one way a load reaches the
 * plant and the run (sim_machine_to_plant, sim_run_config_default). The closed-loop engine
 * (firmware/apps/engine) runs one PWM period per Timer0 interrupt (pil_common.h) from boot on:
 * calibration (256 periods, gates off), then ready; "arm" is the user's. Default controller
 * PIL_APP_CTRL at its default fs; "ctrl select" changes it while disarmed.
 * Wall time: a running period costs 50-110 k emulated instructions, so plant
 * time runs at about 1/20 of real time (-icount shift=3).
 * Settings ("config save|show|erase|default"): the record of fw_settings.h in
 * a RAM model of the G4 flash's two pages (settings_flash_model.h), empty at
 * each start of QEMU. The firmware's configuration as parameters (machine,
 * encoder, inverter, speed loop, limits, protections: fw_params.h) changes
 * through the same reconfiguration as a record.
 */
#include <stdio.h>
#include <string.h>

#include "controller.h"
#include "fw_link.h"
#include "fw_params.h"
#include "pil_cl.h"
#include "pil_common.h"
#include "pipeline.h"
#include "qemu_mps2.h"
#include "settings_flash_model.h"
#include "sim_run.h"

#ifndef PIL_APP_CTRL
#define PIL_APP_CTRL "fst"
#endif
#ifndef PIL_APP_LOAD_NM
#define PIL_APP_LOAD_NM 0.3
#endif

static struct {
    sim_run_t run;
    fw_link_t link;
    pil_timer_t timer;
    volatile int plant_failed;
    sfm_t flash;
    fw_settings_t settings;
    ctrl_machine_t machine; /* the compiled-in machine (config default) */
} app;

/* A record's configuration on the running engine (commands run with the
 * period interrupt masked: pil_poll_uart). */
static int app_settings_apply(void *ctx, const settings_t *s, char *why, size_t cap)
{
    (void)ctx;
    return fw_settings_init(&app.run.fw, &app.run.hal, s, app.run.ctrl_cfg_buf, why, cap);
}

static int app_settings_default(void *ctx)
{
    (void)ctx;
    fw_config_t c;
    fw_config_default(&c, &app.machine, ctrl_find(PIL_APP_CTRL));
    return fw_init(&app.run.fw, &app.run.hal, &c) == FW_OK ? CMD_OK : CMD_E_FAILED;
}

/* The PWM-period interrupt (Timer0). */
static void app_isr(void)
{
    if (app.plant_failed) {
        return;
    }
    const uint32_t t_enter = timer1_read();
    if (sim_run_period(&app.run) != 0) {
        app.plant_failed = 1;
        timer0_stop();
        return;
    }
    pil_timer_account(&app.timer, timer1_read() - t_enter, app_isr);
}

int main(void)
{
    memset(&app, 0, sizeof app);
    (void)setvbuf(stdout, NULL, _IONBF, 0);
    const ctrl_desc_t *desc = ctrl_find(PIL_APP_CTRL);
    if (desc == NULL) {
        printf("interactive: controller %s is not registered\n", PIL_APP_CTRL);
        return 2;
    }
    static sim_run_cfg_t c;
    static sim_machine_t rig;
    rig = pil_machine;
    rig.load_kind = SIM_LOAD_PASSIVE;
    rig.load_nm = PIL_APP_LOAD_NM;
    sim_run_config_default(&c, &rig, desc);
    c.fs_hz = desc->fs_default_hz;
    c.free_mech = true;
    c.duration_s = 100.0; /* never reached: the engine is not armed by itself */
    c.win_start_s = 99.0; /* no metrics window, no Ts/10 observer */
    c.win_end_s = 100.0;
    c.defer_start = true;    /* the interrupt runs every period from boot on */
    c.auto_arm = false;      /* only the user arms */
    c.kick_watchdog = false; /* the main loop kicks */
    c.skip_thd = true;
    char err[256];
    if (sim_run_init(&app.run, &c, err, sizeof err) != 0) {
        printf("interactive: %s\n", err);
        return 2;
    }
    app.machine = app.run.fw.machine_own;
    /* the F405's 16 KiB sectors: the record and the anti-cogging table */
    sfm_init_size(&app.flash, 1u, SFM_PAGE_MAX);
    sfm_flash(&app.flash, &app.settings.flash);
    app.settings.apply = app_settings_apply;
    app.settings.apply_default = app_settings_default;
    app.settings.fw = &app.run.fw;
    (void)fw_settings_boot(&app.settings);
    fw_link_init(&app.link, &app.run.fw, pil_uart_write, NULL);
    fw_link_set_settings(&app.link, &app.settings);
    fw_params_attach(&app.link, &fw_params_machine); /* through app_settings_apply */
    fw_params_attach(&app.link, &fw_params_drive);
    hal_qemu_uart_rx_enable();
    printf("pmsm-dtc on QEMU mps2-an386: %s, free rotor, passive load %.2f N*m; controller %s "
           "at %u Hz; calibrating (256 periods), then 'arm' (PROTOCOL.md, 'help')\n",
           rig.name, c.load_passive_nm, desc->name, (unsigned)c.fs_hz);
    printf("%s (flash: RAM model)\n", app.settings.msg);
#if CTRL_COGGING
    if (app.settings.tab_msg[0] != '\0') {
        printf("%s\n", app.settings.tab_msg);
    }
#endif
    pil_timer_start(&app.timer, app_isr);
    for (;;) {
        pil_poll_uart(&app.link);
        fw_watchdog_kick(&app.run.fw);
        if (app.plant_failed == 1) {
            app.plant_failed = 2;
            printf("interactive: the plant integration failed (code %d); the drive is stopped\n",
                   app.run.plant_rc);
        }
        board_idle();
    }
}
