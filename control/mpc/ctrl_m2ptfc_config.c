/* M2PTFC configuration and descriptor (SI -> Q24; floating point allowed here). */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "ctrl_drr_config.h"
#include "ctrl_m2ptfc.h"
#include "ctrl_m2ptfc_config.h"
#include "ctrl_m2ptfc_model_config.h"
#include "estimator.h"

static const ctrl_tunable_t m2ptfc_tunables[] = {
    {"lambda", "1",
     HELP_TEXT("EMA coefficient of sigma_T (6.8); Table 6.2: 0.03 (750 and 2250 r/min)"),
     offsetof(ctrl_m2ptfc_cfg_t, lambda), 1e-4, 1.0},
    {"centre", "0/1",
     HELP_TEXT("1: Te of (6.5)-(6.8) shifted half the ZVV change, mean on T_ref (default); 0: "
               "thesis"),
     offsetof(ctrl_m2ptfc_cfg_t, centre), 0.0, 1.0},
    CTRL_MPC_MODEL_TUNABLES(ctrl_m2ptfc_cfg_t),
};

static void m2ptfc_cfg_default(void *cfg, const ctrl_machine_t *machine)
{
    (void)machine;
    ctrl_m2ptfc_cfg_t *c = cfg;
    memset(c, 0, sizeof *c);
    c->lambda = 0.03; /* Table 6.2 */
    c->centre = 1.0;  /* plan.h realises plans centre-aligned */
}

static int m2ptfc_init(void *state, const void *cfg, const ctrl_setup_t *setup)
{
    ctrl_m2ptfc_t *s = state;
    const ctrl_m2ptfc_cfg_t *c = cfg;
    memset(s, 0, sizeof *s);
    if (!isfinite(c->lambda) || !(c->lambda > 0.0) || c->lambda > 1.0 ||
        !(c->centre == 0.0 || c->centre == 1.0)) {
        return CTRL_EINVAL;
    }
    const int rc = ctrl_mpc_model_init(&s->model, &c->model, setup);
    if (rc != CTRL_OK) {
        return rc;
    }
    double a_nm;
    double b_nm;
    if (ctrl_drr_ab_si(setup->machine, 1.0 / (double)setup->params->fs_hz, &a_nm, &b_nm) !=
        CTRL_OK) {
        return CTRL_EINVAL;
    }
    s->sigma_max = ctrl_q24_from_double(a_nm / setup->bases->torque_nm);
    s->lambda = ctrl_q24_from_double(c->lambda);
    s->centre = c->centre != 0.0 ? 1u : 0u;
    ctrl_m2ptfc_reset(s);
    return CTRL_OK;
}

#if PMSM_LIVE_PARAMS
/* lambda while running: the EMA's coefficient; sigma_T (6.8) keeps its value
 * and follows at the new rate. centre and the model's overrides change the
 * torque the equations use: with the controller stopped only. */
static void m2ptfc_retune(void *state, const void *fresh)
{
    ((ctrl_m2ptfc_t *)state)->lambda = ((const ctrl_m2ptfc_t *)fresh)->lambda;
}
#endif

CTRL_DESC_DEFINE_LIVE(m2ptfc,
                      "Two-candidate M2PTFC without weighting factor (thesis 6.3, (6.5)-(6.12))",
                      10000u, ctrl_m2ptfc_t, ctrl_m2ptfc_cfg_t, m2ptfc_tunables, m2ptfc_cfg_default,
                      m2ptfc_init, ctrl_m2ptfc_reset, ctrl_m2ptfc_step,
                      CTRL_EST_SC_NEXT | CTRL_EST_SECTOR_NEXT, 0u, CTRL_RETUNE(m2ptfc_retune),
                      0x1u);
