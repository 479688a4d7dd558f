/* Configuration arithmetic shared by the STM32 chip supports (stm32_calc.h). */
#include "stm32_calc.h"

int stm32_pwm_timing(uint32_t f_tim_hz, uint32_t fs_hz, stm32_pwm_timing_t *t)
{
    if (t == 0 || fs_hz == 0u || f_tim_hz < 4u * fs_hz) {
        return STM32_E_CONFIG;
    }
    for (uint32_t div = 1u; div <= 65536u; div++) {
        const uint64_t den = 2ull * fs_hz * div;
        if (f_tim_hz % den != 0u) {
            continue;
        }
        const uint64_t arr = f_tim_hz / den;
        if (arr <= 0xFFFFu && arr >= 2u) {
            t->psc = div - 1u;
            t->arr = (uint32_t)arr;
            t->fs_hz = fs_hz;
            return STM32_OK;
        }
    }
    return STM32_E_CONFIG;
}

int stm32_dtg_encode(uint32_t f_dts_hz, uint32_t dead_ns, uint8_t *dtg)
{
    if (dtg == 0 || f_dts_hz == 0u) {
        return STM32_E_CONFIG;
    }
    /* Requested dead time in t_DTS, rounded up. */
    const uint64_t ticks = ((uint64_t)dead_ns * f_dts_hz + 999999999u) / 1000000000u;
    if (ticks <= 127u) {
        *dtg = (uint8_t)ticks;
    } else if (ticks <= 254u) {
        const uint64_t k = (ticks + 1u) / 2u; /* 64..127 steps of 2 t_DTS */
        *dtg = (uint8_t)(0x80u | (uint32_t)(k - 64u));
    } else if (ticks <= 504u) {
        const uint64_t k = (ticks + 7u) / 8u; /* 32..63 steps of 8 t_DTS */
        *dtg = (uint8_t)(0xC0u | (uint32_t)(k - 32u));
    } else if (ticks <= 1008u) {
        const uint64_t k = (ticks + 15u) / 16u; /* 32..63 steps of 16 t_DTS */
        *dtg = (uint8_t)(0xE0u | (uint32_t)(k - 32u));
    } else {
        return STM32_E_CONFIG;
    }
    return STM32_OK;
}

uint32_t stm32_dtg_ticks(uint8_t dtg)
{
    if ((dtg & 0x80u) == 0u) {
        return dtg;
    }
    if ((dtg & 0xC0u) == 0x80u) {
        return (64u + (dtg & 0x3Fu)) * 2u;
    }
    if ((dtg & 0xE0u) == 0xC0u) {
        return (32u + (dtg & 0x1Fu)) * 8u;
    }
    return (32u + (dtg & 0x1Fu)) * 16u;
}

uint32_t stm32_filter_cycles(uint32_t code)
{
    /* {sampling divider, N}; code 0 = no filter. */
    static const uint8_t div[16] = {1, 1, 1, 1, 2, 2, 4, 4, 8, 8, 16, 16, 16, 32, 32, 32};
    static const uint8_t n[16] = {0, 2, 4, 8, 6, 8, 6, 8, 6, 8, 5, 6, 8, 5, 6, 8};
    code &= 0xFu;
    return (uint32_t)div[code] * n[code];
}

static int32_t stm32_s16(uint16_t u)
{
    return u <= 0x7FFFu ? (int32_t)u : (int32_t)u - 65536;
}

uint32_t stm32_enc_extend(stm32_enc_ext_t *e, uint16_t cnt)
{
    if (!e->primed) {
        e->primed = true;
        e->count = (uint32_t)stm32_s16(cnt);
    } else {
        e->count += (uint32_t)stm32_s16((uint16_t)(cnt - e->last));
    }
    e->last = cnt;
    return e->count;
}

uint32_t stm32_enc_at_capture(const stm32_enc_ext_t *e, uint16_t cnt, uint16_t ccr)
{
    return e->count - (uint32_t)stm32_s16((uint16_t)(cnt - ccr));
}

int stm32_usart_brr(uint32_t f_ck_hz, uint32_t baud, uint32_t *brr)
{
    if (baud == 0u) {
        return STM32_E_CONFIG;
    }
    const uint32_t v = (f_ck_hz + baud / 2u) / baud;
    if (v < 16u || v > 0xFFFFu) {
        return STM32_E_CONFIG;
    }
    *brr = v;
    return STM32_OK;
}

int stm32_iwdg_config(uint32_t timeout_ms, uint32_t f_lsi_hz, uint32_t *pr, uint32_t *rlr)
{
    for (uint32_t p = 0u; p <= 6u; p++) {
        const uint64_t div = 4ull << p;
        const uint64_t ticks = ((uint64_t)timeout_ms * f_lsi_hz + div * 1000u - 1u) / (div * 1000u);
        if (ticks >= 1u && ticks <= 4096u) {
            *pr = p;
            *rlr = (uint32_t)ticks - 1u;
            return STM32_OK;
        }
    }
    return STM32_E_CONFIG;
}

uint32_t stm32_iwdg_timeout_ms(uint32_t pr, uint32_t rlr, uint32_t f_lsi_hz)
{
    if (f_lsi_hz == 0u || pr > 6u) {
        return 0u;
    }
    return (uint32_t)(((uint64_t)rlr + 1u) * (4ull << pr) * 1000u / f_lsi_hz);
}
