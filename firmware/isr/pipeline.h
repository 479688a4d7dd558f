/*
 * The control loop at two rates (docs/architecture.md, "Two rates").
 *
 * fw_isr_fast(), the PWM-period interrupt, top to bottom (TI MotorWare style):
 *
 *   t0 = hal_cycles(); re-entry check; the medium task's completion check
 *   hal_adc_read, hal_encoder_read          samples of period start k
 *   commands (arm / disarm / clear) requested from the main loop
 *   boot/calib: gates off, average ADC offsets, then ready
 *   counts -> per unit                      offsets and gains from init
 *   protections                             over-current first: gates off now
 *   ctrl_estimator_update                   estimate at k, predict k+1 with
 *                                           the plan acting in [k, k+1)
 *   torque reference (torque mode, the speed loop's held output, or the
 *   sensorless start's) clamped to the medium task's limits; mean-torque trim
 *   desc->step                              leg duties (and the plan they
 *                                           realise) for [k+1, k+2)
 *   leg duties -> compare values -> hal_pwm_write (effective at k+1)
 *   deadline check (hal_cycles against the period budget)
 *   telemetry: the period's record is written into the ring as it is
 *   computed, published once in tm_every periods (fw_tm_stream)
 *   once in mid_div periods: the medium task's inputs (fw_mid_in_t), and
 *   fw_isr_fast returns true: the caller runs fw_medium() at a lower priority
 *
 * fw_medium(), the medium-rate task (medium.c; fs / mid_div, default 1 kHz):
 * the speed PI, the speed-following protection, the field-weakening and MTPV
 * torque limit and flux reference (field_weak.h, on the DC link's mean over
 * the medium period); its outputs (fw_mid_out_t) act from period k+1 on. It
 * must end before the interrupt of k+1 (else FW_FAULT_DEADLINE). In the first
 * period after a reset (arming, a commissioning step's controller reset) the
 * interrupt ends after the estimate and the task's run completes the period:
 * the torque reference, the controller's step and the compare values
 * (fw_mid_first_step), in time for k+1 as the interrupt's are. The PM-flux
 * tracker's correction and EMA (psi_track.h) are the task's too: the
 * interrupt requests a run at period 0 of the tracker's N and adds the
 * correction's step at the next period.
 * fw_isr() is the two in that order: the host engine's and the tests'
 * scheduler.
 *
 * Fixed-point formats of the conversion (computed at init, pipeline_config.c):
 *   ADC offsets: Q8 counts (average of calib_samples samples, 8 fractional bits)
 *   current gain: Q30 pu per count (nominal A/count from hal_info / i_base,
 *                 times the optional per-channel correction)
 *   i_pu (Q24) = ((raw << 8) - off_q8) * gain_q30 / 2^14 (rounded, saturated;
 *                the difference fits 32 bits: one 32x32 -> 64 multiply)
 *   DC-link gain: Q30 pu per count; vdc_pu (Q24) = raw * gain_q30 / 2^6
 *   compare value = round(duty_q24 * period_counts / 2^24), ties up, in
 *                [0, period_counts]
 *   encoder: position pos in [0, cpr); theta_e = pos * p * 2^32 / cpr (64-bit,
 *            exact modulo one electrical turn) + enc_offset (fx_angle_t); the
 *            counter is taken as aligned (0 at the d axis); every new index
 *            pulse (at position 0) re-synchronises pos = count - index_count,
 *            which removes counts gained or lost by glitches
 *
 * The running state takes its own straight path (fw_period_running), with
 * the protections inlined from protect.h; every other state the general one.
 *
 * All state lives in fw_t (no globals); the controller's state is a static,
 * aligned block of CTRL_STATE_MAX bytes inside it.
 */
#ifndef FIRMWARE_PIPELINE_H
#define FIRMWARE_PIPELINE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "cm.h"
#include "cm_cogging.h"
#include "cm_config.h"
#include "controller.h"
#include "ctrl_params.h"
#include "ctrl_types.h"
#include "deadtime.h"
#include "estimator.h"
#include "field_weak.h"
#include "flux_observer.h"
#include "fw_state.h"
#include "hal.h"
#include "hfi_config.h"
#include "protect.h"
#include "psi_track.h"
#include "sensorless.h"
#include "speed_pi.h"
#include "speed_pi_config.h"
#include "torque_follow.h"

#define FW_OK 0
#define FW_EINVAL (-1) /* NULL, bad machine or configuration */
#define FW_ECTRL (-2)  /* controller rejected its configuration / too large */
#define FW_ERANGE (-3) /* a gain or limit does not fit its Q format */
#define FW_EBUSY (-4)  /* not allowed while running */
#define FW_ENOENT (-5) /* unknown name */

/* One period's record, written by the interrupt straight into the telemetry
 * ring (fw_t.tm_ring) and nothing else of telemetry: the main loop derives
 * the rest (|psi_s|, the sector, SI units; fw_link). Also read by tests and
 * the simulator (fw_telemetry). */
typedef struct {
    uint32_t period; /* ISR count (modulo 2^32) */
    uint8_t state;   /* fw_state_id_t */
    uint8_t fault;   /* latched fault code (protect.h) */
    uint8_t vec;     /* selected vector (plan segment 0) for [k+1, k+2) */
    uint8_t gates;   /* 1 when the gates are requested on */
    union {
        /* The measurements as handed to the estimator (the same four
         * values: a common initial sequence of the two structs). */
        ctrl_meas_t meas;
        struct {
            q24_t i_a, i_b;     /* measured phase currents, Q24 pu */
            q24_t vdc;          /* measured DC link, Q24 pu */
            fx_angle_t theta_e; /* electrical angle from the encoder */
        };
    };
    q24_t i_d, i_q;          /* rotor-frame current at k, Q24 pu */
    q24_t psi_d, psi_q;      /* rotor-frame stator flux at k, Q24 pu (|psi_s|, sector: main loop) */
    q24_t torque;            /* torque estimate at k, Q24 pu */
    q24_t omega_e;           /* electrical speed estimate, Q24 pu */
    q24_t torque_ref;        /* torque reference used at k (after the limits), Q24 pu */
    q24_t torque_max;        /* |torque| limit of this period (field_weak.h), Q24 pu */
    uint8_t fieldweak_limit; /* what bounds it: ctrl_fieldweak_limit_t, + 4 when the request was
                         clipped, + 8 when the flux reference is weakened, + 16 while
                         the torque misses its reference (torque_follow.h) */
    q24_t duty;              /* on-time of segment 0, Q24 fraction */
    q24_t legs[3];           /* leg duties written at k, Q24 fraction */
    uint32_t cycles;         /* ISR duration measured with hal_cycles */
    uint8_t cm_step;         /* commissioning step running (cm_step_id_t), 0 = none */
    uint16_t cm_progress;    /* its progress, per mille */
#if CTRL_SL_HFI
    /* Sensorless (fw_config_t.sensorless): bits 0-1 the angle's mode
     * (CTRL_SL_FORCED, _OBSERVER, _DETECT, _INJECT of sensorless.h), bits 2-4
     * the start's phase (CTRL_SL_PH_*), bits 5-6 where the polarity came from
     * (CTRL_SL_POL_*); 0 with the encoder. In an image with the injection
     * only (CMake option PMSM_SL_HFI): the record's size stays otherwise. */
    uint8_t sl_state;
    int32_t hfi_err; /* the injection's angle error estimate (rotor minus tracked), fx_angle_t
                      * units (2^32 = one electrical turn); 0 without a demodulated sample */
#endif
} fw_telemetry_t;

/* Records kept for the main loop (power of 2): at one record in `every`
 * periods the main loop may fall FW_TM_RING - 1 records behind. */
#define FW_TM_RING 16u

typedef enum { FW_REF_TORQUE = 0, FW_REF_SPEED = 1 } fw_ref_mode_t;

/* The main loop's requests, taken by the interrupt at its next period start
 * (fw_cmd_*, fw_commission_start, fw_tm_stream). */
typedef enum {
    FW_REQ_ARM = 0,
    FW_REQ_DISARM = 1, /* also "stop" of a commissioning step */
    FW_REQ_CLEAR = 2,  /* fault clear */
    FW_REQ_CM = 3,     /* commissioning start (fw_t.cm set up before) */
    FW_REQ_TM = 4,     /* telemetry: publish one record in fw_from_main_t.tm_every periods */
#if PMSM_LIVE_PARAMS
    FW_REQ_SPEED_TUNE = 5, /* live change: the speed PI's gains in fw_t.speed_pi_next */
    FW_REQ_CTRL_TUNE = 6,  /* live change: the controller's retune from fw_t.ctrl_next */
#endif
    FW_REQ_N
} fw_req_t;

/* State shared between the main loop and the interrupt, one writer per block
 * (docs/architecture.md, "State shared between the contexts"; the test
 * tests/loop/test_shared_state.c checks it around every period).
 *
 * fw_from_main_t: written by the main loop only, read by the interrupt. The
 * main loop stores with volatile stores and orders them with release signal
 * fences: a reference before its mode, a request's data before its count,
 * every count before req_sum. The interrupt, which the main loop cannot
 * interrupt, reads a consistent set in any order; the medium task reads none
 * of it (the interrupt hands it what it needs in its slot, fw_mid_in_t). */
typedef struct {
    volatile uint32_t req[FW_REQ_N]; /* requests made, per kind (counted up) */
    volatile uint32_t req_sum;       /* their sum, counted up after them */
    volatile q24_t torque_ref;       /* torque mode: as requested, Q24 pu */
    volatile q24_t torque_ref_lim;   /* torque_ref clamped to +-torque_ref_max, Q24 pu */
    volatile q24_t speed_ref;        /* speed mode: Q24 pu electrical */
    volatile uint8_t ref_mode;       /* fw_ref_mode_t, stored after its reference */
    volatile uint32_t wdg_stamp;     /* fw_t.period at the last fw_watchdog_kick */
    volatile uint32_t tm_every;      /* decimation the next FW_REQ_TM sets (0: stop) */
    volatile uint32_t tm_tail;       /* telemetry records taken (fw_tm_release) */
#if PMSM_LIVE_PARAMS
    /* The count of the speed (0) and controller (1) live change that a new
     * configuration superseded before the interrupt took it: the interrupt
     * takes it and applies nothing (fw_request_withdraw). */
    volatile uint32_t withdrawn[2];
#endif
} fw_from_main_t;

/* fw_to_main_t: written by the interrupt only, read by the main loop
 * (volatile loads). A request is taken once taken[k] == req[k]. */
typedef struct {
    volatile uint32_t taken[FW_REQ_N]; /* requests taken, per kind */
    volatile uint32_t taken_sum;       /* their sum */
    volatile uint32_t tm_head;         /* telemetry records published */
    volatile uint32_t tm_drop;         /* records before it belong to an earlier stream */
    volatile uint32_t tm_dropped;      /* records not published: the ring was full */
} fw_to_main_t;

/* Corner of the mean-torque trim in field weakening (pipeline.c): the DRR
 * EMA's, thesis sec. 5.3.2, as FST's f_i. */
#define FW_TRIM_HZ 50.0

/* The hand-over between the two rates (docs/architecture.md, "Two rates"):
 * one writer per direction, two slots each. The interrupt fills
 * mid_in[(mid_req + 1) & 1], then counts mid_req up; fw_medium reads
 * mid_in[mid_req & 1], fills mid_out[(mid_done + 1) & 1], then counts
 * mid_done up to mid_req; the interrupt reads mid_out[mid_done & 1]. A slot is
 * never written while the other side may read it. */
typedef struct {
    int64_t vdc_sum;         /* the estimator's DC link summed over n periods, Q24 pu */
    uint32_t n;              /* periods summed since the last run (>= 1) */
    q24_t omega_e;           /* electrical speed estimate at k, Q24 pu */
    q24_t tref;              /* torque reference of k before the limits (torque mode, the
                                sensorless start), Q24 pu */
    q24_t torque_now;        /* torque reference of k after the limits (fw_t.torque_ref_now) */
    q24_t speed_ref;         /* Q24 pu electrical */
    q24_t bump_torque;       /* bump: the torque the speed loop restarts from, Q24 pu */
    uint8_t ref_mode;        /* fw_ref_mode_t of k */
    uint8_t hold;            /* 1: the speed loop waits (sensorless start) */
    uint8_t reset;           /* 1: arm or a commissioning reset: the task's state anew */
    uint8_t bump;            /* 1: the speed loop restarts from bump_torque (sensorless handover) */
    uint8_t run;             /* 1: the speed loop and the limits run (the fields above); 0: the
                                PM-flux tracker's run alone */
    uint8_t first;           /* 1: the first period after a reset: after the run, the rest of
                                that period (fw_mid_first_step) */
    uint8_t track;           /* 1: the PM-flux tracker's correction on psi (period 0 of its N) */
    ctrl_psi_track_in_t psi; /* track: the correction's inputs (psi_track.h) */
#if PMSM_LIVE_PARAMS
    uint8_t retune;            /* 1: the speed PI's new gains (retune_pi) before this run */
    ctrl_speed_pi_t retune_pi; /* a live change the interrupt took (fw_apply_tune) */
#endif
} fw_mid_in_t;

typedef struct {
    q24_t speed_tref;  /* speed loop's torque reference, clamped to +-torque_ref_max (in
                          torque mode the limited torque reference: a bumpless switch), Q24 */
    q24_t torque_max;  /* |torque| limit (field_weak.h), Q24 pu */
    q24_t psi_ref;     /* stator-flux reference while weakening, Q24 pu */
    uint8_t limit;     /* ctrl_fieldweak_limit_t: what bounds torque_max */
    uint8_t weakening; /* 1: psi_ref is below the controller's own reference */
    uint8_t fault;     /* a slow protection's fault (FW_FAULT_*), latched by the interrupt */
    /* A tracker run's (in.track): the flux's step, which the interrupt adds at
     * its next period, and with psi_new the parameters it then takes. */
    uint8_t psi_new;
    int64_t psi_delta[2]; /* Q48 pu (ctrl_psi_track_add) */
    q24_t psi_pm;         /* Q24 pu */
    q24_t inv_psi_pm;     /* Q24, 1 / psi_pm */
    q24_t mtpa_k;         /* Q24, Lq / psi_pm */
} fw_mid_out_t;

/* Start-up configuration (SI, read once by fw_init). */
typedef struct {
    const ctrl_machine_t *machine; /* machine the controller is configured for */
    const ctrl_desc_t *ctrl;       /* controller (registry entry or a test one) */
    const void *ctrl_cfg;          /* its SI configuration (desc->cfg_size bytes);
                                      NULL = desc->cfg_default(machine) */
    uint32_t calib_samples;        /* ADC offset averaging (>= 1), default 256 */
    double adc_gain_corr[3];       /* per-channel current gain correction (~1.0) */
    fx_angle_t enc_offset;         /* electrical angle at encoder count 0 */
    int8_t enc_direction;          /* +1: theta_e grows with the count; -1: falls */
    uint32_t enc_cpr;              /* counts per revolution; 0 = hal_info's */
    cm_config_t cm;                /* commissioning levels and times (cm_config.h) */
    /* Outer speed loop: sized from the machine (speed_loop.h) with this
     * bandwidth and phase margin (0 = the defaults there), unless explicit
     * gains are given (speed_kp or speed_ki > 0, in speed_unit). */
    double speed_bw_hz, speed_pm_deg;
    double speed_kp, speed_ki;
    ctrl_speed_unit_t speed_unit;
    double speed_out_max_nm; /* torque-reference limit (> 0), default
                                fw_torque_limit_nm (speed_loop.h) */
    uint32_t speed_loop_hz;  /* the medium-rate task's rate: speed PI, field weakening
                                (divides fs), default 1000; 0 = every period */
    double overspeed_rpm;    /* overspeed trip level (mechanical); 0 = 1.05 x the machine's
                                maximum speed (fw_speed_max_rpm, protect.h) */
    /* PM flux from the voltage model where it is reliable (|speed| >= 10 % of
     * rated; flux_observer.h, encoder mode): once it differs from the
     * configured psi_pm by more than 2 %, the current model, the predictions
     * and every controller use it instead, so the torque does not depend on
     * that value at speed. Default on; off with an output filter between the
     * inverter and the motor (the leg voltages are not the motor's). The
     * inverter's dead time and device drop (0 = none) are what the
     * observer's voltage reconstruction removes. */
    bool psi_adapt;
    double dead_time_s, v_fwd_v;
    /* Dead-time and device-drop compensation of the written duties
     * (control/modulation/deadtime.h) from dead_time_s and v_fwd_v, each
     * edge's sign softened over dead_comp_band_a, A (0 = the default of
     * ctrl_deadtime_band_default: the dead time's share of the ripple and
     * 4 counts of the current's ADC). Default on; with it the estimator and the observers take
     * the uncompensated duties as the applied voltage, without it the
     * observers remove the error themselves. */
    bool dead_comp;
    double dead_comp_band_a;
    /* No position sensor (control/estimation/sensorless.h): the angle and
     * speed from the stator-flux observer, started on a forced angle
     * (current-frequency ramp to 5 % of rated speed, then the handover); the
     * encoder and its protections unused, psi_adapt off (the observer's
     * correction needs the configured psi_pm). Default off. */
    bool sensorless;
    /* High-frequency injection at and near standstill (sensorless only;
     * control/estimation/hfi.h, docs/algorithms.md "High-frequency
     * injection"): the start from the saliency's angle with its polarity by
     * d-axis saturation pulses (or the first motion), the injection's angle
     * below the hand-over speed, the observer's above. Needs a salient
     * machine and a modulated controller (foc, m2ptfc, drr: the injection is
     * added to their voltage); others are refused by name. hfi_cfg: each
     * field 0 takes the machine's default (ctrl_hfi_config_default). Default
     * off. */
    bool hfi; /* beside sensorless: in its padding */
#if CM_MECH
    /* The shaft's friction (Coulomb with the passive load, N*m; viscous,
     * N*m*s): the machine's mechanics beside its inertia, which "ident apply"
     * adopts from the identification (cm_flux.c) and the settings record
     * keeps; 0 = none known. Kept and reported, not yet used by a
     * controller; an image without the mechanics' identification has none. */
    double coulomb_nm, viscous_nms;
#endif
#if CTRL_COGGING
    /* Anti-cogging calibration's sweep (cm_cogging.h; zeroes: its defaults). */
    cm_cog_config_t cog;
#endif
    /* Torque supervision (torque_follow.h): consecutive 50 ms windows in
     * which the mean torque estimate misses the applied reference by more
     * than max(5 %, 2 % of rated) before the fault torque_follow; 0 (the
     * default): the telemetry warning only. */
    uint32_t torque_follow_fault_windows;
#if CTRL_SL_HFI
    ctrl_hfi_config_t hfi_cfg; /* last: no other field's offset moves (fw_config_t.hfi) */
#endif
} fw_config_t;

/* The speed loop and speed limits in force (SI, for reports; set by fw_init). */
typedef struct {
    double kp_nm_s_rad, ki_nm_rad;                  /* per mechanical rad/s, rad */
    double bandwidth_hz, phase_margin_deg, zero_hz; /* of the design; 0 for explicit gains */
    double overspeed_rpm;                           /* trip level */
    double speed_ref_max_rpm;                       /* |speed reference| limit: overspeed / 1.05 */
} fw_speed_info_t;

typedef struct {
    hal_t *hal;
    hal_info_t info;
    ctrl_params_t params;
    ctrl_bases_t bases;
    const ctrl_desc_t *ctrl;
    const ctrl_machine_t *machine; /* the controller's machine (&machine_own) */
    ctrl_machine_t machine_own;    /* copy of the configured (or identified) machine */
    fw_config_t cfg;               /* copy of the start-up configuration (pointers
                                      machine and ctrl_cfg cleared) */
    union {
        max_align_t align;
        unsigned char bytes[CTRL_STATE_MAX];
    } ctrl_state;
    union {
        max_align_t align;
        unsigned char bytes[CTRL_CFG_MAX];
    } ctrl_cfg; /* SI configuration of the selected controller */
    ctrl_estimator_t est;
    ctrl_estimate_t estimate;
    q24_t psi_pm_cfg;    /* the configured psi_pm, Q24 pu */
    q24_t psi_ref_cfg;   /* the machine's fixed flux reference, Q24 pu (0: MTPA); params.psi_ref
                            holds it for a controller that holds it, 0 for a flux-free one */
    q24_t psi_band;      /* |estimate - configured| that engages the tracking, Q24 pu */
    bool psi_engaged;    /* medium task: the estimate has left the band, params follow it */
    uint8_t psi_due;     /* interrupt: the tracker's correction of this period is the medium
                            task's (its step and parameters taken at the next period) */
    ctrl_legs_t applied; /* leg duties acting in [k, k+1): chosen at k-1 (or 0), before
                          * the dead-time compensation (and without the injection) */
    ctrl_deadtime_t deadtime; /* compensation of the written duties (dd 0: off) */
    ctrl_refs_t refs;
    q24_t torque_ref_now; /* torque reference after the limits, before the trim, Q24 pu */
    q24_t trim;           /* mean-torque trim in field weakening, Q24 pu (pipeline.c) */
    q24_t trim_k;         /* its gain per period, 1 - exp(-2 pi FW_TRIM_HZ / fs), Q24 */
    fw_from_main_t ml;    /* the main loop's requests and references (written there only) */
    fw_to_main_t isr;     /* what the interrupt tells the main loop (written there only) */
    q24_t torque_ref_max; /* Q24 pu, clamp of the torque reference */
    q24_t torque_ref_min; /* Q24 pu, fx_neg(torque_ref_max) (set with it) */
    /* The medium-rate task (medium.c) and the hand-over (fw_mid_in_t). */
    uint32_t mid_div;          /* PWM periods per run (>= 1) */
    uint32_t mid_count;        /* interrupt: periods to the next run, 1..mid_div (1: this one) */
    int64_t mid_vdc_sum;       /* interrupt: DC link summed since the last run, Q24 pu */
    uint32_t mid_n;            /* interrupt: periods in mid_vdc_sum */
    uint8_t mid_reset;         /* interrupt: the next run starts the task's state anew */
    uint8_t mid_bump;          /* interrupt: the next run restarts the speed loop at mid_bump_t */
    uint8_t mid_fresh;         /* interrupt: mid_out holds a run since the last reset (else the
                                  period ends after the estimate, the task completes it) */
    fw_telemetry_t *mid_first; /* the record of that first period (fw_mid_first_step) */
    q24_t mid_bump_t;
    fw_mid_in_t mid_in[2];      /* written by the interrupt only */
    fw_mid_out_t mid_out[2];    /* written by fw_medium only */
    volatile uint32_t mid_req;  /* runs requested (interrupt) */
    volatile uint32_t mid_done; /* runs completed (fw_medium) */
    /* The medium task's own state: the speed PI, field weakening and the
     * torque limit (regulators/field_weak.h: the flux the voltage allows,
     * torque limit from the current circle, the voltage ellipse and MTPV). */
    ctrl_speed_pi_t speed_pi;
    ctrl_fieldweak_t fieldweak;
    q24_t torque_max; /* the last run's torque limit, Q24 pu (speed PI's anti-windup) */
    uint8_t mid_mode; /* the last run's fw_ref_mode_t */
    fw_speed_info_t speed_info;
    fw_state_t sm;
    fw_protect_t prot;
    fw_torque_follow_t tqf; /* torque supervision */
    /* calibration */
    uint32_t calib_samples, calib_n;
    uint32_t calib_sum[3];
    int32_t off_q8[3];     /* Q8 counts */
    int32_t gain_q30[3];   /* Q30 pu per count */
    int32_t vdc_gain_q30;  /* Q30 pu per count */
    uint16_t adc_zero;     /* expected offset, counts (hal_info_t.adc_current_zero) */
    uint16_t adc_zero_tol; /* accepted deviation of the measured offsets, counts */
    uint32_t pwm_n8;       /* period_counts * 2^8 if period_counts < 2^24, else 0 */
    q24_t duty_max;        /* largest leg duty the HAL applies (hal_info_t.pwm_cmp_max), Q24 */
    /* encoder */
    uint32_t enc_cpr;
    uint32_t enc_q32; /* floor(p 2^32 / cpr) mod 2^32 (angle per count, integer part) */
    uint32_t enc_r;   /* p 2^32 mod cpr (remainder), cpr < 2^16 */
    uint32_t enc_last;
    uint32_t enc_pos; /* [0, cpr) */
    bool enc_primed;
    bool enc_index_valid;    /* enc_index_last holds a latched index */
    uint32_t enc_index_last; /* counter value at the last index pulse */
    fx_angle_t enc_offset;
    uint32_t enc_neg; /* 0, or all ones: the count is negated (direction -1) */
    /* commissioning (firmware/commission): steps, results */
    cm_t cm;
    const char *cm_what; /* quantity the commissioning limits could not represent */
    uint8_t cm_gates;    /* gates enabled by a commissioning step */
    bool busy;           /* re-entry flag */
    uint32_t period;     /* periods so far (interrupt; the main loop reads it for the watchdog) */
    /* Telemetry ring: the interrupt writes each period's record into slot
     * isr.tm_head and publishes it (tm_head + 1) once in tm_every periods;
     * the main loop takes records from ml.tm_tail (fw_tm_peek /
     * fw_tm_release). Single producer, single consumer: the interrupt never
     * writes a slot in [tm_tail, tm_head). */
    fw_telemetry_t tm_ring[FW_TM_RING];
    fw_telemetry_t *tm_slot;       /* &tm_ring[tm_head mod FW_TM_RING], kept with tm_head */
    const fw_telemetry_t *tm_last; /* the last complete record */
    uint32_t tm_every;             /* interrupt: publish one record in tm_every periods; 0: none */
    uint32_t tm_count;             /* interrupt: periods until the next publication */
    ctrl_diag_t why;               /* why the core refused the last configuration (fw_explain) */
    /* PM-flux tracking (fw_config_t.psi_adapt, estimation/psi_track.h); last,
     * so that its size moves no other field's offset (code size). */
    ctrl_psi_track_t psi_track;
    /* Live changes (fw_speed_retune, fw_tunable_set while running), after it
     * for the same reason: the main loop fills the speed PI's new gains or
     * the controller's state for its new configuration, then requests it
     * (FW_REQ_SPEED_TUNE, FW_REQ_CTRL_TUNE); the interrupt takes the change at
     * its next period's start (fw_apply_commands). The main loop writes
     * neither while its request is pending (fw_tune_pending). */
#if PMSM_LIVE_PARAMS
    ctrl_speed_pi_t speed_pi_next;
    union {
        max_align_t align;
        unsigned char bytes[CTRL_STATE_MAX];
    } ctrl_next;
    /* The interrupt's: the speed PI's change it took, for the medium task's
     * next run (fw_mid_in_t.retune), which applies it between two of its
     * steps; the interrupt never writes speed_pi, which a step may be
     * half-way through when it preempts. */
    ctrl_speed_pi_t speed_pi_taken;
    uint8_t mid_retune; /* 1: speed_pi_taken waits for the next run */
#endif
    /* Sensorless start supervision (pipeline.c, FW_FAULT_SL_START): periods
     * off the observer with a speed asked for beyond the handover's, periods
     * on it since, and the bound (3 x the ramp, settle and polarity pulses'
     * periods + 0.25 s; pipeline_config.c). */
    uint32_t sl_forced_n, sl_obs_n, sl_forced_max;
#if CTRL_SL_HFI
    uint32_t hfi_clipped; /* periods whose injection was clamped (its legs had no room) */
    q24_t hfi_w_still;    /* |speed| the field weakening takes as standstill (medium.c), Q24 pu */
#endif
#if CTRL_COGGING
    /* Anti-cogging (cogging_ff.h, cm_cogging.h): the table, which the step
     * "cogging" measures, and cog_on (main loop: fw_cogging_enable), which
     * adds it to the torque reference in the running state. Last, for the
     * same reason as above. */
    cm_cog_t cog;
    volatile uint8_t cog_on;
#endif
} fw_t;

/* Configuration defaults: speed loop sized from the machine (speed_loop.h),
 * torque limit from the ratings (the rated torque, or less at a fixed flux
 * reference: fw_torque_limit_nm), overspeed at 1.05 x the maximum speed, 256 samples. */
void fw_config_default(fw_config_t *c, const ctrl_machine_t *machine, const ctrl_desc_t *ctrl);

/* Bind the HAL, compute the fixed-point conversion, initialise the controller
 * and protections; gates off, state boot. Returns FW_OK or FW_E*. */
int fw_init(fw_t *fw, hal_t *hal, const fw_config_t *cfg);
const char *fw_strerror(int code);
/* The quantity, value and accepted range behind the last refusal of fw_init,
 * fw_select_controller or fw_tunable_set (when the core said why; else "ok"),
 * as one line (ctrl_diag_format). */
size_t fw_explain(const fw_t *fw, char *buf, size_t cap);

/* The PWM-period interrupt; true when it has handed the medium-rate task a
 * run (the caller then runs fw_medium at a lower priority, to end before the
 * next period's interrupt). */
bool fw_isr_fast(fw_t *fw);
/* The medium-rate task (medium.c): one run on the inputs of the last trigger. */
void fw_medium(fw_t *fw);
/* The medium task's completion of the first period after a reset (pipeline.c;
 * fw_medium only): the rest of that period after the estimate, with its run's
 * outputs mo. */
void fw_mid_first_step(fw_t *fw, const fw_mid_in_t *in, const fw_mid_out_t *mo);
/* One PWM period with the medium task where due: fw_isr_fast, then fw_medium
 * (the scheduler of the host engine, the replay images and the tests). */
void fw_isr(fw_t *fw);

/* Main-loop side (called from the command interface or a test). */
void fw_cmd_arm(fw_t *fw);
void fw_cmd_disarm(fw_t *fw);
void fw_cmd_clear(fw_t *fw);
/* Main loop: request k, its data stored before it (a release fence), the
 * sum counted last (fw_from_main_t). */
void fw_request(fw_t *fw, fw_req_t k);
/* A request made and not yet taken by the interrupt. */
bool fw_cmd_pending(const fw_t *fw, fw_req_t k);
#if PMSM_LIVE_PARAMS
/* Main loop: the live change k (FW_REQ_SPEED_TUNE or FW_REQ_CTRL_TUNE) not
 * taken yet is superseded: the interrupt will take it and apply nothing. Its
 * data may be rewritten after this returns. */
void fw_request_withdraw(fw_t *fw, fw_req_t k);
/* A live change of kind k requested, not withdrawn and not taken yet. */
bool fw_tune_pending(const fw_t *fw, fw_req_t k);
#endif
void fw_watchdog_kick(fw_t *fw);
void fw_set_torque_ref(fw_t *fw, q24_t torque_pu); /* selects torque mode */
void fw_set_speed_ref(fw_t *fw, q24_t omega_e_pu); /* selects speed mode */
/* The references as the main loop set them (fw_from_main_t). */
fw_ref_mode_t fw_ref_mode(const fw_t *fw);
q24_t fw_torque_ref(const fw_t *fw);
q24_t fw_speed_ref(const fw_t *fw);
/* Main loop: the speed loop's torque reference of the medium task's last run
 * (the slot it reads is rewritten only two runs later; one aligned word). */
q24_t fw_speed_loop_torque(const fw_t *fw);
/* Main loop: the interrupt's period count (for the watchdog, the telemetry's
 * time). */
uint32_t fw_period_count(const fw_t *fw);
/* SI helpers (pipeline_config.c; not for the ISR). */
void fw_set_torque_ref_nm(fw_t *fw, double nm);
void fw_set_speed_ref_rpm(fw_t *fw, double rpm); /* clamped to +-speed_info.speed_ref_max_rpm */

fw_state_id_t fw_state(const fw_t *fw);
/* Main loop: the request the interrupt has not taken yet that turns the
 * gates on at its next period ("arm", "commissioning start"), or NULL; then
 * *state (read after the requests: an interrupt that takes one in between has
 * set the state by the time it is read). */
const char *fw_gates_request_pending(const fw_t *fw, fw_state_id_t *state);
/* Main loop: the gates are on (running, commissioning) or go on at the next
 * period (a request pending): no reconfiguration, no flash access. */
bool fw_gates_on_or_pending(const fw_t *fw);
uint32_t fw_fault(const fw_t *fw);
/* The record of the last period (zeroes before the first; NULL for NULL). */
const fw_telemetry_t *fw_telemetry(const fw_t *fw);
/* Main loop: publish one record in every `every` periods into the ring, the
 * first at the period that takes the request (0: stop); records of the
 * earlier stream not yet taken are dropped. */
void fw_tm_stream(fw_t *fw, uint32_t every);
/* Records not published because the main loop was a full ring behind. */
uint32_t fw_tm_dropped(const fw_t *fw);
/* Main loop: the oldest published record not yet taken, or NULL; it stays
 * valid until fw_tm_release(). */
const fw_telemetry_t *fw_tm_peek(fw_t *fw);
void fw_tm_release(fw_t *fw);
/*
 * Main-loop side, configuration time (double allowed; pipeline_config.c).
 * Refused with FW_EBUSY while the gates are on or an arm or commissioning
 * start is pending (fw_gates_on_or_pending: the ISR steps, or is about to
 * step, the controller state these replace).
 * fw_select_controller: cfg NULL = desc->cfg_default(machine); on failure the
 * previous controller stays selected. fw_tunable_set re-initialises the
 * controller with the changed value (FW_ENOENT unknown name, FW_EINVAL range);
 * a name "hfi.<field>" (an image with the injection) is the injection's
 * setting (fw_config_t.hfi_cfg, hfi_config.h), the drive set up again with it.
 */
int fw_select_controller(fw_t *fw, const ctrl_desc_t *desc, const void *cfg);
int fw_tunable_set(fw_t *fw, const char *name, double value);
int fw_tunable_get(const fw_t *fw, const char *name, double *value);
/*
 * Live changes (main loop; taken by the interrupt at its next period, in any
 * state; docs/console.md "Live changes"):
 * - fw_tunable_set with the gates on (or about to go on) changes a tunable
 *   the controller marks live (ctrl_desc_t.live, retune: bumpless where its
 *   state would step), else FW_EBUSY;
 * - fw_speed_retune: the speed loop's bandwidth, phase margin and gains
 *   (fw_config_t.speed_bw_hz, speed_pm_deg, speed_kp, speed_ki), with the
 *   gates on or off: the speed PI's new gains, its integrator carried over
 *   bumplessly (ctrl_speed_pi_retune); FW_EINVAL when the design refuses the
 *   bandwidth or the margin (speed_loop.h), FW_ERANGE (fw->why) when the
 *   gains do not fit; the configuration in force stays then.
 * Both: FW_EBUSY while the previous change waits for the interrupt, and
 * always in an image built without live changes (PMSM_LIVE_PARAMS 0).
 * fw_tunable_is_live: tunables[index] of the selected controller is live.
 */
int fw_speed_retune(fw_t *fw, double bw_hz, double pm_deg, double kp, double ki);
#if PMSM_LIVE_PARAMS
bool fw_tunable_is_live(const fw_t *fw, size_t index);
#else
static inline bool fw_tunable_is_live(const fw_t *fw, size_t index)
{
    (void)fw;
    (void)index;
    return false;
}
#endif

/*
 * Commissioning (main loop; cm.h, docs/identification.md).
 * fw_commission_start: run the steps in order (state ready, calibrated);
 *   FW_EBUSY when not ready, FW_ENOENT when a step needs a result no earlier
 *   step gives (*missing = the step to run first). The ISR enters state
 *   COMMISSION at the next period (FW_ERANGE: the commissioning limits do not
 *   fit this machine, fw->cm_what names the quantity); a failed step latches
 *   FW_FAULT_COMMISSION
 *   (gates off) with the reason in fw->cm.err; stop (fw_cmd_disarm) ends it.
 * fw_commission_apply: the identified Rs, Ld, Lq, psi_pm, inertia, the
 *   encoder offset/direction and (CM_MECH) the Coulomb and viscous friction
 *   replace the configured ones (controller and
 *   estimator re-initialised from the new machine; tunables back to their
 *   defaults). State ready only (FW_EBUSY), FW_ERANGE if they do not fit.
 * fw_commission_poll: applies a completed identification (ident run) once.
 */
int fw_commission_start(fw_t *fw, const uint8_t *steps, uint8_t n, uint8_t *missing);
int fw_commission_apply(fw_t *fw);
bool fw_commission_poll(fw_t *fw);
/* Results in SI (direction absolute). */
void fw_commission_results(const fw_t *fw, cm_si_t *out);

/* What the drive holds beyond its machine data (fw_t.machine_own) that
 * fw_commission_apply adopts, or a configuration gave: the encoder's offset
 * and direction and, with the mechanics' identification, the friction. An
 * application that re-initialises the firmware with new machine data but no
 * configuration of its own (a board's "param set m.*") reads them before
 * fw_init (fw_kept_read: fw_init clears fw_t) and puts them into the new
 * configuration (fw_kept_config), so that an identified motor is not
 * undone by a change of one of its parameters. */
typedef struct {
    fx_angle_t enc_offset;
    int8_t enc_direction;
#if CM_MECH
    double coulomb_nm, viscous_nms;
#endif
} fw_kept_t;
void fw_kept_read(const fw_t *fw, fw_kept_t *k);
void fw_kept_config(const fw_kept_t *k, fw_config_t *c);

/* The configuration in force: the drive's settings (fw_t.cfg), the
 * controller and its tunables (a "param set wc" before it) — what a refused
 * reconfiguration puts back ("the previous data stay"), not the defaults.
 * Read before fw_init (fw_in_force_read: fw_init clears fw_t). A board keeps
 * it static (main loop only), so that the deepest command path's stack
 * (config default -> fw_init) does not grow by it.
 * fw_in_force_config: *c as it was, on machine m, with what the drive held
 * beyond its machine data (kept); false, *c untouched, when no controller
 * was installed (the caller's defaults then). c->ctrl_cfg points into *f. */
typedef struct {
    fw_config_t cfg; /* cfg.ctrl: the controller in use (fw_t.ctrl) */
    union {
        max_align_t align;
        unsigned char bytes[CTRL_CFG_MAX];
    } ctrl_cfg;
} fw_in_force_t;
void fw_in_force_read(const fw_t *fw, fw_in_force_t *f);
bool fw_in_force_config(const fw_in_force_t *f, const ctrl_machine_t *m, const fw_kept_t *kept,
                        fw_config_t *c);

/*
 * Anti-cogging feed-forward (main loop; docs/anticogging.md). The table of
 * the step "cogging" (cm_cogging.h) or one loaded (settings, tests) is added
 * to the torque reference of every controller while running with the
 * encoder, within the period's torque limit.
 * fw_cogging_enable: on (FW_ENOENT without a table measured with this
 *   encoder's counts and direction, FW_EINVAL sensorless: no mechanical
 *   angle, FW_ERANGE a look-ahead that does not fit) or off; taken at the
 *   next period. The table is read ahead of the position by the speed times
 *   the controller's delay from torque reference to torque (FOC 1.5 Ts +
 *   1 / wc, the predictive controllers 2 Ts, the hysteresis ones none;
 *   docs/anticogging.md), set again with each controller.
 * fw_cogging_load: n entries of Q15 of the rated torque against the encoder
 *   position (cogging_ff.h), measured with the encoder's present counts
 *   (the caller checked), n = CTRL_COG_N (else FW_ERANGE); gates off
 *   (FW_EBUSY); the feed-forward stays as it was (off after a load that
 *   replaces a table in use).
 * fw_cogging_table: the table and its entries (NULL when there is none).
 * All FW_ENOENT / NULL in an image without it (CTRL_COGGING 0).
 */
int fw_cogging_enable(fw_t *fw, bool on);
int fw_cogging_load(fw_t *fw, const int16_t *table, uint32_t n);
const int16_t *fw_cogging_table(const fw_t *fw, uint32_t *n);

/* Controller state block (for tests). */
void *fw_ctrl_state(fw_t *fw);

#endif /* FIRMWARE_PIPELINE_H */
