/*
 * Anti-cogging feed-forward (docs/anticogging.md): a table of the torque that
 * cancels the cogging torque against the rotor's mechanical angle, read at
 * the encoder's position every period and added to the torque reference.
 *
 * Cogging is a function of the mechanical angle alone (the magnets against
 * the stator teeth: lcm(slots, 2 p) periods per revolution and harmonics),
 * so the table covers one revolution of the encoder's position, which the
 * calibration (firmware/commission/cm_cogging.c) measured with the same
 * counts per revolution and direction. The table is not tied to one slot
 * count: any periodic or once-per-revolution shape is kept.
 *
 * Formats:
 *   table[i]  int16_t, Q15 of the rated torque (LSB T_rated / 2^15, range
 *             +-T_rated): the electromagnetic torque that cancels the cogging
 *             at the mechanical angle i / n of a turn from encoder position 0
 *             (= -T_cog there)
 *   n         2^n_log2 entries, CTRL_COG_N_LOG2_MIN <= n_log2 <= CTRL_COG_N_LOG2_MAX
 *   turn      Q32 fraction of a revolution: pos * pos_q48 / 2^16 with
 *             pos_q48 = round(2^48 / cpr) (|error| < pos / 2^17 LSB, below a
 *             thousandth of a count)
 *   output    Q24 pu torque: linear interpolation between the two entries
 *             around the angle (15-bit fraction), times torque_rated
 *   lead      look-ahead, Q32 turns per pu electrical speed (int32_t, >= 0):
 *             round(tau w_base / (2 pi p) 2^32), tau the drive's delay from
 *             the torque reference to the torque (docs/anticogging.md); the
 *             advance omega_e (Q24 pu) * lead / 2^24 saturates to +-1/2 turn
 *             and is added to the turn modulo one turn (an angle)
 *   w_k       the look-ahead's speed filter, Q24: 1 - exp(-2 pi fc Ts); the
 *             encoder's speed (quantised to a count per period) averaged
 *             over about 1 / (2 pi fc), w_acc Q48 pu, w Q24 pu
 *   pos_held  the encoder position of the last table read (CTRL_COG_NONE:
 *             none since the last restart), ff_held its output, Q24 pu
 * Per period (ctrl_cogging_step): the speed filter (one 32x32->64 multiply);
 * when the position has moved, one 32x32->64 multiply for the angle, one for
 * the advance, two table reads, two 16x16 multiplies, one 32x32->64 multiply
 * for the scale; no division.
 */
#ifndef CONTROL_COGGING_FF_H
#define CONTROL_COGGING_FF_H

#include <stdbool.h>
#include <stdint.h>

#include "fx.h"

#define CTRL_COG_N_LOG2_MIN 3u
#define CTRL_COG_N_LOG2_MAX 12u
/* The firmware's table: 2048 entries (4 KiB) - about 8 points per period of
 * a 24-slot, 22-pole gimbal motor's cogging (264 periods per revolution). */
#define CTRL_COG_N_LOG2 11u
#define CTRL_COG_N (1u << CTRL_COG_N_LOG2)
/* Entries per rated torque (Q15). */
#define CTRL_COG_ONE 32768
/* pos_held before the first read (positions are below cpr <= 2^31). */
#define CTRL_COG_NONE UINT32_MAX

typedef struct {
    const int16_t *table; /* n entries, Q15 of the rated torque */
    uint32_t n_log2;
    uint32_t cpr;       /* encoder counts per revolution the table was measured with */
    uint64_t pos_q48;   /* round(2^48 / cpr) */
    q24_t torque_rated; /* pu */
    int32_t lead;       /* Q32 turns per pu electrical speed (0: none) */
    int32_t w_k;        /* speed filter's gain, Q24, (0, 2^24] */
    int64_t w_acc;      /* filtered electrical speed, Q48 pu */
    q24_t w;            /* its Q24 value */
    uint32_t pos_held;  /* encoder position of the last read, CTRL_COG_NONE: none */
    q24_t ff_held;      /* the feed-forward read there, Q24 pu */
} ctrl_cogging_t;

/* Configuration (once): 0, or -1 when an argument is out of range (table
 * NULL, n_log2 outside [MIN, MAX], cpr outside [2, 2^31], torque_rated <= 0). */
int ctrl_cogging_init(ctrl_cogging_t *c, const int16_t *table, uint32_t n_log2, uint32_t cpr,
                      q24_t torque_rated);

/* The look-ahead and its speed filter (formats above), restarted: 0, or -1
 * when lead < 0 or w_k outside (0, 2^24] (left unchanged). */
int ctrl_cogging_set_lead(ctrl_cogging_t *c, int32_t lead, int32_t w_k);

/* Forget the speed and the last read (the feed-forward off, or the drive
 * stopped): the next ctrl_cogging_step starts the filter at its speed. */
static inline void ctrl_cogging_restart(ctrl_cogging_t *c)
{
    c->pos_held = CTRL_COG_NONE;
    c->ff_held = 0;
    c->w_acc = 0;
    c->w = 0;
}

/* One period of the look-ahead's speed filter on omega_e (Q24 pu): the
 * filtered speed, Q24 pu. |w_acc| < 2^55: each step adds < 2^31 * 2^24 and
 * the average stays within the input's range. */
static inline q24_t ctrl_cogging_speed(ctrl_cogging_t *c, q24_t omega_e)
{
    c->w_acc += (int64_t)fx_sub(omega_e, c->w) * c->w_k;
    c->w = fx_round_sat(c->w_acc, FX_QBITS);
    return c->w;
}

/* Q32 fraction of a revolution at encoder position pos in [0, cpr). */
static inline uint32_t ctrl_cogging_turn(const ctrl_cogging_t *c, uint32_t pos)
{
    /* pos < cpr: pos * pos_q48 <= 2^48 + 2^31 fits 64 bits. */
    return (uint32_t)(((uint64_t)pos * c->pos_q48) >> 16);
}

/* Table index of a Q32 turn. */
static inline uint32_t ctrl_cogging_bin(const ctrl_cogging_t *c, uint32_t turn)
{
    return turn >> (32u - c->n_log2);
}

/* The feed-forward torque at the Q32 turn, Q24 pu. */
static inline q24_t ctrl_cogging_ff_turn(const ctrl_cogging_t *c, uint32_t turn)
{
    const uint32_t i = turn >> (32u - c->n_log2);
    const uint32_t mask = (1u << c->n_log2) - 1u;
    /* the 15 bits below the index: interpolation weight of the next entry */
    const int32_t f = (int32_t)((turn << c->n_log2) >> 17);
    const int32_t a = c->table[i];
    const int32_t b = c->table[(i + 1u) & mask];
    /* |a (2^15 - f) + b f| <= 2^15 * 2^15: Q30 of the rated torque */
    const int32_t v = a * (CTRL_COG_ONE - f) + b * f;
    return fx_round_sat((int64_t)v * c->torque_rated, 30u);
}

/* The feed-forward torque at encoder position pos in [0, cpr), Q24 pu. */
static inline q24_t ctrl_cogging_ff(const ctrl_cogging_t *c, uint32_t pos)
{
    return ctrl_cogging_ff_turn(c, ctrl_cogging_turn(c, pos));
}

/* The feed-forward torque at pos advanced by the speed omega_e (Q24 pu
 * electrical) times the drive's delay (lead): the torque made tau later
 * meets the cogging where the rotor will be then. */
static inline q24_t ctrl_cogging_ff_ahead(const ctrl_cogging_t *c, uint32_t pos, q24_t omega_e)
{
    /* |omega_e lead| < 2^62; the advance saturates to +-2^31 (half a turn) */
    const int32_t adv = fx_round_sat((int64_t)omega_e * c->lead, 24u);
    /* modulo 2^32 = one turn: an angle's wrap (conversion and sum defined) */
    return ctrl_cogging_ff_turn(c, ctrl_cogging_turn(c, pos) + (uint32_t)adv);
}

/* One period of the feed-forward at encoder position pos in [0, cpr) and the
 * encoder's speed omega_e (Q24 pu electrical), Q24 pu. The speed filter runs
 * every period (from omega_e itself after a restart); the table is read,
 * ahead by the filtered speed, only when the position has moved since the
 * last read. Between two counts the feed-forward holds as the position does:
 * the torque reference then changes no more often than without the
 * look-ahead (FST takes any change of its reference as a step, st_dtc.h). */
static inline q24_t ctrl_cogging_step(ctrl_cogging_t *c, uint32_t pos, q24_t omega_e)
{
    if (c->pos_held == CTRL_COG_NONE) {
        /* |omega_e| < 2^31: the product < 2^55 */
        c->w_acc = (int64_t)omega_e * FX_ONE;
        c->w = omega_e;
    }
    const q24_t w = ctrl_cogging_speed(c, omega_e);
    if (pos != c->pos_held) {
        c->pos_held = pos;
        c->ff_held = ctrl_cogging_ff_ahead(c, pos, w);
    }
    return c->ff_held;
}

#endif /* CONTROL_COGGING_FF_H */
