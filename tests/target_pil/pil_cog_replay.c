/*
 * Bit-exact host/target equivalence of the closed loop with the anti-cogging
 * table on (pil_cog.h): the recorded inputs through fw_isr with the replay
 * HAL, the table loaded and the speed reference and arm at the recorded
 * period, each period's output hash compared with the host's. Built for the
 * host (test_pil_cog_host) and for QEMU (test_pil_cog_qemu). Exit status 0
 * when every period matches.
 */
#include <stdio.h>

#include "hal_replay.h"
#include "pil_cog.h"

static fw_t fw;
static hal_t hal;

int main(void)
{
    const pil_cog_rec_t *r = &pil_cog_rec;
    const ctrl_desc_t *d = ctrl_find("foc");
    if (d == NULL) {
        printf("FAIL foc not in this image's registry\n");
        return 1;
    }
    hal_replay_init(&hal, &r->info);
    fw_config_t fc;
    fw_config_default(&fc, &r->machine, d);
    fc.calib_samples = r->calib_samples;
    fc.enc_offset = r->enc_offset;
    fc.enc_direction = r->enc_direction;
    fc.enc_cpr = r->enc_cpr;
    if (fw_init(&fw, &hal, &fc) != FW_OK) {
        printf("FAIL fw_init\n");
        return 1;
    }
    pil_in_t in;
    uint32_t ff_periods = 0;
    for (uint32_t k = 0; k < r->n; k++) {
        const pil_ident_in_t *s = &r->in[k];
        pil_ident_in_replay(s, &in);
        hal_replay_set_input(&hal, &in);
        if ((s->cmd & PIL_COG_TABLE) != 0u) {
            if (fw_cogging_load(&fw, r->table, CTRL_COG_N) != FW_OK ||
                fw_cogging_enable(&fw, true) != FW_OK) {
                printf("FAIL period %u: the table was refused\n", (unsigned)k);
                return 1;
            }
        }
        if ((s->cmd & PIL_COG_SPEED) != 0u) {
            fw_set_speed_ref(&fw, r->speed_ref_q24);
        }
        if ((s->cmd & PIL_IDENT_ARM) != 0u) {
            fw_cmd_arm(&fw);
        }
        fw_isr(&fw);
        fw_watchdog_kick(&fw);
        if (fw.sm.state == FW_STATE_RUNNING && fw.refs.torque != fw.torque_ref_now) {
            ff_periods++;
        }
        const uint32_t h = pil_cog_hash(&hal.pwm, hal.gates ? 1 : 0, &fw);
        if (h != r->hash[k]) {
            printf("FAIL period %u (of %u): output hash %08lx, recorded %08lx (state %u, "
                   "position %lu, torque reference %ld)\n",
                   (unsigned)k, (unsigned)r->n, (unsigned long)h, (unsigned long)r->hash[k],
                   (unsigned)fw_telemetry(&fw)->state, (unsigned long)fw.enc_pos,
                   (long)fw.refs.torque);
            return 1;
        }
    }
    if (ff_periods != r->ff_periods || ff_periods < r->n / 4u) {
        printf("FAIL the feed-forward acted in %u periods, %u recorded\n", (unsigned)ff_periods,
               (unsigned)r->ff_periods);
        return 1;
    }
    printf("PASS anti-cogging closed loop: %u periods bit-identical (pwm compare, gates, "
           "telemetry, torque reference with the feed-forward, encoder position), the "
           "feed-forward non-zero in %u of them\n",
           (unsigned)r->n, (unsigned)ff_periods);
    return 0;
}
