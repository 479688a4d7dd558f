/*
 * The unit tests' rig for one controller step (C tests of this folder): the
 * registered controller with its default configuration for a machine at
 * 10 kHz, the step context wired to the rig's own estimate and references,
 * the DC link at its nominal value. Include from one translation unit per
 * test (static inline, Unity assertions).
 */
#ifndef TESTS_CHAPTER_CHAPTER_RIG_H
#define TESTS_CHAPTER_CHAPTER_RIG_H

#include <string.h>

#include "controller.h"
#include "ctrl_params.h"
#include "plan.h"
#include "unity.h"

typedef struct {
    ctrl_params_t params;
    ctrl_bases_t bases;
    ctrl_estimate_t est;
    ctrl_refs_t ref;
    ctrl_setup_t su;
    ctrl_ctx_t ctx;
    _Alignas(8) unsigned char state[CTRL_STATE_MAX];
    _Alignas(8) unsigned char cfg[CTRL_CFG_MAX];
    const ctrl_desc_t *d;
} chapter_rig_t;

static inline void chapter_rig_init(chapter_rig_t *rig, const char *name, const ctrl_machine_t *m)
{
    memset(rig, 0, sizeof *rig);
    rig->d = ctrl_find(name);
    TEST_ASSERT_NOT_NULL(rig->d);
    TEST_ASSERT_TRUE(rig->d->state_size <= CTRL_STATE_MAX);
    TEST_ASSERT_TRUE(rig->d->cfg_size <= CTRL_CFG_MAX);
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&rig->params, &rig->bases, m, 10000u));
    rig->d->cfg_default(rig->cfg, m);
    rig->su = (ctrl_setup_t){m, &rig->bases, &rig->params};
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_init(rig->d, rig->state, rig->cfg, &rig->su));
    rig->ctx.params = &rig->params;
    rig->ctx.est = &rig->est;
    rig->ctx.ref = &rig->ref;
    rig->est.vdc = rig->params.vdc_nom;
}

/* One step of the rig's controller; its output as leg duties in out->legs,
 * which must realise its plan when it has one (ctrl_plan_legs). */
static inline void chapter_rig_step(chapter_rig_t *rig, ctrl_out_t *out)
{
    memset(out, 0xA5, sizeof *out);
    rig->d->step(rig->state, &rig->ctx, out);
    if (out->plan.n_seg > 0u) {
        ctrl_legs_t want;
        ctrl_plan_legs(&out->plan, &want);
        TEST_ASSERT_EQUAL_INT32_ARRAY(want.duty, out->legs.duty, 3);
    }
}

#endif /* TESTS_CHAPTER_CHAPTER_RIG_H */
