/* What both sides of the PIL link share (pil_shared.h). */
#include "pil_shared.h"

#include "telemetry_frame.h"

/* One list for both directions (speed_unit, an enum on one side, apart). */
#define PIL_FW_FIELDS(X)                                                                           \
    X(calib_samples)                                                                               \
    X(speed_bw_hz)                                                                                 \
    X(speed_pm_deg)                                                                                \
    X(speed_kp)                                                                                    \
    X(speed_ki)                                                                                    \
    X(overspeed_rpm)                                                                               \
    X(psi_adapt)                                                                                   \
    X(sensorless)                                                                                  \
    X(hfi)                                                                                         \
    X(dead_time_s)                                                                                 \
    X(v_fwd_v)                                                                                     \
    X(enc_offset)                                                                                  \
    X(enc_direction)                                                                               \
    X(enc_cpr)

void pil_setup_from_fw_config(pil_setup_t *s, const fw_config_t *fc)
{
#define PIL_TO_SETUP(f) s->f = fc->f;
    PIL_FW_FIELDS(PIL_TO_SETUP)
#undef PIL_TO_SETUP
    s->speed_unit = (uint8_t)fc->speed_unit;
}

void pil_setup_to_fw_config(const pil_setup_t *s, fw_config_t *fc)
{
#define PIL_TO_FC(f) fc->f = s->f;
    PIL_FW_FIELDS(PIL_TO_FC)
#undef PIL_TO_FC
    fc->speed_unit = (ctrl_speed_unit_t)s->speed_unit;
}

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
    td_u8(b, &n, tm->fieldweak_limit);
#if CTRL_SL_HFI
    td_u8(b, &n, tm->sl_state);
    td_u32(b, &n, (uint32_t)tm->hfi_err);
#endif
    td_u8(b, &n, tm->cm_step);
    td_u32(b, &n, tm->cm_progress);
    return tel_crc16(b, n);
}
