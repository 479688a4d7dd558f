/*
 * Switching-plan helpers and the plan -> centre-aligned leg duties stage.
 *
 * A plan (ctrl_types.h) lists voltage vectors and their on-times as Q24
 * fractions of the period. The PWM stage realises its volt-seconds: the duty of
 * leg x is the sum of the on-times of the segments whose vector has leg x high
 * (Table 4.2). With centre-aligned PWM this gives the same period-average phase
 * voltages as applying the segments one after the other, and an active vector
 * followed by ctrl_zero_after() switches exactly one leg pair per period.
 */
#ifndef CONTROL_PLAN_H
#define CONTROL_PLAN_H

#include <stdint.h>

#include "ctrl_types.h"
#include "fx.h"

/* One vector for the whole period. */
void ctrl_plan_single(ctrl_plan_t *p, uint8_t vec);

/* Active vector vec for duty (clamped to [0, FX_ONE]), the rest of the period
 * the zero vector ctrl_zero_after(vec). Segment 0 is vec. */
void ctrl_plan_active_zero(ctrl_plan_t *p, uint8_t vec, q24_t duty);

/* Two active vectors with duties d1, d2 (each clamped to [0, FX_ONE], d2
 * reduced so d1 + d2 <= FX_ONE), the rest the zero vector after v1. */
void ctrl_plan_two_active(ctrl_plan_t *p, uint8_t v1, q24_t d1, uint8_t v2, q24_t d2);

/* Centre-aligned leg duties realising the plan's volt-seconds, each in [0, FX_ONE].
 * Segments with a vector index > 7 or a negative duration are ignored; a
 * duration above FX_ONE counts as FX_ONE. */
void ctrl_plan_to_legs(const ctrl_plan_t *p, ctrl_legs_t *legs);

/* Period-average alpha/beta voltage of the plan at DC link vdc: sum dur_i V_i
 * (volt-second average, (4.4)); equals the voltage of ctrl_plan_to_legs()
 * for every plan whose durations sum to at most FX_ONE. */
void ctrl_plan_voltage(const ctrl_plan_t *p, q24_t vdc, q24_t *v_alpha, q24_t *v_beta);

#endif /* CONTROL_PLAN_H */
