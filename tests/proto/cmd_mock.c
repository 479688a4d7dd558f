#include "cmd_mock.h"

#include <string.h>

static const char *const mock_ctrl_names[] = {"bst", "fst", "drr"};
#define MOCK_NCTRL 3

static const cmd_param_info_t mock_params[MOCK_NPARAM] = {
    {"h_T", "N*m", "torque hysteresis band (Table 4.7)", false, 0.0, 1.0},
    {"lambda", "", "EMA factor (5.3)", false, 0.001, 1.0},
    {"kp", "N*m*s/rad", "speed PI gain", false, -5.0, 5.0},
    {"fs", "Hz", "control frequency", true, 1000.0, 40000.0},
};

static void mock_write(void *ctx, const char *s, size_t n)
{
    mock_t *m = ctx;
    m->writes++;
    for (size_t i = 0; i < n && m->out_len + 1u < MOCK_OUT_MAX; i++) {
        m->out[m->out_len++] = s[i];
    }
    m->out[m->out_len] = '\0';
}

static void mock_get_status(void *ctx, cmd_status_t *st)
{
    mock_t *m = ctx;
    m->ro_calls++;
    st->state = m->st.fault ? "fault" : (m->st.armed ? "running" : "ready");
    st->armed = m->st.armed;
    st->ctrl = mock_ctrl_names[m->st.ctrl];
    st->fault = m->st.fault;
    st->fault_name = m->st.fault ? "overcurrent" : "none";
    st->mode = m->st.mode;
    st->speed_rpm = 1500.0;
    st->torque_nm = 1.8;
    st->torque_ref_nm = m->st.torque_ref;
    st->speed_ref_rpm = m->st.speed_ref;
    st->torque_max_nm = 2.4;
    st->speed_max_rpm = 3000.0;
    st->tel_mask = m->st.tel_mask;
    st->tel_every = m->st.tel_every;
}

static bool mock_ctrl_at(void *ctx, size_t i, const char **name, const char **title)
{
    mock_t *m = ctx;
    m->ro_calls++;
    if (i >= MOCK_NCTRL) {
        return false;
    }
    *name = mock_ctrl_names[i];
    *title = "mock controller";
    return true;
}

static bool mock_param_at(void *ctx, size_t i, cmd_param_info_t *info)
{
    mock_t *m = ctx;
    m->ro_calls++;
    if (i >= MOCK_NPARAM) {
        return false;
    }
    *info = mock_params[i];
    return true;
}

static int mock_param_index(const char *name)
{
    for (int i = 0; i < MOCK_NPARAM; i++) {
        if (strcmp(name, mock_params[i].name) == 0) {
            return i;
        }
    }
    return -1;
}

static int mock_param_get(void *ctx, const char *name, double *v)
{
    mock_t *m = ctx;
    m->ro_calls++;
    const int i = mock_param_index(name);
    if (i < 0) {
        return CMD_E_NAME;
    }
    *v = m->st.param[i];
    return CMD_OK;
}

/* Common entry of every state-changing op: count, and fail on request. */
static int mock_mut(mock_t *m)
{
    m->mut_calls++;
    const int f = m->fail_next;
    m->fail_next = 0;
    return f;
}

static void mock_name(mock_t *m, const char *name)
{
    strncpy(m->last_name, name, sizeof m->last_name - 1u);
    m->last_name[sizeof m->last_name - 1u] = '\0';
}

static int mock_select(void *ctx, const char *name)
{
    mock_t *m = ctx;
    const int f = mock_mut(m);
    mock_name(m, name);
    if (f != 0) {
        return f;
    }
    for (int i = 0; i < MOCK_NCTRL; i++) {
        if (strcmp(name, mock_ctrl_names[i]) == 0) {
            m->st.ctrl = i;
            return CMD_OK;
        }
    }
    return CMD_E_NAME;
}

static int mock_arm(void *ctx)
{
    mock_t *m = ctx;
    const int f = mock_mut(m);
    if (f != 0) {
        return f;
    }
    m->st.armed = true;
    return CMD_OK;
}

static int mock_disarm(void *ctx)
{
    mock_t *m = ctx;
    const int f = mock_mut(m);
    if (f != 0) {
        return f;
    }
    m->st.armed = false;
    return CMD_OK;
}

static int mock_torque(void *ctx, double v)
{
    mock_t *m = ctx;
    const int f = mock_mut(m);
    m->last_value = v;
    if (f != 0) {
        return f;
    }
    m->st.torque_ref = v;
    m->st.mode = CMD_MODE_TORQUE;
    return CMD_OK;
}

static int mock_speed(void *ctx, double v)
{
    mock_t *m = ctx;
    const int f = mock_mut(m);
    m->last_value = v;
    if (f != 0) {
        return f;
    }
    m->st.speed_ref = v;
    m->st.mode = CMD_MODE_SPEED;
    return CMD_OK;
}

static int mock_param_set(void *ctx, const char *name, double v)
{
    mock_t *m = ctx;
    const int f = mock_mut(m);
    mock_name(m, name);
    m->last_value = v;
    if (f != 0) {
        return f;
    }
    const int i = mock_param_index(name);
    if (i < 0) {
        return CMD_E_NAME;
    }
    m->st.param[i] = v;
    return CMD_OK;
}

static int mock_clear_fault(void *ctx)
{
    mock_t *m = ctx;
    const int f = mock_mut(m);
    if (f != 0) {
        return f;
    }
    m->st.fault = 0;
    return CMD_OK;
}

static int mock_tel_start(void *ctx, uint32_t mask, uint32_t every)
{
    mock_t *m = ctx;
    const int f = mock_mut(m);
    if (f != 0) {
        return f;
    }
    m->st.tel_mask = mask;
    m->st.tel_every = every;
    return CMD_OK;
}

static int mock_tel_stop(void *ctx)
{
    mock_t *m = ctx;
    const int f = mock_mut(m);
    if (f != 0) {
        return f;
    }
    m->st.tel_mask = 0;
    return CMD_OK;
}

static const cmd_ops_t mock_ops_table = {
    .write = mock_write,
    .get_status = mock_get_status,
    .ctrl_at = mock_ctrl_at,
    .param_at = mock_param_at,
    .param_get = mock_param_get,
    .select_controller = mock_select,
    .arm = mock_arm,
    .disarm = mock_disarm,
    .set_torque_ref = mock_torque,
    .set_speed_ref = mock_speed,
    .param_set = mock_param_set,
    .clear_fault = mock_clear_fault,
    .telemetry_start = mock_tel_start,
    .telemetry_stop = mock_tel_stop,
};

void mock_init(mock_t *m)
{
    memset(m, 0, sizeof *m);
    m->st.param[0] = 0.048;
    m->st.param[1] = 0.03;
    m->st.param[2] = 0.006843;
    m->st.param[3] = 10000.0;
}

const cmd_ops_t *mock_ops(void)
{
    return &mock_ops_table;
}

void mock_clear_out(mock_t *m)
{
    m->out_len = 0;
    m->out[0] = '\0';
    m->writes = 0;
}

void mock_feed(cmd_t *c, const char *s)
{
    for (; *s != '\0'; s++) {
        cmd_feed_byte(c, (uint8_t)*s);
    }
}

bool mock_state_equal(const mock_state_t *a, const mock_state_t *b)
{
    for (int i = 0; i < MOCK_NPARAM; i++) {
        if (a->param[i] != b->param[i]) {
            return false;
        }
    }
    return a->armed == b->armed && a->ctrl == b->ctrl && a->fault == b->fault &&
           a->mode == b->mode && a->torque_ref == b->torque_ref && a->speed_ref == b->speed_ref &&
           a->tel_mask == b->tel_mask && a->tel_every == b->tel_every;
}
