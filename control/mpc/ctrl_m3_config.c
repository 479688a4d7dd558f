/* M3 configuration and descriptor (SI -> Q24; floating point allowed here). */
#include <stddef.h>

#include "ctrl_m2ptfc_model_config.h"
#include "ctrl_m3.h"
#include "ctrl_m3_config.h"
#include "estimator.h"

static const ctrl_tunable_t m3_tunables[] = {
    CTRL_MPC_ZETA_TUNABLE(ctrl_m3_cfg_t, "Table 6.2's 440 exceeds ctrl_m1.h's limit"),
    CTRL_MPC_MODEL_TUNABLES(ctrl_m3_cfg_t),
};

CTRL_DESC_DEFINE(m3, "Three-candidate M2PTFC: set (6.1), duty (5.18), cost (6.13) (thesis 6.4.2)",
                 12000u, ctrl_m3_t, ctrl_m3_cfg_t, m3_tunables, ctrl_mpc_wcfg_default,
                 ctrl_mpc_winit, ctrl_mpc_wreset, ctrl_m3_step,
                 CTRL_EST_SC_NEXT | CTRL_EST_SECTOR_NEXT);
