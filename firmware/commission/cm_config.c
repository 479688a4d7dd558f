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
    .i_hold = 0.3f,
    .i_hold_max = 0.6f,
    .i_rs1 = 0.25f,
    .i_rs2 = 0.5f,
    .i_probe = 0.1f,
    .i_open = 0.02f,
    .i_acc = 0.5f,
    .i_spin = 0.8f,
    .i_fd = 0.3f,
    .i_sense = 0.2f,
    .i_guard = 1.0f,
    .i_gate_max = 0.05f,
    .i_min = 0.1f,
    .v_lim = 0.25f,
    .v_lim_run = 0.4f,
    .v_probe0 = 0.02f,
    .vbus_min = 0.8f,
    .vbus_max = 1.2f,
    .l_min_h = 1e-6f,
    .l_max_h = 10.0f,
    .loop_g = 0.2f,
    .damp_rad_s = 30.0f,
    .w_flux = 0.5f,
    .w_loop_rad_s = 100.0f,
    .w_guard = 0.8f,
    .w_settle = 0.01f,
    .torque_run = 0.1f,
    .unbalance_max = 0.15f,
    .sense_lo = 0.75f,
    .sense_hi = 1.3f,
    .cpr_tol = 0.03f,
    .salient_min = 0.05f,
    .gate_duty = 0.05f,
    .scan_hz = 4.0f,
    .t_vbus = 0.05f,
    .t_ramp = 0.02f,
    .t_settle = 0.05f,
    .t_win = 0.1f,
    .t_hold = 0.15f,
    .t_hold_max = 1.0f,
    .t_hf = 0.25f,
    .t_scan_acc = 0.05f,
    .t_flux_max = 1.0f,
    .t_flux_win = 0.1f,
    .t_run = 0.5f,
    .t_gate = 0.02f,
};

void cm_config_default(cm_config_t *c)
{
    /* Read through a pointer the compiler cannot follow: it would otherwise
     * write the constants one by one into the copy (+250 B on the board
     * image). */
    const cm_config_t *volatile src = &cm_config_defaults;
    if (c != NULL) {
        *c = *src;
    }
}

/* String n (0-based) of a list of NUL-terminated strings. */
static const char *cm_nth(const char *list, size_t n)
{
    while (n-- != 0u) {
        list += strlen(list) + 1u;
    }
    return list;
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
    enum { S_I, S_V, S_W, S_T, S_1, S_L, S_LD, S_LQ, S_RS, S_PSI, S_LSB, S_KP, S_KI, S_N };
    /* The flux step's speed loop: crossover w_loop with the configured
     * inertia, i_q = kp e + ki sum e (pu): kp = J w_loop w_base / (p T_base
     * psi), the PI zero at a quarter of the crossover. */
    const double kp = m->inertia_kgm2 * b->w_rad_s /
                      ((double)m->pole_pairs * b->torque_nm * m->psi_pm_wb / b->psi_wb);
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
                               info->adc_current_a_per_count / b->i_a,
                               kp,
                               kp * c->w_loop_rad_s / 4.0 / fs};
    /* Field offsets in 4-byte words (every field is a float or a 32-bit word):
     * a row in three bytes. */
    _Static_assert(sizeof(cm_config_t) < 4u * 255u && offsetof(cm_par_t, n_vbus) < 4u * 256u,
                   "the rows' offsets fit a byte");
#define CM_C(f) ((uint8_t)(offsetof(cm_config_t, f) / 4u))
#define CM_P(f) ((uint8_t)(offsetof(cm_par_t, f) / 4u))
    /* (name, source field or 255 for 1.0, scale, destination field); the names
     * in one string, in the rows' order (a pointer per row took 168 B). */
#define CM_ROWS(X)                                                                                 \
    X("adc current lsb", 255u, S_LSB, CM_P(i_lsb))                                                 \
    X("rated current", 255u, S_I, CM_P(i_rated))                                                   \
    X("i_guard", CM_C(i_guard), S_I, CM_P(i_guard))                                                \
    X("i_hold", CM_C(i_hold), S_I, CM_P(i_hold))                                                   \
    X("i_hold_max", CM_C(i_hold_max), S_I, CM_P(i_hold_max))                                       \
    X("i_rs1", CM_C(i_rs1), S_I, CM_P(i_rs1))                                                      \
    X("i_rs2", CM_C(i_rs2), S_I, CM_P(i_rs2))                                                      \
    X("i_probe", CM_C(i_probe), S_I, CM_P(i_probe))                                                \
    X("i_open", CM_C(i_open), S_I, CM_P(i_open))                                                   \
    X("i_acc", CM_C(i_acc), S_I, CM_P(i_acc))                                                      \
    X("i_spin", CM_C(i_spin), S_I, CM_P(i_spin))                                                   \
    X("i_fd", CM_C(i_fd), S_I, CM_P(i_fd))                                                         \
    X("i_sense", CM_C(i_sense), S_I, CM_P(i_sense))                                                \
    X("i_gate_max", CM_C(i_gate_max), S_I, CM_P(i_gate_max))                                       \
    X("i_min", CM_C(i_min), S_I, CM_P(i_min))                                                      \
    X("v_lim", CM_C(v_lim), S_V, CM_P(v_lim))                                                      \
    X("v_lim_run", CM_C(v_lim_run), S_V, CM_P(v_lim_run))                                          \
    X("v_probe0", CM_C(v_probe0), S_V, CM_P(v_probe0))                                             \
    X("vbus_min", CM_C(vbus_min), S_V, CM_P(vbus_min))                                             \
    X("vbus_max", CM_C(vbus_max), S_V, CM_P(vbus_max))                                             \
    X("l_min", CM_C(l_min_h), S_L, CM_P(l_min))                                                    \
    X("l_max", CM_C(l_max_h), S_L, CM_P(l_max))                                                    \
    X("loop_g", CM_C(loop_g), S_1, CM_P(loop_g))                                                   \
    X("rated speed", 255u, S_W, CM_P(w_rated))                                                     \
    X("w_flux", CM_C(w_flux), S_W, CM_P(w_flux))                                                   \
    X("w_guard", CM_C(w_guard), S_W, CM_P(w_guard))                                                \
    X("w_settle", CM_C(w_settle), S_W, CM_P(w_settle))                                             \
    X("torque_run", CM_C(torque_run), S_T, CM_P(torque_run))                                       \
    X("rated torque", 255u, S_T, CM_P(torque_rated))                                               \
    X("unbalance_max", CM_C(unbalance_max), S_1, CM_P(unbalance_max))                              \
    X("sense_lo", CM_C(sense_lo), S_1, CM_P(sense_lo))                                             \
    X("sense_hi", CM_C(sense_hi), S_1, CM_P(sense_hi))                                             \
    X("cpr_tol", CM_C(cpr_tol), S_1, CM_P(cpr_tol))                                                \
    X("salient_min", CM_C(salient_min), S_1, CM_P(salient_min))                                    \
    X("gate_duty", CM_C(gate_duty), S_1, CM_P(gate_duty))                                          \
    X("configured Ld", 255u, S_LD, CM_P(l_cfg_d))                                                  \
    X("configured Lq", 255u, S_LQ, CM_P(l_cfg_q))                                                  \
    X("configured Rs", 255u, S_RS, CM_P(rs_cfg))                                                   \
    X("configured psi_pm", 255u, S_PSI, CM_P(psi_cfg))                                             \
    X("w_loop_rad_s", CM_C(w_loop_rad_s), S_KP, CM_P(w_kp))                                        \
    X("w_loop_rad_s", CM_C(w_loop_rad_s), S_KI, CM_P(w_ki))
#define CM_ROW_NAME(n, src, kind, dst) n "\0"
#define CM_ROW(n, src, kind, dst) {src, kind, dst},
    static const char names[] = CM_ROWS(CM_ROW_NAME);
    static const struct {
        uint8_t src; /* offsetof(cm_config_t, field) / 4, or 255 for 1.0 */
        uint8_t kind;
        uint8_t dst; /* offsetof(cm_par_t, field) / 4 */
    } t[] = {CM_ROWS(CM_ROW)};
#undef CM_ROW
#undef CM_ROW_NAME
#undef CM_ROWS
#undef CM_C
#undef CM_P
    for (size_t k = 0; k < sizeof t / sizeof t[0]; k++) {
        float src = 1.0f;
        if (t[k].src != 255u) {
            memcpy(&src, (const char *)c + 4u * t[k].src, sizeof src);
        }
        double v = (double)src * scale[t[k].kind];
        if (t[k].dst == offsetof(cm_par_t, l_max) / 4u) {
            v = fmin(v, 127.0); /* "no limit" within Q24 */
        }
        q24_t *dst = (q24_t *)(void *)((char *)q + 4u * t[k].dst);
        if (!isfinite(v) || v < 0.0 || !cm_q24(v, dst) || (*dst == 0 && v > 0.0)) {
            *what = cm_nth(names, k);
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
    /* The scan's count windows need 2 1/8 turns of constant speed in a
     * three-turn move (cm_encoder.c): each ramp at most 3/8 of a turn. */
    if (c->scan_hz * c->t_scan_acc > 0.75) {
        *what = "t_scan_acc";
        return -1;
    }
    if (!(c->dead_time_s >= 0.0f) || !cm_q24((double)c->dead_time_s * b->w_rad_s, &q->td)) {
        *what = "dead_time_s";
        return -1;
    }
    q->n_turn = (uint32_t)((((uint64_t)1 << 32) + q->scan_inc / 2u) / q->scan_inc);
    q->enc_count = (uint32_t)(((uint64_t)(uint32_t)p->pole_pairs << 32) / enc_cpr);
    /* "At rest" tolerates a rotor that toggles one count at the edge it
     * rests on: 1.5 counts over the speed window (a fine encoder on a
     * many-pole motor: 1 count in 16 periods is 2.4 % of the gimbal
     * motor's rated speed) */
    q->w_settle =
        fx_max(q->w_settle, fx_round_sat((int64_t)(q->enc_count * 3u / 32u) * p->dangle_to_omega,
                                         CTRL_DANGLE_SHIFT));
    /* The times t_vbus .. t_gate, in the order of n_vbus .. n_gate (one loop
     * takes less flash than the twelve conversions written out). */
    _Static_assert(
        offsetof(cm_config_t, t_gate) - offsetof(cm_config_t, t_vbus) == 11u * sizeof(float) &&
            offsetof(cm_par_t, n_gate) - offsetof(cm_par_t, n_vbus) == 11u * sizeof(uint32_t),
        "the times and their periods in one order");
    for (size_t k = 0; k < 12u; k++) {
        float t_s;
        memcpy(&t_s, (const char *)c + offsetof(cm_config_t, t_vbus) + k * sizeof t_s, sizeof t_s);
        const uint32_t n = cm_periods(t_s, fs);
        memcpy((char *)q + offsetof(cm_par_t, n_vbus) + k * sizeof n, &n, sizeof n);
    }
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
    q->i_hold_max_nom = q->i_hold_max;
    q->i_acc_nom = q->i_acc;
    q->i_spin_nom = q->i_spin;
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
    {CM_R(fw_vq), 4u, CM_B(v_v), CM_SI_NONE},
    {CM_R(fw_w), 4u, CM_B(w_rad_s), CM_SI_NONE},
    {CM_R(fw_iq), 4u, CM_B(i_a), CM_SI_NONE},
    {CM_R(fw_eq), 4u, CM_B(v_v), CM_SI_NONE},
#if CM_MECH
    {CM_R(fw_dw), 4u, CM_B(w_rad_s), CM_SI_NONE},
#endif
    {CM_R(i_fd), 1u, CM_B(i_a), CM_SI_NONE},
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
#if CM_MECH
    /* Inertia data: sums of i_q (current). */
    for (int t = 0; t < 2; t++) {
        r->jx_iq[t] = (int64_t)floor((double)r->jx_iq[t] * ob.i_a / nb->i_a + 0.5);
    }
#endif
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
    o->coulomb_nm = NAN;
#if !CM_MECH
    (void)pole_pairs;
    (void)ts_s;
#else
    if ((r->have & CM_HAVE_MECH) != 0u && pole_pairs > 0u && r->jx_n[0] > 0u && r->jx_n[1] > 0u) {
        /* Torque T = (psi +- D) i_q (pu) in the +i_d and -i_d windows and
         * transitions, D the reluctance term (Ld - Lq) i_d: at one speed the
         * two windows carry the same friction, (psi + D) i_+ = (psi - D) i_-,
         * so D = psi (i_- - i_+) / (i_- + i_+), least squares over the two
         * speeds (an incremental Ld from the ldq step is not the secant one
         * a saturating machine's torque follows); with less friction than
         * 5 % of the rated current it is not resolved and (Ld - Lq) i_d is
         * taken. The window's torque less J dw/dt over it against its
         * mechanical speed: the friction F + B w_m from the two speeds (the
         * mean of the two windows at each); each transition's J = (integral
         * T dt - F t - B angle_m) / (w_m at its end - at its start), those
         * from the windows' means and changes (a linear drift). Three
         * rounds from J = 0. */
        const double tb = b->torque_nm, pp = (double)pole_pairs;
        const double psi = cm_si(r->psi, 1.0);
        double iq[4], w[4], dw[4], tw[4], tn[4], j = 0.0, bv = 0.0, fc = 0.0;
        /* The current samples' offset (cm_flux.c: taken out of the windows'
         * i_q already), over a transition: kd x the angle it turned / Ts. */
        const double kd = cm_si(cm->par.td, 1.0) / 2.0 * psi / cm_si(r->lq, 1.0);
        for (int k = 0; k < 4; k++) {
            iq[k] = cm_si(r->fw_iq[k], 1.0);
            w[k] = cm_si(r->fw_w[k], b->w_rad_s) / pp;
            dw[k] = cm_si(r->fw_dw[k], b->w_rad_s) / pp;
            tw[k] = (double)r->fw_n[k] * ts_s;
            tn[k] = (double)r->fw_len[k] * ts_s;
        }
        const double sl = iq[3] + iq[0], sh = iq[2] + iq[1];
        const double s2 = sl * sl + sh * sh;
        const double imin = 0.05 * cm_si(cm->par.i_rated, 1.0);
        double d = cm_si(fx_mul(fx_sub(r->ld, r->lq), r->i_fd), 1.0);
        if (s2 > 4.0 * imin * imin) {
            d = psi * ((iq[3] - iq[0]) * sl + (iq[2] - iq[1]) * sh) / s2;
        }
        const double kt[4] = {(psi + d) * tb, (psi + d) * tb, (psi - d) * tb, (psi - d) * tb};
        const double w_lo = (w[0] + w[3]) / 2.0, w_hi = (w[1] + w[2]) / 2.0;
        for (int round = 0; round < 3 && w_hi - w_lo > 0.0; round++) {
            double t[4];
            for (int k = 0; k < 4; k++) {
                t[k] = kt[k] * iq[k] - (tw[k] > 0.0 ? j * dw[k] / tw[k] : 0.0);
            }
            bv = ((t[1] + t[2]) - (t[0] + t[3])) / 2.0 / (w_hi - w_lo);
            fc = (t[0] + t[3]) / 2.0 - bv * w_lo;
            j = 0.0;
            for (int k = 0; k < 2; k++) {
                const int a = k == 0 ? 0 : 2, e = a + 1; /* from window a to e */
                /* the offset over the transition: kd x the angle it turned / Ts */
                const double tdt = kt[a] *
                                   ((double)r->jx_iq[k] / 16777216.0 -
                                    kd * (double)r->jx_th[k] / 4294967296.0 * 2.0 * CTRL_PI /
                                        cm_si(cm->par.ts, 1.0)) *
                                   ts_s;
                const double n = (double)r->jx_n[k] * ts_s;
                const double ang = (double)r->jx_th[k] / 4294967296.0 * 2.0 * CTRL_PI / pp;
                const double dwt =
                    (w[e] - dw[e] / 2.0 * tn[e] / tw[e]) - (w[a] + dw[a] / 2.0 * tn[a] / tw[a]);
                j += (tdt - fc * n - bv * ang) / dwt / 2.0;
            }
        }
        if (w_hi - w_lo > 0.0) {
            o->inertia_kgm2 = j;
            o->friction_nms = bv;
            o->coulomb_nm = fc;
        }
    }
#endif
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
#if CM_MECH
    CM_F(CM_HAVE_MECH, "mechanics", "inertia_kgm2", CM_FIELD_SI, inertia_kgm2),
    CM_F(CM_HAVE_MECH, "mechanics", "friction_nms", CM_F_FRICTION, friction_nms),
    CM_F(CM_HAVE_MECH, "mechanics", "coulomb_nm", CM_F_FRICTION, coulomb_nm),
#endif
};
#undef CM_F

bool cm_fragment_item(const cm_si_t *r, size_t index, cm_item_t *it)
{
    for (size_t k = 0; k < sizeof cm_fragment / sizeof cm_fragment[0]; k++) {
        const uint8_t kind = cm_fragment[k].kind;
        if (!cm_si_has(r, cm_fragment[k].have) ||
            (kind == CM_F_FRICTION && !isfinite(cm_si_field(r, cm_fragment[k].off, CM_FIELD_SI)))) {
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

/* The detail numbers of each error: their labels (L_*, the 1-based order of
 * cm_labels; L_NONE: none) and kinds. The labels as one string (each ends in a
 * NUL): a third of the flash of a pointer per label. */
typedef struct {
    uint8_t label[3];
    uint8_t kind[3];
} cm_detail_t;

enum {
    L_NONE,
    L_FAULT_CODE,
    L_VBUS,
    L_MIN,
    L_MAX,
    L_PHASE,
    L_MEAN,
    L_TOL,
    L_SD,
    L_CURRENT,
    L_NEEDED,
    L_VOLTAGE,
    L_INDUCTANCE,
    L_UNBALANCE,
    L_V_LIM,
    L_LIMIT,
    L_DV,
    L_DI,
    L_COUNTS_MEASURED,
    L_COUNTS_CONFIGURED,
    L_RATIO,
    L_SPEED,
    L_TARGET,
    L_PSI,
    L_D_SIGN,
    L_MEASURED,
    L_PREDICTED,
    L_SUM,
    L_TEST,
    L_AT_START,
    L_SPEED_GAIN,
    L_PERIODS,
    L_TORQUE,
    L_STEP,
    L_CURRENT_MIN,
    L_V_NEEDED,
    L_MOVED_PERMILLE,
    L_TORQUE_MAX,
#if CTRL_COGGING
    L_LAG_COUNTS,
    L_MAX_COUNTS,
    L_DIRECTION,
    L_BIN,
    L_Q15_OF_RATED,
#endif
};

static const char cm_labels[] = "fault_code\0"
                                "vbus\0"
                                "min\0"
                                "max\0"
                                "phase\0"
                                "mean\0"
                                "tol\0"
                                "sd\0"
                                "current\0"
                                "needed\0"
                                "voltage\0"
                                "inductance\0"
                                "unbalance\0"
                                "v_lim\0"
                                "limit\0"
                                "dv\0"
                                "di\0"
                                "counts_measured\0"
                                "counts_configured\0"
                                "ratio\0"
                                "speed\0"
                                "target\0"
                                "psi\0"
                                "d_sign\0"
                                "measured\0"
                                "predicted\0"
                                "sum\0"
                                "test\0"
                                "at_start\0"
                                "speed_gain\0"
                                "periods\0"
                                "torque\0"
                                "step\0"
                                "current_min\0"
                                "v_needed\0"
                                "moved_permille\0"
                                "torque_max\0"
#if CTRL_COGGING
                                "lag_counts\0"
                                "max_counts\0"
                                "direction\0"
                                "bin\0"
                                "q15_of_rated\0"
#endif
    ;

static const cm_detail_t cm_err_detail[CM_E_COUNT] = {
    [CM_E_FAULT] = {{L_FAULT_CODE, L_NONE, L_NONE}, {K_INT, K_NONE, K_NONE}},
    [CM_E_VBUS_LOW] = {{L_VBUS, L_MIN, L_NONE}, {K_V, K_V, K_NONE}},
    [CM_E_VBUS_HIGH] = {{L_VBUS, L_MAX, L_NONE}, {K_V, K_V, K_NONE}},
    [CM_E_OFFSET] = {{L_PHASE, L_MEAN, L_TOL}, {K_INT, K_A, K_A}},
    [CM_E_NOISE] = {{L_PHASE, L_SD, L_TOL}, {K_INT, K_A, K_A}},
    [CM_E_OPEN_PHASE] = {{L_CURRENT, L_NEEDED, L_VOLTAGE}, {K_A, K_A, K_V}},
    [CM_E_SHORTED_PHASE] = {{L_CURRENT, L_INDUCTANCE, L_FAULT_CODE}, {K_A, K_H, K_INT}},
    [CM_E_UNBALANCED] = {{L_UNBALANCE, L_MAX, L_NONE}, {K_FRAC, K_FRAC, K_NONE}},
    [CM_E_VOLTAGE_LIMIT] = {{L_CURRENT, L_V_LIM, L_NONE}, {K_A, K_V, K_NONE}},
    [CM_E_CURRENT_LIMIT] = {{L_CURRENT, L_LIMIT, L_NONE}, {K_A, K_A, K_NONE}},
    [CM_E_RS_RANGE] = {{L_DV, L_DI, L_NONE}, {K_V, K_A, K_NONE}},
    [CM_E_L_RANGE] = {{L_INDUCTANCE, L_MIN, L_MAX}, {K_H, K_H, K_H}},
    [CM_E_ENC_NO_MOTION] = {{L_MOVED_PERMILLE, L_CURRENT, L_TORQUE_MAX}, {K_INT, K_A, K_NM}},
    [CM_E_ENC_CPR] = {{L_COUNTS_MEASURED, L_COUNTS_CONFIGURED, L_RATIO}, {K_INT, K_INT, K_FRAC}},
    [CM_E_ENC_UNSTEADY] = {{L_SPEED, L_LIMIT, L_NONE}, {K_RAD_S, K_RAD_S, K_NONE}},
    [CM_E_SPEED_LOW] = {{L_SPEED, L_TARGET, L_CURRENT}, {K_RAD_S, K_RAD_S, K_A}},
    [CM_E_OVERSPEED] = {{L_SPEED, L_LIMIT, L_NONE}, {K_RAD_S, K_RAD_S, K_NONE}},
    [CM_E_FLUX_RANGE] = {{L_PSI, L_SPEED, L_D_SIGN}, {K_WB, K_RAD_S, K_INT}},
    [CM_E_SENSE_POLARITY] = {{L_PHASE, L_MEASURED, L_PREDICTED}, {K_INT, K_A, K_A}},
    [CM_E_SENSE_GAIN] = {{L_PHASE, L_RATIO, L_MEASURED}, {K_INT, K_FRAC, K_A}},
    [CM_E_SENSE_SUM] = {{L_SUM, L_CURRENT, L_PHASE}, {K_A, K_A, K_INT}},
    [CM_E_GATES_CURRENT] = {{L_PHASE, L_CURRENT, L_TEST}, {K_INT, K_A, K_INT}},
    [CM_E_GATES_VBUS] = {{L_VBUS, L_AT_START, L_TEST}, {K_V, K_V, K_INT}},
    [CM_E_RUN_DIRECTION] = {{L_SPEED_GAIN, L_PERIODS, L_TORQUE}, {K_RAD_S, K_INT, K_NM}},
    [CM_E_RUN_NO_ACCEL] = {{L_SPEED_GAIN, L_PERIODS, L_TORQUE}, {K_RAD_S, K_INT, K_NM}},
    [CM_E_RUN_CURRENT] = {{L_CURRENT, L_NEEDED, L_TORQUE}, {K_A, K_A, K_NM}},
    [CM_E_NEEDS] = {{L_STEP, L_NONE, L_NONE}, {K_INT, K_NONE, K_NONE}},
    [CM_E_SUPPLY] = {{L_CURRENT_MIN, L_V_NEEDED, L_V_LIM}, {K_A, K_V, K_V}},
    [CM_E_LOAD] = {{L_MOVED_PERMILLE, L_CURRENT, L_TORQUE_MAX}, {K_INT, K_A, K_NM}},
#if CTRL_COGGING
    [CM_E_COG_FOLLOW] = {{L_LAG_COUNTS, L_MAX_COUNTS, L_DIRECTION}, {K_INT, K_INT, K_INT}},
    [CM_E_COG_RANGE] = {{L_BIN, L_Q15_OF_RATED, L_DIRECTION}, {K_INT, K_INT, K_INT}},
#endif
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
            if (d->label[k] != 0u) {
                cm_add_pu(o, cm_nth(cm_labels, (size_t)d->label[k] - 1u), cm->detail[k], d->kind[k],
                          b);
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
#if CTRL_COGGING
    case CM_STEP_COGGING:
        cm_add_pu(o, "cogging_peak", cm->detail[0], K_NM, b);
        cm_add_pu(o, "friction", cm->detail[1], K_NM, b);
        cm_add_pu(o, "bins", cm->detail[2], K_INT, b);
        break;
#endif
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
