/* Replay of a bench recording (see bench_replay.h). */
#include "bench_replay.h"

#include <string.h>

#include "controller.h"

const char *bench_replay_open(bench_replay_t *r, const void *blob, size_t size)
{
    if (r == NULL || blob == NULL || size < sizeof(bench_hdr_t)) {
        return "recording too short";
    }
    memset(r, 0, sizeof *r);
    const bench_hdr_t *h = (const bench_hdr_t *)blob;
    if (h->magic != BENCH_MAGIC || h->version != BENCH_VERSION) {
        return "not a bench recording (magic/version)";
    }
    if (h->n == 0u || h->arm_index >= h->n ||
        (size - sizeof *h) / sizeof(bench_rec_t) < (size_t)h->n) {
        return "recording truncated or empty";
    }
    char name[sizeof h->ctrl_name + 1u];
    memcpy(name, h->ctrl_name, sizeof h->ctrl_name);
    name[sizeof h->ctrl_name] = '\0';
    r->desc = ctrl_find(name);
    if (r->desc == NULL) {
        return "controller not in this image's registry";
    }
    r->hdr = h;
    r->rec = (const bench_rec_t *)(const void *)(h + 1);
    r->machine.name = h->machine_name;
    r->machine.pole_pairs = h->pole_pairs;
    r->machine.rs_ohm = h->rs_ohm;
    r->machine.ld_h = h->ld_h;
    r->machine.lq_h = h->lq_h;
    r->machine.psi_pm_wb = h->psi_pm_wb;
    r->machine.vdc_v = h->vdc_v;
    r->machine.inertia_kgm2 = h->inertia_kgm2;
    r->machine.torque_rated_nm = h->torque_rated_nm;
    r->machine.speed_rated_rpm = h->speed_rated_rpm;
    r->machine.current_rated_a = h->current_rated_a;
    r->machine.current_max_a = h->current_max_a;
    r->machine.psi_ref_wb = h->psi_ref_wb;
    r->info.pwm_freq_hz = h->pwm_freq_hz;
    r->info.period_counts = h->period_counts;
    r->info.adc_bits = (uint8_t)h->adc_bits;
    r->info.adc_current_a_per_count = h->adc_current_a_per_count;
    r->info.adc_vdc_v_per_count = h->adc_vdc_v_per_count;
    r->info.encoder_counts_per_rev = h->encoder_counts_per_rev;
    r->info.has_i_c = h->has_i_c != 0u;
    r->info.cycle_clock_hz = h->cycle_clock_hz;
    return NULL;
}

int bench_replay_init(bench_replay_t *r, fw_t *fw, hal_t *hal)
{
    hal_replay_init(hal, &r->info);
    fw_config_t fc;
    fw_config_default(&fc, &r->machine, r->desc);
    fc.calib_samples = r->hdr->calib_samples;
    fc.sensorless = r->hdr->sensorless != 0u;
    fc.hfi = r->hdr->sensorless == 2u;
    fc.dead_time_s = r->hdr->dead_time_s;
    fc.v_fwd_v = r->hdr->v_fwd_v;
    return fw_init(fw, hal, &fc);
}

void bench_replay_input(bench_replay_t *r, fw_t *fw, hal_t *hal, uint32_t k)
{
    const bench_rec_t *s = &r->rec[k];
    for (int x = 0; x < 4; x++) {
        r->in.adc[x] = s->adc[x];
    }
    r->in.cmd = s->cmd;
    r->in.index_seen = s->index_seen;
    r->in.trip = s->trip;
    r->in.enc_count = s->enc_count;
    r->in.index_count = s->index_count;
    hal_replay_set_input(hal, &r->in);
    if ((s->cmd & BENCH_CMD_TORQUE) != 0u) {
        fw_set_torque_ref(fw, r->hdr->torque_ref_q24);
    }
    if ((s->cmd & BENCH_CMD_ARM) != 0u) {
        fw_cmd_arm(fw);
    }
}

int bench_replay_differs(const bench_replay_t *r, const fw_t *fw, const hal_t *hal, uint32_t k)
{
    const bench_rec_t *s = &r->rec[k];
    for (int x = 0; x < 3; x++) {
        if (hal->pwm.cmp[x] != s->cmp[x]) {
            return 1;
        }
    }
    return (uint32_t)fw_state(fw) != s->state_after ? 1 : 0;
}
