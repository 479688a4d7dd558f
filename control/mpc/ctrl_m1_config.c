/* M1 configuration and descriptor (SI -> Q24; floating point allowed here). */
#include <stddef.h>

#include "ctrl_m1.h"
#include "ctrl_m1_config.h"
#include "ctrl_m2ptfc_model_config.h"
#include "estimator.h"

static const ctrl_tunable_t m1_tunables[] = {
    {"zeta", "N*m/Wb",
     "weighting factor of (6.13); 0 = T_rated/psi_pm (default, equal importance, 6.5); "
     "Table 6.2's 250 / 640 exceed the stability limit sqrt(3) 1.5 p psi_pm/Ls (ctrl_m1.h)",
     offsetof(ctrl_m1_cfg_t, zeta), 0.0, 1e5},
    CTRL_MPC_MODEL_TUNABLES(ctrl_m1_cfg_t),
};

const ctrl_desc_t ctrl_desc_m1 = {
    .name = "m1",
    .title = "Conventional M2PTFC: D_f (5.18) for every active vector, cost (6.13) (thesis 6.4.2)",
    .fs_default_hz = 10000u,
    CTRL_DESC_SIZES(ctrl_m1_t, ctrl_m1_cfg_t),
    .tunables = m1_tunables,
    .n_tunables = sizeof m1_tunables / sizeof m1_tunables[0],
    .cfg_default = ctrl_mpc_wcfg_default,
    .init = ctrl_mpc_winit,
    .reset = ctrl_mpc_wreset,
    .step = ctrl_m1_step,
    .est_unused = CTRL_EST_ONLY(CTRL_EST_SC_NEXT),
};
