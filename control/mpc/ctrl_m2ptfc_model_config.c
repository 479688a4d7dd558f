/* Configuration of the k+2 prediction model (SI -> Q24, floating point allowed here). */
#include <math.h>
#include <string.h>

#include "ctrl_m2ptfc_model.h"
#include "ctrl_m2ptfc_model_config.h"

void ctrl_mpc_model_cfg_default(ctrl_mpc_model_cfg_t *c, const ctrl_machine_t *machine)
{
    memset(c, 0, sizeof *c);
    if (machine == NULL) {
        return;
    }
    c->m_rs_ohm = machine->rs_ohm;
    c->m_ld_h = machine->ld_h;
    c->m_lq_h = machine->lq_h;
    c->m_psi_pm_wb = machine->psi_pm_wb;
    c->m_torque_rated_nm = machine->torque_rated_nm;
}

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
                        const ctrl_params_t *params)
{
    if (m == NULL || c == NULL || params == NULL) {
        return CTRL_EINVAL;
    }
    memset(m, 0, sizeof *m);
    double k_rs;
    double k_ld;
    double k_lq;
    double k_psi;
    if (model_ratio(c->rs_ohm, CTRL_MPC_RS_MODEL_MAX, c->m_rs_ohm, &k_rs) != CTRL_OK ||
        model_ratio(c->ld_h, CTRL_MPC_LPSI_MODEL_MAX, c->m_ld_h, &k_ld) != CTRL_OK ||
        model_ratio(c->lq_h, CTRL_MPC_LPSI_MODEL_MAX, c->m_lq_h, &k_lq) != CTRL_OK ||
        model_ratio(c->psi_pm_wb, CTRL_MPC_LPSI_MODEL_MAX, c->m_psi_pm_wb, &k_psi) != CTRL_OK) {
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

/* SI value of 1 pu of flux and torque, from the machine copy and params. */
static int mpc_bases(const ctrl_mpc_model_cfg_t *c, const ctrl_params_t *params, double *psi_b,
                     double *t_b)
{
    const double psi_pu = ctrl_q24_to_double(params->psi_pm);
    const double t_pu = ctrl_q24_to_double(params->torque_rated);
    if (!(psi_pu > 0.0) || !(t_pu > 0.0) || !(c->m_psi_pm_wb > 0.0) ||
        !(c->m_torque_rated_nm > 0.0)) {
        return CTRL_EINVAL;
    }
    *psi_b = c->m_psi_pm_wb / psi_pu;
    *t_b = c->m_torque_rated_nm / t_pu;
    return CTRL_OK;
}

int ctrl_mpc_zeta_pu(const ctrl_mpc_model_cfg_t *c, const ctrl_params_t *params, double zeta,
                     q24_t *out)
{
    double psi_b;
    double t_b;
    if (c == NULL || params == NULL || out == NULL || !isfinite(zeta) || zeta < 0.0 ||
        mpc_bases(c, params, &psi_b, &t_b) != CTRL_OK) {
        return CTRL_EINVAL;
    }
    if (zeta == 0.0) {
        zeta = c->m_torque_rated_nm / c->m_psi_pm_wb; /* equal importance, §6.5 */
    }
    const double pu = zeta * psi_b / t_b;
    if (pu >= 127.0) {
        return CTRL_ERANGE;
    }
    *out = ctrl_q24_from_double(pu);
    return CTRL_OK;
}

int ctrl_mpc_flux_pu(const ctrl_mpc_model_cfg_t *c, const ctrl_params_t *params, double wb,
                     q24_t *out)
{
    double psi_b;
    double t_b;
    if (c == NULL || params == NULL || out == NULL || !isfinite(wb) ||
        mpc_bases(c, params, &psi_b, &t_b) != CTRL_OK) {
        return CTRL_EINVAL;
    }
    const double pu = wb / psi_b;
    if (fabs(pu) >= 127.0) {
        return CTRL_ERANGE;
    }
    *out = ctrl_q24_from_double(pu);
    return CTRL_OK;
}

void ctrl_mpc_wcfg_default(void *cfg, const ctrl_machine_t *machine)
{
    ctrl_mpc_wcfg_t *c = cfg;
    if (c == NULL) {
        return;
    }
    memset(c, 0, sizeof *c);
    c->zeta = 0.0; /* T_rated/psi_pm; Table 6.2's 250 / 440 / 640 lose torque control (ctrl_m1.h) */
    ctrl_mpc_model_cfg_default(&c->model, machine);
}

int ctrl_mpc_winit(void *state, const void *cfg, const ctrl_params_t *params)
{
    ctrl_mpc_wstate_t *s = state;
    const ctrl_mpc_wcfg_t *c = cfg;
    if (s == NULL || c == NULL || params == NULL) {
        return CTRL_EINVAL;
    }
    memset(s, 0, sizeof *s);
    int rc = ctrl_mpc_model_init(&s->model, &c->model, params);
    if (rc == CTRL_OK) {
        rc = ctrl_mpc_zeta_pu(&c->model, params, c->zeta, &s->zeta);
    }
    return rc;
}
