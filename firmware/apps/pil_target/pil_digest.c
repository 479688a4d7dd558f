/* The telemetry record's digest for the PIL link (pil_digest.h). */
#include "pil_digest.h"

#include "telemetry_frame.h"

static void td_u8(uint8_t *b, size_t *n, uint32_t v)
{
    b[(*n)++] = (uint8_t)v;
}

static void td_u32(uint8_t *b, size_t *n, uint32_t v)
{
    for (int k = 0; k < 4; k++) {
        td_u8(b, n, (v >> (8 * k)) & 0xFFu);
    }
}

uint16_t pil_tm_digest(const fw_telemetry_t *tm)
{
    uint8_t b[96];
    size_t n = 0u;
    td_u32(b, &n, tm->period);
    td_u8(b, &n, tm->state);
    td_u8(b, &n, tm->fault);
    td_u8(b, &n, tm->vec);
    td_u8(b, &n, tm->gates);
    const int32_t v[] = {tm->i_a,        tm->i_b,   tm->vdc,     tm->i_d,     tm->i_q,
                         tm->psi_d,      tm->psi_q, tm->torque,  tm->omega_e, tm->torque_ref,
                         tm->torque_max, tm->duty,  tm->legs[0], tm->legs[1], tm->legs[2]};
    for (size_t k = 0; k < sizeof v / sizeof v[0]; k++) {
        td_u32(b, &n, (uint32_t)v[k]);
    }
    td_u32(b, &n, tm->theta_e);
    td_u8(b, &n, tm->fw_limit);
    td_u8(b, &n, tm->cm_step);
    td_u32(b, &n, tm->cm_progress);
    return tel_crc16(b, n);
}
