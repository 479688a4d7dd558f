/*
 * Registry with at most one controller, for the memory-footprint images of
 * tools/bench: BENCH_SIZE_CTRL=ctrl_desc_<name> selects the entry; without
 * it the registry is empty (the baseline image). Linked before libpmsm_control,
 * so control/controller_registry.c (and with it every other controller) is
 * not pulled into the image.
 */
#include <stddef.h>
#include <string.h>

#include "controller.h"

#ifdef BENCH_SIZE_CTRL
extern const ctrl_desc_t BENCH_SIZE_CTRL;
static const ctrl_desc_t *const bench_entry = &BENCH_SIZE_CTRL;
#else
static const ctrl_desc_t *const bench_entry = NULL;
#endif

size_t ctrl_count(void)
{
    return bench_entry != NULL ? 1u : 0u;
}

const ctrl_desc_t *ctrl_at(size_t index)
{
    return index < ctrl_count() ? bench_entry : NULL;
}

const ctrl_desc_t *ctrl_find(const char *name)
{
    if (name == NULL || bench_entry == NULL) {
        return NULL;
    }
    return strcmp(bench_entry->name, name) == 0 ? bench_entry : NULL;
}
