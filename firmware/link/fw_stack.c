/* The main stack's painting and high-water mark (fw_stack.h). */
#include "fw_stack.h"

void fw_stack_paint(uint32_t *lo, uint32_t *end)
{
    /* volatile: a plain loop may become a call (memset-like), whose frame
     * would lie inside the area being painted */
    for (volatile uint32_t *p = lo; p < end; p++) {
        *p = FW_STACK_PAINT;
    }
}

uint32_t fw_stack_used(const uint32_t *lo, const uint32_t *hi)
{
    const volatile uint32_t *p = lo;
    while (p < hi && *p == FW_STACK_PAINT) {
        p++;
    }
    return (uint32_t)((uintptr_t)hi - (uintptr_t)p);
}
