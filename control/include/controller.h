/*
 * One interface for every controller (switching tables, DRR-DTC, M2PTFC, FOC,
 * ...). A controller is a read-only descriptor; its state is an opaque block of
 * desc->state_size bytes owned by the caller (no heap, no globals).
 *
 * Life cycle:
 *   desc->cfg_default(cfg, machine)         SI tunables with the source's defaults
 *   ctrl_tunable_set(desc, cfg, "A", 1.3)   optional overrides by name (checked)
 *   ctrl_init(desc, state, cfg, &setup)     SI -> fixed point, once (*_config.c)
 *   desc->reset(state)                      clear dynamic state, keep config
 *   desc->step(state, &ctx, &out)           every PWM period, integer-only
 * ctrl_init, ctrl_reset and ctrl_step (controller_registry.c) check the
 * pointers once; the descriptor's own functions assume valid arguments.
 */
#ifndef CONTROL_CONTROLLER_H
#define CONTROL_CONTROLLER_H

#include <stddef.h>
#include <stdint.h>

#include "ctrl_params.h"
#include "ctrl_types.h"
#include "help_text.h"

/* Everything a controller sees at sample k. */
typedef struct {
    const ctrl_params_t *params; /* machine parameters for this fs */
    const ctrl_estimate_t *est;  /* estimates at k and predictions for k+1 */
    const ctrl_refs_t *ref;      /* references */
} ctrl_ctx_t;

/* Everything a controller's init reads (configuration time): the SI machine,
 * the SI value of 1 pu of each quantity and the fixed-point parameters, all
 * from one ctrl_params_init(params, bases, machine, fs). */
typedef struct {
    const ctrl_machine_t *machine;
    const ctrl_bases_t *bases;
    const ctrl_params_t *params;
    ctrl_diag_t *diag; /* optional (NULL): why init refused, see ctrl_setup_refuse */
} ctrl_setup_t;

/*
 * A tunable: a double field of the controller's SI configuration struct, set
 * and read by name. Computed parameters (A, B, C, ...) default to 0 meaning
 * "compute from the machine at init"; a non-zero value overrides.
 */
typedef struct {
    const char *name; /* e.g. "h_T" */
    const char *unit; /* e.g. "N*m"; "0/1" marks a switch (only 0 and 1 accepted) */
    const char *help; /* one line, cites the source; NULL without PMSM_HELP_TEXT */
    size_t offset;    /* offsetof(cfg struct, field), field is a double */
    double min, max;  /* accepted range (inclusive) */
} ctrl_tunable_t;

typedef struct ctrl_desc {
    const char *name;       /* run-time selector: "bst", "fst", "drr", "m2ptfc", ... */
    const char *title;      /* one line with the source reference */
    uint32_t fs_default_hz; /* the sampling frequency the source uses */
    size_t state_size;      /* bytes of runtime state */
    size_t cfg_size;        /* bytes of the SI configuration struct */
    const ctrl_tunable_t *tunables;
    size_t n_tunables;
    /* Fill cfg with the source's default parameters for this machine (SI). */
    void (*cfg_default)(void *cfg, const ctrl_machine_t *machine);
    /* Convert cfg to fixed point into state; returns CTRL_OK or a CTRL_E* code. */
    int (*init)(void *state, const void *cfg, const ctrl_setup_t *setup);
    /* Clear the dynamic state (integrators, flags, filters), keep the config. */
    void (*reset)(void *state);
    /* One control period: the output for [k+1, k+2), a plan or leg duties
     * (ctrl_out_t). Integer-only. */
    void (*step)(void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out);
    /* Optional estimator outputs (CTRL_EST_* of estimator.h) this controller never
     * reads, so the pipeline can skip computing them; 0 = it may read all. */
    uint16_t est_unused;
    /* 1: the controller forms its currents from the torque alone (MTPA, or
     * the flux circle of field weakening) and holds no fixed flux reference
     * (ctrl_params_t.psi_ref): the drive's limits then use MTPA for it. */
    uint8_t flux_free;
    /* Optional (NULL: none; absent without PMSM_LIVE_PARAMS, fx.h): a tunable
     * changed while the controller runs.
     * fresh is a state that init made from the changed configuration (same
     * machine, same fs); retune takes from it what that configuration sets -
     * gains, bands, weights - and keeps the dynamic state, adjusted where the
     * output would otherwise step (a PI integrator takes the change of the
     * proportional part). Called between two steps, integer-only. live: bit i
     * set when tunables[i] may change this way (the others only with the
     * controller stopped: init and reset anew). */
#if PMSM_LIVE_PARAMS
    void (*retune)(void *state, const void *fresh);
    uint32_t live;
#endif
} ctrl_desc_t;

/* Size of the caller's state and configuration blocks (the firmware's fw_t):
 * every descriptor checks its types against them at compile time
 * (CTRL_DESC_SIZES). */
#define CTRL_STATE_MAX 1024
#define CTRL_CFG_MAX 512

/* The state_size and cfg_size fields of a descriptor, with the compile-time
 * check that both types fit the blocks above. */
#define CTRL_DESC_SIZES(state_type, cfg_type)                                                      \
    .state_size = sizeof(state_type) +                                                             \
                  0 * sizeof(struct {                                                              \
                      _Static_assert(sizeof(state_type) <= CTRL_STATE_MAX, "state too large");     \
                      int ok;                                                                      \
                  }),                                                                              \
    .cfg_size = sizeof(cfg_type) +                                                                 \
                0 * sizeof(struct {                                                                \
                    _Static_assert(sizeof(cfg_type) <= CTRL_CFG_MAX, "config too large");          \
                    int ok;                                                                        \
                })

/* Defines the descriptor ctrl_desc_<id> (name "<id>"): its sizes checked
 * against the blocks above (CTRL_DESC_SIZES), the tunables counted from their
 * array, est_read the optional estimator outputs (CTRL_EST_* of estimator.h)
 * the controller reads (est_unused = the others). */
#define CTRL_DESC_DEFINE(id, title_, fs_hz, state_type, cfg_type, tunables_, cfg_default_, init_,  \
                         reset_, step_, est_read)                                                  \
    CTRL_DESC_DEFINE_FLUX(id, title_, fs_hz, state_type, cfg_type, tunables_, cfg_default_, init_, \
                          reset_, step_, est_read, 0u)

/* CTRL_DESC_DEFINE with ctrl_desc_t.flux_free. */
#define CTRL_DESC_DEFINE_FLUX(id, title_, fs_hz, state_type, cfg_type, tunables_, cfg_default_,    \
                              init_, reset_, step_, est_read, flux_free_)                          \
    CTRL_DESC_DEFINE_LIVE(id, title_, fs_hz, state_type, cfg_type, tunables_, cfg_default_, init_, \
                          reset_, step_, est_read, flux_free_, NULL, 0u)

/* A descriptor's retune, or none in an image built without live changes
 * (PMSM_LIVE_PARAMS 0, fx.h: the retune functions are not compiled, #if
 * PMSM_LIVE_PARAMS around them). */
#if PMSM_LIVE_PARAMS
#define CTRL_RETUNE(fn) fn
#define CTRL_DESC_TAIL(flux_free_, retune_, live_)                                                 \
    .flux_free = flux_free_, .retune = retune_, .live = live_
#else
#define CTRL_RETUNE(fn) NULL
#define CTRL_DESC_TAIL(flux_free_, retune_, live_) .flux_free = flux_free_
#endif

/* CTRL_DESC_DEFINE_FLUX with ctrl_desc_t.retune (as CTRL_RETUNE(fn)) and
 * .live (tunables changed while running). */
#define CTRL_DESC_DEFINE_LIVE(id, title_, fs_hz, state_type, cfg_type, tunables_, cfg_default_,    \
                              init_, reset_, step_, est_read, flux_free_, retune_, live_)          \
    const ctrl_desc_t ctrl_desc_##id = {                                                           \
        .name = #id,                                                                               \
        .title = title_,                                                                           \
        .fs_default_hz = fs_hz,                                                                    \
        CTRL_DESC_SIZES(state_type, cfg_type),                                                     \
        .tunables = tunables_,                                                                     \
        .n_tunables = sizeof tunables_ / sizeof tunables_[0],                                      \
        .cfg_default = cfg_default_,                                                               \
        .init = init_,                                                                             \
        .reset = reset_,                                                                           \
        .step = step_,                                                                             \
        .est_unused = CTRL_EST_ONLY(est_read),                                                     \
        CTRL_DESC_TAIL(flux_free_, retune_, live_),                                                \
    }

/* Registry (controller_registry.c; the entries are chosen at build time by
 * the CMake list PMSM_CONTROLLERS). */
size_t ctrl_count(void);
const ctrl_desc_t *ctrl_at(size_t index);
const ctrl_desc_t *ctrl_find(const char *name); /* NULL if unknown */

/* Guarded calls (controller_registry.c): every pointer (and the setup's and
 * context's members) is checked here, once. ctrl_cfg_default and ctrl_init
 * return CTRL_EINVAL for a missing one; ctrl_step writes the zero vector V0 for the whole period
 * when the context is incomplete (nothing when out is NULL). */
int ctrl_cfg_default(const ctrl_desc_t *d, void *cfg, const ctrl_machine_t *machine);
int ctrl_init(const ctrl_desc_t *d, void *state, const void *cfg, const ctrl_setup_t *setup);
void ctrl_reset(const ctrl_desc_t *d, void *state);
void ctrl_step(const ctrl_desc_t *d, void *state, const ctrl_ctx_t *ctx, ctrl_out_t *out);

/* Tunables by name (controller_config.c, may use double). Return CTRL_OK,
 * CTRL_ENOENT for an unknown name, CTRL_EINVAL for a value out of range or not finite. */
int ctrl_tunable_set(const ctrl_desc_t *d, void *cfg, const char *name, double value);
int ctrl_tunable_get(const ctrl_desc_t *d, const void *cfg, const char *name, double *value);

/* For init functions (controller_config.c): record in setup->diag (if any)
 * why a value was refused — the quantity, its value, the accepted range — and
 * return code. */
int ctrl_setup_refuse(const ctrl_setup_t *setup, int code, const char *quantity, const char *unit,
                      double value, double lo, double hi);

/* ctrl_q24_from_si (ctrl_params.h) for init functions: si / base into *out
 * when inside [lo_pu, hi_pu], else CTRL_ERANGE with the quantity (in pu),
 * its value and the range in setup->diag. */
int ctrl_setup_q24(const ctrl_setup_t *setup, const char *quantity, double si, double base,
                   double lo_pu, double hi_pu, q24_t *out);

/* Every field listed in t[0..n) of cfg is finite and inside [min, max]:
 * CTRL_OK, else CTRL_EINVAL (also for NULL t or cfg with n > 0). For init
 * functions that validate a whole SI configuration struct. */
int ctrl_tunables_check(const ctrl_tunable_t *t, size_t n, const void *cfg);

#endif /* CONTROL_CONTROLLER_H */
