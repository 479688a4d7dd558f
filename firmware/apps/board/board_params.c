/*
 * Machine data and board values of a board image on the command interface
 * (PROTOCOL.md "param list / get / set", the firmware's own parameters).
 * Machine data change only while the gates are off (not running, not
 * commissioning, no arm pending: "err 8 state in <state>"); every change
 * re-initialises the firmware (board_app_reconfigure: state boot ->
 * calibration -> ready, controller tunables back to their defaults). The
 * board image appends its own values (BOARD_APP_EXTRA_PARAMS of its
 * board_app_cfg.h) and gives the ranges its power stage sets
 * (BOARD_APP_VDC_MAX_V, BOARD_APP_CURRENT_MAX_A).
 */
#include <math.h>
#include <string.h>

#include "board_app.h"
#include "board_app_cfg.h"
#include "cmd.h"
#include "help_text.h"

static board_app_t *board_app_of(void *ctx)
{
    return (board_app_t *)ctx;
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
} board_field_t;

static double *board_field(ctrl_machine_t *m, board_field_t f)
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

/* Throttle values reachable by index. */
typedef enum { T_MODE, T_LOW, T_HIGH, T_DB, T_US, T_STATE, T_CAUSE } board_thr_field_t;

/* Places in board_params: the machine fields at their board_field_t, the
 * common board values, the throttle's at P_T0 + board_thr_field_t, then the
 * board image's own. */
enum {
    P_FS = M_CPR + 1,
    P_DUTY,
    P_TEMP,
    P_TEMP_CHECK,
    P_RESET,
    P_T0,
    P_EXTRA = P_T0 + T_CAUSE + 1
};
#define BOARD_N_PARAMS (P_EXTRA + BOARD_APP_N_EXTRA_PARAMS)
static const fw_link_param_t board_params[BOARD_N_PARAMS];

static int board_get_field(void *ctx, const fw_link_param_t *p, double *v)
{
    board_app_t *a = board_app_of(ctx);
    const board_field_t f = (board_field_t)(p - board_params);
    if (f == M_P) {
        *v = (double)a->fw.machine_own.pole_pairs;
    } else if (f == M_CPR) {
        *v = (double)a->encoder_cpr;
    } else {
        *v = *board_field(&a->fw.machine_own, f);
    }
    return CMD_OK;
}

static int board_set_field(void *ctx, const fw_link_param_t *p, double v)
{
    board_app_t *a = board_app_of(ctx);
    const board_field_t f = (board_field_t)(p - board_params);
    ctrl_machine_t m = a->fw.machine_own; /* in force ("ident apply" rewrites it) */
    uint32_t cpr = a->encoder_cpr;
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
        *board_field(&m, f) = v;
    }
    m.name = "user";
    return board_app_reconfigure(a, &m, cpr, NULL);
}

static int board_get_fs(void *ctx, const fw_link_param_t *p, double *v)
{
    (void)p;
    hal_info_t i;
    hal_info_get(board_app_of(ctx)->hal, &i);
    *v = (double)i.pwm_freq_hz;
    return CMD_OK;
}

static int board_get_duty_max(void *ctx, const fw_link_param_t *p, double *v)
{
    (void)p;
    hal_info_t i;
    hal_info_get(board_app_of(ctx)->hal, &i);
    *v = (double)i.pwm_cmp_max / (double)i.period_counts;
    return CMD_OK;
}

static int board_get_temp(void *ctx, const fw_link_param_t *p, double *v)
{
    (void)p;
    const double t = board_app_of(ctx)->temp_c;
    if (isnan(t)) {
        return CMD_E_FAILED; /* sensor open or shorted */
    }
    *v = t;
    return CMD_OK;
}

static int board_get_temp_check(void *ctx, const fw_link_param_t *p, double *v)
{
    (void)p;
    *v = board_app_of(ctx)->temp_check ? 1.0 : 0.0;
    return CMD_OK;
}

static int board_set_temp_check(void *ctx, const fw_link_param_t *p, double v)
{
    (void)p;
    if (v != 0.0 && v != 1.0) {
        return CMD_E_RANGE;
    }
    board_app_of(ctx)->temp_check = v != 0.0;
    return CMD_OK;
}

static int board_get_reset(void *ctx, const fw_link_param_t *p, double *v)
{
    (void)p;
    *v = (double)board_app_of(ctx)->reset_flags;
    return CMD_OK;
}

/* [throttle] settings: changed only while the throttle has not armed the
 * drive; the decoder restarts (disarmed, waiting for the low end). */
static int board_thr_set(void *ctx, const fw_link_param_t *p, double v)
{
    board_app_t *a = board_app_of(ctx);
    const board_thr_field_t i = (board_thr_field_t)(p - &board_params[P_T0]);
    if (v != floor(v)) {
        return CMD_E_RANGE;
    }
    if (a->thr.state != THR_WAIT_LOW || fw_gates_on_or_pending(&a->fw)) {
        return CMD_E_STATE;
    }
    thr_config_t c = a->thr.cfg;
    uint16_t *f[4] = {NULL, &c.low_us, &c.high_us, &c.deadband_us};
    if (i == T_MODE) {
        c.mode = (uint8_t)v;
    } else {
        *f[i] = (uint16_t)v;
    }
    if (thr_config_check(&c) != 0) {
        return CMD_E_RANGE; /* e.g. a dead band over half the span */
    }
    thr_init(&a->thr, &c, a->now_ms);
    return CMD_OK;
}

static int board_thr_get(void *ctx, const fw_link_param_t *p, double *v)
{
    const thr_t *t = &board_app_of(ctx)->thr;
    const board_thr_field_t i = (board_thr_field_t)(p - &board_params[P_T0]);
    const uint32_t x[7] = {t->cfg.mode, t->cfg.low_us, t->cfg.high_us, t->cfg.deadband_us,
                           t->width_us, t->state,      t->cause};
    *v = (double)x[i];
    return CMD_OK;
}

#define MRW(name, unit, lo, hi, help)                                                              \
    BOARD_APP_RW(name, unit, lo, hi, help, board_get_field, board_set_field)
#define TRW(name, unit, lo, hi, help)                                                              \
    BOARD_APP_RW(name, unit, lo, hi, help, board_thr_get, board_thr_set)

static const fw_link_param_t board_params[BOARD_N_PARAMS] = {
    [M_P] = MRW("m.p", "-", 1.0, 50.0, "pole pairs (re-initialises, disarmed only)"),
    [M_RS] = MRW("m.rs_ohm", "ohm", 0.001, 100.0, "stator resistance per phase"),
    [M_LD] = MRW("m.ld_h", "H", 1e-6, 1.0, "d inductance"),
    [M_LQ] = MRW("m.lq_h", "H", 1e-6, 1.0, "q inductance"),
    [M_PSI] = MRW("m.psi_wb", "Wb", 1e-4, 1.0, "PM flux linkage, peak per phase"),
    [M_VDC] = MRW("m.vdc_v", "V", 8.0, BOARD_APP_VDC_MAX_V, "nominal DC link (the board's rating)"),
    [M_J] = MRW("m.j_kgm2", "kg*m^2", 1e-9, 1.0, "rotor inertia"),
    [M_T] = MRW("m.t_rated_nm", "N*m", 1e-4, 100.0, "rated torque (torque reference limit)"),
    [M_N] = MRW("m.n_rated_rpm", "r/min", 10.0, 100000.0, "rated speed"),
    [M_IR] = MRW("m.i_rated_a", "A", 0.01, BOARD_APP_CURRENT_MAX_A, "rated current, peak"),
    [M_IMAX] = MRW("m.i_max_a", "A", 0.01, BOARD_APP_CURRENT_MAX_A, "over-current trip, peak"),
    [M_PSIREF] = MRW("m.psi_ref_wb", "Wb", 0.0, 1.0, "stator flux reference, 0 = MTPA"),
    [M_CPR] = MRW("enc.cpr", "-", 4.0, 65535.0, "encoder counts per revolution (4 x lines)"),
    [P_FS] = BOARD_APP_RO("b.fs_hz", "Hz", "PWM and control frequency", board_get_fs),
    [P_DUTY] = BOARD_APP_RO("b.duty_max", "-", "largest leg duty (current sampling window)",
                            board_get_duty_max),
    [P_TEMP] = BOARD_APP_RO("b.temp_c", "C", "power stage temperature", board_get_temp),
    [P_TEMP_CHECK] = BOARD_APP_LIVE("b.temp_check", "-", 0.0, 1.0, "1 = over-temperature trip on",
                                    board_get_temp_check, board_set_temp_check),
    [P_RESET] = BOARD_APP_RO("b.reset", "-", BOARD_APP_RESET_HELP, board_get_reset),
    [P_T0 + T_MODE] = TRW("throttle.mode", "-", 0.0, 2.0, "servo input: 0 off, 1 torque, 2 speed"),
    [P_T0 + T_LOW] =
        TRW("throttle.low_us", "us", 800.0, 1499.0, "pulse at zero (calibrated low end)"),
    [P_T0 + T_HIGH] = TRW("throttle.high_us", "us", 1501.0, 2200.0, "pulse at full scale"),
    [P_T0 + T_DB] = TRW("throttle.deadband_us", "us", 0.0, 349.0, "zero up to low_us + this"),
    [P_T0 + T_US] = BOARD_APP_RO("throttle.us", "us", "last valid pulse width", board_thr_get),
    [P_T0 + T_STATE] =
        BOARD_APP_RO("throttle.state", "-", "0 disarmed (1 s at the low end arms), 1 armed, 2 lost",
                     board_thr_get),
    [P_T0 + T_CAUSE] = BOARD_APP_RO(
        "throttle.cause", "-", "last loss: 1 no pulse, 2 invalid pulses (100 ms)", board_thr_get),
    BOARD_APP_EXTRA_PARAMS};

void board_app_params_attach(board_app_t *a)
{
    fw_link_set_params(&a->link, board_params, sizeof board_params / sizeof board_params[0], a);
}
