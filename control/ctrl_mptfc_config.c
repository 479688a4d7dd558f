/* FS-MPTFC configuration and descriptor (SI -> Q24; floating point allowed here). */
#include <stddef.h>
#include <string.h>

#include "ctrl_mptfc.h"

static const ctrl_tunable_t mptfc_tunables[] = {
    {"zeta", "N*m/Wb",
     "weighting factor of (6.13); 0 = T_rated/psi_pm (default, 6.5); see ctrl_m1.h for "
     "the stability limit",
     offsetof(ctrl_mptfc_cfg_t, zeta), 0.0, 1e5},
    CTRL_MPC_MODEL_TUNABLES(ctrl_mptfc_cfg_t),
};

static void mptfc_cfg_default(void *cfg, const ctrl_machine_t *machine)
{
    ctrl_mptfc_cfg_t *c = cfg;
    memset(c, 0, sizeof *c);
    c->zeta = 0.0; /* T_rated/psi_pm (ctrl_m1.h) */
    ctrl_mpc_model_cfg_default(&c->model, machine);
}

static int mptfc_init(void *state, const void *cfg, const ctrl_params_t *params)
{
    ctrl_mptfc_t *s = state;
    const ctrl_mptfc_cfg_t *c = cfg;
    if (s == NULL || c == NULL || params == NULL) {
        return CTRL_EINVAL;
    }
    memset(s, 0, sizeof *s);
    int rc = ctrl_mpc_model_init(&s->model, &c->model, params);
    if (rc == CTRL_OK) {
        rc = ctrl_mpc_zeta_pu(&c->model, params, c->zeta, &s->zeta);
    }
    return rc;
}

const ctrl_desc_t ctrl_desc_mptfc = {
    .name = "mptfc",
    .title = "Finite-set MPTFC: 8 vectors at D = 1, cost (6.13) (thesis 6.4.1)",
    .fs_default_hz = 10000u,
    .state_size = sizeof(ctrl_mptfc_t),
    .cfg_size = sizeof(ctrl_mptfc_cfg_t),
    .tunables = mptfc_tunables,
    .n_tunables = sizeof mptfc_tunables / sizeof mptfc_tunables[0],
    .cfg_default = mptfc_cfg_default,
    .init = mptfc_init,
    .reset = ctrl_mptfc_reset,
    .step = ctrl_mptfc_step,
};
