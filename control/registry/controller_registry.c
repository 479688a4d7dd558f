/* The list of controllers selectable by name, chosen at build time: the CMake
 * list PMSM_CONTROLLERS (or pmsm_controller_registry(<lib> names...)) becomes
 * ctrl_registry_list.h, CTRL_REGISTRY_LIST(X) = X(bst) X(fst) ... Only the
 * listed controllers' objects are linked. */
#include <string.h>

#include "controller.h"
#include "ctrl_registry_list.h"

#define CTRL_REGISTRY_DECLARE(n) extern const ctrl_desc_t ctrl_desc_##n;
CTRL_REGISTRY_LIST(CTRL_REGISTRY_DECLARE)

#define CTRL_REGISTRY_ENTRY(n) &ctrl_desc_##n,
static const ctrl_desc_t *const registry[] = {CTRL_REGISTRY_LIST(CTRL_REGISTRY_ENTRY) NULL};

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
