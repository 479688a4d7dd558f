/* Replay of a recording through the pipeline (see pil_replay.h). */
#include "pil_replay.h"

#include <string.h>

#include "controller.h"

/* Sets *mm for the first difference; returns 1 if a and b differ. */
static int pil_cmp(pil_mismatch_t *mm, uint32_t k, const char *field, int64_t want, int64_t got)
{
    if (want == got) {
        return 0;
    }
    mm->period = k;
    mm->field = field;
    mm->want = want;
    mm->got = got;
    return 1;
}

static int pil_compare(pil_mismatch_t *mm, uint32_t k, const pil_out_t *w, const hal_t *h,
                       const fw_telemetry_t *tm)
{
    static const char *const cmp_names[3] = {"pwm.cmp[0]", "pwm.cmp[1]", "pwm.cmp[2]"};
    static const char *const leg_names[3] = {"tm.legs[0]", "tm.legs[1]", "tm.legs[2]"};
    for (int x = 0; x < 3; x++) {
        if (pil_cmp(mm, k, cmp_names[x], w->cmp[x], h->pwm.cmp[x]) != 0) {
            return 1;
        }
    }
    if (pil_cmp(mm, k, "gates", w->gates, h->gates ? 1 : 0) != 0 ||
        pil_cmp(mm, k, "tm.state", w->state, tm->state) != 0 ||
        pil_cmp(mm, k, "tm.fault", w->fault, tm->fault) != 0 ||
        pil_cmp(mm, k, "tm.vec", w->vec, tm->vec) != 0 ||
        pil_cmp(mm, k, "tm.i_a", w->i_a, tm->i_a) != 0 ||
        pil_cmp(mm, k, "tm.i_b", w->i_b, tm->i_b) != 0 ||
        pil_cmp(mm, k, "tm.vdc", w->vdc, tm->vdc) != 0 ||
        pil_cmp(mm, k, "tm.i_d", w->i_d, tm->i_d) != 0 ||
        pil_cmp(mm, k, "tm.i_q", w->i_q, tm->i_q) != 0 ||
        pil_cmp(mm, k, "tm.psi_d", w->psi_d, tm->psi_d) != 0 ||
        pil_cmp(mm, k, "tm.psi_q", w->psi_q, tm->psi_q) != 0 ||
        pil_cmp(mm, k, "tm.torque", w->torque, tm->torque) != 0 ||
        pil_cmp(mm, k, "tm.omega_e", w->omega_e, tm->omega_e) != 0 ||
        pil_cmp(mm, k, "tm.torque_ref", w->torque_ref, tm->torque_ref) != 0 ||
        pil_cmp(mm, k, "tm.duty", w->duty, tm->duty) != 0) {
        return 1;
    }
    for (int x = 0; x < 3; x++) {
        if (pil_cmp(mm, k, leg_names[x], w->legs[x], tm->legs[x]) != 0) {
            return 1;
        }
    }
    return pil_cmp(mm, k, "tm.theta_e", w->theta_e, tm->theta_e) != 0 ||
           pil_cmp(mm, k, "tm.period", w->period, tm->period) != 0 ||
           pil_cmp(mm, k, "tm.cycles", w->cycles, tm->cycles) != 0;
}

int pil_replay_run(const pil_rec_t *rec, fw_t *fw, hal_t *hal, pil_mismatch_t *mm)
{
    if (rec == NULL || fw == NULL || hal == NULL || mm == NULL) {
        return -1;
    }
    memset(mm, 0, sizeof *mm);
    const ctrl_desc_t *desc = ctrl_find(rec->name);
    if (desc == NULL) {
        mm->field = "controller not in this image's registry";
        return -1;
    }
    hal_replay_init(hal, &rec->info);
    fw_config_t fc;
    fw_config_default(&fc, &rec->machine, desc);
    fc.calib_samples = rec->calib_samples;
    fc.sensorless = rec->sensorless != 0u;
    if (fw_init(fw, hal, &fc) != FW_OK) {
        mm->field = "fw_init failed";
        return -1;
    }
    for (uint32_t k = 0; k < rec->n; k++) {
        const pil_in_t *in = &rec->in[k];
        hal_replay_set_input(hal, in);
        if ((in->cmd & PIL_CMD_TORQUE) != 0u) {
            fw_set_torque_ref(fw, rec->torque_ref_q24);
        }
        if ((in->cmd & PIL_CMD_ARM) != 0u) {
            fw_cmd_arm(fw);
        }
        fw_isr(fw);
        fw_watchdog_kick(fw);
        if (pil_compare(mm, k, &rec->out[k], hal, fw_telemetry(fw)) != 0) {
            return 1;
        }
    }
    return 0;
}
