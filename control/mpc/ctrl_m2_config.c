/* M2 configuration and descriptor (SI -> Q24; floating point allowed here). */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "ctrl_m2.h"
#include "ctrl_m2_config.h"
#include "ctrl_m2ptfc_model_config.h"
#include "estimator.h"

static const ctrl_tunable_t m2_tunables[] = {
    {"eps_psi", "Wb",
     HELP_TEXT("flux band of the hard constraint (6.17); Table 6.2: 0.0066, 0.00942 at 2250 r/min"),
     offsetof(ctrl_m2_cfg_t, eps_psi), 1e-6, 1.0},
    {"y", "1", HELP_TEXT("number of discrete duty steps D = nu/y (6.15); Table 6.1: 4"),
     offsetof(ctrl_m2_cfg_t, y), 1.0, (double)CTRL_M2_Y_MAX},
    CTRL_MPC_MODEL_TUNABLES(ctrl_m2_cfg_t),
};

static void m2_cfg_default(void *cfg, const ctrl_machine_t *machine)
{
    (void)machine;
    ctrl_m2_cfg_t *c = cfg;
    memset(c, 0, sizeof *c);
    c->eps_psi = 6.60e-3; /* Table 6.2, 750 r/min */
    c->y = 4.0;           /* Table 6.1 */
}

static int m2_init(void *state, const void *cfg, const ctrl_setup_t *setup)
{
    ctrl_m2_t *s = state;
    const ctrl_m2_cfg_t *c = cfg;
    memset(s, 0, sizeof *s);
    if (ctrl_tunables_check(m2_tunables, sizeof m2_tunables / sizeof m2_tunables[0], c) !=
            CTRL_OK ||
        c->y != floor(c->y)) {
        return CTRL_EINVAL;
    }
    int rc = ctrl_mpc_model_init(&s->model, &c->model, setup);
    if (rc == CTRL_OK) {
        rc = ctrl_setup_q24(setup, "eps_psi / flux base", c->eps_psi, setup->bases->psi_wb, 0.0,
                            127.0, &s->eps_psi);
    }
    if (rc != CTRL_OK) {
        return rc;
    }
    s->y = (uint8_t)c->y;
    for (unsigned nu = 0; nu <= s->y; nu++) {
        s->d_nu[nu] = ctrl_q24_from_double((double)nu / c->y); /* (6.15) */
    }
    return CTRL_OK;
}

CTRL_DESC_DEFINE(m2,
                 "Discrete-duty M2PTFC: D = nu/y (6.15), cost (6.16) with flux band (6.17) "
                 "(thesis 6.4.2)",
                 10000u, ctrl_m2_t, ctrl_m2_cfg_t, m2_tunables, m2_cfg_default, m2_init,
                 ctrl_m2_reset, ctrl_m2_step, CTRL_EST_SC_NEXT | CTRL_EST_SECTOR_NEXT);
