/* Serial link: cmd_ops_t on the pipeline, telemetry samples (see fw_link.h). */
#include "fw_link.h"

#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "controller.h"
#include "ctrl_units.h"
#include "fw_stack.h"
#include "transforms.h"
#include "vectors.h"

static fw_link_t *fw_link_of(void *ctx)
{
    return (fw_link_t *)ctx;
}

static void op_write(void *ctx, const char *text, size_t len)
{
    fw_link_t *l = fw_link_of(ctx);
    if (l->write != NULL) {
        l->write(l->write_ctx, (const uint8_t *)text, len);
    }
}

static double fw_link_rpm(const fw_t *fw, q24_t omega_e)
{
    return ctrl_elec_to_rpm(ctrl_q24_to_double(omega_e) * fw->bases.w_rad_s, fw->params.pole_pairs);
}

static void op_get_status(void *ctx, cmd_status_t *st)
{
    const fw_link_t *l = fw_link_of(ctx);
    const fw_t *fw = l->fw;
    memset(st, 0, sizeof *st);
    st->state = fw_state_name(fw_state(fw));
    st->armed = fw_state(fw) == FW_STATE_RUNNING;
    st->ctrl = fw->ctrl != NULL ? fw->ctrl->name : "";
    st->fault = fw_fault(fw);
    st->fault_name = fw_fault_name(st->fault);
    st->mode = fw_ref_mode(fw) == FW_REF_SPEED ? CMD_MODE_SPEED : CMD_MODE_TORQUE;
    /* The last period's record: the estimate while running, the
     * commissioning step's (cm_monitor) while it runs, else none (0: the
     * record's "no estimate") - never the last run's estimate after a stop. */
    const fw_telemetry_t *r = fw_telemetry(fw);
    st->speed_rpm = fw_link_rpm(fw, r->omega_e);
    st->torque_nm = ctrl_q24_to_double(r->torque) * fw->bases.torque_nm;
    st->torque_ref_nm = ctrl_q24_to_double(fw->torque_ref_now) * fw->bases.torque_nm;
    st->speed_ref_rpm = fw_link_rpm(fw, fw_speed_ref(fw));
    st->torque_max_nm = ctrl_q24_to_double(fw->torque_ref_max) * fw->bases.torque_nm;
    st->speed_max_rpm = l->speed_max_rpm;
    st->tel_mask = l->tel.mask;
    st->tel_every = l->tel.every;
    if (l->stack_hi != NULL) {
        st->stack_size = (uint32_t)((uintptr_t)l->stack_hi - (uintptr_t)l->stack_lo);
        st->stack_used = fw_stack_used(l->stack_lo, l->stack_hi);
    }
}

static bool op_ctrl_at(void *ctx, size_t index, const char **name, const char **title)
{
    (void)ctx;
    const ctrl_desc_t *d = ctrl_at(index);
    if (d == NULL) {
        return false;
    }
    *name = d->name;
    *title = d->title;
    return true;
}

/* The application parameter called name, or NULL. */
static const fw_link_param_t *fw_link_param(const fw_link_t *l, const char *name)
{
    for (size_t i = 0; i < l->n_params; i++) {
        if (strcmp(l->params[i].info.name, name) == 0) {
            return &l->params[i];
        }
    }
    return NULL;
}

static bool op_param_at(void *ctx, size_t index, cmd_param_info_t *info)
{
    const fw_link_t *l = fw_link_of(ctx);
    const fw_t *fw = l->fw;
    const size_t n_ctrl = fw->ctrl != NULL ? fw->ctrl->n_tunables : 0u;
#if CTRL_SL_HFI
    /* the injection's settings after the controller's tunables ("hfi.*") */
    const size_t n_tun = n_ctrl + ctrl_hfi_desc.n_tunables;
#else
    const size_t n_tun = n_ctrl;
#endif
    if (index >= n_tun) {
        index -= n_tun;
#if PMSM_LIVE_PARAMS
        if (index < l->n_table_params) {
            return l->table_at(l, index, info);
        }
        index -= l->n_table_params;
#endif
        if (index >= l->n_params) {
            return false;
        }
        *info = l->params[index].info;
        return true;
    }
#if CTRL_SL_HFI
    const ctrl_tunable_t *t =
        index < n_ctrl ? &fw->ctrl->tunables[index] : &ctrl_hfi_desc.tunables[index - n_ctrl];
#else
    const ctrl_tunable_t *t = &fw->ctrl->tunables[index];
#endif
    info->name = t->name;
    info->unit = t->unit;
    info->help = t->help;
    info->min = t->min;
    info->max = t->max;
    info->access = index < n_ctrl && fw_tunable_is_live(fw, index) ? CMD_PARAM_LIVE : CMD_PARAM_RW;
    return true;
}

static int fw_link_err(int fw_rc)
{
    switch (fw_rc) {
    case FW_OK:
        return CMD_OK;
    case FW_EBUSY:
        return CMD_E_STATE;
    case FW_ENOENT:
        return CMD_E_NAME;
    case FW_EINVAL:
        return CMD_E_RANGE;
    default:
        return CMD_E_FAILED;
    }
}

static int op_param_get(void *ctx, const char *name, double *value)
{
    const fw_link_t *l = fw_link_of(ctx);
    const fw_link_param_t *p = fw_link_param(l, name);
    if (p != NULL) {
        return p->get(l->params_ctx, p, value);
    }
    const int rc = fw_link_err(fw_tunable_get(l->fw, name, value));
#if PMSM_LIVE_PARAMS
    return rc == CMD_E_NAME && l->table_get != NULL ? l->table_get(l, name, value) : rc;
#else
    return rc;
#endif
}

/* A configuration op's result; on a refusal the core's reason is kept for
 * the "err 10 failed" detail (op_failed_detail). */
static int fw_link_cfg_err(fw_link_t *l, int fw_rc)
{
    memset(&l->why, 0, sizeof l->why);
    if (fw_rc != FW_OK) {
        l->why = l->fw->why;
    }
    return fw_link_err(fw_rc);
}

static int op_select_controller(void *ctx, const char *name)
{
    const ctrl_desc_t *d = ctrl_find(name);
    if (d == NULL) {
        return CMD_E_NAME;
    }
    fw_link_t *l = fw_link_of(ctx);
    return fw_link_cfg_err(l, fw_select_controller(l->fw, d, NULL));
}

static int op_arm(void *ctx)
{
    const fw_link_t *l = fw_link_of(ctx);
    fw_t *fw = l->fw;
    if (l->hold != NULL) {
        return CMD_E_STATE; /* op_state_detail names why */
    }
    if (fw_state(fw) == FW_STATE_FAULT) {
        return CMD_E_FAULT;
    }
    if (fw_state(fw) != FW_STATE_READY) {
        return CMD_E_STATE;
    }
    fw_cmd_arm(fw);
    return CMD_OK;
}

static int op_disarm(void *ctx)
{
    fw_cmd_disarm(fw_link_of(ctx)->fw);
    return CMD_OK;
}

static int op_set_torque_ref(void *ctx, double nm)
{
    fw_t *fw = fw_link_of(ctx)->fw;
    const double max = ctrl_q24_to_double(fw->torque_ref_max) * fw->bases.torque_nm;
    if (!(nm >= -max && nm <= max)) {
        return CMD_E_RANGE;
    }
    fw_set_torque_ref_nm(fw, nm);
    return CMD_OK;
}

static int op_set_speed_ref(void *ctx, double rpm)
{
    fw_link_t *l = fw_link_of(ctx);
    if (!(rpm >= -l->speed_max_rpm && rpm <= l->speed_max_rpm)) {
        return CMD_E_RANGE;
    }
    fw_set_speed_ref_rpm(l->fw, rpm);
    return CMD_OK;
}

/* "in <state>" or "<request> pending (<state>)" into state_text: its length. */
static size_t fw_link_state_text(fw_link_t *l)
{
    fw_state_id_t s;
    const char *req = fw_gates_request_pending(l->fw, &s);
    const int n = req != NULL
                      ? snprintf(l->state_text, sizeof l->state_text, "%s pending (%s)", req,
                                 fw_state_name(s))
                      : snprintf(l->state_text, sizeof l->state_text, "in %s", fw_state_name(s));
    return n > 0 && (size_t)n < sizeof l->state_text ? (size_t)n : 0u;
}

static int op_param_set(void *ctx, const char *name, double value)
{
    fw_link_t *l = fw_link_of(ctx);
    const fw_link_param_t *p = fw_link_param(l, name);
    int rc;
#if PMSM_LIVE_PARAMS
    l->why_note = false;
#endif
    if (p != NULL) {
        memset(&l->why, 0, sizeof l->why); /* the application sets it (fw_link_set_why) */
        rc = p->set != NULL ? p->set(l->params_ctx, p, value) : CMD_E_READONLY;
    } else {
        rc = fw_link_cfg_err(l, fw_tunable_set(l->fw, name, value));
#if PMSM_LIVE_PARAMS
        if (rc == CMD_E_NAME && l->table_set != NULL) {
            rc = l->table_set(l, name, value);
        }
#endif
    }
#if PMSM_LIVE_PARAMS
    if (rc == CMD_E_STATE) {
        /* Why, for err 8: the state, and that the parameter changes only with
         * the gates off, or that the last live change is still on its way
         * (where some parameters are live and others not; without live
         * parameters the state alone says it). */
        const size_t n = fw_link_state_text(l);
        const bool pending =
            fw_tune_pending(l->fw, FW_REQ_SPEED_TUNE) || fw_tune_pending(l->fw, FW_REQ_CTRL_TUNE);
        (void)snprintf(l->state_text + n, sizeof l->state_text - n, ": %s%s",
                       pending ? "the last live change is not taken yet" : name,
                       pending ? "" : " changes with the gates off only");
        l->state_note = true;
    }
#endif
    return rc;
}

void fw_link_set_why(fw_link_t *l, const ctrl_diag_t *why)
{
    if (l != NULL && why != NULL) {
        l->why = *why;
    }
}

void fw_link_set_why_text(fw_link_t *l, const char *why)
{
    if (l != NULL && why != NULL) {
        (void)snprintf(l->why_text, CMD_OUT_MAX - 16u, "%s", why);
        l->why_note = true;
    }
}

/* The reason of the last refusal in one response line after "err 10 failed "
 * (CMD_OUT_MAX - 16 characters): "<quantity> = <value> <unit> outside [<min>,
 * <max>]", then the SI data it follows from when that fits. Consumed once. */
static const char *op_failed_detail(void *ctx)
{
    fw_link_t *l = fw_link_of(ctx);
    const ctrl_diag_t *d = &l->why;
#if PMSM_LIVE_PARAMS
    if (l->why_note) {
        l->why_note = false;
        return l->why_text;
    }
#endif
    if (d->code == CTRL_OK || d->quantity == NULL) {
        return NULL;
    }
    const size_t cap = CMD_OUT_MAX - 16u;
    char *t = l->why_text;
    const char *u = d->unit != NULL && d->unit[0] != '\0' ? " " : "";
    int n = snprintf(t, cap, "%s = %.4g%s%s outside [%.4g, %.4g]", d->quantity, d->value, u,
                     d->unit != NULL ? d->unit : "", d->min, d->max);
    if (d->min == 0.0 && d->max == 0.0) {
        n = snprintf(t, cap, "%s missing", d->quantity);
    }
    if (n > 0 && (size_t)n < cap && d->depends != NULL &&
        (size_t)n + strlen(d->depends) + 3u < cap) {
        (void)snprintf(t + n, cap - (size_t)n, " (%s)", d->depends);
    }
    memset(&l->why, 0, sizeof l->why);
    return t;
}

static int op_clear_fault(void *ctx)
{
    fw_t *fw = fw_link_of(ctx)->fw;
    if (fw_state(fw) == FW_STATE_FAULT) {
        /* Applied at the next period start (the ISR owns the state). */
        fw_cmd_clear(fw);
    }
    return CMD_OK;
}

static int op_telemetry_start(void *ctx, uint32_t mask, uint32_t decimation)
{
    fw_link_t *l = fw_link_of(ctx);
    if (tel_start(&l->tel, mask, decimation) != 0) {
        return CMD_E_RANGE;
    }
    fw_tm_stream(l->fw, decimation); /* drops records of an earlier stream */
    l->send_meta = 1u;
    return CMD_OK;
}

static int op_telemetry_stop(void *ctx)
{
    fw_link_t *l = fw_link_of(ctx);
    tel_stop(&l->tel);
    fw_tm_stream(l->fw, 0u);
    return CMD_OK;
}

/* ---- commissioning (cm.h) ---- */

/* The identification sequence ("ident run"). */
static const uint8_t fw_link_ident_plan[] = {CM_STEP_VBUS, CM_STEP_PROBE, CM_STEP_ENCODER,
                                             CM_STEP_RS,   CM_STEP_LDQ,   CM_STEP_FLUX};

static bool op_cm_step_at(void *ctx, size_t index, const char **name, unsigned *kind)
{
    (void)ctx;
    if (index + 1u >= (size_t)CM_STEP_COUNT) {
        return false;
    }
    const uint8_t s = (uint8_t)(index + 1u);
    *name = cm_step_name(s);
    switch (s) {
    case CM_STEP_VBUS:
    case CM_STEP_ENCODER:
        *kind = CMD_CM_IDENT | CMD_CM_BRINGUP;
        break;
    case CM_STEP_GATES:
    case CM_STEP_SENSE:
    case CM_STEP_RUN:
        *kind = CMD_CM_BRINGUP;
        break;
    default:
        *kind = CMD_CM_IDENT;
        break;
    }
    return true;
}

static void op_cm_status(void *ctx, cmd_cm_status_t *st)
{
    const fw_t *fw = fw_link_of(ctx)->fw;
    cm_outcome_t o;
    cm_outcome(&fw->cm, &fw->bases, &o);
    st->verdict = o.verdict;
    st->step = o.step;
    st->error = o.error;
    st->n = o.n;
    for (size_t k = 0; k < o.n && k < 3u; k++) {
        st->label[k] = o.label[k];
        st->value[k] = o.value[k];
        st->unit[k] = o.unit[k];
    }
}

/* The measured values, in SI, in a fixed order: the result bit that gives
 * each, its field of cm_si_t and how that is read (cm_si_has, cm_si_field). */
#define FW_R(have, key, unit, kind, f)                                                             \
    {                                                                                              \
        have, kind, (uint16_t)offsetof(cm_si_t, f), key, unit                                      \
    }
static const struct {
    uint8_t have, kind;
    uint16_t off;
    const char *key, *unit;
} fw_link_results[] = {
    FW_R(CM_HAVE_VBUS, "vbus_v", "V", CM_FIELD_SI, vbus_v),
    FW_R(CM_HAVE_LPROBE, "probe_l_mh", "mH", CM_FIELD_MILLI, l_probe_h),
    FW_R(CM_HAVE_ENC, "encoder_direction", "", CM_FIELD_INT, enc_dir),
    FW_R(CM_HAVE_ENC, "encoder_offset_deg", "deg", CM_FIELD_SI, enc_offset_deg),
    FW_R(CM_HAVE_ENC, "encoder_counts", "", CM_FIELD_U32, enc_cpr),
    FW_R(CM_HAVE_RS, "rs_ohm", "Ohm", CM_FIELD_SI, rs_ohm),
    FW_R(CM_HAVE_RS, "inverter_error_v", "V", CM_FIELD_SI, v_inv_v),
    FW_R(CM_HAVE_RS, "unbalance", "", CM_FIELD_SI, unbalance),
    FW_R(CM_HAVE_LDQ, "ld_mh", "mH", CM_FIELD_MILLI, ld_h),
    FW_R(CM_HAVE_LDQ, "lq_mh", "mH", CM_FIELD_MILLI, lq_h),
    FW_R(CM_HAVE_LDQ, "salient", "", CM_FIELD_BOOL, salient),
    FW_R(CM_HAVE_FLUX, "psi_pm_wb", "Wb", CM_FIELD_SI, psi_wb),
#if CM_MECH /* else not measured (cm.h) */
    FW_R(CM_HAVE_MECH, "inertia_kgm2", "kg*m^2", CM_FIELD_SI, inertia_kgm2),
    FW_R(CM_HAVE_MECH, "friction_nms", "N*m*s", CM_FIELD_SI, friction_nms),
    FW_R(CM_HAVE_MECH, "coulomb_nm", "N*m", CM_FIELD_SI, coulomb_nm),
#endif
};
#undef FW_R

static bool op_cm_result_at(void *ctx, size_t index, const char **key, double *value,
                            const char **unit)
{
    cm_si_t r;
    fw_commission_results(fw_link_of(ctx)->fw, &r);
    for (size_t k = 0; k < sizeof fw_link_results / sizeof fw_link_results[0]; k++) {
        if (!cm_si_has(&r, fw_link_results[k].have) || index-- != 0u) {
            continue;
        }
        *key = fw_link_results[k].key;
        *value = cm_si_field(&r, fw_link_results[k].off, (cm_field_t)fw_link_results[k].kind);
        *unit = fw_link_results[k].unit;
        return true;
    }
    return false;
}

static bool op_cm_ini_at(void *ctx, size_t index, cmd_cm_item_t *item)
{
    cm_si_t r;
    fw_commission_results(fw_link_of(ctx)->fw, &r);
    cm_item_t it;
    if (!cm_fragment_item(&r, index, &it)) {
        return false;
    }
    item->section = it.section;
    item->key = it.key;
    item->value = it.value;
    item->integer = it.integer;
    return true;
}

int fw_link_offsets_text(const fw_t *fw, char *buf, size_t cap)
{
    const int32_t *o = fw->off_q8; /* 0 <= off_q8 < 2^24: rounded without overflow */
    return snprintf(buf, cap, "current offsets %ld %ld %ld counts, expected %u +- %u",
                    (long)((o[0] + 128) >> 8), (long)((o[1] + 128) >> 8), (long)((o[2] + 128) >> 8),
                    (unsigned)fw->adc_zero, (unsigned)fw->adc_zero_tol);
}

static int op_cm_start(void *ctx, const char *what, const char **detail)
{
    fw_link_t *l = fw_link_of(ctx);
    fw_t *fw = l->fw;
    if (l->hold != NULL) {
        *detail = l->hold;
        return CMD_E_STATE;
    }
    uint8_t steps[CM_STEP_COUNT];
    uint8_t n = 0;
    const bool run = strcmp(what, "run") == 0;
    if (run || strcmp(what, "resume") == 0) {
        for (size_t i = 0; i < sizeof fw_link_ident_plan; i++) {
            const uint8_t s = fw_link_ident_plan[i];
            /* resume: from the first step whose results are not all there */
            if (!run && n == 0u && (cm_step_gives(s) & ~fw->cm.res.have) == 0u) {
                continue;
            }
            steps[n++] = s;
        }
        if (n == 0u) {
            *detail = "nothing to resume";
            return CMD_E_STATE;
        }
    } else {
        const uint8_t s = cm_step_find(what);
        if (s == CM_STEP_NONE) {
            return CMD_E_NAME;
        }
        steps[n++] = s;
    }
    uint8_t missing = CM_STEP_NONE;
    switch (fw_commission_start(fw, steps, n, &missing)) {
    case FW_OK:
        if (steps[0] == CM_STEP_SENSE) {
            /* the offsets the step's currents are measured from, said
             * before the step judges what it measures */
            (void)fw_link_offsets_text(fw, l->cm_note, sizeof l->cm_note);
            *detail = l->cm_note;
        }
        return CMD_OK;
    case FW_ENOENT:
        (void)snprintf(l->cm_detail, sizeof l->cm_detail, "needs %s", cm_step_name(missing));
        *detail = l->cm_detail;
        return CMD_E_STATE;
    case FW_ERANGE:
        (void)snprintf(l->cm_detail, sizeof l->cm_detail, "limit %s",
                       fw->cm_what != NULL ? fw->cm_what : "?");
        *detail = l->cm_detail;
        return CMD_E_RANGE;
    case FW_EBUSY:
        *detail = "not ready";
        return CMD_E_STATE;
    default:
        return CMD_E_FAILED;
    }
}

static int op_cm_apply(void *ctx)
{
    fw_t *fw = fw_link_of(ctx)->fw;
    if ((fw->cm.res.have & (CM_HAVE_RS | CM_HAVE_LDQ | CM_HAVE_FLUX | CM_HAVE_ENC)) == 0u) {
        return CMD_E_STATE;
    }
    return fw_link_err(fw_commission_apply(fw));
}

static int op_stop(void *ctx)
{
    fw_cmd_disarm(fw_link_of(ctx)->fw);
    return CMD_OK;
}

/* "config ..." (cmd.h): fw_settings.c's, when the application attached a
 * store (fw_link_set_settings); the settings code is not linked otherwise. */
static int op_config(void *ctx, const char *what, const char **detail)
{
    fw_link_t *l = fw_link_of(ctx);
    if (l->settings == NULL || l->settings_cmd == NULL) {
        return CMD_E_UNSUPPORTED;
    }
    return l->settings_cmd(l->settings, l->fw, what, detail);
}

static bool op_config_item_at(void *ctx, size_t index, cmd_config_item_t *it)
{
    const fw_link_t *l = fw_link_of(ctx);
    return l->settings != NULL && l->settings_item != NULL &&
           l->settings_item(l->settings, index, it);
}

/* The state an op was refused in: "in <state>", or the request pending that
 * turns the gates on at the next period: "arm pending (ready)". */
static const char *op_state_detail(void *ctx)
{
    fw_link_t *l = fw_link_of(ctx);
    if (l->state_note) {
        l->state_note = false; /* op_param_set's: the state and why */
        return l->state_text;
    }
    if (l->hold != NULL) {
        return l->hold; /* held off for good: that is the state */
    }
    (void)fw_link_state_text(l);
    return l->state_text;
}

#if CTRL_COGGING
/* "cogging on | off | status" (cmd.h): the feed-forward (pipeline.h). */
static int op_cogging(void *ctx, const char *what, const char **detail)
{
    fw_t *fw = fw_link_of(ctx)->fw;
    const bool have = fw_cogging_table(fw, NULL) != NULL;
    if (strcmp(what, "status") == 0) {
        *detail = fw->cog_on != 0u ? "on" : (have ? "off" : "none");
        return CMD_OK;
    }
    const int rc = fw_cogging_enable(fw, strcmp(what, "on") == 0);
    if (rc == FW_ENOENT) {
        *detail = "no table for this encoder: ident cogging";
        return CMD_E_STATE;
    }
    if (rc == FW_EINVAL) {
        *detail = "sensorless: no mechanical angle";
        return CMD_E_STATE;
    }
    if (rc == FW_ERANGE) {
        /* the look-ahead tau w_rated / (2 pi p) in [0, 1/2) turn (cogging_ff.h) */
        *detail = "look-ahead beyond half a turn at the rated speed: rated speed or current loop";
        return CMD_E_RANGE;
    }
    return fw_link_err(rc);
}
#endif

static const cmd_ops_t fw_link_ops = {
    op_write,
    op_get_status,
    op_ctrl_at,
    op_param_at,
    op_param_get,
    op_select_controller,
    op_arm,
    op_disarm,
    op_set_torque_ref,
    op_set_speed_ref,
    op_param_set,
    op_clear_fault,
    op_telemetry_start,
    op_telemetry_stop,
    op_cm_step_at,
    op_cm_status,
    op_cm_result_at,
    op_cm_ini_at,
    op_cm_start,
    op_cm_apply,
    op_stop,
    op_failed_detail,
    op_config,
    op_config_item_at,
    op_state_detail,
#if CTRL_COGGING
    op_cogging,
#else
    NULL, /* no anti-cogging in this image: "err 12 unsupported" */
#endif
};

void fw_link_init(fw_link_t *l, fw_t *fw, fw_link_write_fn write, void *write_ctx)
{
    if (l == NULL || fw == NULL) {
        return;
    }
    memset(l, 0, sizeof *l);
    l->fw = fw;
    l->write = write;
    l->write_ctx = write_ctx;
    l->speed_max_rpm = fw->speed_info.speed_ref_max_rpm;
    tel_init(&l->tel);
    cmd_init(&l->cmd, &fw_link_ops, l);
}

void fw_link_set_params(fw_link_t *l, const fw_link_param_t *params, size_t n, void *ctx)
{
    if (l != NULL) {
        l->params = params;
        l->n_params = params != NULL ? n : 0u;
        l->params_ctx = ctx;
    }
}

void fw_link_set_stack(fw_link_t *l, const uint32_t *lo, const uint32_t *hi)
{
    if (l != NULL && lo != NULL && hi > lo) {
        l->stack_lo = lo;
        l->stack_hi = hi;
    }
}

bool fw_link_rx(fw_link_t *l, uint8_t byte)
{
    return l != NULL && cmd_feed_byte(&l->cmd, byte);
}

/* A telemetry sample from an interrupt record (main loop): |psi_s| (4.3)
 * and the sector (4.5) from the rotor-frame flux and the angle, the
 * references from the main loop's own values. */
static void fw_link_sample(const fw_t *fw, const fw_telemetry_t *r, tel_sample_t *s)
{
    s->tick = r->period;
    s->i_a = r->i_a;
    s->i_b = r->i_b;
    s->i_d = r->i_d;
    s->i_q = r->i_q;
    s->psi = fx_mag(r->psi_d, r->psi_q);
    s->psi_ref = fw->refs.psi;
    s->torque = r->torque;
    s->torque_ref = r->torque_ref;
    s->speed = r->omega_e;
    s->speed_ref = fw_speed_ref(fw);
    s->vector = (int32_t)r->vec;
    s->duty = r->duty;
    s->vdc = r->vdc;
    s->theta = (int32_t)(r->theta_e >> 8);
    q24_t sn;
    q24_t cs;
    fx_sincos(r->theta_e, &sn, &cs);
    q24_t pa;
    q24_t pb;
    ctrl_inv_park(r->psi_d, r->psi_q, sn, cs, &pa, &pb);
    /* no estimate in the record (not running): no sector */
    s->sector = (r->psi_d | r->psi_q) != 0 ? (int32_t)ctrl_sector(pa, pb) : 0;
    s->state = (int32_t)r->state;
    s->fault = (int32_t)r->fault;
    s->cycles = (int32_t)(r->cycles > (uint32_t)INT32_MAX ? (uint32_t)INT32_MAX : r->cycles);
    s->cm_step = (int32_t)r->cm_step;
    s->cm_progress = (int32_t)r->cm_progress;
    s->torque_max = r->torque_max;
    s->fieldweak_limit = (int32_t)r->fieldweak_limit;
#if CTRL_SL_HFI
    s->sl_state = (int32_t)r->sl_state;
    s->angle_err = fx_rshift32_round(r->hfi_err, 8u);
#endif
}

void fw_link_poll(fw_link_t *l)
{
    if (l == NULL) {
        return;
    }
    /* A completed identification is adopted here, in the main loop. */
    (void)fw_commission_poll(l->fw);
    if (l->write == NULL) {
        return;
    }
    uint8_t wire[TEL_WIRE_MAX];
    if (l->send_meta != 0u) {
        l->send_meta = 0u;
        const size_t n = tel_encode_meta(&l->tel, l->fw->info.pwm_freq_hz, &l->fw->bases,
                                         l->fw->params.pole_pairs, wire, sizeof wire);
        if (n > 0u) {
            l->write(l->write_ctx, wire, n);
        }
    }
    const fw_telemetry_t *r;
    while ((r = fw_tm_peek(l->fw)) != NULL) {
        tel_sample_t s;
        fw_link_sample(l->fw, r, &s);
        fw_tm_release(l->fw);
        const size_t n = tel_encode_sample(&l->tel, &s, wire, sizeof wire);
        if (n > 0u) {
            l->write(l->write_ctx, wire, n);
        }
    }
}
