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

#endif /* FIRMWARE_FW_PWM_H */
