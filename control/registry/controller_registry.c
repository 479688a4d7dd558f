/* The list of controllers selectable by name. Add one line per controller. */
#include <string.h>

#include "controller.h"

/* Descriptors are defined in each controller's own file. */
/* CONTROLLER-DECLARATIONS (keep sorted by chapter) */
/* chapter 4: switching-table DTC (st_dtc.h) */
extern const ctrl_desc_t ctrl_desc_bst, ctrl_desc_mbst, ctrl_desc_ast, ctrl_desc_zst, ctrl_desc_fst;
/* chapter 5: duty-ratio-regulated DTC and its baselines (ctrl_drr.h) */
extern const ctrl_desc_t ctrl_desc_drr, ctrl_desc_drr_d1, ctrl_desc_drr_d2, ctrl_desc_drr_pi,
    ctrl_desc_drr_df;
/* chapter 6: M2PTFC and its baselines (ctrl_m2ptfc.h, ctrl_m1.h, ctrl_mptfc.h, ctrl_m3.h,
 * ctrl_m2.h) */
extern const ctrl_desc_t ctrl_desc_m2ptfc, ctrl_desc_m1, ctrl_desc_mptfc, ctrl_desc_m3,
    ctrl_desc_m2;
/* chapter S1: FOC, HDTC, SVM-DTC, HP-DTC (ctrl_foc.h, ctrl_s1_dtc.h) */
extern const ctrl_desc_t ctrl_desc_foc, ctrl_desc_foc_hyst, ctrl_desc_hdtc, ctrl_desc_svm_dtc,
    ctrl_desc_hpdtc;

/* One entry per line, grouped by chapter; keep clang-format from packing it. */
/* clang-format off */
static const ctrl_desc_t *const registry[] = {
    /* CONTROLLER-ENTRIES */
    &ctrl_desc_bst, &ctrl_desc_mbst, &ctrl_desc_ast, &ctrl_desc_zst, &ctrl_desc_fst,
    &ctrl_desc_drr, &ctrl_desc_drr_d1, &ctrl_desc_drr_d2, &ctrl_desc_drr_pi, &ctrl_desc_drr_df,
    &ctrl_desc_m2ptfc, &ctrl_desc_m1, &ctrl_desc_mptfc, &ctrl_desc_m3, &ctrl_desc_m2,
    &ctrl_desc_foc, &ctrl_desc_foc_hyst, &ctrl_desc_hdtc, &ctrl_desc_svm_dtc, &ctrl_desc_hpdtc,
    NULL,
};
/* clang-format on */

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
