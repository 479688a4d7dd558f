/*
 * Step "cogging" (ident cogging): the anti-cogging table (cogging_ff.h)
 * measured against the encoder's position (docs/anticogging.md).
 *
 * Method (after ODrive's anti-cogging calibration, which holds a position at
 * each count; here a slow sweep under a stiff position loop, both ways): the
 * step runs the selected controller with a torque reference from its own
 * position loop (PD on the position error and the speed error, plus an
 * integral), whose reference moves at a constant slow speed, once forward
 * over `revs` revolutions, then backward. Well below the loop's bandwidth
 * the rotor follows the reference and the torque reference is the torque
 * that holds the rotor on it:
 *   forward:  T(theta) = -T_cog(theta) + T_fric + T_L
 *   backward: T(theta) = -T_cog(theta) - T_fric + T_L
 * (T_fric: Coulomb friction, a passive load and the viscous friction at the
 * sweep speed; T_L: an active load). The mean of each direction per table bin
 * (the torque reference's mean over the bin), the two directions averaged
 * (friction cancels), less their mean over the revolution (an active load
 * and any bias: cogging has no mean) is the table: -T_cog against the angle.
 * The mean difference of the directions is half of it the friction at the
 * sweep speed (reported).
 *
 * The loop's gains come from the configured inertia J (the identified one
 * once applied): Kp = J w^2, Kd = 2 zeta J w (zeta 0.8), Ki = Kp w / 8, with
 * w = 2 pi bw_hz. Its rejection of a disturbance at f is about
 * 1 - (f / bw)^2, so the sweep speed must put the cogging's periods well
 * below bw_hz: rpm / 60 * lcm(slots, 2p) <= bw_hz / 4 keeps the table within
 * about 6 % of the cogging (and the two directions' phase lags cancel in
 * the average).
 *
 * Errors: cog_follow (the rotor lags the reference by more than the error
 * that makes the rated torque, or 64 counts: blocked, loaded beyond the
 * rated torque, or a loop too weak for the cogging: detail the lag and the
 * bound in counts, the direction), cog_range (a mean beyond +-rated torque,
 * or a bin the sweep did not reach: detail the bin, the value in Q15 of the
 * rated torque), cog_config (the loop's gains do not fit their formats).
 */
#ifndef FIRMWARE_COMMISSION_CM_COGGING_H
#define FIRMWARE_COMMISSION_CM_COGGING_H

#include <stdint.h>

#include "cm.h"
#include "cogging_ff.h"

/* Sweep configuration (SI; 0 = the default). */
typedef struct {
    double rpm;    /* sweep speed, mechanical r/min (default 3) */
    double bw_hz;  /* position loop's natural frequency (default 50 Hz) */
    uint32_t revs; /* revolutions measured per direction (default 1) */
} cm_cog_config_t;

#define CM_COG_RPM_DEFAULT 3.0
#define CM_COG_BW_DEFAULT 50.0
/* bins converted per period at the end of a direction (one or two 64-bit
 * divisions each: 16 divisions cost about 30 % of a 20 kHz period's budget
 * on the Cortex-M4) */
#define CM_COG_BINS_PER_PERIOD 4u
#define CM_COG_CNT_MAX 4095u /* samples kept per bin and direction (sum < 2^28) */
/* bins' sums cleared per period of the first hold (all 12 KiB at once cost
 * more than a 20 kHz period's budget on the Cortex-M4) */
#define CM_COG_CLEAR_PER_PERIOD 64u

/* A gain as mantissa and shift: y = round(x m / 2^s). */
typedef struct {
    int32_t m;
    uint8_t s;
} cm_cog_gain_t;

typedef struct cm_cog {
    /* the table (cogging_ff.h) and the feed-forward's view of it */
    int16_t table[CTRL_COG_N];
    ctrl_cogging_t map;
    uint8_t valid;    /* the table holds a completed calibration */
    uint32_t enc_neg; /* the encoder direction it was measured with (fw_t.enc_neg) */
    uint32_t cal_cpr; /* the encoder counts per revolution it was measured with */
    /* per direction: Q16 pu torque sums and samples per bin */
    int32_t sum[CTRL_COG_N];
    uint16_t cnt[CTRL_COG_N];
    /* loop (cm_cogging_configure) */
    uint8_t ok;        /* configured */
    cm_cog_gain_t kp;  /* Q16 counts -> Q24 pu torque */
    cm_cog_gain_t kd;  /* Q24 pu electrical speed -> Q24 pu torque */
    cm_cog_gain_t ki;  /* Q16 counts x period -> Q24 pu torque */
    cm_cog_gain_t kw;  /* Q16 counts per period -> Q24 pu electrical speed */
    int32_t v_q16;     /* sweep speed, Q16 counts per period */
    int64_t e_max;     /* largest position error, Q16 counts */
    q24_t t_lim;       /* torque reference limit (rated), pu */
    uint32_t n_settle; /* periods of the hold before each sweep (0.2 s) */
    uint32_t n_ramp;   /* periods of the speed ramps (0.1 s) */
    uint32_t lead;     /* counts swept before measuring (1/16 revolution) */
    uint32_t revs;
    uint64_t progress_k; /* 1000 * 2^32 / the step's periods */
    /* run state */
    uint32_t last;       /* encoder position of the last period */
    int64_t pos;         /* unwrapped position, counts */
    int64_t pos_ref;     /* Q16 counts */
    int64_t mark;        /* position where the phase's travel began */
    int32_t v;           /* reference speed, Q16 counts per period */
    q24_t integ;         /* integral part, pu torque */
    int8_t dir;          /* +1 forward, -1 backward */
    uint32_t fin;        /* next bin of the conversion */
    uint32_t clr;        /* next bin of the sums' clearing (the first hold) */
    int64_t mean_sum[2]; /* sums of the directions' means (Q15 rated) */
} cm_cog_t;

/* SI -> the loop's formats (main loop, at configuration): 0, or -1 when a
 * gain does not fit (c->ok stays 0; the step then fails with cog_config). */
int cm_cogging_configure(cm_cog_t *c, const cm_cog_config_t *cfg, const ctrl_machine_t *m,
                         const ctrl_params_t *p, const ctrl_bases_t *b, uint32_t fs_hz,
                         uint32_t cpr);

#endif /* FIRMWARE_COMMISSION_CM_COGGING_H */
