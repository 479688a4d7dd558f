/* PIL link frames: payloads, framing and the stream decoder (pil_frame.h). */
#include "pil_frame.h"

#include <string.h>

#include "telemetry_frame.h"

static const char *const pil_err_names[PIL_E_COUNT] = {
    "ok",
    "link time-out (frame lost or late)",
    "link CRC error (frame corrupted)",
    "link sequence error (frame lost, repeated or reordered)",
    "link format error (bad framing, type or length)",
    "link closed (the other side stopped)",
    "target diverged from the host firmware",
    "target refused the configuration",
};

const char *pil_err_name(int err)
{
    return (err >= 0 && err < (int)PIL_E_COUNT) ? pil_err_names[err] : "unknown link fault";
}

uint16_t pil_seq_next(uint16_t s)
{
    return s == 0xFFFFu ? 1u : (uint16_t)(s + 1u);
}

/* ---- little-endian writer / reader with bounds ---- */

typedef struct {
    uint8_t *p;
    size_t n, cap;
    bool bad;
} pil_w_t;

typedef struct {
    const uint8_t *p;
    size_t n, at;
    bool bad;
} pil_r_t;

static void w_u8(pil_w_t *w, uint32_t v)
{
    if (w->n + 1u > w->cap) {
        w->bad = true;
        return;
    }
    w->p[w->n++] = (uint8_t)v;
}

static void w_u16(pil_w_t *w, uint32_t v)
{
    w_u8(w, v & 0xFFu);
    w_u8(w, (v >> 8) & 0xFFu);
}

static void w_u32(pil_w_t *w, uint32_t v)
{
    w_u16(w, v & 0xFFFFu);
    w_u16(w, v >> 16);
}

static void w_f64(pil_w_t *w, double v)
{
    uint64_t u;
    memcpy(&u, &v, sizeof u);
    w_u32(w, (uint32_t)u);
    w_u32(w, (uint32_t)(u >> 32));
}

static void w_str(pil_w_t *w, const char *s)
{
    const size_t n = strlen(s);
    w_u8(w, (uint32_t)n);
    for (size_t i = 0; i < n; i++) {
        w_u8(w, (uint8_t)s[i]);
    }
}

static uint32_t r_u8(pil_r_t *r)
{
    if (r->at + 1u > r->n) {
        r->bad = true;
        return 0u;
    }
    return r->p[r->at++];
}

static uint32_t r_u16(pil_r_t *r)
{
    const uint32_t lo = r_u8(r);
    return lo | (r_u8(r) << 8);
}

static uint32_t r_u32(pil_r_t *r)
{
    const uint32_t lo = r_u16(r);
    return lo | (r_u16(r) << 16);
}

static double r_f64(pil_r_t *r)
{
    const uint64_t lo = r_u32(r);
    const uint64_t u = lo | ((uint64_t)r_u32(r) << 32);
    double v;
    memcpy(&v, &u, sizeof v);
    return v;
}

static bool r_bool(pil_r_t *r)
{
    const uint32_t v = r_u8(r);
    if (v > 1u) {
        r->bad = true;
    }
    return v == 1u;
}

/* A string of at most cap - 1 bytes, NUL-terminated into out. */
static void r_str(pil_r_t *r, char *out, size_t cap)
{
    const size_t n = r_u8(r);
    if (n >= cap) {
        r->bad = true;
        out[0] = '\0';
        return;
    }
    for (size_t i = 0; i < n; i++) {
        out[i] = (char)r_u8(r);
    }
    out[n] = '\0';
}

static size_t w_done(const pil_w_t *w)
{
    return w->bad ? 0u : w->n;
}

static int r_done(const pil_r_t *r)
{
    return (r->bad || r->at != r->n) ? PIL_E_FORMAT : PIL_OK;
}

/* ---- payloads ---- */

size_t pil_sample_pack(const pil_sample_t *s, uint8_t *out, size_t cap)
{
    pil_w_t w = {out, 0u, cap, false};
    w_u16(&w, s->adc.i_a);
    w_u16(&w, s->adc.i_b);
    w_u16(&w, s->adc.i_c);
    w_u16(&w, s->adc.vdc);
    w_u32(&w, s->enc.count);
    w_u8(&w, s->enc.index_seen ? 1u : 0u);
    w_u32(&w, s->enc.index_count);
    w_u8(&w, s->trip ? 1u : 0u);
    w_u8(&w, s->cmd);
    w_u32(&w, (uint32_t)s->torque_ref);
    w_u32(&w, (uint32_t)s->speed_ref);
    return w_done(&w);
}

/* uint32 -> int32 two's complement without implementation-defined conversion. */
static int32_t pil_i32(uint32_t u)
{
    return u <= 0x7FFFFFFFu ? (int32_t)u : (int32_t)(u - 0x80000000u) - 0x7FFFFFFF - 1;
}

int pil_sample_unpack(const uint8_t *p, size_t n, pil_sample_t *s)
{
    pil_r_t r = {p, n, 0u, false};
    memset(s, 0, sizeof *s);
    s->adc.i_a = (uint16_t)r_u16(&r);
    s->adc.i_b = (uint16_t)r_u16(&r);
    s->adc.i_c = (uint16_t)r_u16(&r);
    s->adc.vdc = (uint16_t)r_u16(&r);
    s->enc.count = r_u32(&r);
    s->enc.index_seen = r_bool(&r);
    s->enc.index_count = r_u32(&r);
    s->trip = r_bool(&r);
    s->cmd = (uint8_t)r_u8(&r);
    s->torque_ref = pil_i32(r_u32(&r));
    s->speed_ref = pil_i32(r_u32(&r));
    if (s->cmd > 0x3Fu) {
        r.bad = true;
    }
    return r_done(&r);
}

size_t pil_apply_pack(const pil_apply_t *a, uint8_t *out, size_t cap)
{
    pil_w_t w = {out, 0u, cap, false};
    for (int x = 0; x < 3; x++) {
        w_u32(&w, a->pwm.cmp[x]);
    }
    w_u8(&w, a->flags);
    w_u8(&w, a->state);
    w_u8(&w, a->fault);
    w_u32(&w, a->cycles);
    w_u16(&w, a->tm_digest);
    return w_done(&w);
}

int pil_apply_unpack(const uint8_t *p, size_t n, pil_apply_t *a)
{
    pil_r_t r = {p, n, 0u, false};
    memset(a, 0, sizeof *a);
    for (int x = 0; x < 3; x++) {
        a->pwm.cmp[x] = r_u32(&r);
    }
    a->flags = (uint8_t)r_u8(&r);
    a->state = (uint8_t)r_u8(&r);
    a->fault = (uint8_t)r_u8(&r);
    a->cycles = r_u32(&r);
    a->tm_digest = (uint16_t)r_u16(&r);
    if (a->flags > 0x07u) {
        r.bad = true;
    }
    return r_done(&r);
}

size_t pil_setup_pack(const pil_setup_t *s, uint8_t *out, size_t cap)
{
    pil_w_t w = {out, 0u, cap, false};
    const ctrl_machine_t *m = &s->machine;
    w_str(&w, s->ctrl);
    w_u32(&w, (uint32_t)m->pole_pairs);
    const double md[] = {m->rs_ohm,
                         m->ld_h,
                         m->lq_h,
                         m->psi_pm_wb,
                         m->vdc_v,
                         m->inertia_kgm2,
                         m->torque_rated_nm,
                         m->speed_rated_rpm,
                         m->current_rated_a,
                         m->current_max_a,
                         m->psi_ref_wb,
                         m->speed_max_rpm};
    for (size_t k = 0; k < sizeof md / sizeof md[0]; k++) {
        w_f64(&w, md[k]);
    }
    w_u8(&w, s->n_sets);
    for (size_t k = 0; k < s->n_sets && k < PIL_SETS_MAX; k++) {
        w_str(&w, s->sets[k].name);
        w_f64(&w, s->sets[k].value);
    }
    w_u32(&w, s->calib_samples);
    w_f64(&w, s->speed_bw_hz);
    w_f64(&w, s->speed_pm_deg);
    w_f64(&w, s->speed_kp);
    w_f64(&w, s->speed_ki);
    w_u8(&w, s->speed_unit);
    w_f64(&w, s->overspeed_rpm);
    w_u8(&w, s->psi_adapt ? 1u : 0u);
    w_u8(&w, s->sensorless ? 1u : 0u);
    w_u8(&w, s->hfi ? 1u : 0u);
    w_f64(&w, s->dead_time_s);
    w_f64(&w, s->v_fwd_v);
    w_u32(&w, s->enc_offset);
    w_u8(&w, (uint8_t)s->enc_direction);
    w_u32(&w, s->enc_cpr);
    const hal_info_t *i = &s->info;
    w_u32(&w, i->pwm_freq_hz);
    w_u32(&w, i->period_counts);
    w_u8(&w, i->adc_bits);
    w_f64(&w, i->adc_current_a_per_count);
    w_f64(&w, i->adc_vdc_v_per_count);
    w_u32(&w, i->encoder_counts_per_rev);
    w_u8(&w, i->has_i_c ? 1u : 0u);
    w_u32(&w, i->cycle_clock_hz);
    w_u32(&w, i->pwm_cmp_max);
    if (s->n_sets > PIL_SETS_MAX) {
        w.bad = true;
    }
    return w_done(&w);
}

int pil_setup_unpack(const uint8_t *p, size_t n, pil_setup_t *s)
{
    pil_r_t r = {p, n, 0u, false};
    memset(s, 0, sizeof *s);
    ctrl_machine_t *m = &s->machine;
    r_str(&r, s->ctrl, sizeof s->ctrl);
    m->name = "pil";
    m->pole_pairs = (int)pil_i32(r_u32(&r));
    double *const md[] = {&m->rs_ohm,
                          &m->ld_h,
                          &m->lq_h,
                          &m->psi_pm_wb,
                          &m->vdc_v,
                          &m->inertia_kgm2,
                          &m->torque_rated_nm,
                          &m->speed_rated_rpm,
                          &m->current_rated_a,
                          &m->current_max_a,
                          &m->psi_ref_wb,
                          &m->speed_max_rpm};
    for (size_t k = 0; k < sizeof md / sizeof md[0]; k++) {
        *md[k] = r_f64(&r);
    }
    s->n_sets = (uint8_t)r_u8(&r);
    if (s->n_sets > PIL_SETS_MAX) {
        return PIL_E_FORMAT;
    }
    for (size_t k = 0; k < s->n_sets; k++) {
        r_str(&r, s->sets[k].name, sizeof s->sets[k].name);
        s->sets[k].value = r_f64(&r);
    }
    s->calib_samples = r_u32(&r);
    s->speed_bw_hz = r_f64(&r);
    s->speed_pm_deg = r_f64(&r);
    s->speed_kp = r_f64(&r);
    s->speed_ki = r_f64(&r);
    s->speed_unit = (uint8_t)r_u8(&r);
    s->overspeed_rpm = r_f64(&r);
    s->psi_adapt = r_bool(&r);
    s->sensorless = r_bool(&r);
    s->hfi = r_bool(&r);
    s->dead_time_s = r_f64(&r);
    s->v_fwd_v = r_f64(&r);
    s->enc_offset = r_u32(&r);
    const uint32_t dir = r_u8(&r);
    s->enc_direction = dir == 0xFFu ? (int8_t)-1 : (int8_t)1;
    if (dir != 0xFFu && dir != 1u) {
        r.bad = true;
    }
    s->enc_cpr = r_u32(&r);
    hal_info_t *i = &s->info;
    i->pwm_freq_hz = r_u32(&r);
    i->period_counts = r_u32(&r);
    i->adc_bits = (uint8_t)r_u8(&r);
    i->adc_current_a_per_count = r_f64(&r);
    i->adc_vdc_v_per_count = r_f64(&r);
    i->encoder_counts_per_rev = r_u32(&r);
    i->has_i_c = r_bool(&r);
    i->cycle_clock_hz = r_u32(&r);
    i->pwm_cmp_max = r_u32(&r);
    return r_done(&r);
}

size_t pil_ready_pack(const pil_ready_t *rd, uint8_t *out, size_t cap)
{
    pil_w_t w = {out, 0u, cap, false};
    w_u32(&w, (uint32_t)rd->rc);
    w_u32(&w, rd->cycle_clock_hz);
    char why[PIL_WHY_MAX];
    memcpy(why, rd->why, sizeof why);
    why[PIL_WHY_MAX - 1u] = '\0';
    w_str(&w, why);
    return w_done(&w);
}

int pil_ready_unpack(const uint8_t *p, size_t n, pil_ready_t *rd)
{
    pil_r_t r = {p, n, 0u, false};
    memset(rd, 0, sizeof *rd);
    rd->rc = pil_i32(r_u32(&r));
    rd->cycle_clock_hz = r_u32(&r);
    r_str(&r, rd->why, sizeof rd->why);
    return r_done(&r);
}

/* ---- framing ---- */

size_t pil_frame_encode(uint8_t type, uint16_t seq, const uint8_t *payload, size_t len,
                        uint8_t *wire, size_t cap)
{
    uint8_t body[PIL_BODY_MAX];
    if (len + 5u > PIL_BODY_MAX || (payload == NULL && len != 0u) || wire == NULL || cap < 2u) {
        return 0u;
    }
    body[0] = type;
    body[1] = (uint8_t)(seq & 0xFFu);
    body[2] = (uint8_t)(seq >> 8);
    if (len > 0u) {
        memcpy(&body[3], payload, len);
    }
    const uint16_t crc = tel_crc16(body, len + 3u);
    body[len + 3u] = (uint8_t)(crc >> 8);
    body[len + 4u] = (uint8_t)(crc & 0xFFu);
    const size_t e = tel_cobs_encode(body, len + 5u, &wire[1], cap - 2u);
    if (e == 0u) {
        return 0u;
    }
    wire[0] = 0u;
    wire[e + 1u] = 0u;
    return e + 2u;
}

void pil_dec_init(pil_dec_t *d)
{
    d->len = 0u;
    d->overflow = false;
}

bool pil_dec_busy(const pil_dec_t *d)
{
    return d->len > 0u || d->overflow;
}

static bool pil_type_known(uint8_t t)
{
    return t >= PIL_T_SETUP && t <= PIL_T_FAULT;
}

int pil_dec_feed(pil_dec_t *d, uint8_t byte, pil_frame_t *out, bool *got)
{
    *got = false;
    if (byte != 0u) {
        if (d->len < sizeof d->buf) {
            d->buf[d->len++] = byte;
        } else {
            d->overflow = true;
        }
        return PIL_OK;
    }
    if (d->len == 0u && !d->overflow) {
        return PIL_OK; /* the delimiter between two frames */
    }
    const bool overflow = d->overflow;
    const size_t len = d->len;
    pil_dec_init(d);
    uint8_t body[PIL_BODY_MAX];
    size_t n = 0u;
    if (overflow || tel_cobs_decode(d->buf, len, body, sizeof body, &n) != 0 || n < 5u) {
        return PIL_E_FORMAT;
    }
    if (tel_crc16(body, n) != 0u) {
        return PIL_E_CRC;
    }
    if (!pil_type_known(body[0])) {
        return PIL_E_FORMAT;
    }
    out->type = body[0];
    out->seq = (uint16_t)(body[1] | (body[2] << 8));
    out->len = (uint16_t)(n - 5u);
    memcpy(out->payload, &body[3], n - 5u);
    *got = true;
    return PIL_OK;
}
