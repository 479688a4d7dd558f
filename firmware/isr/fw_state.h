/*
 * Drive state machine: boot -> ADC offset calibration -> ready -> running,
 * ready -> commission (identification / bring-up steps, firmware/commission)
 * -> ready, and fault from anywhere. Transitions happen only on commands (arm, disarm,
 * clear) or on events raised by the pipeline (calibration done, fault). A
 * fault latches until a clear command; the gates stay off in every state but
 * running. Pure logic: no HAL access here (the pipeline acts on the result).
 */
#ifndef FIRMWARE_FW_STATE_H
#define FIRMWARE_FW_STATE_H

#include <stdbool.h>
#include <stdint.h>

typedef enum {
    FW_STATE_BOOT = 0,  /* after reset, nothing sampled yet */
    FW_STATE_CALIB,     /* gates off, averaging ADC offsets */
    FW_STATE_READY,     /* calibrated, gates off, waiting for arm */
    FW_STATE_RUNNING,   /* gates on, controller in the loop */
    FW_STATE_FAULT,     /* gates off, latched until clear */
    FW_STATE_COMMISSION /* a commissioning step drives the inverter (cm.h) */
} fw_state_id_t;

typedef enum {
    FW_EV_START = 0,  /* first period after boot: begin calibration */
    FW_EV_CALIB_DONE, /* offsets averaged and plausible */
    FW_EV_ARM,        /* command: enable the gates and run */
    FW_EV_DISARM,     /* command: gates off, back to ready */
    FW_EV_FAULT,      /* a protection fired (any state) */
    FW_EV_CLEAR,      /* command: leave fault (only when no fault is active) */
    FW_EV_CM_START,   /* command: start commissioning (from ready) */
    FW_EV_CM_END      /* commissioning finished or stopped: back to ready */
} fw_event_t;

typedef struct {
    fw_state_id_t state;
    uint32_t fault_code; /* first fault that latched (FW_FAULT_* of protect.h), 0 = none */
    bool calibrated;     /* ADC offsets valid (set by FW_EV_CALIB_DONE) */
} fw_state_t;

void fw_state_init(fw_state_t *s);

/*
 * Apply one event. fault_code is used by FW_EV_FAULT only (the first fault
 * latches; later ones do not overwrite it). Returns true when the state
 * changed. Events that are not valid in the current state are ignored
 * (e.g. arm while in fault, clear while running).
 */
bool fw_state_event(fw_state_t *s, fw_event_t ev, uint32_t fault_code);

/* Whether the gates may be on in this state. */
bool fw_state_gates_allowed(const fw_state_t *s);

/* fw_state_gates_allowed for a valid s, inlined into the interrupt. */
static inline bool fw_state_gates_on(const fw_state_t *s)
{
    return s->state == FW_STATE_RUNNING || s->state == FW_STATE_COMMISSION;
}

const char *fw_state_name(fw_state_id_t st);

#endif /* FIRMWARE_FW_STATE_H */
