/* The list of controllers selectable by name. Add one line per controller. */
#include <string.h>

#include "controller.h"

/* Descriptors are defined in each controller's own file. */
/* CONTROLLER-DECLARATIONS (keep sorted by chapter) */

static const ctrl_desc_t *const registry[] = {
    /* CONTROLLER-ENTRIES */
    NULL,
};

size_t ctrl_count(void)
{
    return sizeof registry / sizeof registry[0] - 1u;
}

const ctrl_desc_t *ctrl_at(size_t index)
{
    return index < ctrl_count() ? registry[index] : NULL;
}

const ctrl_desc_t *ctrl_find(const char *name)
{
    if (name == NULL) {
        return NULL;
    }
    for (size_t i = 0; i < ctrl_count(); i++) {
        if (strcmp(registry[i]->name, name) == 0) {
            return registry[i];
        }
    }
    return NULL;
}
