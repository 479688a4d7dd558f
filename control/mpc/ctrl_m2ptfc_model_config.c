/* Configuration of the k+2 prediction model (SI -> Q24, floating point allowed here). */
#include <math.h>
#include <string.h>

#include "ctrl_m2ptfc_model.h"
#include "ctrl_m2ptfc_model_config.h"

/* value_SI / machine_SI for an override, 1 when the override is off (0);
 * an override outside [0, max] (the tunable's range) is refused. */
static int model_ratio(double override, double max, double machine, double *ratio)
{
    if (!(override >= 0.0) || !isfinite(override) || override > max) {
        return CTRL_EINVAL;
    }
    if (override == 0.0) {
        *ratio = 1.0;
        return CTRL_OK;
    }
    if (!(machine > 0.0) || !isfinite(machine)) {
        return CTRL_EINVAL; /* an override needs the machine value to scale from */
    }
    *ratio = override / machine;
    return CTRL_OK;
}

int ctrl_mpc_model_init(ctrl_mpc_model_t *m, const ctrl_mpc_model_cfg_t *c,
                        const ctrl_setup_t *setup)
{
    const ctrl_machine_t *mc = setup->machine;
    const ctrl_params_t *params = setup->params;
    memset(m, 0, sizeof *m);
    double k_rs;
    double k_ld;
    double k_lq;
    double k_psi;
    if (model_ratio(c->rs_ohm, CTRL_MPC_RS_MODEL_MAX, mc->rs_ohm, &k_rs) != CTRL_OK ||
        model_ratio(c->ld_h, CTRL_MPC_LPSI_MODEL_MAX, mc->ld_h, &k_ld) != CTRL_OK ||
        model_ratio(c->lq_h, CTRL_MPC_LPSI_MODEL_MAX, mc->lq_h, &k_lq) != CTRL_OK ||
        model_ratio(c->psi_pm_wb, CTRL_MPC_LPSI_MODEL_MAX, mc->psi_pm_wb, &k_psi) != CTRL_OK) {
        return CTRL_EINVAL;
    }
    const double ts = ctrl_q24_to_double(params->ts);
    const double rs = ctrl_q24_to_double(params->rs) * k_rs;
    const double inv_ld = ctrl_q24_to_double(params->inv_ld) / k_ld;
    const double inv_lq = ctrl_q24_to_double(params->inv_lq) / k_lq;
    const double psi_pm = ctrl_q24_to_double(params->psi_pm) * k_psi;
    if (!(ts > 0.0) || !(inv_ld > 0.0) || !(inv_lq > 0.0) || !(psi_pm > 0.0)) {
        return CTRL_EINVAL;
    }
    const double a = psi_pm * inv_ld;
    const double b = inv_lq - inv_ld;
    const double ts_rs = ts * rs;
    const double ts_v = ts * 2.0 / 3.0;
    /* Limits of the fast k+2 arithmetic (ctrl_m2ptfc_model.h). */
    if (fabs(a) > ctrl_q24_to_double(CTRL_MPC_AB_MAX) ||
        fabs(b) > ctrl_q24_to_double(CTRL_MPC_AB_MAX) ||
        ts_rs > ctrl_q24_to_double(CTRL_MPC_TS_RS_MAX) ||
        ts_v > ctrl_q24_to_double(CTRL_MPC_TS_V_MAX)) {
        return CTRL_ERANGE;
    }
    m->a = ctrl_q24_from_double(a);
    m->b = ctrl_q24_from_double(b);
    m->ts_rs = ctrl_q24_from_double(ts_rs);
    m->ts_v = ctrl_q24_from_double(ts_v);
    return CTRL_OK;
}

int ctrl_mpc_zeta_pu(const ctrl_setup_t *setup, double zeta, q24_t *out)
{
    if (!isfinite(zeta) || zeta < 0.0) {
        return CTRL_EINVAL;
    }
    if (zeta == 0.0) {
        zeta = setup->machine->torque_rated_nm / setup->machine->psi_pm_wb; /* §6.5 */
    }
    /* (T/T_base) = zeta_pu (psi/psi_base) */
    return ctrl_q24_from_si(zeta * setup->bases->psi_wb, setup->bases->torque_nm, 0.0, 127.0, out);
}

void ctrl_mpc_wcfg_default(void *cfg, const ctrl_machine_t *machine)
{
    (void)machine;
    ctrl_mpc_wcfg_t *c = cfg;
    memset(c, 0, sizeof *c);
    c->zeta = 0.0; /* T_rated/psi_pm; Table 6.2's 250 / 440 / 640 lose torque control (ctrl_m1.h) */
}

int ctrl_mpc_winit(void *state, const void *cfg, const ctrl_setup_t *setup)
{
    ctrl_mpc_wstate_t *s = state;
    const ctrl_mpc_wcfg_t *c = cfg;
    memset(s, 0, sizeof *s);
    int rc = ctrl_mpc_model_init(&s->model, &c->model, setup);
    if (rc == CTRL_OK) {
        rc = ctrl_mpc_zeta_pu(setup, c->zeta, &s->zeta);
    }
    return rc;
}
