/* Drive state machine (see fw_state.h). */
#include "fw_state.h"

#include <stddef.h>

void fw_state_init(fw_state_t *s)
{
    if (s == NULL) {
        return;
    }
    s->state = FW_STATE_BOOT;
    s->fault_code = 0u;
    s->calibrated = false;
}

static bool fw_state_go(fw_state_t *s, fw_state_id_t next)
{
    const bool changed = s->state != next;
    s->state = next;
    return changed;
}

bool fw_state_event(fw_state_t *s, fw_event_t ev, uint32_t fault_code)
{
    if (s == NULL) {
        return false;
    }
    switch (ev) {
    case FW_EV_FAULT:
        /* Any state: the first fault latches its code. */
        if (s->state != FW_STATE_FAULT) {
            s->fault_code = fault_code;
        }
        return fw_state_go(s, FW_STATE_FAULT);
    case FW_EV_START:
        return s->state == FW_STATE_BOOT ? fw_state_go(s, FW_STATE_CALIB) : false;
    case FW_EV_CALIB_DONE:
        if (s->state != FW_STATE_CALIB) {
            return false;
        }
        s->calibrated = true;
        return fw_state_go(s, FW_STATE_READY);
    case FW_EV_ARM:
        return s->state == FW_STATE_READY ? fw_state_go(s, FW_STATE_RUNNING) : false;
    case FW_EV_DISARM:
        /* Also stops commissioning. */
        return s->state == FW_STATE_RUNNING || s->state == FW_STATE_COMMISSION
                   ? fw_state_go(s, FW_STATE_READY)
                   : false;
    case FW_EV_CM_START:
        return s->state == FW_STATE_READY ? fw_state_go(s, FW_STATE_COMMISSION) : false;
    case FW_EV_CM_END:
        return s->state == FW_STATE_COMMISSION ? fw_state_go(s, FW_STATE_READY) : false;
    case FW_EV_CLEAR:
        if (s->state != FW_STATE_FAULT) {
            return false;
        }
        s->fault_code = 0u;
        /* Offsets are kept: a fault does not invalidate the calibration. A
         * fault during calibration (before offsets exist) restarts it. */
        return fw_state_go(s, s->calibrated ? FW_STATE_READY : FW_STATE_CALIB);
    default:
        return false;
    }
}

bool fw_state_gates_allowed(const fw_state_t *s)
{
    return s != NULL && fw_state_gates_on(s);
}

const char *fw_state_name(fw_state_id_t st)
{
    switch (st) {
    case FW_STATE_BOOT:
        return "boot";
    case FW_STATE_CALIB:
        return "calib";
    case FW_STATE_READY:
        return "ready";
    case FW_STATE_RUNNING:
        return "running";
    case FW_STATE_FAULT:
        return "fault";
    case FW_STATE_COMMISSION:
        return "commission";
    default:
        return "?";
    }
}
