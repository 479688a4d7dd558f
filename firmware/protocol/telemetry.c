/*
 * Telemetry producer and signal table (see telemetry.h).
 */
#include "telemetry.h"

#include <string.h>

#include "ctrl_units.h"
#include "help_text.h"

#define TEL_SIG(name, unit, help, kind, field)                                                     \
    {                                                                                              \
        name, unit, HELP_TEXT(help), kind, (uint16_t)offsetof(tel_sample_t, field)                 \
    }

static const tel_signal_t tel_signals[TEL_SIG_COUNT] = {
    TEL_SIG("i_a", "A", "phase current a", TEL_KIND_CURRENT, i_a),
    TEL_SIG("i_b", "A", "phase current b", TEL_KIND_CURRENT, i_b),
    TEL_SIG("i_d", "A", "d-axis current", TEL_KIND_CURRENT, i_d),
    TEL_SIG("i_q", "A", "q-axis current", TEL_KIND_CURRENT, i_q),
    TEL_SIG("psi", "Wb", "stator flux amplitude (4.3)", TEL_KIND_FLUX, psi),
    TEL_SIG("psi_ref", "Wb", "stator flux reference", TEL_KIND_FLUX, psi_ref),
    TEL_SIG("torque", "N*m", "estimated torque (3.6)", TEL_KIND_TORQUE, torque),
    TEL_SIG("torque_ref", "N*m", "torque reference", TEL_KIND_TORQUE, torque_ref),
    TEL_SIG("speed", "r/min", "rotor speed (mechanical)", TEL_KIND_SPEED, speed),
    TEL_SIG("speed_ref", "r/min", "speed reference", TEL_KIND_SPEED, speed_ref),
    TEL_SIG("vector", "", "selected voltage vector 0..7 (Table 4.2)", TEL_KIND_INTEGER, vector),
    TEL_SIG("duty", "", "duty of the selected vector", TEL_KIND_FRACTION, duty),
    TEL_SIG("vdc", "V", "DC-link voltage", TEL_KIND_VOLTAGE, vdc),
    TEL_SIG("theta", "rad", "rotor electrical angle", TEL_KIND_ANGLE, theta),
    TEL_SIG("sector", "", "stator flux sector 1..6 (4.5)", TEL_KIND_INTEGER, sector),
    TEL_SIG("state", "", "firmware state code", TEL_KIND_INTEGER, state),
    TEL_SIG("fault", "", "latched fault code", TEL_KIND_INTEGER, fault),
    TEL_SIG("cycles", "", "ISR execution time, CPU cycles", TEL_KIND_INTEGER, cycles),
    TEL_SIG("cm_step", "", "commissioning step running (0 none)", TEL_KIND_INTEGER, cm_step),
    TEL_SIG("cm_progress", "", "its progress, per mille", TEL_KIND_INTEGER, cm_progress),
    TEL_SIG("torque_max", "N*m", "torque limit (current circle, voltage ellipse, MTPV)",
            TEL_KIND_TORQUE, torque_max),
    TEL_SIG("fieldweak_limit", "",
            "limit: 0 current, 1 voltage, 2 MTPV, 3 flux; +4 clipped, +8 weakened, +16 torque "
            "not followed",
            TEL_KIND_INTEGER, fieldweak_limit),
#if CTRL_SL_HFI
    TEL_SIG("sl_state", "",
            "sensorless: bits 0-1 mode (0 forced, 1 observer, 2 pulses, 3 injection), 2-4 start "
            "phase, 5-6 polarity from (1 saturation, 2 motion)",
            TEL_KIND_INTEGER, sl_state),
    TEL_SIG("angle_err", "rad", "the injection's angle error estimate (rotor minus tracked)",
            TEL_KIND_ANGLE, angle_err),
#endif
};

const tel_signal_t *tel_signal_at(size_t index)
{
    return (index < (size_t)TEL_SIG_COUNT) ? &tel_signals[index] : NULL;
}

int tel_signal_find(const char *s, size_t len)
{
    if (s == NULL) {
        return -1;
    }
    for (size_t i = 0; i < (size_t)TEL_SIG_COUNT; i++) {
        const char *name = tel_signals[i].name;
        if (strlen(name) == len && memcmp(name, s, len) == 0) {
            return (int)i;
        }
    }
    return -1;
}

double tel_signal_scale(size_t index, const ctrl_bases_t *b, int32_t pole_pairs)
{
    const double q24 = 1.0 / 16777216.0; /* 2^-24 */
    if (index >= (size_t)TEL_SIG_COUNT) {
        return 0.0;
    }
    const tel_kind_t kind = (tel_kind_t)tel_signals[index].kind;
    if (kind == TEL_KIND_INTEGER) {
        return 1.0;
    }
    if (kind == TEL_KIND_FRACTION) {
        return q24;
    }
    if (kind == TEL_KIND_ANGLE) {
        return CTRL_TWO_PI * q24;
    }
    if (b == NULL) {
        return 0.0; /* unknown bases: the PC shows raw values */
    }
    switch (kind) {
    case TEL_KIND_CURRENT:
        return b->i_a * q24;
    case TEL_KIND_VOLTAGE:
        return b->v_v * q24;
    case TEL_KIND_FLUX:
        return b->psi_wb * q24;
    case TEL_KIND_TORQUE:
        return b->torque_nm * q24;
    case TEL_KIND_SPEED:
        return (pole_pairs > 0) ? ctrl_elec_to_rpm(b->w_rad_s, pole_pairs) * q24 : 0.0;
    default:
        return 0.0;
    }
}

void tel_init(tel_t *t)
{
    if (t != NULL) {
        memset(t, 0, sizeof *t);
    }
}

int tel_start(tel_t *t, uint32_t mask, uint32_t every)
{
    if (t == NULL || mask == 0u || (mask & ~TEL_MASK_ALL) != 0u || every < 1u ||
        every > TEL_EVERY_MAX) {
        return -1;
    }
    t->mask = mask;
    t->every = every;
    return 0;
}

void tel_stop(tel_t *t)
{
    if (t != NULL) {
        t->mask = 0;
    }
}

bool tel_active(const tel_t *t)
{
    return t != NULL && t->mask != 0u;
}

size_t tel_wire_size(uint32_t mask)
{
    return TEL_COBS_SIZE(tel_payload_size(TEL_TYPE_SAMPLE, mask)) + 2u;
}

/* A frame of this stream: type, sequence number and signal mask. */
static void tel_frame_start(const tel_t *t, uint8_t type, tel_frame_t *f)
{
    memset(f, 0, sizeof *f);
    f->type = type;
    f->seq = t->seq;
    f->mask = t->mask;
}

/* Encode f; the sequence number advances only for a frame written. */
static size_t tel_frame_finish(tel_t *t, const tel_frame_t *f, uint8_t *wire, size_t cap)
{
    const size_t len = tel_frame_encode(f, wire, cap);
    if (len != 0) {
        t->seq++;
    }
    return len;
}

size_t tel_encode_sample(tel_t *t, const tel_sample_t *s, uint8_t *wire, size_t cap)
{
    if (t == NULL || s == NULL || wire == NULL || t->mask == 0u || cap < TEL_WIRE_MAX) {
        return 0;
    }
    tel_frame_t f;
    tel_frame_start(t, TEL_TYPE_SAMPLE, &f);
    f.tick = s->tick;
    unsigned n = 0;
    for (size_t i = 0; i < (size_t)TEL_SIG_COUNT; i++) {
        if ((t->mask & (1ul << i)) != 0u) {
            int32_t v;
            memcpy(&v, (const uint8_t *)s + tel_signals[i].offset, sizeof v);
            f.value[n++] = v;
        }
    }
    return tel_frame_finish(t, &f, wire, cap);
}

size_t tel_encode_meta(tel_t *t, uint32_t fs_hz, const ctrl_bases_t *bases, int32_t pole_pairs,
                       uint8_t *wire, size_t cap)
{
    if (t == NULL || wire == NULL || t->mask == 0u || cap < TEL_WIRE_MAX) {
        return 0;
    }
    tel_frame_t f;
    tel_frame_start(t, TEL_TYPE_META, &f);
    f.fs_hz = fs_hz;
    f.every = t->every;
    unsigned n = 0;
    for (size_t i = 0; i < (size_t)TEL_SIG_COUNT; i++) {
        if ((t->mask & (1ul << i)) != 0u) {
            f.scale[n++] = (float)tel_signal_scale(i, bases, pole_pairs);
        }
    }
    return tel_frame_finish(t, &f, wire, cap);
}
