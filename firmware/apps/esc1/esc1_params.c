/*
 * Machine data and board values of the B-G431B-ESC1 image on the command
 * interface (PROTOCOL.md "param list / get / set", the firmware's own
 * parameters). Machine data change only while the gates are off (not
 * running, not commissioning, no arm pending: "err 8 state in <state>");
 * every change re-initialises the firmware (state boot -> calibration ->
 * ready, controller tunables back to their defaults) and moves the hardware
 * over-current threshold with m.i_max_a. What "config save" stores
 * (esc1_settings.c: the machine, the encoder, the controller, the throttle
 * input) is applied after the next power-up; without a record, or after
 * "config erase", the compiled-in machine (esc1_default_machine, generated
 * from its machine file: esc1_app.h) and the throttle's defaults are.
 */
#include <math.h>
#include <string.h>

#include "board_esc1.h"
#include "cmd.h"
#include "esc1_app.h"
#include "g4_core.h"
#include "help_text.h"

/* Out of line: three callers, each inlined copy of its soft-double compares
 * took more flash than a call. */
__attribute__((noinline)) double esc1_hw_trip_a(const g4_board_t *b, const ctrl_machine_t *m)
{
    double a = 1.5 * m->current_max_a;
    if (a < 8.0) {
        a = 8.0;
    }
    return a > b->current_peak_a ? b->current_peak_a : a;
}

void esc1_config_default(fw_config_t *c, const g4_board_t *b, const ctrl_machine_t *m,
                         const ctrl_desc_t *ctrl)
{
    fw_config_default(c, m, ctrl);
    /* A code g4_dtg_encode refuses has already stopped g4_hal_init (board
     * init halts), so the board never runs with the 0 left here then. */
    uint8_t dtg = 0;
    if (g4_dtg_encode(b->sysclk_hz, b->dead_time_ns, &dtg) == G4_OK) {
        c->dead_time_s = (double)g4_dtg_ticks(dtg) / (double)b->sysclk_hz;
    }
}

static esc1_t *esc1_of(void *ctx)
{
    return (esc1_t *)ctx;
}

/* Machine fields reachable by name. */
typedef enum {
    M_P,
    M_RS,
    M_LD,
    M_LQ,
    M_PSI,
    M_VDC,
    M_J,
    M_T,
    M_N,
    M_IR,
    M_IMAX,
    M_PSIREF,
    M_CPR
} esc1_field_t;

static double *esc1_field(ctrl_machine_t *m, esc1_field_t f)
{
    switch (f) {
    case M_RS:
        return &m->rs_ohm;
    case M_LD:
        return &m->ld_h;
    case M_LQ:
        return &m->lq_h;
    case M_PSI:
        return &m->psi_pm_wb;
    case M_VDC:
        return &m->vdc_v;
    case M_J:
        return &m->inertia_kgm2;
    case M_T:
        return &m->torque_rated_nm;
    case M_N:
        return &m->speed_rated_rpm;
    case M_IR:
        return &m->current_rated_a;
    case M_IMAX:
        return &m->current_max_a;
    case M_PSIREF:
        return &m->psi_ref_wb;
    default:
        return NULL;
    }
}

/* Throttle values reachable by index (esc1_thr_get / esc1_thr_set). */
typedef enum { T_MODE, T_LOW, T_HIGH, T_DB, T_US, T_STATE, T_CAUSE } esc1_thr_field_t;

/* Places in esc1_params: the machine fields at their esc1_field_t, the board
 * values, the throttle's at P_T0 + esc1_thr_field_t. */
enum {
    P_FS = M_CPR + 1,
    P_DUTY,
    P_HW_TRIP,
    P_TEMP,
    P_TRIP,
    P_RESET,
    P_TEMP_CHECK,
    P_T0,
    ESC1_N_PARAMS = P_T0 + T_CAUSE + 1
};
static const fw_link_param_t esc1_params[ESC1_N_PARAMS];

/* Machine data and the encoder: entries M_P .. M_CPR of esc1_params. The
 * machine in force is the drive's (fw_t.machine_own, which "ident apply"
 * rewrites): read and edited there, never from a copy of the board's. */
static int esc1_get_field(void *ctx, const fw_link_param_t *p, double *v)
{
    esc1_t *s = esc1_of(ctx);
    const esc1_field_t f = (esc1_field_t)(p - esc1_params);
    if (f == M_P) {
        *v = (double)s->fw.machine_own.pole_pairs;
    } else if (f == M_CPR) {
        *v = (double)s->encoder_cpr;
    } else {
        *v = *esc1_field(&s->fw.machine_own, f);
    }
    return CMD_OK;
}

static int esc1_set_field(void *ctx, const fw_link_param_t *p, double v)
{
    esc1_t *s = esc1_of(ctx);
    const esc1_field_t f = (esc1_field_t)(p - esc1_params);
    ctrl_machine_t m = s->fw.machine_own;
    uint32_t cpr = s->encoder_cpr;
    if (f == M_P || f == M_CPR) {
        if (v != floor(v)) {
            return CMD_E_RANGE; /* integers only */
        }
        if (f == M_P) {
            m.pole_pairs = (int)v;
        } else {
            cpr = (uint32_t)v;
        }
    } else {
        *esc1_field(&m, f) = v;
    }
    m.name = "esc1_user";
    return esc1_reconfigure(s, &m, cpr);
}

static int esc1_get_fs(void *ctx, const fw_link_param_t *p, double *v)
{
    (void)p;
    *v = (double)esc1_of(ctx)->hal.info.pwm_freq_hz;
    return CMD_OK;
}

static int esc1_get_duty_max(void *ctx, const fw_link_param_t *p, double *v)
{
    (void)p;
    const hal_info_t *i = &esc1_of(ctx)->hal.info;
    *v = (double)i->pwm_cmp_max / (double)i->period_counts;
    return CMD_OK;
}

static int esc1_get_hw_trip(void *ctx, const fw_link_param_t *p, double *v)
{
    (void)p;
    *v = esc1_of(ctx)->hal.trip_current_a;
    return CMD_OK;
}

static int esc1_get_temp(void *ctx, const fw_link_param_t *p, double *v)
{
    (void)p;
    const double t = esc1_of(ctx)->temp_c;
    if (isnan(t)) {
        return CMD_E_FAILED; /* sensor open or shorted */
    }
    *v = t;
    return CMD_OK;
}

static int esc1_get_trip(void *ctx, const fw_link_param_t *p, double *v)
{
    (void)p;
    *v = (double)g4_hal_trip_cause(&esc1_of(ctx)->hal);
    return CMD_OK;
}

static int esc1_get_reset(void *ctx, const fw_link_param_t *p, double *v)
{
    (void)p;
    *v = (double)(esc1_of(ctx)->reset_csr >> 24);
    return CMD_OK;
}

static int esc1_get_temp_check(void *ctx, const fw_link_param_t *p, double *v)
{
    (void)p;
    *v = esc1_of(ctx)->temp_check ? 1.0 : 0.0;
    return CMD_OK;
}

static int esc1_set_temp_check(void *ctx, const fw_link_param_t *p, double v)
{
    (void)p;
    if (v != 0.0 && v != 1.0) {
        return CMD_E_RANGE;
    }
    esc1_of(ctx)->temp_check = v != 0.0;
    return CMD_OK;
}

/* [throttle] settings: changed only while the throttle has not armed the
 * drive; the decoder restarts (disarmed, waiting for the low end). */
static int esc1_thr_set(void *ctx, const fw_link_param_t *p, double v)
{
    esc1_t *s = esc1_of(ctx);
    const esc1_thr_field_t i = (esc1_thr_field_t)(p - &esc1_params[P_T0]);
    if (v != floor(v)) {
        return CMD_E_RANGE;
    }
    if (s->thr.state != THR_WAIT_LOW || fw_gates_on_or_pending(&s->fw)) {
        return CMD_E_STATE;
    }
    thr_config_t c = s->thr.cfg;
    uint16_t *f[4] = {NULL, &c.low_us, &c.high_us, &c.deadband_us};
    if (i == T_MODE) {
        c.mode = (uint8_t)v;
    } else {
        *f[i] = (uint16_t)v;
    }
    if (thr_config_check(&c) != 0) {
        return CMD_E_RANGE; /* e.g. a dead band over half the span */
    }
    thr_init(&s->thr, &c, s->now_ms);
    return CMD_OK;
}

static int esc1_thr_get(void *ctx, const fw_link_param_t *p, double *v)
{
    const thr_t *t = &esc1_of(ctx)->thr;
    const esc1_thr_field_t i = (esc1_thr_field_t)(p - &esc1_params[P_T0]);
    const uint32_t x[7] = {t->cfg.mode, t->cfg.low_us, t->cfg.high_us, t->cfg.deadband_us,
                           t->width_us, t->state,      t->cause};
    *v = (double)x[i];
    return CMD_OK;
}

#define ESC1_RW(name, unit, lo, hi, help, get, set)                                                \
    {                                                                                              \
        {name, unit, HELP_TEXT(help), CMD_PARAM_RW, lo, hi}, get, set                              \
    }
#define ESC1_RO(name, unit, help, get)                                                             \
    {                                                                                              \
        {name, unit, HELP_TEXT(help), CMD_PARAM_RO, 0.0, 0.0}, get, NULL                           \
    }

static const fw_link_param_t esc1_params[ESC1_N_PARAMS] = {
    [M_P] = ESC1_RW("m.p", "-", 1.0, 50.0, "pole pairs (re-initialises, disarmed only)",
                    esc1_get_field, esc1_set_field),
    [M_RS] = ESC1_RW("m.rs_ohm", "ohm", 0.001, 100.0, "stator resistance per phase", esc1_get_field,
                     esc1_set_field),
    [M_LD] = ESC1_RW("m.ld_h", "H", 1e-6, 1.0, "d inductance", esc1_get_field, esc1_set_field),
    [M_LQ] = ESC1_RW("m.lq_h", "H", 1e-6, 1.0, "q inductance", esc1_get_field, esc1_set_field),
    [M_PSI] = ESC1_RW("m.psi_wb", "Wb", 1e-4, 1.0, "PM flux linkage, peak per phase",
                      esc1_get_field, esc1_set_field),
    [M_VDC] = ESC1_RW("m.vdc_v", "V", 8.0, 25.2, "nominal DC link (board max 25.2 V)",
                      esc1_get_field, esc1_set_field),
    [M_J] =
        ESC1_RW("m.j_kgm2", "kg*m^2", 1e-9, 1.0, "rotor inertia", esc1_get_field, esc1_set_field),
    [M_T] = ESC1_RW("m.t_rated_nm", "N*m", 1e-4, 100.0, "rated torque (torque reference limit)",
                    esc1_get_field, esc1_set_field),
    [M_N] = ESC1_RW("m.n_rated_rpm", "r/min", 10.0, 100000.0, "rated speed", esc1_get_field,
                    esc1_set_field),
    [M_IR] = ESC1_RW("m.i_rated_a", "A", 0.01, 40.0, "rated current, peak", esc1_get_field,
                     esc1_set_field),
    [M_IMAX] =
        ESC1_RW("m.i_max_a", "A", 0.01, 40.0, "over-current trip, peak (hw trip 1.5x, >= 8 A)",
                esc1_get_field, esc1_set_field),
    [M_PSIREF] = ESC1_RW("m.psi_ref_wb", "Wb", 0.0, 1.0, "stator flux reference, 0 = MTPA",
                         esc1_get_field, esc1_set_field),
    [M_CPR] = ESC1_RW("enc.cpr", "-", 4.0, 65535.0, "encoder counts per revolution (4 x lines)",
                      esc1_get_field, esc1_set_field),
    [P_FS] = ESC1_RO("b.fs_hz", "Hz", "PWM and control frequency", esc1_get_fs),
    [P_DUTY] = ESC1_RO("b.duty_max", "-", "largest leg duty (low-side current sampling window)",
                       esc1_get_duty_max),
    [P_HW_TRIP] = ESC1_RO("b.hw_trip_a", "A", "hardware over-current threshold (comparators)",
                          esc1_get_hw_trip),
    [P_TEMP] = ESC1_RO("b.temp_c", "C", "board temperature (NTC, linear model)", esc1_get_temp),
    [P_TRIP] = ESC1_RO("b.trip", "-", "trip latch: 1 over-current, 2 system break, 4 board (temp)",
                       esc1_get_trip),
    [P_RESET] =
        ESC1_RO("b.reset", "-",
                "RCC_CSR reset flags at start-up >> 24: 2 option bytes, 4 pin, 8 brown-out, "
                "16 software, 32 watchdog",
                esc1_get_reset),
    [P_TEMP_CHECK] = {{"b.temp_check", "-", HELP_TEXT("1 = board over-temperature trip on"),
                       CMD_PARAM_LIVE, 0.0, 1.0},
                      esc1_get_temp_check,
                      esc1_set_temp_check},
    [P_T0 + T_MODE] =
        ESC1_RW("throttle.mode", "-", 0.0, 2.0, "PWM pad (PA15): 0 off, 1 torque, 2 speed",
                esc1_thr_get, esc1_thr_set),
    [P_T0 + T_LOW] = ESC1_RW("throttle.low_us", "us", THR_PULSE_MIN_US, THR_LOW_MAX_US,
                             "pulse at zero (calibrated low end)", esc1_thr_get, esc1_thr_set),
    [P_T0 + T_HIGH] = ESC1_RW("throttle.high_us", "us", THR_HIGH_MIN_US, THR_PULSE_MAX_US,
                              "pulse at full scale", esc1_thr_get, esc1_thr_set),
    [P_T0 + T_DB] = ESC1_RW("throttle.deadband_us", "us", 0.0, 349.0, "zero up to low_us + this",
                            esc1_thr_get, esc1_thr_set),
    [P_T0 + T_US] = ESC1_RO("throttle.us", "us", "last valid pulse width", esc1_thr_get),
    [P_T0 + T_STATE] =
        ESC1_RO("throttle.state", "-", "0 disarmed (1 s at the low end arms), 1 armed, 2 lost",
                esc1_thr_get),
    [P_T0 + T_CAUSE] = ESC1_RO("throttle.cause", "-",
                               "last loss: 1 no pulse, 2 invalid pulses (100 ms)", esc1_thr_get),
};

void esc1_params_attach(esc1_t *s)
{
    fw_link_set_params(&s->link, esc1_params, sizeof esc1_params / sizeof esc1_params[0], s);
}

int esc1_reconfigure(esc1_t *s, const ctrl_machine_t *m, uint32_t encoder_cpr)
{
    return esc1_reconfigure_cfg(s, m, encoder_cpr, NULL);
}

/* The default configuration for the machine staged in s->machine, with what
 * the drive held beyond its machine data (identified, or a settings
 * record's: the encoder's offset and direction; fw_kept_t), so that a
 * machine parameter changed after it does not put back the uncalibrated
 * encoder (0, +1). */
static void esc1_config_kept(esc1_t *s, const ctrl_desc_t *ctrl, const fw_kept_t *kept)
{
    esc1_config_default(&s->fc, s->hal.board, &s->machine, ctrl);
    fw_kept_config(kept, &s->fc);
}

/* What a refusal puts back (fw_in_force_t; static: the stack of the
 * deepest command path does not grow by it). */
static fw_in_force_t esc1_in_force;

int esc1_reconfigure_cfg(esc1_t *s, const ctrl_machine_t *m, uint32_t encoder_cpr,
                         const fw_config_t *cfg)
{
    /* fw_init below starts the firmware anew: not while the gates are on
     * (running, or an identification driving the legs) or about to go on */
    if (fw_gates_on_or_pending(&s->fw)) {
        return CMD_E_STATE;
    }
    const double trip = esc1_hw_trip_a(s->hal.board, m);
    if (encoder_cpr < 4u || encoder_cpr > 0xFFFFu) {
        return CMD_E_RANGE;
    }
    const ctrl_machine_t old = s->fw.machine_own;
    const uint32_t old_cpr = s->encoder_cpr;
    fw_kept_t kept; /* fw_init clears fw_t: read here */
    fw_kept_read(&s->fw, &kept);
    /* fw_init clears fw_t, so the controller in use and its settings are
     * kept here for the restore (else a refused machine left the firmware
     * without one). */
    const ctrl_desc_t *ctrl = s->fw.ctrl;
    fw_in_force_read(&s->fw, &esc1_in_force);
    const uint32_t t0 = g4_cycles(); /* the hold's length: the start-up report */
    hal_ctrl_hold(&s->hal, true);
    s->machine = *m;
    s->encoder_cpr = encoder_cpr;
    s->hal.info.encoder_counts_per_rev = encoder_cpr;
    if (cfg != NULL) {
        s->fc = *cfg;
        s->fc.machine = &s->machine;
    } else {
        esc1_config_kept(s, ctrl, &kept);
    }
    int rc = fw_init(&s->fw, &s->hal, &s->fc);
    if (rc == FW_OK && g4_hal_set_trip_current(&s->hal, trip) != G4_OK) {
        rc = FW_ERANGE;
    }
    if (rc != FW_OK) {
        /* The core's reason for "err 10 failed", before the restore clears it. */
        fw_link_set_why(&s->link, &s->fw.why);
        /* The previous data worked: back to them. */
        s->machine = old;
        s->encoder_cpr = old_cpr;
        s->hal.info.encoder_counts_per_rev = old_cpr;
        /* as it was, tunables included; nothing installed before: the defaults */
        if (!fw_in_force_config(&esc1_in_force, &s->machine, &kept, &s->fc)) {
            esc1_config_kept(s, ctrl, &kept);
        }
        (void)fw_init(&s->fw, &s->hal, &s->fc);
        (void)g4_hal_set_trip_current(&s->hal, esc1_hw_trip_a(s->hal.board, &old));
    }
    /* the drive's speed reference limit, which it clamps to (as at power-up,
     * fw_link_init): the link refuses a reference beyond it */
    s->link.speed_max_rpm = s->fw.speed_info.speed_ref_max_rpm;
    hal_ctrl_hold(&s->hal, false);
    esc1_init_time(s, t0);
    /* In its range but refused by the core (e.g. a per-unit value outside its
     * Q format): "err 10 failed <quantity> = <value> outside [<min>, <max>]",
     * the previous data in force. */
    return rc == FW_OK ? CMD_OK : CMD_E_FAILED;
}
