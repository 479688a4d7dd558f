/* FS-MPTFC configuration and descriptor (SI -> Q24; floating point allowed here). */
#include <stddef.h>

#include "ctrl_m2ptfc_model_config.h"
#include "ctrl_mptfc.h"
#include "ctrl_mptfc_config.h"
#include "estimator.h"

static const ctrl_tunable_t mptfc_tunables[] = {
    CTRL_MPC_ZETA_TUNABLE(ctrl_mptfc_cfg_t, "see ctrl_m1.h for the stability limit"),
    CTRL_MPC_MODEL_TUNABLES(ctrl_mptfc_cfg_t),
};

CTRL_DESC_DEFINE(mptfc, "Finite-set MPTFC: 8 vectors at D = 1, cost (6.13) (thesis 6.4.1)", 10000u,
                 ctrl_mptfc_t, ctrl_mptfc_cfg_t, mptfc_tunables, ctrl_mpc_wcfg_default,
                 ctrl_mpc_winit, ctrl_mpc_wreset, ctrl_mptfc_step, CTRL_EST_SC_NEXT);
