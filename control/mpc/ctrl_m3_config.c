/* M3 configuration and descriptor (SI -> Q24; floating point allowed here). */
#include <stddef.h>

#include "ctrl_m2ptfc_model_config.h"
#include "ctrl_m3.h"
#include "ctrl_m3_config.h"
#include "estimator.h"

static const ctrl_tunable_t m3_tunables[] = {
    {"zeta", "N*m/Wb",
     "weighting factor of (6.13); 0 = T_rated/psi_pm (default, 6.5); Table 6.2: 110 at "
     "2250 r/min (fs 16 kHz) works, 440 at 750 r/min exceeds the limit of ctrl_m1.h",
     offsetof(ctrl_m3_cfg_t, zeta), 0.0, 1e5},
    CTRL_MPC_MODEL_TUNABLES(ctrl_m3_cfg_t),
};

const ctrl_desc_t ctrl_desc_m3 = {
    .name = "m3",
    .title = "Three-candidate M2PTFC: set (6.1), duty (5.18), cost (6.13) (thesis 6.4.2)",
    .fs_default_hz = 12000u,
    CTRL_DESC_SIZES(ctrl_m3_t, ctrl_m3_cfg_t),
    .tunables = m3_tunables,
    .n_tunables = sizeof m3_tunables / sizeof m3_tunables[0],
    .cfg_default = ctrl_mpc_wcfg_default,
    .init = ctrl_mpc_winit,
    .reset = ctrl_mpc_wreset,
    .step = ctrl_m3_step,
    .est_unused = CTRL_EST_ONLY(CTRL_EST_SC_NEXT | CTRL_EST_SECTOR_NEXT),
};
