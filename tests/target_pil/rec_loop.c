/* The recorders' host closed loop (rec_loop.h). */
#include "rec_loop.h"

const char *rec_loop_init(rec_loop_t *loop, const ctrl_desc_t *d, const sim_machine_t *sm,
                          uint32_t fs, double speed_rpm, uint32_t calib_samples,
                          unsigned sensorless)
{
    ctrl_machine_t cm;
    sim_ctrl_machine_from(sm, &cm);
    plant_config_t pc;
    sim_machine_to_plant(sm, &pc);
    pc.mech = PLANT_MECH_IMPOSED;
    pc.speed0_rpm = speed_rpm;
    if (plant_init(&loop->plant, &pc) != PLANT_OK) {
        return "plant_init failed for ";
    }
    hal_sim_config_t hc;
    hal_sim_config_default(&hc, fs, sm->current_max_a, sm->vdc_v);
    if (hal_sim_init(&loop->hal, &hc, &loop->plant) != HAL_SIM_OK) {
        return "hal_sim_init failed for ";
    }
    fw_config_t fc;
    fw_config_default(&fc, &cm, d);
    fc.calib_samples = calib_samples;
    fc.sensorless = sensorless != 0u;
    fc.hfi = sensorless == 2u;
    /* the plant's inverter, compensated as the simulator's drive does */
    fc.dead_time_s = sm->dead_time_s;
    fc.v_fwd_v = sm->v_fwd_v;
    if (fw_init(&loop->fw, &loop->hal, &fc) != FW_OK) {
        return "fw_init failed for ";
    }
    hal_info_get(&loop->hal, &loop->info);
    loop->armed = 0;
    loop->torque_ref_armed = 0;
    return NULL;
}

void rec_loop_isr(rec_loop_t *loop, double torque_nm, pil_in_t *in)
{
    hal_t *hal = &loop->hal;
    uint8_t cmd = 0u;
    if (!loop->armed && fw_state(&loop->fw) == FW_STATE_READY) {
        fw_set_torque_ref_nm(&loop->fw, torque_nm);
        fw_cmd_arm(&loop->fw);
        cmd = PIL_CMD_TORQUE | PIL_CMD_ARM;
        loop->armed = 1;
        loop->torque_ref_armed = fw_torque_ref(&loop->fw);
    }
    hal_sim_period_begin(hal);
    in->adc[0] = hal->adc.i_a;
    in->adc[1] = hal->adc.i_b;
    in->adc[2] = hal->adc.i_c;
    in->adc[3] = hal->adc.vdc;
    in->cmd = cmd;
    in->index_seen = hal->enc.index_seen ? 1u : 0u;
    in->trip = hal->trip ? 1u : 0u;
    in->enc_count = hal->enc.count;
    in->index_count = hal->enc.index_count;
    fw_isr(&loop->fw);
    fw_watchdog_kick(&loop->fw);
}

int rec_loop_end(rec_loop_t *loop)
{
    return hal_sim_period_end(&loop->hal);
}
