/*
 * Host/target equivalence of the closed loop with the anti-cogging table on
 * (control/regulators/cogging_ff.h): a recording on the host of the stress
 * machine with cogging (nonideal/thesis_spmsm_stress.ini: stiction, Coulomb
 * and viscous friction, cogging 10 % of rated, a passive load), FOC in
 * speed mode at 30 r/min with the table of the plant's cogging loaded and
 * the feed-forward on, from fw_init. pil_cog_gen (host) writes every
 * period's ISR inputs, the table and a hash of each period's outputs (the
 * ones pil_ident_hash covers, plus the torque reference with the
 * feed-forward in it, the feed-forward itself and the encoder position it was
 * read at, the look-ahead's filtered speed and the feed-forward it holds)
 * into pil_cog_data.c; pil_cog_replay replays the inputs through
 * fw_isr on the host and in QEMU and compares every period's hash.
 */
#ifndef TESTS_TARGET_PIL_PIL_COG_H
#define TESTS_TARGET_PIL_PIL_COG_H

#include "cogging_ff.h"
#include "pil_ident.h"

#define PIL_COG_TABLE 0x10u /* fw_cogging_load(table) and fw_cogging_enable before the ISR */
#define PIL_COG_SPEED 0x20u /* fw_set_speed_ref(speed_ref_q24) before the ISR */
/* PIL_IDENT_ARM: fw_cmd_arm before the ISR */

typedef struct {
    hal_info_t info;
    ctrl_machine_t machine;
    fx_angle_t enc_offset;
    int8_t enc_direction;
    uint32_t enc_cpr, calib_samples;
    int32_t speed_ref_q24;
    uint32_t n;
    const pil_ident_in_t *in;
    const uint32_t *hash;
    const int16_t *table; /* CTRL_COG_N entries */
    uint32_t ff_periods;  /* periods the feed-forward was non-zero in the recording */
} pil_cog_rec_t;

extern const pil_cog_rec_t pil_cog_rec;

static inline uint32_t pil_cog_hash(const hal_pwm_t *pwm, int gates, const fw_t *fw)
{
    uint32_t h = pil_ident_hash(pwm, gates, fw);
    h = pil_ident_mix(h, (uint32_t)fw->refs.torque);
    h = pil_ident_mix(h, (uint32_t)fw->torque_ref_now);
    h = pil_ident_mix(h, fw->enc_pos);
    h = pil_ident_mix(h, (uint32_t)ctrl_cogging_ff(&fw->cog.map, fw->enc_pos));
    /* the look-ahead's state: its filtered speed and the feed-forward held */
    h = pil_ident_mix(h, (uint32_t)fw->cog.map.w);
    h = pil_ident_mix(h, (uint32_t)fw->cog.map.ff_held);
    h = pil_ident_mix(h, fw->cog_on);
    return h;
}

#endif /* TESTS_TARGET_PIL_PIL_COG_H */
