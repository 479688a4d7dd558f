/* Shared parts of the replay recordings' generators (pil_gen_util.h). */
#include "pil_gen_util.h"

#include <string.h>

int pil_gen_die(const char *prog, const char *msg, const char *arg)
{
    fprintf(stderr, "%s: %s%s\n", prog, msg, arg != NULL ? arg : "");
    return 1;
}

int pil_gen_args(int argc, char **argv, const char *prog, const char **machine, const char **out)
{
    *machine = *out = NULL;
    for (int i = 1; i + 1 < argc; i += 2) {
        if (strcmp(argv[i], "--machine") == 0) {
            *machine = argv[i + 1];
        } else if (strcmp(argv[i], "--out") == 0) {
            *out = argv[i + 1];
        } else {
            return pil_gen_die(prog, "unknown option ", argv[i]);
        }
    }
    if (*machine == NULL || *out == NULL) {
        return pil_gen_die(prog, "usage: --machine FILE --out FILE.c", NULL);
    }
    return 0;
}

void pil_gen_in(const hal_t *h, uint8_t cmd, pil_ident_in_t *i)
{
    i->adc[0] = h->adc.i_a;
    i->adc[1] = h->adc.i_b;
    i->adc[2] = h->adc.i_c;
    i->adc[3] = h->adc.vdc;
    i->enc_count = h->enc.count;
    i->index_count = h->enc.index_count;
    i->flags = (uint8_t)((h->enc.index_seen ? 1u : 0u) | (h->trip ? 2u : 0u));
    i->cmd = cmd;
}

void pil_gen_write_in_hash(FILE *f, const pil_ident_in_t *in, const uint32_t *hash, uint32_t n)
{
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
    fprintf(f, "};\n");
}

void pil_gen_write_info_machine(FILE *f, const hal_info_t *hi, const ctrl_machine_t *m)
{
    fprintf(f, " {%uu, %uu, %u, %.17g, %.17g, %uu, %s, %uu},\n", hi->pwm_freq_hz, hi->period_counts,
            hi->adc_bits, hi->adc_current_a_per_count, hi->adc_vdc_v_per_count,
            hi->encoder_counts_per_rev, hi->has_i_c ? "true" : "false", hi->cycle_clock_hz);
    fprintf(f,
            " {\"%s\", %d, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g, "
            "%.17g, %.17g},\n",
            m->name, m->pole_pairs, m->rs_ohm, m->ld_h, m->lq_h, m->psi_pm_wb, m->vdc_v,
            m->inertia_kgm2, m->torque_rated_nm, m->speed_rated_rpm, m->current_rated_a,
            m->current_max_a, m->psi_ref_wb, m->speed_max_rpm);
}
