/* Configuration of the k+2 prediction model (SI -> Q24, floating point allowed here). */
#include <math.h>
#include <string.h>

#include "ctrl_cfg_math.h"
#include "ctrl_m2ptfc_model.h"
#include "ctrl_m2ptfc_model_config.h"

/* value_SI / machine_SI for an override, 1 when the override is off (0);
 * an override outside [0, max] (the tunable's range) is refused, named. The
 * machine value is > 0 here (ctrl_params_init; Rs = 0 is taken apart). */
static int model_ratio(const ctrl_setup_t *setup, const char *name, const char *unit,
                       double override, double max, double machine, double *ratio)
{
    if (!(override >= 0.0) || !isfinite(override) || override > max) {
        return ctrl_setup_refuse(setup, CTRL_EINVAL, name, unit, override, 0.0, max);
    }
    *ratio = override == 0.0 || !(machine > 0.0) ? 1.0 : override / machine;
    return CTRL_OK;
}

int ctrl_mpc_model_init(ctrl_mpc_model_t *m, const ctrl_mpc_model_cfg_t *c,
                        const ctrl_setup_t *setup)
{
    const ctrl_machine_t *mc = setup->machine;
    const ctrl_params_t *params = setup->params;
    memset(m, 0, sizeof *m);
    double k_rs = 1.0;
    double k_ld = 1.0;
    double k_lq = 1.0;
    double k_psi = 1.0;
    int rc =
        model_ratio(setup, "rs_model", "ohm", c->rs_ohm, CTRL_MPC_RS_MODEL_MAX, mc->rs_ohm, &k_rs);
    rc =
        rc ? rc
           : model_ratio(setup, "ld_model", "H", c->ld_h, CTRL_MPC_LPSI_MODEL_MAX, mc->ld_h, &k_ld);
    rc =
        rc ? rc
           : model_ratio(setup, "lq_model", "H", c->lq_h, CTRL_MPC_LPSI_MODEL_MAX, mc->lq_h, &k_lq);
    rc = rc ? rc
            : model_ratio(setup, "psi_pm_model", "Wb", c->psi_pm_wb, CTRL_MPC_LPSI_MODEL_MAX,
                          mc->psi_pm_wb, &k_psi);
    if (rc != CTRL_OK) {
        return rc;
    }
    /* Ts in pu from the SI data (not the rounded params->ts: one rounding of
     * Ts 2/3 and Ts Rs instead of two). */
    const double ts = setup->bases->w_rad_s / (double)params->fs_hz;
    /* A lossless machine (Rs = 0) has no Rs to scale: the override in pu. */
    const double rs =
        mc->rs_ohm > 0.0 ? ctrl_q24_to_double(params->rs) * k_rs : c->rs_ohm / setup->bases->r_ohm;
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
    const double vdc_max = 2.0 * ctrl_q24_to_double(params->vdc_nom);
    /* |psi| on |i| = current_max is at most |(psi_pm + Ld i_max, Lq i_max)|. */
    const double i_max = ctrl_q24_to_double(params->current_max);
    const double psi_max =
        ctrl_cfg_hypot(ctrl_q24_to_double(params->psi_pm) + i_max / inv_ld, i_max / inv_lq);
    /* Limits of the fast k+2 arithmetic (ctrl_m2ptfc_model.h). */
    const double ab_max = ctrl_q24_to_double(CTRL_MPC_AB_MAX);
    if (fabs(a) > ab_max) {
        return ctrl_setup_refuse(setup, CTRL_ERANGE, "prediction model psi_pm / Ld", "pu", a, 0.0,
                                 ab_max);
    }
    if (fabs(b) > ab_max) {
        return ctrl_setup_refuse(setup, CTRL_ERANGE, "prediction model 1/Lq - 1/Ld", "pu", b,
                                 -ab_max, ab_max);
    }
    if (ts_rs > ctrl_q24_to_double(CTRL_MPC_TS_RS_MAX)) {
        return ctrl_setup_refuse(setup, CTRL_ERANGE, "prediction model Ts Rs / Ld", "", ts_rs, 0.0,
                                 ctrl_q24_to_double(CTRL_MPC_TS_RS_MAX));
    }
    if (ts_v * vdc_max > ctrl_q24_to_double(CTRL_MPC_TSV_MAX)) {
        return ctrl_setup_refuse(setup, CTRL_ERANGE, "flux step 2/3 x 2 Vdc Ts / psi_pm", "",
                                 ts_v * vdc_max, 0.0, ctrl_q24_to_double(CTRL_MPC_TSV_MAX));
    }
    if (psi_max > CTRL_MPC_PSI_MAX) {
        return ctrl_setup_refuse(setup, CTRL_ERANGE, "flux at current_max / psi_pm", "", psi_max,
                                 1.0, CTRL_MPC_PSI_MAX);
    }
    m->a = ctrl_q24_from_double(a);
    /* With the machine's psi_pm the model follows the PM flux in use. */
    m->a_psi = c->psi_pm_wb > 0.0 ? 0 : ctrl_q24_from_double(inv_ld);
    m->psi_seen = params->psi_pm;
    m->b = ctrl_q24_from_double(b);
    m->ts_rs = ctrl_q24_from_double(ts_rs);
    m->ts_v = ctrl_q24_from_double(ts_v);
    m->vdc_max = ctrl_q24_from_double(vdc_max);
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
    return ctrl_setup_q24(setup, "zeta x flux base / torque base", zeta * setup->bases->psi_wb,
                          setup->bases->torque_nm, 0.0, 127.0, out);
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
