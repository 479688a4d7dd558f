/*
 * Bit-exact host/target equivalence of the identification (pil_ident.h): the
 * recorded inputs through fw_isr with the replay HAL, the main-loop calls
 * (start, adoption, torque, arm) at the recorded periods, and each period's
 * output hash compared with the host's. Built for the host
 * (test_pil_ident_host) and for QEMU (test_pil_ident_qemu). Exit status 0
 * when every period matches and the identified values are the host's.
 */
#include <stdio.h>

#include "hal_replay.h"
#include "pil_ident.h"

static fw_t fw;
static hal_t hal;

/* Instruction-count markers for tools/ident_cost (the bench's TCG plugin):
 * begin before fw_isr, then the end marker of the step that ran (0: not
 * commissioning, 7: running; the plugin takes eight). Empty functions that
 * are never inlined. */
#define PIL_MARK(name)                                                                             \
    __attribute__((noinline)) void name(void);                                                     \
    __attribute__((noinline)) void name(void)                                                      \
    {                                                                                              \
        __asm__ volatile("" ::: "memory");                                                         \
    }
PIL_MARK(pil_mark_begin)
PIL_MARK(pil_mark_end0)
PIL_MARK(pil_mark_end1)
PIL_MARK(pil_mark_end2)
PIL_MARK(pil_mark_end3)
PIL_MARK(pil_mark_end4)
PIL_MARK(pil_mark_end5)
PIL_MARK(pil_mark_end6)
PIL_MARK(pil_mark_end7)
static void (*const pil_mark_end[8])(void) = {pil_mark_end0, pil_mark_end1, pil_mark_end2,
                                              pil_mark_end3, pil_mark_end4, pil_mark_end5,
                                              pil_mark_end6, pil_mark_end7};

int main(void)
{
    const pil_ident_rec_t *r = &pil_ident_rec;
    const ctrl_desc_t *d = ctrl_find("m2ptfc");
    if (d == NULL) {
        printf("FAIL m2ptfc not in this image's registry\n");
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
    static const uint8_t plan[] = {CM_STEP_VBUS, CM_STEP_PROBE, CM_STEP_ENCODER,
                                   CM_STEP_RS,   CM_STEP_LDQ,   CM_STEP_FLUX};
    pil_in_t in;
    for (uint32_t k = 0; k < r->n; k++) {
        const pil_ident_in_t *s = &r->in[k];
        pil_ident_in_replay(s, &in);
        hal_replay_set_input(&hal, &in);
        if ((s->cmd & PIL_IDENT_START) != 0u) {
            uint8_t missing;
            if (fw_commission_start(&fw, plan, (uint8_t)sizeof plan, &missing) != FW_OK) {
                printf("FAIL period %u: fw_commission_start refused\n", (unsigned)k);
                return 1;
            }
        }
        if ((s->cmd & PIL_IDENT_TORQUE) != 0u) {
            fw_set_torque_ref(&fw, r->torque_ref_q24);
        }
        if ((s->cmd & PIL_IDENT_ARM) != 0u) {
            fw_cmd_arm(&fw);
        }
        const uint32_t sec = fw.sm.state == FW_STATE_RUNNING ? 7u
                             : fw.sm.state == FW_STATE_COMMISSION && fw.cm.step <= CM_STEP_FLUX
                                 ? fw.cm.step
                                 : 0u;
        void (*const end)(void) = pil_mark_end[sec];
        pil_mark_begin();
        fw_isr(&fw);
        end();
        fw_watchdog_kick(&fw);
        if ((s->cmd & PIL_IDENT_APPLY) != 0u) {
            const cm_results_t *q = &fw.cm.res;
            if (q->rs != r->rs || q->ld != r->ld || q->lq != r->lq || q->psi != r->psi ||
                q->enc_off != r->enc_off || q->enc_dir != r->enc_dir) {
                printf("FAIL identified values differ: rs %ld/%ld ld %ld/%ld lq %ld/%ld psi "
                       "%ld/%ld offset %lu/%lu\n",
                       (long)q->rs, (long)r->rs, (long)q->ld, (long)r->ld, (long)q->lq, (long)r->lq,
                       (long)q->psi, (long)r->psi, (unsigned long)q->enc_off,
                       (unsigned long)r->enc_off);
                return 1;
            }
            if (!fw_commission_poll(&fw)) {
                printf("FAIL period %u: the results were not adopted\n", (unsigned)k);
                return 1;
            }
        }
        const uint32_t h = pil_ident_hash(&hal.pwm, hal.gates ? 1 : 0, &fw);
        if (h != r->hash[k]) {
            printf("FAIL period %u (of %u): output hash %08lx, recorded %08lx (state %u, step "
                   "%u, phase %lu)\n",
                   (unsigned)k, (unsigned)r->n, (unsigned long)h, (unsigned long)r->hash[k],
                   (unsigned)fw_telemetry(&fw)->state, (unsigned)fw_telemetry(&fw)->cm_step,
                   (unsigned long)fw.cm.phase);
            return 1;
        }
    }
    printf("PASS identification: %u periods bit-identical (pwm compare, gates, telemetry, "
           "commissioning state), identified rs %ld ld %ld lq %ld psi %ld (Q24 pu), offset "
           "%lu, direction %ld, then adopted and run\n",
           (unsigned)r->n, (long)r->rs, (long)r->ld, (long)r->lq, (long)r->psi,
           (unsigned long)r->enc_off, (long)r->enc_dir);
    return 0;
}
