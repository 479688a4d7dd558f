/* M1 configuration and descriptor (SI -> Q24; floating point allowed here). */
#include <stddef.h>

#include "ctrl_m1.h"
#include "ctrl_m1_config.h"
#include "ctrl_m2ptfc_model_config.h"
#include "estimator.h"

static const ctrl_tunable_t m1_tunables[] = {
    CTRL_MPC_ZETA_TUNABLE(ctrl_m1_cfg_t, "Table 6.2's 250, 640 exceed ctrl_m1.h's limit"),
    CTRL_MPC_MODEL_TUNABLES(ctrl_m1_cfg_t),
};

CTRL_DESC_DEFINE(
    m1, "Conventional M2PTFC: D_f (5.18) for every active vector, cost (6.13) (thesis 6.4.2)",
    10000u, ctrl_m1_t, ctrl_m1_cfg_t, m1_tunables, ctrl_mpc_wcfg_default, ctrl_mpc_winit,
    ctrl_mpc_wreset, ctrl_m1_step, CTRL_EST_SC_NEXT);
