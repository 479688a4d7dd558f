/*
 * Compare values of the PWM timer from leg duties (the interrupt's last
 * step, inline; tests/loop/test_fw_fast.c checks them against the 64-bit
 * rounding).
 */
#ifndef FIRMWARE_FW_PWM_H
#define FIRMWARE_FW_PWM_H

#include <stdint.h>

/* Compare value of a leg duty d in [0, FX_ONE] for a period of n counts:
 * round(d n / 2^24) (ties up), in [0, n]; d n < 2^24 * 2^32 in 64 bits. */
static inline uint32_t fw_pwm_compare(uint32_t d, uint32_t n)
{
#if defined(__GNUC__)
    /* Emits nothing; keeps gcc from sign-extending d (from a q24_t) as if
     * it could be negative (an extra ASR and MLA per leg). */
    __asm__("" : "+r"(d));
#endif
    return (uint32_t)(((uint64_t)d * n + (1u << 23)) >> 24);
}

/* The same with n8 = n * 2^8 (n < 2^24): the high word of d n8 is
 * floor(d n / 2^24) and bit 31 of the low word is bit 23 of d n, the rounding
 * bit (one UMULL and one add). */
static inline uint32_t fw_pwm_compare8(uint32_t d, uint32_t n8)
{
#if defined(__GNUC__)
    __asm__("" : "+r"(d));
#endif
    const uint64_t p = (uint64_t)d * n8;
    return (uint32_t)(p >> 32) + ((uint32_t)p >> 31);
}

/* Leg duties (Q24, each in [0, FX_ONE]) limited to dmax in (0, FX_ONE], the
 * largest duty the board applies (hal_info_t.pwm_cmp_max: a zero vector
 * around the current sampling instant). All three legs move down together
 * first, by the excess of the highest one but no further than the lowest one
 * allows: the line voltages, hence the space vector (4.4), are unchanged
 * whenever max - min <= dmax (an active vector with V7 as its zero vector
 * becomes one with V0). What is left is cut from the legs above dmax: only a
 * vector asked for longer than dmax of the period is shortened. */
static inline void fw_legs_limit(int32_t duty[3], int32_t dmax)
{
    const int32_t hi = duty[0] > duty[1] ? (duty[0] > duty[2] ? duty[0] : duty[2])
                                         : (duty[1] > duty[2] ? duty[1] : duty[2]);
    if (hi <= dmax) {
        return;
    }
    const int32_t lo = duty[0] < duty[1] ? (duty[0] < duty[2] ? duty[0] : duty[2])
                                         : (duty[1] < duty[2] ? duty[1] : duty[2]);
    const int32_t shift = hi - dmax < lo ? hi - dmax : lo; /* in [0, FX_ONE] */
    for (int x = 0; x < 3; x++) {
        const int32_t d = duty[x] - shift;
        duty[x] = d < dmax ? d : dmax;
    }
}

#endif /* FIRMWARE_FW_PWM_H */
