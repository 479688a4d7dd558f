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
}
