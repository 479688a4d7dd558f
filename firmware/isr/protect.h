/*
 * Drive protections. Each check is a small integer-only inline function the
 * pipeline calls in a fixed order every PWM period; each returns 0 or a fault
 * code (FW_FAULT_*), which the pipeline latches through the state machine.
 * The straightforward forms they are checked against (saturating |i| > i_max,
 * the per-move Q16.16 encoder rate) live in tests/loop/test_fw_fast.c.
 *
 * Criteria (thresholds derived from the machine in protect_config.c):
 *  - over-current: |i_a|, |i_b| or |i_c| > i_max (machine current_max_a). The
 *    pipeline calls it first, right after the conversion, and switches the
 *    gates off in the same period (before the estimator runs).
 *  - hardware trip input (hal_trip_active): same reaction.
 *  - DC link: v_dc > vdc_max (default 1.25 Vdc_nom) or < vdc_min (0.70 Vdc_nom)
 *    on one sample (the link capacitor makes a one-sample excursion of 25 %
 *    implausible as noise: ADC noise is a few counts).
 *  - encoder stuck: the counter has not moved for enc_stuck_periods periods
 *    although the rate its last move proves was >= enc_rate_min. That rate is
 *    a lower bound of the rotor's speed, not the move over the time it took: a
 *    rotor resting on a count edge toggles the count back and forth while it
 *    hardly moves (fw_protect_encoder_check). enc_rate_min is the
 *    rate from which the rotor, decelerated by the largest torque the drive and
 *    load can produce (a_max = (T(i_max) + T_rated) / J), still travels at
 *    least two counts before it can stop: r^2 / (2 a_max) >= 2 counts. Below it
 *    a stop cannot be told from a stuck sensor (documented limitation).
 *  - encoder jump: |delta_k - delta_{k-1}| > enc_jump_max counts (second
 *    difference of the count) with delta_k != 0. A real rotor changes its rate
 *    by at most a_max*Ts^2 counts per period; quantisation adds +-2 counts.
 *    delta_k == 0 is left to the stuck check (a frozen counter is "stuck").
 *  - deadline: the ISR entered while the previous one was still running
 *    (re-entry flag) or its duration measured with hal_cycles exceeded the
 *    period (cycle budget from hal_info_t.cycle_clock_hz).
 *  - watchdog: the periods since the main loop's last kick (fw_watchdog_kick
 *    stamps the interrupt's period count; the interrupt subtracts, so each
 *    side writes only its own count); more than wdg_periods of them is a
 *    fault.
 *  - overspeed: |estimated electrical speed| > omega_max, checked while
 *    running right after the estimator. Level: the machine's maximum speed
 *    (fw_speed_max_rpm: declared, or where the back-EMF meets the DC link) x
 *    FW_OVERSPEED_REL unless configured (fw_config_t.overspeed_rpm). In
 *    torque mode with a light load the rotor accelerates until the torque
 *    limit meets the load, which this catches. The speed-reference limit is
 *    the level / FW_OVERSPEED_REL (the maximum speed by default).
 */
#ifndef FIRMWARE_PROTECT_H
#define FIRMWARE_PROTECT_H

#include <stdbool.h>
#include <stdint.h>

#include "ctrl_params.h"
#include "fx.h"

enum {
    FW_FAULT_NONE = 0,
    FW_FAULT_OVERCURRENT = 1,   /* phase current above i_max */
    FW_FAULT_HW_TRIP = 2,       /* hardware trip comparator */
    FW_FAULT_DC_OVERVOLT = 3,   /* DC link above vdc_max */
    FW_FAULT_DC_UNDERVOLT = 4,  /* DC link below vdc_min */
    FW_FAULT_ENC_STUCK = 5,     /* encoder counter frozen while turning */
    FW_FAULT_ENC_JUMP = 6,      /* implausible encoder step */
    FW_FAULT_DEADLINE = 7,      /* ISR overrun or re-entry */
    FW_FAULT_WATCHDOG = 8,      /* main loop stopped kicking */
    FW_FAULT_CALIB = 9,         /* ADC offset outside the plausible range */
    FW_FAULT_OVERSPEED = 10,    /* |speed| above the overspeed level */
    FW_FAULT_COMMISSION = 11,   /* a commissioning step failed (cm_t.err names why) */
    FW_FAULT_SPEED_FOLLOW = 12, /* speed moves away from its reference at full torque */
    FW_FAULT_TORQUE_FOLLOW =
        13,                 /* mean torque estimate off the applied reference (torque_follow.h) */
    FW_FAULT_SL_START = 14, /* sensorless start: still on the forced angle after its time */
    FW_FAULT_COUNT = 15
};

/* Overspeed level relative to the machine's maximum speed (criteria above). */
#define FW_OVERSPEED_REL 1.05

/*
 * The machine's maximum mechanical speed (r/min): m->speed_max_rpm when
 * declared (> 0), else the speed at which the magnets' line-to-line back-EMF
 * reaches the DC link, sqrt(3) w_e psi_pm = Vdc, but at least the rated speed.
 * Above that speed a fault that turns the gates off leaves the inverter's
 * diodes rectifying the back-EMF into the DC link (uncontrolled generation:
 * braking current and link overvoltage), so a drive must not go there unless
 * the machine's data say it is built for it (field weakening keeps the
 * terminal voltage down only while the gates are on). Thesis SPMSM: 3217
 * r/min; 80 kW IPMSM: 3970 r/min; the machine files declare their range.
 * Returns 0 for a declared value below the rated speed or not finite.
 */
double fw_speed_max_rpm(const ctrl_machine_t *m);

/* Name of a fault code ("overcurrent", ...); "unknown" for others. */
const char *fw_fault_name(uint32_t code);

typedef struct {
    q24_t i_max;                /* phase-current trip level, Q24 pu (> 0) */
    q24_t vdc_max, vdc_min;     /* DC-link window, Q24 pu */
    int32_t enc_jump_max;       /* counts; max |second difference| per period */
    uint32_t enc_stuck_periods; /* periods without a count before "stuck" */
    int32_t enc_rate_min_q16;   /* counts per period, Q16.16; stuck check armed above */
    uint32_t deadline_cycles;   /* cycle budget per ISR; 0 disables the overrun check */
    uint32_t wdg_periods;       /* periods without a kick before the fault; 0 disables */
    q24_t omega_max;            /* overspeed level, Q24 pu electrical speed (> 0) */
    uint32_t follow_periods;    /* speed following: periods beyond its band before the fault */
} fw_protect_cfg_t;

typedef struct {
    fw_protect_cfg_t cfg;
    /* |x| > lim as one unsigned compare, (uint32_t)x + off > span (mod 2^32)
     * with off = lim, span = 2 lim (constants from fw_protect_init): for
     * 0 <= lim <= INT32_MAX, x + lim lies in [0, 2 lim] exactly when |x| <= lim,
     * in (2 lim, 2^32) when x > lim and, wrapped, in [2^31 + lim, 2^32) when
     * x < -lim. */
    uint32_t i_off, i_span; /* i_max, 0 <= i_max <= FW_PROTECT_I_MAX_LIM */
    uint32_t j_off, j_span; /* enc_jump_max (enc_primed 2 only when it is >= 0) */
    uint32_t enc_last;      /* counter at the previous period */
    int32_t enc_last_delta; /* counts moved in the previous period */
    uint32_t enc_still;     /* periods since the counter last moved */
    /* The last move: its counts (the sign is its direction), the counts the
     * rotor surely travelled and the periods without a move before it. Rate
     * (Q16.16) = floor(move_dist 2^16 / (move_still + 2)). */
    int32_t enc_move_delta;
    uint32_t enc_move_dist;
    uint32_t enc_move_still;
    /* 0: nothing, 1: enc_last valid, 2: enc_last_delta valid (fast form),
     * 3: the same with a negative enc_jump_max (every move is a jump). */
    uint8_t enc_primed;
    /* deadline_cycles and wdg_periods with 0 ("off") as UINT32_MAX, which no
     * uint32_t exceeds: one compare each. */
    uint32_t deadline_lim, wdg_lim;
    /* Speed following (fw_protect_speed_follow): the reference it watches, the
     * least |speed error| since the torque reached its limit (Q24 pu
     * electrical), 1 while it does. */
    q24_t follow_ref, follow_min; /* INT32_MAX: torque not at its limit */
    uint32_t follow_count;        /* consecutive periods beyond the band */
} fw_protect_t;

/*
 * Thresholds from SI data (protect_config.c, configuration time only):
 * machine (current_max_a, vdc_v, torque_rated_nm, inertia_kgm2, pole pairs),
 * the control frequency, the encoder resolution, the ADC-side bases and the
 * overspeed level (mechanical r/min, > 0).
 * Returns CTRL_OK, or CTRL_EINVAL / CTRL_ERANGE for missing, non-physical or
 * unrepresentable data with *why (if not NULL) naming the quantity, its value
 * and its range.
 */
int fw_protect_config(fw_protect_cfg_t *cfg, const ctrl_machine_t *m, const ctrl_bases_t *b,
                      uint32_t fs_hz, uint32_t enc_counts_per_rev, uint32_t cycle_clock_hz,
                      double overspeed_rpm, ctrl_diag_t *why);

/* Largest trip level the current check takes (64 pu): then i_c = -(i_a + i_b)
 * of two in-range phases stays below 2^31 and one unsigned compare decides. */
#define FW_PROTECT_I_MAX_LIM ((q24_t)1 << 30)

/* Copies cfg and derives the constants of the checks from it: change the
 * configuration only through fw_protect_init. CTRL_OK, or CTRL_EINVAL (p
 * unchanged) for i_max outside [0, FW_PROTECT_I_MAX_LIM]. */
int fw_protect_init(fw_protect_t *p, const fw_protect_cfg_t *cfg);
/* Forget the encoder history (on arm, on a fault clear). */
void fw_protect_reset(fw_protect_t *p);

/* ---- The checks, inlined into the interrupt. ---- */

/* fw_protect_encoder while the counter history is incomplete, or with a
 * negative enc_jump_max (enc_primed != 2; protect.c). */
uint32_t fw_protect_encoder_prime(fw_protect_t *p, uint32_t count);

/*
 * Over-current: |i_a|, |i_b| or |i_c| = |i_a + i_b| > i_max with the unsigned
 * compare of fw_protect_t (0 <= i_max <= 2^30). i_c is decided only when
 * |i_a|, |i_b| <= i_max: then |i_a + i_b| <= 2^31 and the compare is exact
 * for it too (3 i_max < 2^32); when i_a or i_b already trips, the third term
 * does not matter.
 */
static inline uint32_t fw_protect_current(const fw_protect_t *p, q24_t i_a, q24_t i_b)
{
    const uint32_t off = p->i_off;
    const uint32_t span = p->i_span;
    const uint32_t a = (uint32_t)i_a;
    const uint32_t b = (uint32_t)i_b;
    if (a + off > span || b + off > span || a + b + off > span) {
        return FW_FAULT_OVERCURRENT;
    }
    return FW_FAULT_NONE;
}

static inline uint32_t fw_protect_vdc(const fw_protect_t *p, q24_t vdc)
{
    if (vdc > p->cfg.vdc_max) {
        return FW_FAULT_DC_OVERVOLT;
    }
    if (vdc < p->cfg.vdc_min) {
        return FW_FAULT_DC_UNDERVOLT;
    }
    return FW_FAULT_NONE;
}

/* *d = a - b; true (and *d = 0) when the difference does not fit an int32_t
 * (gcc/clang: their overflow builtin, SUBS + a branch on V). */
static inline bool fw_protect_sub_overflow(int32_t a, int32_t b, int32_t *d)
{
#if defined(__GNUC__)
    if (__builtin_sub_overflow(a, b, d)) {
        *d = 0;
        return true;
    }
    return false;
#else
    const int64_t w = (int64_t)a - b;
    const bool ovf = w < INT32_MIN || w > INT32_MAX;
    *d = ovf ? 0 : (int32_t)w;
    return ovf;
#endif
}

/* Whether the rate at the last move, floor(dist 2^16 / (still + 2)) (the
 * Q16.16 counts per period), is >= rate_min: for integers, floor(a / b) >= r
 * <=> a >= r b (b >= 1), so no division; a <= 2^48, r b < 2^63. */
static inline bool fw_protect_rate_armed(const fw_protect_t *p)
{
    const int32_t r = p->cfg.enc_rate_min_q16;
    if (r <= 0) {
        return true;
    }
    const uint64_t a = (uint64_t)p->enc_move_dist << 16;
    return a >= (uint64_t)(uint32_t)r * ((uint64_t)p->enc_move_still + 2u);
}

/*
 * fw_protect_encoder once the history is complete (enc_primed 2 or 3): the
 * signed modulo-2^32 difference; at a move the jump test on its second
 * difference (a difference of two int32_t that overflows is above any limit)
 * and the move's size and duration; without a move the stuck test.
 */
static inline uint32_t fw_protect_encoder_check(fw_protect_t *p, uint32_t count)
{
    const int32_t delta = fx_u2i(count - p->enc_last);
    p->enc_last = count;
    uint32_t fault = FW_FAULT_NONE;
    if (delta != 0) {
        int32_t dd;
        const bool ovf = fw_protect_sub_overflow(delta, p->enc_last_delta, &dd);
        if (p->enc_primed != 2u || ovf || (uint32_t)dd + p->j_off > p->j_span) {
            fault = FW_FAULT_ENC_JUMP;
        }
        /* What the move proves (counts seen in its direction). The previous
         * move took the count to c; at the sample before it the rotor was
         * short of edge c. If this move goes the same way, the rotor is past
         * edge c + |delta| now: more than |delta| counts in the still + 2
         * periods since. Reversed (or no move before), the first edge it
         * passed may be the one it passed the other way just before: more
         * than |delta| - 1 counts in the last period, so over the still + 2
         * too. A count toggling at one edge (a rotor resting on it) proves 0. */
        const uint32_t mag = delta < 0 ? 0u - (uint32_t)delta : (uint32_t)delta;
        const bool same = delta > 0 ? p->enc_move_delta > 0 : p->enc_move_delta < 0;
        p->enc_move_dist = same ? mag : mag - 1u;
        p->enc_move_delta = delta;
        p->enc_move_still = p->enc_still;
        p->enc_still = 0u;
    } else {
        if (p->enc_still < UINT32_MAX) {
            p->enc_still++;
        }
        if (p->enc_still >= p->cfg.enc_stuck_periods && fw_protect_rate_armed(p)) {
            fault = FW_FAULT_ENC_STUCK;
        }
    }
    p->enc_last_delta = delta;
    return fault;
}

static inline uint32_t fw_protect_encoder(fw_protect_t *p, uint32_t count)
{
    if (p->enc_primed != 2u) {
        return fw_protect_encoder_prime(p, count); /* 0, 1, or 3 */
    }
    return fw_protect_encoder_check(p, count);
}

static inline uint32_t fw_protect_deadline(const fw_protect_t *p, uint32_t elapsed_cycles)
{
    if (elapsed_cycles > p->deadline_lim) {
        return FW_FAULT_DEADLINE;
    }
    return FW_FAULT_NONE;
}

/* |omega_e| > omega_max, as an unsigned compare (exact for 0 <= omega_max <
 * 2^31: omega + omega_max in [0, 2 omega_max] exactly when |omega| is within). */
static inline uint32_t fw_protect_overspeed(const fw_protect_t *p, q24_t omega_e)
{
    const uint32_t lim = (uint32_t)p->cfg.omega_max;
    if ((uint32_t)omega_e + lim > 2u * lim) {
        return FW_FAULT_OVERSPEED;
    }
    return FW_FAULT_NONE;
}

/*
 * Speed following (speed mode): while the speed loop's torque reference t is
 * at its limit t_max (the speed PI's output limit: the configured one, or the
 * last period's field-weakening limit) in the direction of the speed error
 * e = speed_ref - omega, |e| can only shrink - unless the load exceeds what
 * the drive can give, or the machine does not make the torque the estimator
 * reports (a sensorless angle off the rotor, a controller that lost the
 * torque). Either way the speed runs away under full torque, so once |e| has
 * stayed more than omega_max / 16 (the band: 6 % of the overspeed level,
 * 246 r/min on the thesis SPMSM, well above the sensorless speed estimate's
 * 14-31 r/min rms noise) above its least value since the torque saturated
 * for more than follow_periods (50 ms: the estimate's spikes are shorter) in
 * a row, the drive stops (gates off) instead of spinning up to the overspeed
 * trip. A new reference or a torque off its limit starts the watch again.
 */
uint32_t fw_protect_speed_follow(fw_protect_t *p, q24_t speed_ref, q24_t omega, q24_t t,
                                 q24_t t_max);

/* since: periods since the main loop's last kick (modulo 2^32: the fault
 * latches long before it wraps). */
static inline uint32_t fw_protect_watchdog_tick(const fw_protect_t *p, uint32_t since)
{
    return since > p->wdg_lim ? FW_FAULT_WATCHDOG : FW_FAULT_NONE;
}

#endif /* FIRMWARE_PROTECT_H */
