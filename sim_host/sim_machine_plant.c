/* A machine description -> the plant's configuration (no file access: also
 * compiled into the QEMU images, which get their machine as data). */
#include <string.h>

#include "sim_machine.h"

void sim_machine_to_plant(const sim_machine_t *m, plant_config_t *cfg)
{
    memset(cfg, 0, sizeof(*cfg));
    cfg->pole_pairs = m->pole_pairs;
    cfg->rs_ohm = m->rs_ohm;
    cfg->ld_h = m->ld_h;
    cfg->lq_h = m->lq_h;
    cfg->psi_pm_wb = m->psi_pm_wb;
    cfg->fluxmap = NULL;
    cfg->vdc_v = m->vdc_v;
    cfg->dc_cap_f = m->dc_cap_f;
    cfg->dc_src_r_ohm = m->dc_src_r_ohm;
    cfg->dead_time_s = m->dead_time_s;
    cfg->v_fwd_v = m->v_fwd_v;
    cfg->mech = PLANT_MECH_IMPOSED;
    cfg->inertia_kgm2 = m->inertia_kgm2;
    cfg->friction_nms = m->friction_nms;
    cfg->filter = m->filter;
    cfg->coulomb_nm = m->coulomb_nm;
    cfg->stiction_nm = m->stiction_nm;
    const int n_per_rev = sim_machine_cog_per_rev(m);
    if (n_per_rev > 0 && (m->cogging_nm > 0.0 || m->cog_harm_n > 0)) {
        cfg->cog_per_rev = n_per_rev;
        cfg->cog_n = 1 + m->cog_harm_n;
        cfg->cog_amp_nm[0] = m->cogging_nm;
        cfg->cog_phase_rad[0] = m->cogging_phase_deg * PLANT_PI / 180.0;
        for (int k = 0; k < m->cog_harm_n; ++k) {
            cfg->cog_amp_nm[k + 1] = m->cog_harm_nm[k];
            cfg->cog_phase_rad[k + 1] =
                (k < m->cog_harm_deg_n ? m->cog_harm_deg[k] : 0.0) * PLANT_PI / 180.0;
        }
    }
    if (m->load_kind == SIM_LOAD_CONSTANT) {
        cfg->load_torque_nm = m->load_nm;
    } else if (m->load_kind == SIM_LOAD_PASSIVE) {
        cfg->load_passive_nm = m->load_nm;
    } else if (m->load_kind == SIM_LOAD_TIME || m->load_kind == SIM_LOAD_SPEED) {
        cfg->load_profile = m->load_profile;
    }
}

static int gcd_int(int a, int b)
{
    while (b != 0) {
        const int t = a % b;
        a = b;
        b = t;
    }
    return a;
}

int sim_machine_cog_per_rev(const sim_machine_t *m)
{
    if (m->slots <= 0 || m->pole_pairs <= 0) {
        return 0;
    }
    const int poles = 2 * m->pole_pairs;
    return m->slots / gcd_int(m->slots, poles) * poles;
}

int sim_machine_nonideal(const sim_machine_t *m)
{
    return m->coulomb_nm > 0.0 || m->stiction_nm > 0.0 ||
           (m->slots > 0 && (m->cogging_nm > 0.0 || m->cog_harm_n > 0)) ||
           m->load_kind != SIM_LOAD_NONE;
}
