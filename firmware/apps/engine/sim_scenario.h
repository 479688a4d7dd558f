/*
 * Scenario files for the host simulator: time- or speed-triggered steps of
 * the references, the load and the imposed speed.
 *
 * Format (text, one event per line; '#' starts a comment; blank lines skipped):
 *   at <t_s>            <assignments...>    fires at t >= t_s (seconds after arm)
 *   when speed>=<rpm>   <assignments...>    fires when the true mechanical speed
 *   when speed<=<rpm>   <assignments...>    crosses the level (r/min, signed)
 * Events fire in FILE ORDER: an event is armed only after the one before it
 * has fired (so "at 0.01 torque_ref=2" then "when speed>=1500 torque_ref=-2"
 * means: step to 2 N*m at 10 ms, then to -2 N*m once 1500 r/min is reached).
 * Assignments (at least one, each key at most once per event):
 *   torque_ref=<N*m>    torque reference (a torque-mode run: --torque-ref)
 *   speed_ref=<rpm>     speed reference (a speed-mode run: --speed-ref-rpm)
 *   load=<N*m>          constant (active) load torque, free mechanics
 *   load_passive=<N*m>  passive load of this magnitude (>= 0), free mechanics:
 *                       it opposes the rotation, holds the rotor at rest while
 *                       the motor torque is smaller, never drives it
 *   speed=<rpm>         imposed speed (a dynamometer run)
 * sim_run_init checks the assignments against the run (an error when a key
 * does not apply to it; a warning for an event after the end).
 * Example:
 *   # dynamic test of thesis Fig. 4.14 (free mechanics, torque mode)
 *   at 0      torque_ref=0
 *   at 0.002  torque_ref=2 load_passive=1.6
 *   when speed>=1500 torque_ref=-2
 */
#ifndef FIRMWARE_HOST_SIM_SCENARIO_H
#define FIRMWARE_HOST_SIM_SCENARIO_H

#include <stddef.h>
#include <stdio.h>

#define SIM_SCN_MAX_EVENTS 256

typedef enum { SIM_TRIG_AT = 0, SIM_TRIG_SPEED_GE = 1, SIM_TRIG_SPEED_LE = 2 } sim_trig_t;

enum {
    SIM_SET_TORQUE_REF = 1u << 0,
    SIM_SET_SPEED_REF = 1u << 1,
    SIM_SET_LOAD = 1u << 2,
    SIM_SET_SPEED = 1u << 3,
    SIM_SET_LOAD_PASSIVE = 1u << 4
};

typedef struct {
    sim_trig_t trig;
    double level; /* seconds (AT) or r/min (SPEED_*) */
    unsigned set; /* SIM_SET_* mask */
    double torque_ref_nm, speed_ref_rpm, load_nm, speed_rpm, load_passive_nm;
    int line;
} sim_event_t;

typedef struct {
    sim_event_t ev[SIM_SCN_MAX_EVENTS];
    size_t n;
    size_t next; /* index of the next event to fire */
} sim_scenario_t;

/* Parse a scenario from a file. Returns 0, or -1 with "file:line: message". */
int sim_scenario_load(sim_scenario_t *s, const char *path, char *err, size_t errlen);
int sim_scenario_parse(sim_scenario_t *s, FILE *f, const char *name, char *err, size_t errlen);

#endif /* FIRMWARE_HOST_SIM_SCENARIO_H */
