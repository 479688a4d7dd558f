/* Serial link: cmd_ops_t on the pipeline, telemetry samples (see fw_link.h). */
#include "fw_link.h"

#include <string.h>

#include "controller.h"
#include "ctrl_units.h"
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
    st->mode = fw->ref_mode == FW_REF_SPEED ? CMD_MODE_SPEED : CMD_MODE_TORQUE;
    st->speed_rpm = fw_link_rpm(fw, fw->estimate.omega_e);
    st->torque_nm = ctrl_q24_to_double(fw->estimate.now.torque) * fw->bases.torque_nm;
    st->torque_ref_nm = ctrl_q24_to_double(fw->refs.torque) * fw->bases.torque_nm;
    st->speed_ref_rpm = fw_link_rpm(fw, fw->speed_ref);
    st->torque_max_nm = ctrl_q24_to_double(fw->torque_ref_max) * fw->bases.torque_nm;
    st->speed_max_rpm = l->speed_max_rpm;
    st->tel_mask = l->tel.mask;
    st->tel_every = l->tel.every;
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
    const size_t n_tun = fw->ctrl != NULL ? fw->ctrl->n_tunables : 0u;
    if (index >= n_tun) {
        if (index - n_tun >= l->n_params) {
            return false;
        }
        *info = l->params[index - n_tun].info;
        return true;
    }
    const ctrl_tunable_t *t = &fw->ctrl->tunables[index];
    info->name = t->name;
    info->unit = t->unit;
    info->help = t->help;
    info->min = t->min;
    info->max = t->max;
    info->read_only = false;
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
        return p->get(l->params_ctx, value);
    }
    return fw_link_err(fw_tunable_get(l->fw, name, value));
}

static int op_select_controller(void *ctx, const char *name)
{
    const ctrl_desc_t *d = ctrl_find(name);
    if (d == NULL) {
        return CMD_E_NAME;
    }
    return fw_link_err(fw_select_controller(fw_link_of(ctx)->fw, d, NULL));
}

static int op_arm(void *ctx)
{
    fw_t *fw = fw_link_of(ctx)->fw;
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

static int op_param_set(void *ctx, const char *name, double value)
{
    fw_link_t *l = fw_link_of(ctx);
    const fw_link_param_t *p = fw_link_param(l, name);
    if (p != NULL) {
        return p->set != NULL ? p->set(l->params_ctx, value) : CMD_E_READONLY;
    }
    return fw_link_err(fw_tunable_set(l->fw, name, value));
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
    l->q_tail = l->q_head; /* drop samples of an earlier mask */
    l->send_meta = 1u;
    return CMD_OK;
}

static int op_telemetry_stop(void *ctx)
{
    tel_stop(&fw_link_of(ctx)->tel);
    return CMD_OK;
}

static const cmd_ops_t fw_link_ops = {
    op_write,           op_get_status,        op_ctrl_at,   op_param_at,
    op_param_get,       op_select_controller, op_arm,       op_disarm,
    op_set_torque_ref,  op_set_speed_ref,     op_param_set, op_clear_fault,
    op_telemetry_start, op_telemetry_stop,
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

void fw_link_rx(fw_link_t *l, uint8_t byte)
{
    if (l != NULL) {
        cmd_feed_byte(&l->cmd, byte);
    }
}

void fw_link_isr(fw_link_t *l)
{
    if (l == NULL || !tel_due(&l->tel)) {
        return;
    }
    if (l->q_head - l->q_tail >= FW_LINK_QLEN) {
        l->dropped++;
        return;
    }
    const fw_t *fw = l->fw;
    const fw_telemetry_t *tm = &fw->tm;
    tel_sample_t *s = &l->q[l->q_head & (FW_LINK_QLEN - 1u)];
    s->tick = tm->period;
    s->i_a = tm->i_a;
    s->i_b = tm->i_b;
    s->i_d = fw->estimate.now.i_d;
    s->i_q = fw->estimate.now.i_q;
    s->psi = tm->psi_amp;
    s->psi_ref = fw->refs.psi;
    s->torque = tm->torque;
    s->torque_ref = tm->torque_ref;
    s->speed = tm->omega_e;
    s->speed_ref = fw->speed_ref;
    s->vector = (int32_t)tm->vec;
    s->duty = tm->duty;
    s->vdc = tm->vdc;
    s->theta = (int32_t)(tm->theta_e >> 8);
    /* now.sector may be switched off in the estimator (controller.h est_unused). */
    s->sector = (int32_t)ctrl_sector(fw->estimate.now.psi_alpha, fw->estimate.now.psi_beta);
    s->state = (int32_t)tm->state;
    s->fault = (int32_t)tm->fault;
    s->cycles = (int32_t)(tm->cycles > (uint32_t)INT32_MAX ? (uint32_t)INT32_MAX : tm->cycles);
    l->q_head++;
}

void fw_link_poll(fw_link_t *l)
{
    if (l == NULL || l->write == NULL) {
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
    while (l->q_tail != l->q_head) {
        const tel_sample_t *s = &l->q[l->q_tail & (FW_LINK_QLEN - 1u)];
        const size_t n = tel_encode_sample(&l->tel, s, wire, sizeof wire);
        l->q_tail++;
        if (n > 0u) {
            l->write(l->write_ctx, wire, n);
        }
    }
}
