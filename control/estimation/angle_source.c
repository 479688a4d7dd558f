/* Built-in angle sources (angle_source.h): encoder and forced angle. */
#include "angle_source.h"

/* ---- encoder: the sensor's angle, speed from its differences ---- */

static void angle_encoder_reset(void *state, const ctrl_params_t *p)
{
    (void)p;
    ctrl_angle_encoder_t *s = state;
    s->omega_acc = 0;
    s->omega = 0;
    s->theta_prev = 0u;
    s->primed = 0u;
}

static void angle_encoder_update(void *state, const ctrl_params_t *p, const ctrl_angle_in_t *in,
                                 ctrl_angle_out_t *out)
{
    ctrl_angle_encoder_step(state, p, in->theta_meas, out);
}

const ctrl_angle_src_t ctrl_angle_encoder = {
    .name = "encoder",
    .state_size = sizeof(ctrl_angle_encoder_t) +
                  0 * sizeof(struct {
                      _Static_assert(sizeof(ctrl_angle_encoder_t) <= CTRL_ANGLE_STATE_MAX, "state");
                      int ok;
                  }),
    .uses_voltage = 0u,
    .reset = angle_encoder_reset,
    .update = angle_encoder_update,
};

/* ---- forced: theta advances by the commanded speed ---- */

typedef struct {
    fx_angle_t theta; /* angle reported at the next update */
    fx_angle_t step;  /* omega Ts, angle units per period */
    q24_t omega;      /* commanded speed, Q24 pu */
} angle_forced_t;

static void angle_forced_reset(void *state, const ctrl_params_t *p)
{
    /* The command is a setting, not history: kept (ctrl_angle_forced_set). */
    (void)state;
    (void)p;
}

static void angle_forced_update(void *state, const ctrl_params_t *p, const ctrl_angle_in_t *in,
                                ctrl_angle_out_t *out)
{
    (void)p;
    (void)in;
    angle_forced_t *s = state;
    out->theta = s->theta;
    out->omega = s->omega;
    s->theta += s->step; /* modulo one turn */
}

const ctrl_angle_src_t ctrl_angle_forced = {
    .name = "forced",
    .state_size = sizeof(angle_forced_t) +
                  0 * sizeof(struct {
                      _Static_assert(sizeof(angle_forced_t) <= CTRL_ANGLE_STATE_MAX, "state");
                      int ok;
                  }),
    .uses_voltage = 0u,
    .reset = angle_forced_reset,
    .update = angle_forced_update,
};

void ctrl_angle_forced_set(void *state, const ctrl_params_t *p, fx_angle_t theta, q24_t omega)
{
    if (state == NULL || p == NULL) {
        return;
    }
    angle_forced_t *s = state;
    s->theta = theta;
    s->omega = omega;
    s->step = ctrl_angle_step(p, omega);
}
