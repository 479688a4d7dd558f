/*
 * Random but valid settings records for the settings tests and the fuzz
 * target's seeds (xorshift32: the same records on the host and in QEMU).
 */
#ifndef TESTS_SETTINGS_SETTINGS_GEN_H
#define TESTS_SETTINGS_SETTINGS_GEN_H

#include <stdint.h>
#include <string.h>

#include "settings.h"

static inline uint32_t sgen_rand(uint32_t *x)
{
    uint32_t v = *x;
    v ^= v << 13;
    v ^= v >> 17;
    v ^= v << 5;
    *x = v;
    return v;
}

/* A finite double from 52 random mantissa bits and an exponent in [2^-30, 2^30). */
static inline double sgen_double(uint32_t *x)
{
    const uint64_t mant = ((uint64_t)sgen_rand(x) << 20) ^ (uint64_t)sgen_rand(x);
    const uint64_t expo = 1023u - 30u + (uint64_t)(sgen_rand(x) % 60u);
    const uint64_t bits =
        ((uint64_t)(sgen_rand(x) & 1u) << 63) | (expo << 52) | (mant & 0xFFFFFFFFFFFFFull);
    double d;
    memcpy(&d, &bits, sizeof d);
    return d;
}

static inline void sgen_name(uint32_t *x, char *out, unsigned maxlen)
{
    const unsigned n = 1u + sgen_rand(x) % (maxlen - 1u);
    for (unsigned i = 0; i < n; i++) {
        out[i] = (char)('a' + (int)(sgen_rand(x) % 26u));
    }
    out[n] = '\0';
}

static inline void sgen_settings(uint32_t *x, settings_t *s)
{
    memset(s, 0, sizeof *s);
    s->pole_pairs = (int32_t)(1u + sgen_rand(x) % 50u);
    double *d[] = {&s->rs_ohm,
                   &s->ld_h,
                   &s->lq_h,
                   &s->psi_pm_wb,
                   &s->vdc_v,
                   &s->inertia_kgm2,
                   &s->torque_rated_nm,
                   &s->speed_rated_rpm,
                   &s->current_rated_a,
                   &s->current_max_a,
                   &s->psi_ref_wb,
                   &s->speed_max_rpm,
                   &s->dead_time_s,
                   &s->v_fwd_v,
                   &s->speed_bw_hz,
                   &s->speed_pm_deg,
                   &s->speed_kp,
                   &s->speed_ki,
                   &s->speed_out_max_nm,
                   &s->overspeed_rpm,
                   &s->id_rs_ohm,
                   &s->id_ld_h,
                   &s->id_lq_h,
                   &s->id_psi_wb,
                   &s->id_inertia_kgm2,
                   &s->id_enc_offset_deg,
                   &s->coulomb_nm,
                   &s->viscous_nms,
                   &s->id_coulomb_nm,
                   &s->id_viscous_nms};
    for (unsigned i = 0; i < sizeof d / sizeof d[0]; i++) {
        *d[i] = sgen_double(x);
    }
    s->enc_cpr = sgen_rand(x);
    s->enc_direction = (sgen_rand(x) & 1u) != 0u ? 1 : -1;
    s->enc_offset = sgen_rand(x);
    s->sensorless = (uint8_t)(sgen_rand(x) & 1u);
    s->psi_adapt = (uint8_t)(sgen_rand(x) & 1u);
    sgen_name(x, s->ctrl, SETTINGS_NAME_MAX);
    s->n_tunables = (uint8_t)(sgen_rand(x) % (SETTINGS_TUNABLES_MAX + 1u));
    for (unsigned k = 0; k < s->n_tunables; k++) {
        sgen_name(x, s->tunable_name[k], SETTINGS_NAME_MAX);
        s->tunable_value[k] = sgen_double(x);
    }
    s->speed_unit = (uint8_t)(sgen_rand(x) % 3u);
    s->speed_loop_hz = sgen_rand(x);
    s->thr_mode = (uint8_t)(sgen_rand(x) % 3u);
    s->thr_low_us = (uint16_t)sgen_rand(x);
    s->thr_high_us = (uint16_t)sgen_rand(x);
    s->thr_deadband_us = (uint16_t)sgen_rand(x);
    s->thr_stored = 1u; /* format 2 on */
    s->id_have = sgen_rand(x);
    s->id_enc_dir = (int8_t)((int)(sgen_rand(x) % 3u) - 1);
    s->id_enc_cpr = sgen_rand(x);
}

#endif /* TESTS_SETTINGS_SETTINGS_GEN_H */
