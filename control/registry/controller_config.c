/*
 * Tunables by name over a controller's SI configuration struct (controller.h).
 * Configuration only: floating point allowed.
 */
#include <math.h>
#include <string.h>

#include "controller.h"

static const ctrl_tunable_t *tunable_find(const ctrl_desc_t *d, const char *name)
{
    if (d->tunables == NULL) {
        return NULL;
    }
    for (size_t i = 0; i < d->n_tunables; i++) {
        if (d->tunables[i].name != NULL && strcmp(d->tunables[i].name, name) == 0) {
            return &d->tunables[i];
        }
    }
    return NULL;
}

/* The field must lie inside the configuration struct. */
static int tunable_in_cfg(const ctrl_desc_t *d, const ctrl_tunable_t *t)
{
    return d->cfg_size >= sizeof(double) && t->offset <= d->cfg_size - sizeof(double);
}

int ctrl_tunable_set(const ctrl_desc_t *d, void *cfg, const char *name, double value)
{
    if (d == NULL || cfg == NULL || name == NULL) {
        return CTRL_EINVAL;
    }
    const ctrl_tunable_t *t = tunable_find(d, name);
    if (t == NULL) {
        return CTRL_ENOENT;
    }
    if (!tunable_in_cfg(d, t) || !isfinite(value) || value < t->min || value > t->max) {
        return CTRL_EINVAL;
    }
    if (strcmp(t->unit, "0/1") == 0 && value != 0.0 && value != 1.0) {
        return CTRL_EINVAL; /* a switch: 0 or 1 only (controller.h) */
    }
    memcpy((char *)cfg + t->offset, &value, sizeof value);
    return CTRL_OK;
}

int ctrl_tunable_get(const ctrl_desc_t *d, const void *cfg, const char *name, double *value)
{
    if (d == NULL || cfg == NULL || name == NULL || value == NULL) {
        return CTRL_EINVAL;
    }
    const ctrl_tunable_t *t = tunable_find(d, name);
    if (t == NULL) {
        return CTRL_ENOENT;
    }
    if (!tunable_in_cfg(d, t)) {
        return CTRL_EINVAL;
    }
    memcpy(value, (const char *)cfg + t->offset, sizeof *value);
    return CTRL_OK;
}

int ctrl_tunables_check(const ctrl_tunable_t *t, size_t n, const void *cfg)
{
    if (n > 0u && (t == NULL || cfg == NULL)) {
        return CTRL_EINVAL;
    }
    for (size_t i = 0; i < n; i++) {
        double v;
        memcpy(&v, (const char *)cfg + t[i].offset, sizeof v);
        if (!isfinite(v) || v < t[i].min || v > t[i].max) {
            return CTRL_EINVAL;
        }
    }
    return CTRL_OK;
}

int ctrl_setup_refuse(const ctrl_setup_t *setup, int code, const char *quantity, const char *unit,
                      double value, double lo, double hi)
{
    return ctrl_diag_refuse(setup != NULL ? setup->diag : NULL, code, quantity, unit, value, lo, hi,
                            NULL);
}

int ctrl_setup_q24(const ctrl_setup_t *setup, const char *quantity, double si, double base,
                   double lo_pu, double hi_pu, q24_t *out)
{
    if (ctrl_q24_from_si(si, base, lo_pu, hi_pu, out) != CTRL_OK) {
        return ctrl_setup_refuse(setup, CTRL_ERANGE, quantity, "pu", si / base, lo_pu, hi_pu);
    }
    return CTRL_OK;
}
