/*
 * Servo-style throttle input (the RC "PWM" signal of flight controllers and
 * receivers), decoded without hardware: the board measures each pulse's
 * width and period (timer input capture) and hands them here with the time;
 * this module judges them, arms and disarms as ESCs do and gives the
 * reference. Integer-only; the same results on the host and the target.
 *
 * Signal: a pulse of 1000..2000 us (the calibrated end points low_us,
 * high_us) repeated at 50..490 Hz. A pulse is valid when its width lies in
 * [THR_PULSE_MIN_US, THR_PULSE_MAX_US] = [800, 2200] us and its period in
 * [THR_PERIOD_MIN_US, THR_PERIOD_MAX_US] (490 Hz and 50 Hz with margin for
 * the sender's clock); anything else (a glitch, a pulse out of range) is
 * dropped and counted, and refreshes nothing.
 *
 * Reference: 0 up to low_us + deadband_us, rising linearly to 1 at high_us
 * (Q24 fraction of the mode's full scale; above high_us: 1).
 *
 * Arming (the ESC convention): after power-up, and after every disarm, the
 * drive arms only once valid pulses have stayed at the low end (width <=
 * low_us + deadband_us) for THR_ARM_LOW_MS = 1 s without a break: a throttle
 * held high at power-up never arms it. Loss: no valid pulse for
 * THR_TIMEOUT_MS = 100 ms -> the reference ramps to zero over THR_RAMP_MS,
 * then the drive is disarmed (gates off) with the cause (no pulse, or only
 * invalid pulses); it re-arms only by the low-end rule.
 */
#ifndef FIRMWARE_THROTTLE_THROTTLE_H
#define FIRMWARE_THROTTLE_THROTTLE_H

#include <stdbool.h>
#include <stdint.h>

#include "fx.h"

#define THR_PULSE_MIN_US 800u
#define THR_PULSE_MAX_US 2200u
/* The calibrated end points lie on either side of the centre pulse: low_us in
 * [THR_PULSE_MIN_US, THR_LOW_MAX_US], high_us in [THR_HIGH_MIN_US,
 * THR_PULSE_MAX_US] (thr_config_check). */
#define THR_CENTRE_US 1500u
#define THR_LOW_MAX_US (THR_CENTRE_US - 1u)
#define THR_HIGH_MIN_US (THR_CENTRE_US + 1u)
#define THR_PERIOD_MIN_US 2000u  /* 500 Hz: 490 Hz + 2 % */
#define THR_PERIOD_MAX_US 22000u /* 45 Hz: 50 Hz - 10 % */
#define THR_ARM_LOW_MS 1000u
#define THR_TIMEOUT_MS 100u
#define THR_RAMP_MS 100u

typedef enum { THR_MODE_OFF = 0, THR_MODE_TORQUE = 1, THR_MODE_SPEED = 2 } thr_mode_t;

/* The [throttle] settings. */
typedef struct {
    uint8_t mode;         /* thr_mode_t */
    uint16_t low_us;      /* calibrated low end, default 1000 */
    uint16_t high_us;     /* calibrated high end, default 2000 */
    uint16_t deadband_us; /* zero reference up to low_us + deadband_us, default 30 */
} thr_config_t;

typedef enum {
    THR_WAIT_LOW = 0, /* disarmed: waiting for 1 s at the low end */
    THR_ARMED = 1,
    THR_RAMP_DOWN = 2 /* signal lost: reference ramping to zero, then disarm */
} thr_state_t;

typedef enum {
    THR_CAUSE_NONE = 0,
    THR_CAUSE_NO_PULSE = 1, /* no pulse at all for 100 ms (wire unplugged) */
    THR_CAUSE_INVALID = 2   /* pulses, but none valid for 100 ms (out of range) */
} thr_cause_t;

typedef enum { THR_EV_NONE = 0, THR_EV_ARM = 1, THR_EV_DISARM = 2 } thr_event_t;

typedef struct {
    thr_config_t cfg;
    uint8_t state; /* thr_state_t */
    uint8_t cause; /* thr_cause_t of the last loss (kept until the next arm) */
    bool low;      /* the low-end run is going on since t_low_ms */
    bool invalid_since_valid;
    uint32_t t_low_ms, t_valid_ms, t_lost_ms;
    q24_t cmd;         /* reference of the last valid pulse, Q24 fraction [0, 1] */
    q24_t ramp_from;   /* reference when the signal was lost, Q24 */
    uint16_t width_us; /* last valid width */
    uint32_t n_valid, n_invalid;
} thr_t;

typedef struct {
    uint8_t event; /* thr_event_t: what the drive must do now */
    q24_t ref;     /* reference, Q24 fraction [0, 1] of the mode's full scale */
    /* The ramp's factor, Q24: 1 while armed, falling linearly to 0 while the
     * signal is lost (ref = the last reference times it), 0 disarmed. A
     * speed-mode drive ramps its last torque by it. */
    q24_t ramp;
} thr_out_t;

/* 0 when the settings are usable, else the index of the first bad one
 * (THR_BAD_MODE, _LOW, _HIGH, _DEADBAND): mode <= THR_MODE_SPEED, low_us in
 * [800, 1500), high_us in (1500, 2200], deadband_us < (high_us - low_us) / 2. */
enum { THR_BAD_MODE = 1, THR_BAD_LOW = 2, THR_BAD_HIGH = 3, THR_BAD_DEADBAND = 4 };
int thr_config_check(const thr_config_t *c);
void thr_config_default(thr_config_t *c);

/* Disarmed, waiting for the low end; cfg must pass thr_config_check. */
void thr_init(thr_t *t, const thr_config_t *c, uint32_t now_ms);
/* One measured pulse: width and period (rising edge to rising edge), us. */
void thr_pulse(thr_t *t, uint32_t width_us, uint32_t period_us, uint32_t now_ms);
/* The state at now_ms (call often, pulses or not): arming, loss, ramp. */
thr_out_t thr_update(thr_t *t, uint32_t now_ms);

#endif /* FIRMWARE_THROTTLE_THROTTLE_H */
