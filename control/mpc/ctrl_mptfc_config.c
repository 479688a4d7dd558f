/* FS-MPTFC configuration and descriptor (SI -> Q24; floating point allowed here). */
#include <stddef.h>

#include "ctrl_m2ptfc_model_config.h"
#include "ctrl_mptfc.h"
#include "ctrl_mptfc_config.h"
#include "estimator.h"

static const ctrl_tunable_t mptfc_tunables[] = {
    {"zeta", "N*m/Wb",
     "weighting factor of (6.13); 0 = T_rated/psi_pm (default, 6.5); see ctrl_m1.h for "
     "the stability limit",
     offsetof(ctrl_mptfc_cfg_t, zeta), 0.0, 1e5},
    CTRL_MPC_MODEL_TUNABLES(ctrl_mptfc_cfg_t),
};

const ctrl_desc_t ctrl_desc_mptfc = {
    .name = "mptfc",
    .title = "Finite-set MPTFC: 8 vectors at D = 1, cost (6.13) (thesis 6.4.1)",
    .fs_default_hz = 10000u,
    CTRL_DESC_SIZES(ctrl_mptfc_t, ctrl_mptfc_cfg_t),
    .tunables = mptfc_tunables,
    .n_tunables = sizeof mptfc_tunables / sizeof mptfc_tunables[0],
    .cfg_default = ctrl_mpc_wcfg_default,
    .init = ctrl_mpc_winit,
    .reset = ctrl_mpc_wreset,
    .step = ctrl_mptfc_step,
    .est_unused = CTRL_EST_ONLY(CTRL_EST_SC_NEXT),
};
