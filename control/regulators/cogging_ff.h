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
 * Per period: one 32x32->64 multiply for the angle, two table reads, two
 * 16x16 multiplies, one 32x32->64 multiply for the scale; no division.
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

typedef struct {
    const int16_t *table; /* n entries, Q15 of the rated torque */
    uint32_t n_log2;
    uint32_t cpr;       /* encoder counts per revolution the table was measured with */
    uint64_t pos_q48;   /* round(2^48 / cpr) */
    q24_t torque_rated; /* pu */
} ctrl_cogging_t;

/* Configuration (once): 0, or -1 when an argument is out of range (table
 * NULL, n_log2 outside [MIN, MAX], cpr outside [2, 2^31], torque_rated <= 0). */
int ctrl_cogging_init(ctrl_cogging_t *c, const int16_t *table, uint32_t n_log2, uint32_t cpr,
                      q24_t torque_rated);

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

/* The feed-forward torque at encoder position pos in [0, cpr), Q24 pu. */
static inline q24_t ctrl_cogging_ff(const ctrl_cogging_t *c, uint32_t pos)
{
    const uint32_t turn = ctrl_cogging_turn(c, pos);
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

#endif /* CONTROL_COGGING_FF_H */
