/* M1 configuration and descriptor (SI -> Q24; floating point allowed here). */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "ctrl_m1.h"

static const ctrl_tunable_t m1_tunables[] = {
    {"zeta", "N*m/Wb",
     "weighting factor of (6.13); 0 = T_rated/psi_pm (default, equal importance, 6.5); "
     "Table 6.2's 250 / 640 exceed the stability limit sqrt(3) 1.5 p psi_pm/Ls (ctrl_m1.h)",
     offsetof(ctrl_m1_cfg_t, zeta), 0.0, 1e5},
    CTRL_MPC_MODEL_TUNABLES(ctrl_m1_cfg_t),
};

static void m1_cfg_default(void *cfg, const ctrl_machine_t *machine)
{
    ctrl_m1_cfg_t *c = cfg;
    memset(c, 0, sizeof *c);
    c->zeta = 0.0; /* T_rated/psi_pm; Table 6.2's 250 loses torque control (ctrl_m1.h) */
    ctrl_mpc_model_cfg_default(&c->model, machine);
}

static int m1_init(void *state, const void *cfg, const ctrl_params_t *params)
{
    ctrl_m1_t *s = state;
    const ctrl_m1_cfg_t *c = cfg;
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

const ctrl_desc_t ctrl_desc_m1 = {
    .name = "m1",
    .title = "Conventional M2PTFC: D_f (5.18) for every active vector, cost (6.13) (thesis 6.4.2)",
    .fs_default_hz = 10000u,
    .state_size = sizeof(ctrl_m1_t),
    .cfg_size = sizeof(ctrl_m1_cfg_t),
    .tunables = m1_tunables,
    .n_tunables = sizeof m1_tunables / sizeof m1_tunables[0],
    .cfg_default = m1_cfg_default,
    .init = m1_init,
    .reset = ctrl_m1_reset,
    .step = ctrl_m1_step,
};
