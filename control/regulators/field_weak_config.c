/*
 * Field-weakening limits: SI -> fixed point (configuration time, floating
 * point allowed). Equations: field_weak.h.
 */
#include "field_weak_config.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "ctrl_cfg_math.h"
#include "ctrl_units.h"

void ctrl_fieldweak_cfg_default(ctrl_fieldweak_cfg_t *c)
{
    if (c != NULL) {
        c->v_frac = CTRL_FIELDWEAK_VFRAC_DEFAULT;
        c->current_max_a = 0.0;
        c->torque_margin = CTRL_FIELDWEAK_TORQUE_MARGIN_DEFAULT;
        c->torque_margin_brake = CTRL_FIELDWEAK_TORQUE_MARGIN_BRAKE_DEFAULT;
        c->vdc_lpf_hz = CTRL_FIELDWEAK_VDC_LPF_HZ_DEFAULT;
    }
}

static int fieldweak_refuse(char *why, size_t n, int code, const char *what, double v, double lo,
                            double hi, const char *unit)
{
    if (why != NULL && n > 0u) {
        snprintf(why, n, "field weakening: %s = %g %s is outside [%g, %g] %s", what, v, unit, lo,
                 hi, unit);
    }
    return code;
}

/* x (pu) -> Q24 when |x| <= 100 pu, else CTRL_ERANGE with the quantity named. */
static int fieldweak_q24(double x, const char *what, q24_t *out, char *why, size_t n)
{
    if (!isfinite(x) || fabs(x) > 100.0) {
        return fieldweak_refuse(why, n, CTRL_ERANGE, what, x, -100.0, 100.0, "pu");
    }
    *out = ctrl_q24_from_double(x);
    return CTRL_OK;
}

int ctrl_fieldweak_init(ctrl_fieldweak_t *s, const ctrl_fieldweak_cfg_t *c, const ctrl_machine_t *m,
                        const ctrl_bases_t *b, const ctrl_params_t *p, char *why, size_t why_len)
{
    if (why != NULL && why_len > 0u) {
        why[0] = '\0';
    }
    if (s == NULL || c == NULL || m == NULL || b == NULL || p == NULL || p->fs_hz == 0u) {
        if (why != NULL && why_len > 0u) {
            snprintf(why, why_len, "field weakening: missing configuration");
        }
        return CTRL_EINVAL;
    }
    memset(s, 0, sizeof *s);
    const double fs = (double)p->fs_hz;
    if (!(c->v_frac > 0.0 && c->v_frac <= CTRL_FIELDWEAK_VFRAC_MAX)) {
        return fieldweak_refuse(why, why_len, CTRL_EINVAL, "v_frac", c->v_frac, 0.0,
                                CTRL_FIELDWEAK_VFRAC_MAX, "x Vdc/sqrt(3)");
    }
    if (!(c->torque_margin > 0.0 && c->torque_margin <= 1.0)) {
        return fieldweak_refuse(why, why_len, CTRL_EINVAL, "torque_margin", c->torque_margin, 0.0,
                                1.0, "");
    }
    if (!(c->torque_margin_brake > 0.0 && c->torque_margin_brake <= 1.0)) {
        return fieldweak_refuse(why, why_len, CTRL_EINVAL, "torque_margin_brake",
                                c->torque_margin_brake, 0.0, 1.0, "");
    }
    if (!(c->vdc_lpf_hz > 0.0 && c->vdc_lpf_hz < 0.5 * fs)) {
        return fieldweak_refuse(why, why_len, CTRL_EINVAL, "vdc_lpf_hz", c->vdc_lpf_hz, 0.0,
                                0.5 * fs, "Hz");
    }
    const double i_si = c->current_max_a == 0.0 ? m->current_rated_a : c->current_max_a;
    if (!(i_si > 0.0 && i_si <= m->current_max_a)) {
        return fieldweak_refuse(why, why_len, CTRL_EINVAL, "current limit", i_si, 0.0,
                                m->current_max_a, "A (up to the over-current trip, current_max_a)");
    }
    if (!(m->lq_h >= m->ld_h)) {
        return fieldweak_refuse(why, why_len, CTRL_EINVAL, "lq_h (reverse saliency Lq < Ld)",
                                m->lq_h, m->ld_h, INFINITY, "H");
    }
    /* Per unit, from the SI data and the bases (no base value assumed). */
    const double psi = m->psi_pm_wb / b->psi_wb;
    const double ld = m->ld_h / b->l_h;
    const double lq = m->lq_h / b->l_h;
    const double rs = m->rs_ohm / b->r_ohm;
    const double i = i_si / b->i_a;
    double md;
    double mq;
    ctrl_mtpa_split(psi, ld, lq, i, &md, &mq); /* Lq >= Ld: checked above */
    const double t_mtpa = psi * mq + (ld - lq) * md * mq;
    const double psi_mtpa = ctrl_cfg_hypot(ld * md + psi, lq * mq);
    const double c1 = psi / ld;
    const double c2 = 1.0 / ld - 1.0 / lq;
    const double vf = c->v_frac / sqrt(3.0);
    s->v_frac = (int32_t)ctrl_cfg_llround(vf * (double)(1L << 30));
    int rc = CTRL_OK;
    rc = rc ? rc : fieldweak_q24(i, "current limit", &s->i_max, why, why_len);
    rc = rc ? rc : fieldweak_q24(2.0 * rs, "2 Rs", &s->two_rs, why, why_len);
    rc = rc ? rc : fieldweak_q24(rs * i, "Rs I_max", &s->rs_imax, why, why_len);
    rc = rc ? rc : fieldweak_q24(rs / psi, "Rs / psi_pm", &s->rs_ipsi, why, why_len);
    rc = rc ? rc : fieldweak_q24(psi, "psi_pm", &s->psi_pm, why, why_len);
    rc = rc ? rc : fieldweak_q24(ld, "Ld", &s->ld, why, why_len);
    rc = rc ? rc : fieldweak_q24(ld - lq, "Ld - Lq", &s->ld_m_lq, why, why_len);
    rc = rc ? rc : fieldweak_q24(1.0 / (lq * lq), "1/Lq^2", &s->inv_lq2, why, why_len);
    rc = rc ? rc : fieldweak_q24(1.0 / ld, "1/Ld", &s->inv_ld, why, why_len);
    rc = rc ? rc
            : fieldweak_q24(psi_mtpa, "MTPA flux at the current limit", &s->psi_mtpa, why, why_len);
    rc = rc ? rc
            : fieldweak_q24(t_mtpa, "MTPA torque at the current limit", &s->t_mtpa, why, why_len);
    rc = rc ? rc : fieldweak_q24(psi + lq * i, "psi_pm + Lq I", &s->psi_ceil, why, why_len);
    rc = rc ? rc : fieldweak_q24(2.0 * ld * psi, "2 Ld psi_pm", &s->b, why, why_len);
    rc = rc ? rc : fieldweak_q24(lq * lq - ld * ld, "Lq^2 - Ld^2", &s->dl2, why, why_len);
    rc = rc ? rc
            : fieldweak_q24(psi * psi + lq * lq * i * i, "psi_pm^2 + Lq^2 I^2", &s->c0, why,
                            why_len);
    rc = rc ? rc : fieldweak_q24(c1, "psi_pm/Ld", &s->c1, why, why_len);
    rc = rc ? rc : fieldweak_q24(c2, "1/Ld - 1/Lq", &s->c2, why, why_len);
    rc = rc ? rc : fieldweak_q24(c1 * c1, "(psi_pm/Ld)^2", &s->c1_sq, why, why_len);
    rc = rc ? rc : fieldweak_q24(8.0 * c2 * c2, "8 (1/Ld - 1/Lq)^2", &s->c2_sq8, why, why_len);
    rc = rc ? rc : fieldweak_q24(c->torque_margin, "torque_margin", &s->t_margin, why, why_len);
    rc = rc ? rc
            : fieldweak_q24(c->torque_margin_brake, "torque_margin_brake", &s->t_margin_brake, why,
                            why_len);
    rc = rc ? rc
            : fieldweak_q24(1.0 - ctrl_cfg_exp(-2.0 * CTRL_PI * c->vdc_lpf_hz / fs),
                            "DC-link filter coefficient", &s->vdc_k, why, why_len);
    s->id_star = FX_MAX;
    if (lq > ld && rc == CTRL_OK) {
        const double id_star = ld * psi / (lq * lq - ld * ld);
        if (id_star < 100.0) {
            s->id_star = ctrl_q24_from_double(id_star);
        }
    }
    if (rc != CTRL_OK) {
        memset(s, 0, sizeof *s);
        return rc;
    }
    ctrl_fieldweak_reset(s);
    return CTRL_OK;
}
