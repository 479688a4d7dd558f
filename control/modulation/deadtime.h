/*
 * Dead-time and device-drop compensation of the leg duties (the inverter's
 * voltage error, removed where the voltage is made).
 *
 * After each edge of a leg both switches are off for t_d and the phase
 * current picks a diode: with i > 0 (out of the leg) the lower one, so a
 * rising edge comes t_d late; with i < 0 the upper one, so a falling edge
 * comes t_d late. A centre-aligned pulse (0 < d < 1) has one edge of each
 * kind per period, so the leg's mean voltage is d Vdc - sign(i) t_d fs Vdc;
 * the devices' forward drop v_f (transistor or diode, taken alike) adds
 * - sign(i) v_f. The compensation adds the same error back to the duty
 * before it is written:
 *     d' = d + s(i) (t_d fs + v_f / Vdc),
 * the per-phase average-voltage method of S.-G. Jeong and M.-H. Park, "The
 * analysis and compensation of dead-time effects in PWM inverters" (IEEE
 * Trans. Industrial Electronics, 1991). Two refinements as a drive engineer
 * expects them:
 *  - the sign is that of the current while the duties act, [k+1, k+2): the
 *    estimator's prediction i_dq(k+1) at the angle of the middle of that
 *    period, theta(k+1) + omega Ts / 2, not the sample at k, which lags by
 *    1.5 periods (the current-vector angle instead of the sampled phase
 *    currents, as A. R. Munoz and T. A. Lipo, "On-line dead-time compensation
 *    technique for open-loop PWM-VSI drives", IEEE Trans. Power Electronics,
 *    1999, argue for: no chattering on noisy zero crossings);
 *  - near zero current the PWM ripple carries the current through zero
 *    inside the period and the pulse's two edges see different signs: the
 *    current at an edge is the period's mean i plus the ripple there, and
 *    the ripple of a centre-aligned period is zero at its start and middle
 *    and odd about the middle, so the rising edge sees i - r and the falling
 *    edge i + r (or the reverse), and the leg's error is t_d fs times the
 *    mean of the two edges' signs (the zero-current analysis of J.-W. Choi
 *    and S.-K. Sul, "Inverter output voltage synthesis using novel dead time
 *    compensation", IEEE Trans. Power Electronics, 1996: the error follows
 *    the current at the switching instants, not its mean). With the phase
 *    voltage Vdc (s_x - (s_a + s_b + s_c) / 3) integrated from the period's
 *    start to leg x's rising edge ((1 - d_x) Ts / 2) against its mean,
 *        r_x = Vdc Ts / (6 L) [ (d_y - d_x)+ + (d_z - d_x)+
 *                               - ((d_y - d_x) + (d_z - d_x)) (1 - d_x) ],
 *    (e)+ = max(e, 0), y and z the other legs; |bracket| <= 1/2, at most
 *    Vdc / (12 L fs) (a leg at 1/2 against two at 0 or 1), 0 for a leg at 0
 *    or 1 and for three equal duties: at low speed, where all legs sit near
 *    1/2, it is small and the compensation acts down to small currents. L
 *    the mean of the inverse inductances, 2 / (1/Ld + 1/Lq) (the ripple's
 *    direction against d is any over a turn). Each edge's sign is taken as
 *    i / w within [-1, 1], w the current's uncertainty at an edge (the
 *    ripple's change over the t_d / 2 the compensation moves an edge and
 *    the current's sensing: ctrl_deadtime_band_default):
 *        s(i) = (sat((i - r) / w) + sat((i + r) / w)) / 2.
 * Legs without an edge in the period (clamped legs of a plan): a leg at 0
 * stays 0; a leg at 1 with i < 0 is written below 1, so that it ends low and
 * the next period starts without a late falling edge; a pulse after a period
 * that ended high with i < 0 is shortened by t_d fs more for that edge; a leg
 * at 1 after a low end with i > 0 loses t_d to its late rising edge, made up
 * by shortening the other legs' pulses (the line voltages kept).
 * The drop is referred to the nominal DC link (no division per period): the
 * dead-time part, the larger, is exact at any DC link.
 * What the estimator and the observers are told was applied stays the
 * uncompensated duty: the compensated one makes it true (firmware/isr).
 * Integer-only per period; configuration in deadtime_config.c.
 */
#ifndef CONTROL_DEADTIME_H
#define CONTROL_DEADTIME_H

/* 0: built without it (CMake option PMSM_DEAD_COMP, flash-tight images):
 * ctrl_deadtime_init leaves it off (dd = 0). */
#ifndef CTRL_DEAD_COMP
#define CTRL_DEAD_COMP 1
#endif

#include <stdint.h>

#include "ctrl_params.h"
#include "ctrl_types.h"
#include "fx.h"

/* Shift of inv_w (Q16): 1 / w up to 2^15 per pu. */
#define CTRL_DT_BAND_SHIFT 16u

typedef struct {
    q24_t dd;      /* duty error per leg at full sign, t_d fs + v_f / Vdc_nom, Q24
                    * fraction of the period; 0 = no compensation */
    q24_t dt;      /* its dead-time part, t_d fs, Q24 fraction */
    int32_t inv_w; /* 1 / w, the edge sign's half-width, Q16 per pu (CTRL_DT_BAND_SHIFT) */
#if CTRL_DEAD_COMP
    q24_t k_rip; /* Ts V_base / (6 L I_base): the edge ripple r_x per unit of its
                  * bracket and of DC link (pu), Q24 pu (only where built: the
                  * images without it keep their layout) */
#endif
    /* ---- state ---- */
    uint32_t high_prev; /* bit x: leg x was high at the end of the last period */
} ctrl_deadtime_t;

/* SI configuration. */
typedef struct {
    double dead_time_s; /* t_d, [0, Ts / 4]; 0 with v_fwd_v 0: off */
    double v_fwd_v;     /* forward drop of the conducting device, [0, 10 % of Vdc] V */
    double band_a;      /* w, half-width of each edge's sign transition (the current's
                         * uncertainty at an edge), A (0 = ctrl_deadtime_band_default) */
} ctrl_deadtime_config_t;

/* w, A: the ripple's largest change over the t_d / 2 the compensation moves
 * an edge, (2/3) Vdc (t_d / 2) / L, plus 4 counts of the current's ADC
 * (i_a_per_count, A per count) for the sensing the prediction starts from
 * (deadtime_config.c). A drive whose current is noisier sets band_a. */
double ctrl_deadtime_band_default(const ctrl_machine_t *m, double dead_time_s,
                                  double i_a_per_count);

/* Fixed-point constants; CTRL_OK, or CTRL_EINVAL naming the quantity in *why. */
int ctrl_deadtime_init(ctrl_deadtime_t *d, const ctrl_deadtime_config_t *c, const ctrl_params_t *p,
                       const ctrl_bases_t *b, ctrl_diag_t *why);

/* Add the compensation to legs (the duties that act in [k+1, k+2)), each
 * taken within [0, FX_ONE]; est: the estimate of k (next.i_d, next.i_q,
 * next.theta_e, dtheta, vdc). Nothing when d->dd == 0. */
void ctrl_deadtime_apply(ctrl_deadtime_t *d, const ctrl_estimate_t *est, ctrl_legs_t *legs);

/* The duties written for [k+1, k+2) (after every limit; zeros with the
 * gates off): which legs end that period high. */
void ctrl_deadtime_written(ctrl_deadtime_t *d, const ctrl_legs_t *written);

#endif /* CONTROL_DEADTIME_H */
