/* The control interrupt's progress, seen from the main loop (board_isr_watch.h). */
#include "board_isr_watch.h"

bool board_isr_watch_check(board_isr_watch_t *w, uint32_t count, uint32_t now, bool gates_on,
                           uint32_t limit)
{
    if (!gates_on) {
        w->on = false;
        return false;
    }
    if (!w->on || count != w->count) {
        w->on = true;
        w->count = count;
        w->since = now;
        return false;
    }
    return now - w->since >= limit; /* unsigned: across the counter's wrap */
}
