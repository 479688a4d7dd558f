/*
 * Commissioning: SI configuration -> per-unit limits and periods, and the
 * results back in SI (configuration and reporting time only).
 */
#include "cm_config.h"
#include "cm_internal.h"
#include "ctrl_units.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

/* The defaults as data, copied whole: 43 stores of double constants took
 * more flash as code than the table (-104 B on the board image). */
static const cm_config_t cm_config_defaults = {
    .i_hold = 0.3,
    .i_rs1 = 0.25,
    .i_rs2 = 0.5,
    .i_probe = 0.1,
    .i_open = 0.02,
    .i_acc = 0.5,
    .i_fd = 0.2,
    .i_sense = 0.2,
    .i_guard = 1.0,
    .i_gate_max = 0.05,
    .i_min = 0.1,
    .v_lim = 0.25,
    .v_lim_run = 0.4,
    .v_probe0 = 0.02,
    .vbus_min = 0.8,
    .vbus_max = 1.2,
    .l_min_h = 1e-6,
    .l_max_h = 10.0,
    .loop_g = 0.2,
    .damp_rad_s = 30.0,
    .w_flux = 0.3,
    .w_guard = 0.8,
    .w_settle = 0.01,
    .torque_run = 0.1,
    .unbalance_max = 0.15,
    .sense_lo = 0.75,
    .sense_hi = 1.3,
    .cpr_tol = 0.03,
    .salient_min = 0.05,
    .gate_duty = 0.05,
    .scan_hz = 4.0,
    .t_vbus = 0.05,
    .t_ramp = 0.02,
    .t_settle = 0.05,
    .t_win = 0.1,
    .t_hold = 0.15,
    .t_hold_max = 1.0,
    .t_hf = 0.25,
    .t_scan_acc = 0.05,
    .t_flux_max = 1.0,
    .t_flux_win = 0.1,
    .t_run = 0.5,
    .t_gate = 0.02,
};

void cm_config_default(cm_config_t *c)
{
    if (c != NULL) {
        *c = cm_config_defaults;
    }
}

/* x (pu) -> Q24, or false when it does not fit. */
static bool cm_q24(double x, q24_t *out)
{
    const double v = floor(x * 16777216.0 + 0.5);
    if (!isfinite(v) || v > 2147483647.0 || v < -2147483648.0) {
        return false;
    }
    *out = (q24_t)v;
    return true;
}

static uint32_t cm_periods(double t_s, double fs)
{
    const double n = floor(t_s * fs + 0.5);
    return n < 1.0 ? 1u : (n > 4.0e9 ? 4000000000u : (uint32_t)n);
}

int cm_configure(cm_t *cm, const cm_config_t *c, const ctrl_params_t *p, const ctrl_bases_t *b,
                 const ctrl_machine_t *m, const hal_info_t *info, uint32_t enc_cpr,
                 const char **what)
{
    const char *dummy;
    if (what == NULL) {
        what = &dummy;
    }
    *what = NULL;
    if (cm == NULL || c == NULL || p == NULL || b == NULL || m == NULL || info == NULL ||
        info->period_counts == 0u || enc_cpr == 0u || !(b->i_a > 0.0) || !(b->v_v > 0.0)) {
        *what = "configuration";
        return -1;
    }
    cm_par_t *q = &cm->par;
    memset(q, 0, sizeof *q);
    const double fs = (double)p->fs_hz;
    const double ir = m->current_rated_a / b->i_a;
    const double vn = m->vdc_v / b->v_v;
    const double wr =
        m->speed_rated_rpm * 2.0 * CTRL_PI / 60.0 * (double)m->pole_pairs / b->w_rad_s;
    if (cm->res.have == 0u) {
        cm->res.bases = *b;
    }
    q->pwm_n = info->period_counts;
    q->inv_n_q32 = (uint32_t)(4294967296.0 / (double)info->period_counts);
    q->enc_cpr = enc_cpr;
    q->ts = p->ts;
    q->dangle_to_omega = p->dangle_to_omega;
    q->has_i_c = info->has_i_c ? 1u : 0u;
    q->pole_pairs = (uint8_t)p->pole_pairs;
    /* value = (the configuration's field, or 1) x scale[kind] -> Q24 field */
    enum { S_I, S_V, S_W, S_T, S_1, S_L, S_LD, S_LQ, S_RS, S_PSI, S_LSB, S_N };
    const double scale[S_N] = {ir,
                               vn,
                               wr,
                               m->torque_rated_nm / b->torque_nm,
                               1.0,
                               1.0 / b->l_h,
                               m->ld_h / b->l_h,
                               m->lq_h / b->l_h,
                               m->rs_ohm / b->r_ohm,
                               m->psi_pm_wb / b->psi_wb,
                               info->adc_current_a_per_count / b->i_a};
#define CM_C(f) ((int16_t)offsetof(cm_config_t, f))
#define CM_P(f) ((uint16_t)offsetof(cm_par_t, f))
    static const struct {
        const char *name;
        int16_t src; /* offsetof(cm_config_t, field), or -1 for 1.0 */
        uint8_t kind;
        uint16_t dst; /* offsetof(cm_par_t, field) */
    } t[] = {
        {"adc current lsb", -1, S_LSB, CM_P(i_lsb)},
        {"rated current", -1, S_I, CM_P(i_rated)},
        {"i_guard", CM_C(i_guard), S_I, CM_P(i_guard)},
        {"i_hold", CM_C(i_hold), S_I, CM_P(i_hold)},
        {"i_rs1", CM_C(i_rs1), S_I, CM_P(i_rs1)},
        {"i_rs2", CM_C(i_rs2), S_I, CM_P(i_rs2)},
        {"i_probe", CM_C(i_probe), S_I, CM_P(i_probe)},
        {"i_open", CM_C(i_open), S_I, CM_P(i_open)},
        {"i_acc", CM_C(i_acc), S_I, CM_P(i_acc)},
        {"i_fd", CM_C(i_fd), S_I, CM_P(i_fd)},
        {"i_sense", CM_C(i_sense), S_I, CM_P(i_sense)},
        {"i_gate_max", CM_C(i_gate_max), S_I, CM_P(i_gate_max)},
        {"i_min", CM_C(i_min), S_I, CM_P(i_min)},
        {"v_lim", CM_C(v_lim), S_V, CM_P(v_lim)},
        {"v_lim_run", CM_C(v_lim_run), S_V, CM_P(v_lim_run)},
        {"v_probe0", CM_C(v_probe0), S_V, CM_P(v_probe0)},
        {"vbus_min", CM_C(vbus_min), S_V, CM_P(vbus_min)},
        {"vbus_max", CM_C(vbus_max), S_V, CM_P(vbus_max)},
        {"l_min", CM_C(l_min_h), S_L, CM_P(l_min)},
        {"l_max", CM_C(l_max_h), S_L, CM_P(l_max)},
        {"loop_g", CM_C(loop_g), S_1, CM_P(loop_g)},
        {"rated speed", -1, S_W, CM_P(w_rated)},
        {"w_flux", CM_C(w_flux), S_W, CM_P(w_flux)},
        {"w_guard", CM_C(w_guard), S_W, CM_P(w_guard)},
        {"w_settle", CM_C(w_settle), S_W, CM_P(w_settle)},
        {"torque_run", CM_C(torque_run), S_T, CM_P(torque_run)},
        {"rated torque", -1, S_T, CM_P(torque_rated)},
        {"unbalance_max", CM_C(unbalance_max), S_1, CM_P(unbalance_max)},
        {"sense_lo", CM_C(sense_lo), S_1, CM_P(sense_lo)},
        {"sense_hi", CM_C(sense_hi), S_1, CM_P(sense_hi)},
        {"cpr_tol", CM_C(cpr_tol), S_1, CM_P(cpr_tol)},
        {"salient_min", CM_C(salient_min), S_1, CM_P(salient_min)},
        {"gate_duty", CM_C(gate_duty), S_1, CM_P(gate_duty)},
        {"configured Ld", -1, S_LD, CM_P(l_cfg_d)},
        {"configured Lq", -1, S_LQ, CM_P(l_cfg_q)},
        {"configured Rs", -1, S_RS, CM_P(rs_cfg)},
        {"configured psi_pm", -1, S_PSI, CM_P(psi_cfg)},
    };
#undef CM_C
#undef CM_P
    for (size_t k = 0; k < sizeof t / sizeof t[0]; k++) {
        double src = 1.0;
        if (t[k].src >= 0) {
            memcpy(&src, (const char *)c + t[k].src, sizeof src);
        }
        double v = src * scale[t[k].kind];
        if (t[k].dst == offsetof(cm_par_t, l_max)) {
            v = fmin(v, 127.0); /* "no limit" within Q24 */
        }
        q24_t *dst = (q24_t *)(void *)((char *)q + t[k].dst);
        if (!isfinite(v) || v < 0.0 || !cm_q24(v, dst) || (*dst == 0 && v > 0.0)) {
            *what = t[k].name;
            return -1;
        }
    }
    const double dk = floor(b->w_rad_s / c->damp_rad_s * 65536.0 + 0.5);
    if (!(dk >= 1.0) || dk > 2147483647.0) {
        *what = "damp_rad_s";
        return -1;
    }
    q->damp_k = (int32_t)dk;
    const double inc = c->scan_hz / fs * 4294967296.0;
    if (!(inc >= 1.0) || inc > 1073741824.0) {
        *what = "scan_hz";
        return -1;
    }
    q->scan_inc = (fx_angle_t)floor(inc + 0.5);
    q->n_vbus = cm_periods(c->t_vbus, fs);
    q->n_ramp = cm_periods(c->t_ramp, fs);
    q->n_settle = cm_periods(c->t_settle, fs);
    q->n_win = cm_periods(c->t_win, fs);
    q->n_hold = cm_periods(c->t_hold, fs);
    q->n_hold_max = cm_periods(c->t_hold_max, fs);
    q->n_hf = cm_periods(c->t_hf, fs);
    q->n_scan_acc = cm_periods(c->t_scan_acc, fs);
    q->n_flux_max = cm_periods(c->t_flux_max, fs);
    q->n_flux_win = cm_periods(c->t_flux_win, fs);
    q->n_run = cm_periods(c->t_run, fs);
    q->n_gate = cm_periods(c->t_gate, fs);
    q->n_rest = cm_periods(0.005, fs);
    /* Test currents within the voltage: at most what CM_V_USE of the step's
     * voltage limit drives through the configured Rs (standstill: alignment,
     * the rs levels; spinning at w_flux: the flux step's currents, less the
     * back-EMF, with w L in series; after "rs" again with the measured Rs and
     * inverter error, cm_refit_currents); the rs levels keep their ratio.
     * The smallest accepted current: i_min, at least 64 ADC counts (the rs
     * step's slope from 32 counts of difference). A step whose current falls
     * below it ends with CM_E_SUPPLY. */
    q->i_min = fx_max(q->i_min, 64 * q->i_lsb);
    q->i_hold_nom = q->i_hold;
    q->i_acc_nom = q->i_acc;
    q->i_fd_nom = q->i_fd;
    {
        const double rs = m->rs_ohm / b->r_ohm;
        const double cap = CM_V_USE * c->v_lim * vn / rs;
        if (cap < (double)q->i_rs2 / 16777216.0) { /* the levels keep their ratio */
            (void)cm_q24(c->i_rs1 * ir * cap / (c->i_rs2 * ir), &q->i_rs1);
            (void)cm_q24(cap, &q->i_rs2);
        }
        cm_refit_currents(cm);
    }
    /* Open phase: at least 8 ADC counts (noise is a fraction of one). */
    q->i_open = fx_max(q->i_open, 8 * q->i_lsb);
    /* Probe: at least two compare steps of voltage. */
    const double step = 2.0 * vn / (double)info->period_counts;
    if (q->v_probe0 < (q24_t)(step * 16777216.0)) {
        (void)cm_q24(step, &q->v_probe0);
    }
    return 0;
}

static double cm_si(q24_t x, double base)
{
    return (double)x / 16777216.0 * base;
}

static q24_t cm_re(q24_t x, double ob, double nb)
{
    q24_t y = 0;
    return cm_q24((double)x * ob / nb / 16777216.0, &y) ? y : (x >= 0 ? FX_MAX : FX_MIN);
}

/* The results held in pu of cm_results_t.bases: the field, how many, its base
 * (ctrl_bases_t) and its SI field in cm_si_t (CM_SI_NONE: only rebased).
 * cm_rebase and cm_results_si walk it. */
#define CM_R(f) ((uint16_t)offsetof(cm_results_t, f))
#define CM_B(f) ((uint16_t)offsetof(ctrl_bases_t, f))
#define CM_S(f) ((uint16_t)offsetof(cm_si_t, f))
#define CM_SI_NONE 0xFFFFu
static const struct {
    uint16_t res, n, base, si;
} cm_pu_fields[] = {
    {CM_R(vbus), 1u, CM_B(v_v), CM_S(vbus_v)},
    {CM_R(i_off), 3u, CM_B(i_a), CM_S(i_off_a)},
    {CM_R(i_noise), 3u, CM_B(i_a), CM_S(i_noise_a)},
    {CM_R(l_probe), 1u, CM_B(l_h), CM_S(l_probe_h)},
    {CM_R(rs), 1u, CM_B(r_ohm), CM_S(rs_ohm)},
    {CM_R(v_inv), 1u, CM_B(v_v), CM_S(v_inv_v)},
    {CM_R(ld), 1u, CM_B(l_h), CM_S(ld_h)},
    {CM_R(lq), 1u, CM_B(l_h), CM_S(lq_h)},
    {CM_R(ld_raw), 1u, CM_B(l_h), CM_S(ld_raw_h)},
    {CM_R(lq_raw), 1u, CM_B(l_h), CM_S(lq_raw_h)},
    {CM_R(psi), 1u, CM_B(psi_wb), CM_S(psi_wb)},
    {CM_R(psi_pos), 1u, CM_B(psi_wb), CM_S(psi_pos_wb)},
    {CM_R(psi_neg), 1u, CM_B(psi_wb), CM_S(psi_neg_wb)},
    {CM_R(omega_flux), 1u, CM_B(w_rad_s), CM_S(omega_flux_rad_s)},
    {CM_R(acc_dw), 1u, CM_B(w_rad_s), CM_SI_NONE},
    {CM_R(coast_w0), 1u, CM_B(w_rad_s), CM_SI_NONE},
    {CM_R(coast_w1), 1u, CM_B(w_rad_s), CM_SI_NONE},
    {CM_R(coast_wm), 1u, CM_B(w_rad_s), CM_SI_NONE},
};
#undef CM_R
#undef CM_B
#undef CM_S

static double cm_base_at(const ctrl_bases_t *b, uint16_t off)
{
    double v;
    memcpy(&v, (const char *)b + off, sizeof v);
    return v;
}

void cm_rebase(cm_t *cm, const ctrl_bases_t *nb, bool enc_adopted)
{
    cm_results_t *r = &cm->res;
    const ctrl_bases_t ob = r->bases;
    for (size_t k = 0; k < sizeof cm_pu_fields / sizeof cm_pu_fields[0]; k++) {
        const double o = cm_base_at(&ob, cm_pu_fields[k].base);
        const double n = cm_base_at(nb, cm_pu_fields[k].base);
        for (uint16_t j = 0; j < cm_pu_fields[k].n; j++) {
            q24_t x;
            char *f = (char *)r + cm_pu_fields[k].res + j * sizeof x;
            memcpy(&x, f, sizeof x);
            x = cm_re(x, o, n);
            memcpy(f, &x, sizeof x);
        }
    }
    /* Inertia data: sum i_q (current). */
    r->acc_torque_sum = (int64_t)floor((double)r->acc_torque_sum * ob.i_a / nb->i_a + 0.5);
    if (enc_adopted) {
        /* The drive now counts in the identified direction; the offset is
         * taken against the angle without the drive's offset, so it stays. */
        r->enc_dir = 1;
    }
    r->bases = *nb;
}

void cm_results_si(const cm_t *cm, int enc_dir_cfg, uint8_t pole_pairs, double ts_s, cm_si_t *o)
{
    memset(o, 0, sizeof *o);
    const cm_results_t *r = &cm->res;
    const ctrl_bases_t *b = &r->bases;
    o->have = r->have;
    for (size_t k = 0; k < sizeof cm_pu_fields / sizeof cm_pu_fields[0]; k++) {
        const double base = cm_base_at(b, cm_pu_fields[k].base);
        for (uint16_t j = 0; cm_pu_fields[k].si != CM_SI_NONE && j < cm_pu_fields[k].n; j++) {
            q24_t x;
            memcpy(&x, (const char *)r + cm_pu_fields[k].res + j * sizeof x, sizeof x);
            const double v = cm_si(x, base);
            memcpy((char *)o + cm_pu_fields[k].si + j * sizeof v, &v, sizeof v);
        }
    }
    o->enc_dir = (enc_dir_cfg < 0 ? -1 : 1) * (r->enc_dir < 0 ? -1 : 1);
    o->enc_offset_deg = (double)r->enc_off / 4294967296.0 * 360.0;
    o->enc_cpr = r->enc_cpr;
    o->enc_cpr_cfg = cm->par.enc_cpr;
    o->unbalance = (double)r->unbalance / 16777216.0;
    o->salient = r->salient != 0u;
    o->inertia_kgm2 = NAN;
    o->friction_nms = NAN;
    if ((r->have & CM_HAVE_MECH) != 0u && r->acc_dw > 0 && r->acc_n > 0u && pole_pairs > 0u) {
        /* J = integral(T dt) / d(omega_m), T = psi i_q (pu, i_d = 0). */
        const double psi = (double)r->psi / 16777216.0;
        const double iq_sum = (double)r->acc_torque_sum / 16777216.0;
        const double tdt = psi * iq_sum * b->torque_nm * ts_s;
        const double dwm = cm_si(r->acc_dw, b->w_rad_s) / (double)pole_pairs;
        o->inertia_kgm2 = tdt / dwm;
        if (r->coast_n > 0u && r->coast_wm > 0) {
            /* Coasting with no torque: J dw/dt = -B w (mechanical; the ratio
             * dw / w is the same in electrical units). */
            const double dw = cm_si(fx_sub(r->coast_w1, r->coast_w0), b->w_rad_s);
            const double wm = cm_si(r->coast_wm, b->w_rad_s);
            o->friction_nms = -o->inertia_kgm2 * dw / ((double)r->coast_n * ts_s) / wm;
        }
    }
}

bool cm_si_has(const cm_si_t *r, uint32_t have)
{
    return (r->have & have) != 0u &&
           (have != CM_HAVE_MECH || (isfinite(r->inertia_kgm2) && r->inertia_kgm2 > 0.0));
}

double cm_si_field(const cm_si_t *r, size_t off, cm_field_t kind)
{
    const char *f = (const char *)r + off;
    double v;
    int i;
    uint32_t u;
    bool b;
    switch (kind) {
    case CM_FIELD_INT:
        memcpy(&i, f, sizeof i);
        return (double)i;
    case CM_FIELD_U32:
        memcpy(&u, f, sizeof u);
        return (double)u;
    case CM_FIELD_BOOL:
        memcpy(&b, f, sizeof b);
        return b ? 1.0 : 0.0;
    default:
        memcpy(&v, f, sizeof v);
        return kind == CM_FIELD_MILLI ? v * 1e3 : v;
    }
}

/* The machine-file fragment: the result bit that gives each item, its field
 * of cm_si_t and how that is read (a cm_field_t, or the encoder's lines:
 * counts / 4, or the friction: only when finite, >= 0). */
enum { CM_F_LINES = CM_FIELD_COUNT, CM_F_FRICTION };
#define CM_F(have, sec, key, kind, f)                                                              \
    {                                                                                              \
        have, kind, (uint16_t)offsetof(cm_si_t, f), sec, key                                       \
    }
static const struct {
    uint8_t have, kind;
    uint16_t off;
    const char *section, *key;
} cm_fragment[] = {
    CM_F(CM_HAVE_RS, "machine", "rs_ohm", CM_FIELD_SI, rs_ohm),
    CM_F(CM_HAVE_LDQ, "machine", "ld_mh", CM_FIELD_MILLI, ld_h),
    CM_F(CM_HAVE_LDQ, "machine", "lq_mh", CM_FIELD_MILLI, lq_h),
    CM_F(CM_HAVE_FLUX, "machine", "psi_pm_wb", CM_FIELD_SI, psi_wb),
    CM_F(CM_HAVE_ENC, "sensors", "encoder_lines", CM_F_LINES, enc_cpr_cfg),
    CM_F(CM_HAVE_ENC, "sensors", "encoder_offset_deg", CM_FIELD_SI, enc_offset_deg),
    CM_F(CM_HAVE_ENC, "sensors", "encoder_direction", CM_FIELD_INT, enc_dir),
    CM_F(CM_HAVE_MECH, "mechanics", "inertia_kgm2", CM_FIELD_SI, inertia_kgm2),
    CM_F(CM_HAVE_MECH, "mechanics", "friction_nms", CM_F_FRICTION, friction_nms),
};
#undef CM_F

bool cm_fragment_item(const cm_si_t *r, size_t index, cm_item_t *it)
{
    for (size_t k = 0; k < sizeof cm_fragment / sizeof cm_fragment[0]; k++) {
        const uint8_t kind = cm_fragment[k].kind;
        if (!cm_si_has(r, cm_fragment[k].have) ||
            (kind == CM_F_FRICTION && !isfinite(r->friction_nms))) {
            continue;
        }
        if (index-- != 0u) {
            continue;
        }
        double v;
        if (kind == CM_F_LINES) {
            v = (double)((uint32_t)cm_si_field(r, cm_fragment[k].off, CM_FIELD_U32) / 4u);
        } else if (kind == CM_F_FRICTION) {
            v = fmax(cm_si_field(r, cm_fragment[k].off, CM_FIELD_SI), 0.0);
        } else {
            v = cm_si_field(r, cm_fragment[k].off, (cm_field_t)kind);
        }
        *it = (cm_item_t){cm_fragment[k].section, cm_fragment[k].key, v,
                          kind == CM_F_LINES || kind == CM_FIELD_INT};
        return true;
    }
    return false;
}

/* ---- outcome ---- */

typedef enum { K_NONE, K_A, K_V, K_H, K_OHM, K_WB, K_RAD_S, K_FRAC, K_INT, K_NM, K_DEG } cm_kind_t;

typedef struct {
    const char *label[3];
    uint8_t kind[3];
} cm_detail_t;

static const cm_detail_t cm_err_detail[CM_E_COUNT] = {
    [CM_E_FAULT] = {{"fault_code", NULL, NULL}, {K_INT, K_NONE, K_NONE}},
    [CM_E_VBUS_LOW] = {{"vbus", "min", NULL}, {K_V, K_V, K_NONE}},
    [CM_E_VBUS_HIGH] = {{"vbus", "max", NULL}, {K_V, K_V, K_NONE}},
    [CM_E_OFFSET] = {{"phase", "mean", "tol"}, {K_INT, K_A, K_A}},
    [CM_E_NOISE] = {{"phase", "sd", "tol"}, {K_INT, K_A, K_A}},
    [CM_E_OPEN_PHASE] = {{"current", "needed", "voltage"}, {K_A, K_A, K_V}},
    [CM_E_SHORTED_PHASE] = {{"current", "inductance", "fault_code"}, {K_A, K_H, K_INT}},
    [CM_E_UNBALANCED] = {{"unbalance", "max", NULL}, {K_FRAC, K_FRAC, K_NONE}},
    [CM_E_VOLTAGE_LIMIT] = {{"current", "v_lim", NULL}, {K_A, K_V, K_NONE}},
    [CM_E_CURRENT_LIMIT] = {{"current", "limit", NULL}, {K_A, K_A, K_NONE}},
    [CM_E_RS_RANGE] = {{"dv", "di", NULL}, {K_V, K_A, K_NONE}},
    [CM_E_L_RANGE] = {{"inductance", "min", "max"}, {K_H, K_H, K_H}},
    [CM_E_ENC_NO_MOTION] = {{"moved_permille", "expected_permille", NULL}, {K_INT, K_INT, K_NONE}},
    [CM_E_ENC_CPR] = {{"counts_measured", "counts_configured", "ratio"}, {K_INT, K_INT, K_FRAC}},
    [CM_E_ENC_UNSTEADY] = {{"speed", "limit", NULL}, {K_RAD_S, K_RAD_S, K_NONE}},
    [CM_E_SPEED_LOW] = {{"speed", "target", "at_voltage_limit"}, {K_RAD_S, K_RAD_S, K_INT}},
    [CM_E_OVERSPEED] = {{"speed", "limit", NULL}, {K_RAD_S, K_RAD_S, K_NONE}},
    [CM_E_FLUX_RANGE] = {{"psi", "speed", "d_sign"}, {K_WB, K_RAD_S, K_INT}},
    [CM_E_SENSE_POLARITY] = {{"phase", "measured", "predicted"}, {K_INT, K_A, K_A}},
    [CM_E_SENSE_GAIN] = {{"phase", "ratio", "measured"}, {K_INT, K_FRAC, K_A}},
    [CM_E_SENSE_SUM] = {{"sum", "current", "phase"}, {K_A, K_A, K_INT}},
    [CM_E_GATES_CURRENT] = {{"phase", "current", "test"}, {K_INT, K_A, K_INT}},
    [CM_E_GATES_VBUS] = {{"vbus", "at_start", "test"}, {K_V, K_V, K_INT}},
    [CM_E_RUN_DIRECTION] = {{"speed_gain", "periods", "torque"}, {K_RAD_S, K_INT, K_NM}},
    [CM_E_RUN_NO_ACCEL] = {{"speed_gain", "periods", "torque"}, {K_RAD_S, K_INT, K_NM}},
    [CM_E_RUN_CURRENT] = {{"current", "needed", "torque"}, {K_A, K_A, K_NM}},
    [CM_E_NEEDS] = {{"step", NULL, NULL}, {K_INT, K_NONE, K_NONE}},
    [CM_E_SUPPLY] = {{"current_min", "v_needed", "v_lim"}, {K_A, K_V, K_V}},
};

static const char *const cm_units[] = {"",      "A", "V", "H",   "Ohm", "Wb",
                                       "rad/s", "",  "",  "N*m", "deg"};

static double cm_value(int32_t v, uint8_t kind, const ctrl_bases_t *b)
{
    switch (kind) {
    case K_A:
        return cm_si(v, b->i_a);
    case K_V:
        return cm_si(v, b->v_v);
    case K_H:
        return cm_si(v, b->l_h);
    case K_OHM:
        return cm_si(v, b->r_ohm);
    case K_WB:
        return cm_si(v, b->psi_wb);
    case K_RAD_S:
        return cm_si(v, b->w_rad_s);
    case K_FRAC:
        return (double)v / 16777216.0;
    case K_NM:
        return cm_si(v, b->torque_nm);
    case K_DEG:
        return (double)(uint32_t)v / 4294967296.0 * 360.0;
    default:
        return (double)v;
    }
}

static void cm_add(cm_outcome_t *o, const char *label, double v, const char *unit)
{
    if (o->n < 3u) {
        o->label[o->n] = label;
        o->value[o->n] = v;
        o->unit[o->n] = unit;
        o->n++;
    }
}

/* A value in pu (or counts, an angle) with its kind's SI unit. */
static void cm_add_pu(cm_outcome_t *o, const char *label, int32_t v, uint8_t kind,
                      const ctrl_bases_t *b)
{
    cm_add(o, label, cm_value(v, kind, b), cm_units[kind]);
}

void cm_outcome(const cm_t *cm, const ctrl_bases_t *b, cm_outcome_t *o)
{
    memset(o, 0, sizeof *o);
    o->step = cm_step_name(cm->active ? cm->step : cm->last_step);
    o->error = cm_err_name(cm->err);
    if (cm->active) {
        o->verdict = "running";
        cm_add(o, "progress", (double)cm->progress / 10.0, "%");
        return;
    }
    if (!cm->done) {
        o->verdict = "idle";
        return;
    }
    if (cm->err == CM_E_STOPPED) {
        o->verdict = "stopped";
        return;
    }
    if (cm->err != CM_E_NONE) {
        o->verdict = "fail";
        const cm_detail_t *d = &cm_err_detail[cm->err];
        for (int k = 0; k < 3; k++) {
            if (d->label[k] != NULL) {
                cm_add_pu(o, d->label[k], cm->detail[k], d->kind[k], b);
            }
        }
        return;
    }
    o->verdict = "pass";
    const cm_results_t *r = &cm->res;
    const ctrl_bases_t *rb = &r->bases;
    switch (cm->last_step) {
    case CM_STEP_VBUS: {
        double off = 0.0, sd = 0.0;
        for (int k = 0; k < 3; k++) {
            off = fmax(off, fabs(cm_si(r->i_off[k], rb->i_a)));
            sd = fmax(sd, cm_si(r->i_noise[k], rb->i_a));
        }
        cm_add_pu(o, "vbus", r->vbus, K_V, rb);
        cm_add(o, "offset_max", off, "A");
        cm_add(o, "noise_max", sd, "A");
        break;
    }
    case CM_STEP_PROBE:
        cm_add_pu(o, "inductance", r->l_probe, K_H, rb);
        break;
    case CM_STEP_ENCODER:
        cm_add_pu(o, "direction", r->enc_dir, K_INT, rb);
        cm_add_pu(o, "counts", (int32_t)r->enc_cpr, K_INT, rb);
        cm_add_pu(o, "offset", (int32_t)r->enc_off, K_DEG, rb);
        break;
    case CM_STEP_SENSE:
        for (int k = 0; k < 3; k++) {
            static const char *const names[3] = {"ratio_a", "ratio_b", "ratio_c"};
            cm_add(o, names[k], (double)cm->detail[k] / 16777216.0, "");
        }
        break;
    case CM_STEP_RUN:
        cm_add_pu(o, "speed_gain", cm->detail[0], K_RAD_S, b);
        cm_add_pu(o, "periods", cm->detail[1], K_INT, b);
        cm_add_pu(o, "torque", cm->detail[2], K_NM, b);
        break;
    default:
        /* A whole identification: its main figures. */
        if ((r->have & CM_HAVE_RS) != 0u) {
            cm_add_pu(o, "rs", r->rs, K_OHM, rb);
        }
        if ((r->have & CM_HAVE_LDQ) != 0u) {
            cm_add_pu(o, "ld", r->ld, K_H, rb);
        }
        if ((r->have & CM_HAVE_FLUX) != 0u) {
            cm_add_pu(o, "psi", r->psi, K_WB, rb);
        }
        break;
    }
}
