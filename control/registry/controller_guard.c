/* The guarded calls of controller.h: every pointer is checked here, once, so
 * that the descriptors' own init, reset and step assume valid arguments. */
#include <stddef.h>

#include "controller.h"
#include "plan.h"

int ctrl_cfg_default(const ctrl_desc_t *d, void *cfg, const ctrl_machine_t *machine)
{
    if (d == NULL || d->cfg_default == NULL || cfg == NULL || machine == NULL) {
        return CTRL_EINVAL;
    }
    d->cfg_default(cfg, machine);
    return CTRL_OK;
}

int ctrl_init(const ctrl_desc_t *d, void *state, const void *cfg, const ctrl_setup_t *setup)
{
    if (d == NULL || d->init == NULL || state == NULL || cfg == NULL || setup == NULL ||
        setup->machine == NULL || setup->bases == NULL || setup->params == NULL ||
        setup->params->fs_hz == 0u) {
        return CTRL_EINVAL;
    }
    return d->init(state, cfg, setup);
}

void ctrl_reset(const ctrl_desc_t *d, void *state)
{
    if (d != NULL && d->reset != NULL && state != NULL) {
        d->reset(state);
    }
}

void ctrl_step(const ctrl_desc_t *d, void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out)
{
    if (out == NULL) {
        return;
    }
    if (d == NULL || d->step == NULL || state == NULL || ctx == NULL || ctx->params == NULL ||
        ctx->est == NULL || ctx->ref == NULL) {
        ctrl_out_single(out, 0u); /* no voltage */
        return;
    }
    d->step(state, ctx, out);
}
