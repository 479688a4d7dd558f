/*
 * One interface for every controller (switching tables, DRR-DTC, M2PTFC, FOC,
 * ...). A controller is a read-only descriptor; its state is an opaque block of
 * desc->state_size bytes owned by the caller (no heap, no globals).
 *
 * Life cycle:
 *   desc->cfg_default(cfg, machine)         SI tunables with the seed's defaults
 *   ctrl_tunable_set(desc, cfg, "A", 1.3)   optional overrides by name (checked)
 *   desc->init(state, cfg, params)          SI -> fixed point, once (*_config.c)
 *   desc->reset(state)                      clear dynamic state, keep config
 *   desc->step(state, &ctx, &plan)          every PWM period, integer-only
 */
#ifndef CONTROL_CONTROLLER_H
#define CONTROL_CONTROLLER_H

#include <stddef.h>
#include <stdint.h>

#include "ctrl_params.h"
#include "ctrl_types.h"

/* Everything a controller sees at sample k. */
typedef struct {
    const ctrl_params_t *params; /* machine parameters for this fs */
    const ctrl_estimate_t *est;  /* estimates at k and predictions for k+1 */
    const ctrl_refs_t *ref;      /* references */
    const ctrl_plan_t *applied;  /* plan acting during [k, k+1) (chosen at k-1) */
} ctrl_ctx_t;

/*
 * A tunable: a double field of the controller's SI configuration struct, set
 * and read by name. Computed parameters (A, B, C, ...) default to 0 meaning
 * "compute from the machine at init"; a non-zero value overrides.
 */
typedef struct {
    const char *name; /* e.g. "h_T" */
    const char *unit; /* e.g. "N*m"; "0/1" marks a switch (only 0 and 1 accepted) */
    const char *help; /* one line, cites the seed */
    size_t offset;    /* offsetof(cfg struct, field), field is a double */
    double min, max;  /* accepted range (inclusive) */
} ctrl_tunable_t;

typedef struct ctrl_desc {
    const char *name;       /* run-time selector: "bst", "fst", "drr", "m2ptfc", ... */
    const char *title;      /* one line with the seed reference */
    uint32_t fs_default_hz; /* the sampling frequency the seed uses */
    size_t state_size;      /* bytes of runtime state */
    size_t cfg_size;        /* bytes of the SI configuration struct */
    const ctrl_tunable_t *tunables;
    size_t n_tunables;
    /* Fill cfg with the seed's default parameters for this machine. */
    void (*cfg_default)(void *cfg, const ctrl_machine_t *machine);
    /* Convert cfg to fixed point into state; returns CTRL_OK or a CTRL_E* code. */
    int (*init)(void *state, const void *cfg, const ctrl_params_t *params);
    /* Clear the dynamic state (integrators, flags, filters), keep the config. */
    void (*reset)(void *state);
    /* One control period: choose the plan for [k+1, k+2). Integer-only. */
    void (*step)(void *state, const ctrl_ctx_t *ctx, ctrl_plan_t *out);
    /* Optional estimator outputs (CTRL_EST_* of estimator.h) this controller never
     * reads, so the pipeline can skip computing them; 0 = it may read all. */
    uint8_t est_unused;
} ctrl_desc_t;

/* Largest state_size / cfg_size of any registered controller, for static buffers. */
#define CTRL_STATE_MAX 1024
#define CTRL_CFG_MAX 512

/* Registry (controller_registry.c). */
size_t ctrl_count(void);
const ctrl_desc_t *ctrl_at(size_t index);
const ctrl_desc_t *ctrl_find(const char *name); /* NULL if unknown */

/* Tunables by name (controller_config.c, may use double). Return CTRL_OK,
 * CTRL_ENOENT for an unknown name, CTRL_EINVAL for a value out of range or not finite. */
int ctrl_tunable_set(const ctrl_desc_t *d, void *cfg, const char *name, double value);
int ctrl_tunable_get(const ctrl_desc_t *d, const void *cfg, const char *name, double *value);

/* (appended by review) Every field listed in t[0..n) of cfg is finite and inside
 * [min, max]: CTRL_OK, else CTRL_EINVAL (also for NULL t or cfg with n > 0).
 * For init functions that validate a whole SI configuration struct. */
int ctrl_tunables_check(const ctrl_tunable_t *t, size_t n, const void *cfg);

/* (appended by review) 1 when ctx and every pointer a step needs (params,
 * est, ref) are non-NULL; ctx->applied may be NULL. Steps answer an invalid
 * context with the zero vector. */
static inline int ctrl_ctx_ok(const ctrl_ctx_t *ctx)
{
    return ctx != NULL && ctx->params != NULL && ctx->est != NULL && ctx->ref != NULL;
}

#endif /* CONTROL_CONTROLLER_H */
