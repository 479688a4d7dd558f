/* The firmware's configuration as parameters (fw_params.h). */
#include "fw_params.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cmd.h"
#include "ctrl_units.h"
#include "fw_settings.h"
#include "settings.h"

enum {
    U_NONE,
    U_OHM,
    U_H,
    U_WB,
    U_V,
    U_KGM2,
    U_NM,
    U_RPM,
    U_A,
    U_DEG,
    U_S,
    U_HZ,
    U_KP, /* the speed PI's gains: by speed.unit (fw_params_unit) */
    U_KI
};
static const char *const fw_params_units[] = {"-",   "ohm",   "H", "Wb",  "V", "kg*m^2",
                                              "N*m", "r/min", "A", "deg", "s", "Hz"};
/* The speed PI's gains in N*m per speed.unit (ctrl_speed_unit_t) and per
 * speed.unit x s. */
static const char *const fw_params_kp_units[] = {"N*m*s/rad", "N*m/(r/min)", "N*m*s/rad_e"};
static const char *const fw_params_ki_units[] = {"N*m/rad", "N*m/(r/min*s)", "N*m/rad_e"};

#define FW_SIGN 4u /* an integer field that is -1 or 1 */

#if PMSM_HELP_TEXT
#define P(key, unit, lo, hi, flags, help)                                                          \
    {                                                                                              \
        lo, hi, key, help, unit, flags                                                             \
    }
#else
#define P(key, unit, lo, hi, flags, help)                                                          \
    {                                                                                              \
        lo, hi, key, unit, flags                                                                   \
    }
#endif

/* Ranges: what a machine file accepts (sim_host/sim_machine.c); the core
 * refuses a combination it cannot represent, naming it. */
static const fw_param_t fw_params_machine_p[] = {
    P("m.p", U_NONE, 1, 50, 0u, "pole pairs"),
    P("m.rs_ohm", U_OHM, 0, 100, 0u, "stator resistance per phase (0: lossless)"),
    P("m.ld_h", U_H, 1e-7, 10, 0u, "d-axis inductance"),
    P("m.lq_h", U_H, 1e-7, 10, 0u, "q-axis inductance"),
    P("m.psi_wb", U_WB, 0, 10, 0u, "PM flux linkage, peak per phase"),
    P("m.vdc_v", U_V, 1, 1e5, 0u, "nominal DC link (per-unit base, DC-link trips 0.70 and 1.25 x)"),
    P("m.j_kgm2", U_KGM2, 1e-9, 1e6, 0u, "rotor inertia (the speed loop's design)"),
    P("m.t_rated_nm", U_NM, 1e-4, 1e5, 0u, "rated torque"),
    P("m.n_rated_rpm", U_RPM, 1, 1e6, 0u, "rated speed"),
    P("m.i_rated_a", U_A, 1e-3, 1e5, 0u, "rated current, peak (the torque limit's circle)"),
    P("m.i_max_a", U_A, 1e-3, 1e5, 0u, "over-current trip, peak phase current"),
    P("m.psi_ref_wb", U_WB, 0, 10, 0u,
      "stator-flux reference of the DTC/MPC controllers, 0 = MTPA"),
    P("m.n_max_rpm", U_RPM, 0, 1e6, 0u,
      "maximum speed, 0 = where the back-EMF meets the DC link (at least rated)"),
    P("enc.cpr", U_NONE, 4, 65535, 0u, "encoder counts per revolution (4 x lines)"),
};

static const fw_param_t fw_params_drive_p[] = {
    P("enc.dir", U_NONE, -1, 1, FW_SIGN,
      "encoder direction: 1 angle grows with the count, -1 falls"),
    P("enc.offset", U_DEG, 0, 360, FW_PARAM_TURN,
      "electrical angle of the d axis at count 0 (ident step encoder measures it)"),
#if CTRL_SL_HFI
    P("est.sensorless", U_NONE, 0, 2, 0u,
      "1: the flux observer's angle and speed, encoder unused; 2: with injection at standstill"),
#else
    P("est.sensorless", U_NONE, 0, 1, 0u,
      "1: angle and speed from the flux observer, the encoder unused"),
#endif
    P("est.psi_adapt", U_NONE, 0, 1, 0u,
      "1: PM flux tracked from the voltage model above 10 % of rated speed"),
    P("inv.dead_time_s", U_S, 0, 1e-4, 0u, "inverter dead time (compensated; observers' voltage)"),
    P("inv.v_fwd_v", U_V, 0, 100, 0u, "device forward drop of the inverter"),
    P("speed.bw_hz", U_HZ, 0, 1e4, FW_PARAM_LIVE,
      "speed-loop crossover; setting it designs the gains (0: the most the margin allows)"),
    P("speed.pm_deg", U_DEG, 0, 80, FW_PARAM_LIVE,
      "speed-loop phase margin, 20..80 (0: 60); setting it designs the gains"),
    P("speed.kp", U_KP, 0, 1e6, FW_PARAM_LIVE,
      "speed PI Kp (with speed.ki 0: designed); setting it fixes both"),
    P("speed.ki", U_KI, 0, 1e8, FW_PARAM_LIVE, "speed PI Ki (see speed.kp)"),
    P("speed.unit", U_NONE, 0, 2, 0u,
      "speed of speed.kp/ki: 0 mechanical rad/s, 1 r/min, 2 electrical rad/s"),
    P("speed.loop_hz", U_HZ, 0, 1e5, 0u,
      "rate of the speed loop and field weakening (divides fs), 0 = every period"),
    P("lim.torque_nm", U_NM, 1e-4, 1e6, 0u,
      "torque-reference limit (torque mode and the speed loop's output)"),
    P("prot.overspeed_rpm", U_RPM, 0, 1e6, 0u, "overspeed trip, 0 = 1.05 x maximum speed"),
};
#undef P

const fw_params_table_t fw_params_machine = {
    fw_params_machine_p, sizeof fw_params_machine_p / sizeof fw_params_machine_p[0]};
const fw_params_table_t fw_params_drive = {fw_params_drive_p,
                                           sizeof fw_params_drive_p / sizeof fw_params_drive_p[0]};

/* The index-th entry of the attached tables, or NULL. */
static const fw_param_t *fw_params_at(const fw_link_t *l, size_t index)
{
    for (size_t t = 0; t < FW_LINK_TABLES && l->tables[t] != NULL; t++) {
        if (index < l->tables[t]->n) {
            return &l->tables[t]->p[index];
        }
        index -= l->tables[t]->n;
    }
    return NULL;
}

static const fw_param_t *fw_params_find(const fw_link_t *l, const char *name)
{
    const fw_param_t *p;
    for (size_t i = 0; (p = fw_params_at(l, i)) != NULL; i++) {
        if (strcmp(p->key, name) == 0) {
            return p;
        }
    }
    return NULL;
}

static bool fw_params_info(const fw_link_t *l, size_t index, cmd_param_info_t *info)
{
    const fw_param_t *p = fw_params_at(l, index);
    if (p == NULL) {
        return false;
    }
    const unsigned su = l->fw->cfg.speed_unit <= 2u ? (unsigned)l->fw->cfg.speed_unit : 0u;
    info->name = p->key;
    info->unit = p->unit == U_KP   ? fw_params_kp_units[su]
                 : p->unit == U_KI ? fw_params_ki_units[su]
                                   : fw_params_units[p->unit];
#if PMSM_HELP_TEXT
    info->help = p->help;
#else
    info->help = NULL;
#endif
    info->access = (p->flags & FW_PARAM_LIVE) != 0u ? CMD_PARAM_LIVE : CMD_PARAM_RW;
    info->min = p->min;
    info->max = p->max;
    return true;
}

/* The configuration in force as a record (the application's own fields too). */
static void fw_params_capture(const fw_link_t *l, settings_t *s)
{
    fw_settings_capture(l->fw, s);
    if (l->settings != NULL && l->settings->capture != NULL) {
        l->settings->capture(l->settings->ctx, s);
    }
}

/* 2^32 / 360: an angle of 2^-32 turn per count in degrees. */
#define FW_TURN_PER_DEG 11930464.711111111

static int fw_params_get(const fw_link_t *l, const char *name, double *value)
{
    const fw_param_t *p = fw_params_find(l, name);
    if (p == NULL) {
        return CMD_E_NAME;
    }
    settings_t s;
    settings_field_ref_t r;
    fw_params_capture(l, &s);
    if (!settings_field_find(&s, p->key, &r)) {
        return CMD_E_FAILED; /* a key the record does not have (test_params_link) */
    }
    if (r.f64) {
        memcpy(value, r.at, sizeof *value);
    } else {
        *value = (double)settings_field_int(&r);
        if ((p->flags & FW_PARAM_TURN) != 0u) {
            *value /= FW_TURN_PER_DEG;
        }
    }
    return CMD_OK;
}

/* After a reconfiguration: the telemetry stream as it was (fw_init stopped
 * it; a new META frame, the bases may have changed) and the speed-reference
 * limit in force. */
static void fw_params_resume(fw_link_t *l)
{
    if (l->tel.mask != 0u) {
        fw_tm_stream(l->fw, l->tel.every);
        l->send_meta = 1u;
    }
    l->speed_max_rpm = l->fw->speed_info.speed_ref_max_rpm;
}

static int fw_params_set(fw_link_t *l, const char *name, double v)
{
    const fw_param_t *p = fw_params_find(l, name);
    if (p == NULL) {
        return CMD_E_NAME;
    }
    fw_settings_t *st = l->settings;
    if (st == NULL || st->apply == NULL) {
        return CMD_E_UNSUPPORTED;
    }
    settings_t s;
    settings_field_ref_t r;
    fw_params_capture(l, &s);
    if (!settings_field_find(&s, p->key, &r)) {
        return CMD_E_FAILED;
    }
    uint8_t old[8];
    memcpy(old, r.at, sizeof old); /* a field is at most 8 bytes, the record larger */
    if (r.f64) {
        memcpy(r.at, &v, sizeof v);
    } else {
        if ((p->flags & FW_PARAM_TURN) != 0u) {
            v = floor(v * FW_TURN_PER_DEG + 0.5); /* [0, 360] deg: [0, 2^32] counts */
            v = v >= 4294967296.0 ? 0.0 : v;      /* 360 deg is 0 */
        }
        if (v != floor(v) || v < (double)r.lo || v > (double)r.hi ||
            ((p->flags & FW_SIGN) != 0u && v == 0.0)) {
            return CMD_E_RANGE; /* the interpreter adds the range, ", whole numbers" */
        }
        settings_field_set_int(&r, (int64_t)v);
    }
    fw_t *fw = l->fw;
    if ((p->flags & FW_PARAM_LIVE) != 0u) {
        /* The bandwidth and the margin are the design's: setting one designs
         * the gains (explicit ones cleared). Setting a gain makes both
         * explicit, the other as it is in force (the design's, in speed.unit,
         * when they were designed). */
        if (r.at == (uint8_t *)&s.speed_bw_hz || r.at == (uint8_t *)&s.speed_pm_deg) {
            s.speed_kp = 0.0;
            s.speed_ki = 0.0;
        } else if (!(fw->cfg.speed_kp > 0.0) && !(fw->cfg.speed_ki > 0.0)) {
            /* fw_speed_info_t's gains are per mechanical rad/s (fw_speed_gains) */
            const unsigned su = (unsigned)fw->cfg.speed_unit;
            const double per_rad = su == 1u   ? 60.0 / CTRL_TWO_PI
                                   : su == 2u ? (double)fw->machine->pole_pairs
                                              : 1.0;
            if (r.at == (uint8_t *)&s.speed_kp) {
                s.speed_ki = fw->speed_info.ki_nm_rad / per_rad;
            } else {
                s.speed_kp = fw->speed_info.kp_nm_s_rad / per_rad;
            }
        }
        const int rc = fw_speed_retune(fw, s.speed_bw_hz, s.speed_pm_deg, s.speed_kp, s.speed_ki);
        if (rc == FW_EBUSY) {
            return CMD_E_STATE;
        }
        if (rc == FW_ERANGE) {
            fw_link_set_why(l, &fw->why);
        } else if (rc != FW_OK) {
            fw_link_set_why_text(l, "speed loop: bandwidth above what the phase margin allows, or "
                                    "margin outside [20, 80] deg");
        }
        return rc == FW_OK ? CMD_OK : CMD_E_FAILED;
    }
    if (fw_gates_on_or_pending(fw)) {
        return CMD_E_STATE;
    }
    char why[CMD_OUT_MAX - 16u];
    why[0] = '\0';
    int rc = st->apply(st->ctx, &s, why, sizeof why);
    if (rc != CMD_OK) {
        /* Refused: the reason is the answer's; the configuration before it
         * is applied again (an application may have left the firmware without
         * one). */
        char none[8];
        memcpy(r.at, old, sizeof old);
        (void)st->apply(st->ctx, &s, none, sizeof none);
        fw_link_set_why_text(l, why[0] != '\0' ? why : "refused");
        rc = rc == CMD_E_RANGE ? CMD_E_FAILED : rc;
    }
    fw_params_resume(l);
    return rc;
}

void fw_params_attach(fw_link_t *l, const fw_params_table_t *t)
{
    if (l == NULL || t == NULL) {
        return;
    }
    for (size_t i = 0; i < FW_LINK_TABLES; i++) {
        if (l->tables[i] == NULL) {
            l->tables[i] = t;
            l->n_table_params += t->n;
            l->table_at = fw_params_info;
            l->table_get = fw_params_get;
            l->table_set = fw_params_set;
            return;
        }
    }
}
