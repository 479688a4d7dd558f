/*
 * Host/target equivalence of the identification (firmware/commission): a
 * recording of the whole "ident run" on the host closed loop - the thesis
 * SPMSM with ADC noise, an encoder at 137 deg counting backwards, wrong
 * configured parameters - followed by the main loop adopting the results and
 * a short torque-mode run with them. pil_ident_gen (host) writes every
 * period's ISR inputs and a hash of its outputs into pil_ident_data.c;
 * pil_ident_replay replays the inputs through fw_isr on the host and in QEMU
 * and compares the hashes (the first differing period is reported) and the
 * identified values. About 83 000 periods: its own image, so the other
 * replay image stays small.
 */
#ifndef TESTS_TARGET_PIL_PIL_IDENT_H
#define TESTS_TARGET_PIL_PIL_IDENT_H

#include <stddef.h>
#include <stdint.h>

#include "ctrl_params.h"
#include "hal.h"
#include "pil_data.h"
#include "pipeline.h"

#define PIL_IDENT_START 0x1u  /* fw_commission_start(the ident plan) before the ISR */
#define PIL_IDENT_APPLY 0x2u  /* fw_commission_poll after the ISR (it adopted) */
#define PIL_IDENT_TORQUE 0x4u /* fw_set_torque_ref(torque_ref_q24) before the ISR */
#define PIL_IDENT_ARM 0x8u    /* fw_cmd_arm before the ISR */

typedef struct {
    uint16_t adc[4]; /* i_a, i_b, i_c, vdc counts */
    uint32_t enc_count, index_count;
    uint8_t cmd;   /* PIL_IDENT_* */
    uint8_t flags; /* bit 0 index seen, bit 1 trip latched */
} pil_ident_in_t;

typedef struct {
    hal_info_t info;
    ctrl_machine_t machine; /* the configured (wrong) machine */
    fx_angle_t enc_offset;
    int8_t enc_direction;
    uint32_t enc_cpr, calib_samples;
    int32_t torque_ref_q24;
    uint32_t n;
    const pil_ident_in_t *in;
    const uint32_t *hash; /* pil_ident_hash after each period */
    /* identified, pu of the identification's bases, before adoption */
    int32_t rs, ld, lq, psi;
    uint32_t enc_off;
    int32_t enc_dir;
} pil_ident_rec_t;

extern const pil_ident_rec_t pil_ident_rec;

/* A recorded period's samples as the replay HAL's input (hal_replay.h). */
static inline void pil_ident_in_replay(const pil_ident_in_t *s, pil_in_t *in)
{
    in->adc[0] = s->adc[0];
    in->adc[1] = s->adc[1];
    in->adc[2] = s->adc[2];
    in->adc[3] = s->adc[3];
    in->cmd = 0u;
    in->index_seen = (uint8_t)(s->flags & 1u);
    in->trip = (uint8_t)((s->flags >> 1) & 1u);
    in->enc_count = s->enc_count;
    in->index_count = s->index_count;
}

/* FNV-1a over one period's outputs: compare values, gate request, the
 * telemetry sample and the commissioning state. */
static inline uint32_t pil_ident_mix(uint32_t h, uint32_t v)
{
    for (int b = 0; b < 4; b++) {
        h ^= (v >> (8 * b)) & 0xFFu;
        h *= 16777619u;
    }
    return h;
}

static inline uint32_t pil_ident_hash(const hal_pwm_t *pwm, int gates, const fw_t *fw)
{
    const fw_telemetry_t *t = fw_telemetry(fw);
    uint32_t h = 2166136261u;
    for (int x = 0; x < 3; x++) {
        h = pil_ident_mix(h, pwm->cmp[x]);
        h = pil_ident_mix(h, (uint32_t)t->legs[x]);
    }
    const uint32_t v[] = {(uint32_t)gates,
                          t->state,
                          t->fault,
                          t->vec,
                          (uint32_t)t->i_a,
                          (uint32_t)t->i_b,
                          (uint32_t)t->vdc,
                          (uint32_t)t->torque,
                          (uint32_t)t->omega_e,
                          (uint32_t)t->duty,
                          t->theta_e,
                          t->period,
                          t->cycles,
                          t->cm_step,
                          t->cm_progress,
                          fw->cm.err,
                          fw->cm.res.have,
                          (uint32_t)fw->cm.res.rs,
                          (uint32_t)fw->cm.res.psi};
    for (size_t k = 0; k < sizeof v / sizeof v[0]; k++) {
        h = pil_ident_mix(h, v[k]);
    }
    return h;
}

#endif /* TESTS_TARGET_PIL_PIL_IDENT_H */
