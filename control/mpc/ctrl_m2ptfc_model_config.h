/*
 * Configuration side of the chapter-6 k+2 prediction model: SI values (double) converted to the
 * fixed-point state of ctrl_m2ptfc_model.h. Included only by *_config.c files, tests and
 * the firmware's configuration code; the per-sample code includes ctrl_m2ptfc_model.h
 * alone and stays integer-only.
 */
#ifndef CONTROL_CTRL_M2PTFC_MODEL_CONFIG_H
#define CONTROL_CTRL_M2PTFC_MODEL_CONFIG_H

#include <stddef.h>

#include "controller.h"
#include "ctrl_m2ptfc_model.h"
#include "ctrl_params.h"
#include "fx.h"

/* SI overrides of the prediction model (0 = the machine's value). Part of
 * each MPC controller's configuration struct. */
typedef struct {
    double rs_ohm, ld_h, lq_h, psi_pm_wb; /* tunables "rs_model" ... (0 = machine) */
} ctrl_mpc_model_cfg_t;

/* Configuration shared by the weighted-cost controllers m1, m3 and
 * mptfc (cost (6.13) with one weight zeta and the k+2 model): one
 * cfg_default / init / reset serves the three descriptors (state:
 * ctrl_mpc_wstate_t in ctrl_m2ptfc_model.h). */
typedef struct {
    double zeta;                /* "zeta", N*m/Wb, (6.13); 0 = T_rated/psi_pm (6.5) */
    ctrl_mpc_model_cfg_t model; /* model overrides, see ctrl_mpc_model_cfg_t */
} ctrl_mpc_wcfg_t;

/* ---- configuration (ctrl_m2ptfc_model_config.c, may use double) ---- */

/* ctrl_desc_t.cfg_default of m1, m3, mptfc: zeta 0 (T_rated/psi_pm), model
 * overrides off. cfg is a ctrl_mpc_wcfg_t. */
void ctrl_mpc_wcfg_default(void *cfg, const ctrl_machine_t *machine);

/* ctrl_desc_t.init of m1, m3, mptfc: model constants and zeta in pu; state
 * is a ctrl_mpc_wstate_t, cfg a ctrl_mpc_wcfg_t. CTRL_OK, CTRL_EINVAL
 * (zeta < 0 or not finite, bad model) or CTRL_ERANGE. */
int ctrl_mpc_winit(void *state, const void *cfg, const ctrl_setup_t *setup);

/* Tunable-table entries of the model overrides, for a cfg struct T with a
 * member "model" (expanded only in *_config.c files). */
#define CTRL_MPC_RS_MODEL_MAX 1000.0 /* ohm, upper bound of "rs_model" */
#define CTRL_MPC_LPSI_MODEL_MAX 10.0 /* H or Wb, upper bound of "ld/lq/psi_pm_model" */
/* clang-format off */
#define CTRL_MPC_MODEL_TUNABLES(T)                                                  \
    {"rs_model", "ohm", HELP_TEXT("Rs of the k+2 prediction (6.10); 0 = machine"),            \
     offsetof(T, model.rs_ohm), 0.0, CTRL_MPC_RS_MODEL_MAX},                       \
    {"ld_model", "H", HELP_TEXT("Ld of the k+2 prediction (6.12); 0 = machine"),              \
     offsetof(T, model.ld_h), 0.0, CTRL_MPC_LPSI_MODEL_MAX},                       \
    {"lq_model", "H", HELP_TEXT("Lq of the k+2 prediction (6.12); 0 = machine"),              \
     offsetof(T, model.lq_h), 0.0, CTRL_MPC_LPSI_MODEL_MAX},                       \
    {"psi_pm_model", "Wb", HELP_TEXT("psi_pm of the k+2 prediction (6.12); 0 = machine"),     \
     offsetof(T, model.psi_pm_wb), 0.0, CTRL_MPC_LPSI_MODEL_MAX}
/* The weighting factor zeta of (6.13) of M1, M3 and FS-MPTFC (field zeta of
 * T), with what this controller's help adds. */
#define CTRL_MPC_ZETA_TUNABLE(T, more)                                              \
    {"zeta", "N*m/Wb",                                                             \
     HELP_TEXT("weight of (6.13); 0 = T_rated/psi_pm (6.5); " more), offsetof(T, zeta),  \
     0.0, 1e5}
/* clang-format on */

/* Model constants for the setup (with the overrides of c). CTRL_OK,
 * CTRL_EINVAL (an override negative, not finite or above its tunable's
 * maximum) or CTRL_ERANGE (model outside the CTRL_MPC_* limits of
 * ctrl_m2ptfc_model.h). */
int ctrl_mpc_model_init(ctrl_mpc_model_t *m, const ctrl_mpc_model_cfg_t *c,
                        const ctrl_setup_t *setup);

/* A torque per flux weight zeta (N*m/Wb) of (6.13) in pu (Q24); zeta == 0 gives
 * the equal-importance value T_rated / psi_pm (§6.5). CTRL_OK, CTRL_EINVAL or
 * CTRL_ERANGE. */
int ctrl_mpc_zeta_pu(const ctrl_setup_t *setup, double zeta, q24_t *out);

#endif /* CONTROL_CTRL_M2PTFC_MODEL_CONFIG_H */
