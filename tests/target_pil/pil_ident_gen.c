/*
 * Host generator of pil_ident_data.c (pil_ident.h): records the whole
 * identification on the host closed loop, then the adoption of the results
 * and 1000 periods of m2ptfc in torque mode with them.
 *   pil_ident_gen --machine nonideal/thesis_spmsm_stress.ini --out pil_ident_data.c
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "pil_ident.h"
#include "sim_ident.h"

#define GEN_RUN_PERIODS 1000u
#define GEN_MAX_PERIODS 200000u
/* The free rotor reaches ~400 r/min in the 50 ms of the run (no overspeed). */
#define GEN_TORQUE_NM 0.1

static int die(const char *msg, const char *arg)
{
    fprintf(stderr, "pil_ident_gen: %s%s\n", msg, arg != NULL ? arg : "");
    return 1;
}

int main(int argc, char **argv)
{
    const char *machine = NULL, *out = NULL;
    for (int i = 1; i + 1 < argc; i += 2) {
        if (strcmp(argv[i], "--machine") == 0) {
            machine = argv[i + 1];
        } else if (strcmp(argv[i], "--out") == 0) {
            out = argv[i + 1];
        } else {
            return die("unknown option ", argv[i]);
        }
    }
    if (machine == NULL || out == NULL) {
        return die("usage: pil_ident_gen --machine FILE --out FILE.c", NULL);
    }
    static sim_machine_t spm, plant, conf;
    char err[512];
    if (sim_machine_load(machine, &spm, err, sizeof err) != 0) {
        return die(err, NULL);
    }
    sim_ident_case(&spm, &plant, &conf);
    const ctrl_desc_t *d = ctrl_find("m2ptfc");
    if (d == NULL) {
        return die("m2ptfc is not registered", NULL);
    }
    static sim_run_t run;
    /* The recording starts at fw_init: sim_ident_setup has booted and
     * calibrated already, so its calibration periods are recorded first by
     * redoing them here on a fresh run (the same seed gives the same samples). */
    if (sim_ident_setup(&run, &plant, &conf, d, 2.0, 7u, err, sizeof err) != 0) {
        return die(err, NULL);
    }
    static pil_ident_in_t in[GEN_MAX_PERIODS];
    static uint32_t hash[GEN_MAX_PERIODS];
    /* Replay from fw_init: re-initialise the firmware on the same HAL and
     * record its boot and calibration too. */
    fw_config_t fc;
    fw_config_default(&fc, &run.cfg.ctrl_machine, d);
    fc.calib_samples = run.cfg.calib_samples;
    fc.enc_offset = 0u;
    fc.enc_direction = 1;
    fc.enc_cpr = 4u * (uint32_t)conf.encoder_lines;
    if (fw_init(&run.fw, &run.hal, &fc) != FW_OK) {
        return die("fw_init failed", NULL);
    }
    uint32_t n = 0;
    uint32_t after = 0;
    int phase = 0; /* 0 boot/calib, 1 identifying, 2 running */
    int32_t tref = 0;
    static const uint8_t plan[] = {CM_STEP_VBUS, CM_STEP_PROBE, CM_STEP_ENCODER,
                                   CM_STEP_RS,   CM_STEP_LDQ,   CM_STEP_FLUX};
    int32_t rs = 0, ld = 0, lq = 0, psi = 0, dir = 0;
    uint32_t off = 0;
    while (n < GEN_MAX_PERIODS && after < GEN_RUN_PERIODS) {
        uint8_t cmd = 0u;
        if (phase == 0 && fw_state(&run.fw) == FW_STATE_READY) {
            uint8_t missing;
            if (fw_commission_start(&run.fw, plan, (uint8_t)sizeof plan, &missing) != FW_OK) {
                return die("fw_commission_start refused", NULL);
            }
            cmd |= PIL_IDENT_START;
            phase = 1;
        }
        if (phase == 2 && after == 0u) {
            fw_set_torque_ref_nm(&run.fw, GEN_TORQUE_NM);
            tref = fw_torque_ref(&run.fw);
            fw_cmd_arm(&run.fw);
            cmd |= PIL_IDENT_TORQUE | PIL_IDENT_ARM;
        }
        if (sim_run_period(&run) != 0) {
            return die("plant failed", NULL);
        }
        const hal_t *h = &run.hal;
        pil_ident_in_t *i = &in[n];
        i->adc[0] = h->adc.i_a;
        i->adc[1] = h->adc.i_b;
        i->adc[2] = h->adc.i_c;
        i->adc[3] = h->adc.vdc;
        i->enc_count = h->enc.count;
        i->index_count = h->enc.index_count;
        i->flags = (uint8_t)((h->enc.index_seen ? 1u : 0u) | (h->trip ? 2u : 0u));
        const int gates = (h->gates_on || h->gate_enable_pending) ? 1 : 0;
        if (phase == 1 && fw_state(&run.fw) != FW_STATE_COMMISSION) {
            if (run.fw.cm.err != CM_E_NONE) {
                return die("identification failed: ", cm_err_name(run.fw.cm.err));
            }
            const cm_results_t *r = &run.fw.cm.res;
            rs = r->rs;
            ld = r->ld;
            lq = r->lq;
            psi = r->psi;
            off = r->enc_off;
            dir = r->enc_dir;
            if (!fw_commission_poll(&run.fw)) {
                return die("the results were not adopted", NULL);
            }
            cmd |= PIL_IDENT_APPLY;
            phase = 2;
        }
        i->cmd = cmd;
        hash[n] = pil_ident_hash(&h->shadow, gates, &run.fw);
        n++;
        if (phase == 2 && (cmd & PIL_IDENT_APPLY) == 0u) {
            after++;
        }
    }
    if (phase != 2 || fw_state(&run.fw) != FW_STATE_RUNNING) {
        return die("the recording did not end running", NULL);
    }
    FILE *f = fopen(out, "w");
    if (f == NULL) {
        return die("cannot write ", out);
    }
    fprintf(f,
            "/* Generated by pil_ident_gen from %s: do not edit. */\n#include \"pil_ident.h\"\n\n",
            machine);
    fprintf(f, "static const pil_ident_in_t in_[%u] = {\n", n);
    for (uint32_t k = 0; k < n; k++) {
        const pil_ident_in_t *i = &in[k];
        fprintf(f, "{{%u,%u,%u,%u},%uu,%uu,%u,%u},\n", i->adc[0], i->adc[1], i->adc[2], i->adc[3],
                i->enc_count, i->index_count, i->cmd, i->flags);
    }
    fprintf(f, "};\nstatic const uint32_t hash_[%u] = {\n", n);
    for (uint32_t k = 0; k < n; k++) {
        fprintf(f, "%uu,%s", hash[k], (k % 8u) == 7u ? "\n" : "");
    }
    const hal_info_t *hi = &run.fw.info;
    const ctrl_machine_t *m = &run.cfg.ctrl_machine;
    fprintf(f, "};\nconst pil_ident_rec_t pil_ident_rec = {\n");
    fprintf(f, " {%uu, %uu, %u, %.17g, %.17g, %uu, %s, %uu},\n", hi->pwm_freq_hz, hi->period_counts,
            hi->adc_bits, hi->adc_current_a_per_count, hi->adc_vdc_v_per_count,
            hi->encoder_counts_per_rev, hi->has_i_c ? "true" : "false", hi->cycle_clock_hz);
    fprintf(f,
            " {\"%s\", %d, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g, "
            "%.17g},\n",
            m->name, m->pole_pairs, m->rs_ohm, m->ld_h, m->lq_h, m->psi_pm_wb, m->vdc_v,
            m->inertia_kgm2, m->torque_rated_nm, m->speed_rated_rpm, m->current_rated_a,
            m->current_max_a, m->psi_ref_wb);
    fprintf(f, " %uu, %d, %uu, %uu, %ld, %uu, in_, hash_,\n %ld, %ld, %ld, %ld, %uu, %ld};\n",
            fc.enc_offset, fc.enc_direction, fc.enc_cpr, fc.calib_samples, (long)tref, n, (long)rs,
            (long)ld, (long)lq, (long)psi, off, (long)dir);
    if (fclose(f) != 0) {
        return die("write error on ", out);
    }
    fprintf(stderr, "pil_ident_gen: %u periods (identification %.3f s, then %u running)\n", n,
            (double)(n - GEN_RUN_PERIODS) / (double)hi->pwm_freq_hz, GEN_RUN_PERIODS);
    sim_run_free(&run);
    return 0;
}
