/* HAL simulation back-end on the host plant (model in hal_sim.h). */
#include "hal_sim.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

void hal_sim_config_default(hal_sim_config_t *c, uint32_t pwm_freq_hz, double current_max_a,
                            double vdc_v)
{
    if (c == NULL) {
        return;
    }
    memset(c, 0, sizeof *c);
    c->pwm_freq_hz = pwm_freq_hz;
    c->timer_clock_hz = 100000000u;
    c->cycle_clock_hz = 100000000u;
    c->cycles_per_read = 50u;
    c->adc_bits = 12u;
    c->i_fullscale_a = 1.5 * current_max_a;
    c->vdc_fullscale_v = 2.0 * vdc_v;
    c->adc_noise_counts = 0.5;
    c->enc_lines = 2500u;
    c->enc_index = true;
    c->enc_zero_count = 0u;
    c->enc_zero_rad = 0.0;
    c->enc_dir = 1;
    c->adc_invert = 0u;
    c->trip_level_a = 1.25 * current_max_a;
    c->seed = 1u;
}

/* splitmix64: a small, well-mixed generator (Steele et al. 2014). */
static uint64_t hal_sim_rng_next(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Uniform in (0, 1]: 53 random bits, never 0 (log below). */
static double hal_sim_rng_unit(uint64_t *s)
{
    return ((double)(hal_sim_rng_next(s) >> 11) + 1.0) * (1.0 / 9007199254740992.0);
}

/* Standard normal by Box-Muller (one of the pair is used: simple, deterministic). */
static double hal_sim_gauss(uint64_t *s)
{
    const double u1 = hal_sim_rng_unit(s);
    const double u2 = hal_sim_rng_unit(s);
    return sqrt(-2.0 * log(u1)) * cos(2.0 * PLANT_PI * u2);
}

int hal_sim_init(hal_t *h, const hal_sim_config_t *cfg, plant_t *plant)
{
    if (h == NULL || cfg == NULL || plant == NULL) {
        return HAL_SIM_EINVAL;
    }
    memset(h, 0, sizeof *h);
    if (cfg->pwm_freq_hz == 0u || cfg->timer_clock_hz < 2u * cfg->pwm_freq_hz ||
        cfg->adc_bits < 8u || cfg->adc_bits > 16u || !(cfg->i_fullscale_a > 0.0) ||
        !(cfg->vdc_fullscale_v > 0.0) || !(cfg->adc_noise_counts >= 0.0) ||
        !isfinite(cfg->i_fullscale_a) || !isfinite(cfg->vdc_fullscale_v) ||
        !isfinite(cfg->adc_noise_counts) || cfg->enc_lines == 0u || cfg->enc_lines > 100000000u ||
        !(cfg->trip_level_a >= 0.0) || !isfinite(cfg->enc_zero_rad) ||
        !(cfg->duty_max >= 0.0 && cfg->duty_max <= 1.0)) {
        return HAL_SIM_EINVAL;
    }
    for (int i = 0; i < 4; i++) {
        if (!isfinite(cfg->adc_offset_counts[i]) || !isfinite(cfg->adc_gain_err[i]) ||
            fabs(cfg->adc_gain_err[i]) >= 0.5) {
            return HAL_SIM_EINVAL;
        }
    }
    h->cfg = *cfg;
    h->plant = plant;
    const double n = floor((double)cfg->timer_clock_hz / (2.0 * (double)cfg->pwm_freq_hz) + 0.5);
    h->period_counts = (uint32_t)n;
    h->cmp_max = cfg->duty_max > 0.0 ? (uint32_t)floor(cfg->duty_max * n) : h->period_counts;
    h->period_s = 1.0 / (double)cfg->pwm_freq_hz;
    h->rng = cfg->seed;
    h->gates_on = false;
    return HAL_SIM_OK;
}

static uint16_t hal_sim_adc_count(hal_t *h, double value_counts)
{
    double c = value_counts;
    if (h->cfg.adc_noise_counts > 0.0) {
        c += h->cfg.adc_noise_counts * hal_sim_gauss(&h->rng);
    }
    const double top = (double)((1u << h->cfg.adc_bits) - 1u);
    c = floor(c + 0.5);
    c = c < 0.0 ? 0.0 : (c > top ? top : c);
    return (uint16_t)c;
}

static void hal_sim_sample(hal_t *h)
{
    const hal_sim_config_t *c = &h->cfg;
    double i_abc[3];
    if (c->sense_motor_side) {
        plant_i_abc(h->plant, i_abc);
    } else {
        plant_i_inverter_abc(h->plant, i_abc);
    }
    i_abc[0] += h->short_i_a;
    i_abc[1] -= h->short_i_a;

    const double full = (double)(1u << c->adc_bits);
    const double lsb_i = 2.0 * c->i_fullscale_a / full;
    const double mid = full / 2.0;
    for (int x = 0; x < 3; x++) {
        const double sense = ((c->adc_invert >> x) & 1u) != 0u ? -i_abc[x] : i_abc[x];
        const double cnt =
            mid + c->adc_offset_counts[x] + (1.0 + c->adc_gain_err[x]) * sense / lsb_i;
        const uint16_t v = hal_sim_adc_count(h, cnt);
        if (x == 0) {
            h->adc.i_a = v;
        } else if (x == 1) {
            h->adc.i_b = v;
        } else {
            h->adc.i_c = v;
        }
    }
    const double lsb_v = c->vdc_fullscale_v / full;
    h->adc.vdc = hal_sim_adc_count(h, c->adc_offset_counts[3] +
                                          (1.0 + c->adc_gain_err[3]) * plant_vdc(h->plant) / lsb_v);

    if (c->trip_level_a > 0.0) {
        for (int x = 0; x < 3; x++) {
            if (fabs(i_abc[x]) > c->trip_level_a) {
                h->trip = true;
            }
        }
    }

    /* Encoder from the unwrapped mechanical angle. */
    const uint32_t cpr = 4u * c->enc_lines;
    const double theta_m =
        (c->enc_dir == -1 ? -1.0 : 1.0) * (plant_theta_m(h->plant) - c->enc_zero_rad);
    const double pos = floor(theta_m * (double)cpr / (2.0 * PLANT_PI));
    const double turns = floor(theta_m / (2.0 * PLANT_PI));
    /* pos modulo 2^32 without converting an out-of-range double. */
    const double m32 = 4294967296.0;
    const double wrapped = pos - m32 * floor(pos / m32);
    uint32_t count = (uint32_t)wrapped + c->enc_zero_count;
    count += (uint32_t)h->enc_glitch_total;
    if (h->enc_stuck) {
        count = h->enc_stuck_count;
    } else {
        h->enc_stuck_count = count;
    }
    h->enc.count = count;
    const int64_t t = (int64_t)turns;
    if (c->enc_index && h->primed && t != h->enc_turns_prev) {
        /* The index is at theta_m = 0 mod 2 pi: the larger of the two turn counts. */
        const int64_t k = t > h->enc_turns_prev ? t : h->enc_turns_prev;
        const double idx = (double)k * (double)cpr;
        h->enc.index_seen = true;
        /* The hardware latches the counter register, spurious counts included. */
        h->enc.index_count = (uint32_t)(idx - m32 * floor(idx / m32)) + c->enc_zero_count +
                             (uint32_t)h->enc_glitch_total;
    }
    h->enc_turns_prev = t;
    h->primed = true;
}

void hal_sim_period_begin(hal_t *h)
{
    if (h == NULL) {
        return;
    }
    h->active = h->shadow;
    if (h->gate_enable_pending) {
        h->gates_on = true;
        h->gate_enable_pending = false;
    }
    h->reads_this_period = 0u;
    hal_sim_sample(h);
}

int hal_sim_period_end(hal_t *h)
{
    if (h == NULL) {
        return PLANT_EINVAL;
    }
    int rc;
    if (h->gates_on && !h->motor_off) {
        double d[3];
        for (int x = 0; x < 3; x++) {
            /* The back-end limits the compare values as a board does. */
            const uint32_t cmp = h->active.cmp[x] > h->cmp_max ? h->cmp_max : h->active.cmp[x];
            d[x] = (double)cmp / (double)h->period_counts;
        }
        rc = plant_advance_period(h->plant, h->period_s, d);
        if (h->short_slope_a_s != 0.0) {
            h->short_i_a += h->short_slope_a_s * h->period_s;
        }
        if (h->short_l_h > 0.0) {
            /* Mean line voltage a-b of the period over the short's inductance. */
            h->short_i_a += (d[0] - d[1]) * plant_vdc(h->plant) * h->period_s / h->short_l_h;
        }
    } else {
        const uint8_t off[3] = {PLANT_LEG_OFF, PLANT_LEG_OFF, PLANT_LEG_OFF};
        rc = plant_advance(h->plant, h->period_s, off);
        h->short_i_a = 0.0;
    }
    h->period_index++;
    /* Cycle counter: one period of CPU clock (modulo 2^32). */
    h->cycles += h->cfg.cycle_clock_hz / h->cfg.pwm_freq_hz;
    return rc;
}

uint64_t hal_sim_period(const hal_t *h)
{
    return h != NULL ? h->period_index : 0u;
}

bool hal_sim_gates_on(const hal_t *h)
{
    return h != NULL && h->gates_on;
}

void hal_sim_pwm_active(const hal_t *h, hal_pwm_t *pwm)
{
    if (h != NULL && pwm != NULL) {
        *pwm = h->active;
    }
}

void hal_sim_inject_short(hal_t *h, double slope_a_per_s)
{
    if (h != NULL && isfinite(slope_a_per_s)) {
        h->short_slope_a_s = slope_a_per_s;
        if (slope_a_per_s == 0.0) {
            h->short_i_a = 0.0;
        }
    }
}

void hal_sim_inject_vdc(hal_t *h, double vdc_v)
{
    if (h == NULL || !(vdc_v > 0.0) || !isfinite(vdc_v)) {
        return;
    }
    /* The plant has no setter for its source voltage (stiff link): set the
     * source and the present link voltage together. */
    h->plant->cfg.vdc_v = vdc_v;
    h->plant->vdc = vdc_v;
}

void hal_sim_inject_encoder_stuck(hal_t *h, bool stuck)
{
    if (h != NULL) {
        h->enc_stuck = stuck;
    }
}

void hal_sim_inject_encoder_glitch(hal_t *h, int32_t counts)
{
    if (h != NULL) {
        /* Modulo-2^32 accumulation, done in unsigned arithmetic. */
        h->enc_glitch_total = (int32_t)(uint32_t)((uint32_t)h->enc_glitch_total + (uint32_t)counts);
    }
}

void hal_sim_inject_motor_off(hal_t *h, bool off)
{
    if (h != NULL) {
        h->motor_off = off;
    }
}

void hal_sim_inject_winding_short(hal_t *h, double l_short_h)
{
    if (h != NULL && isfinite(l_short_h) && l_short_h >= 0.0) {
        h->short_l_h = l_short_h;
        if (l_short_h == 0.0) {
            h->short_i_a = 0.0;
        }
    }
}

void hal_sim_inject_overrun(hal_t *h, uint32_t cycles)
{
    if (h != NULL) {
        h->overrun_pending = cycles;
    }
}

/* ---- hal.h ---- */

void hal_info_get(const hal_t *h, hal_info_t *info)
{
    if (h == NULL || info == NULL) {
        return;
    }
    memset(info, 0, sizeof *info);
    const double full = (double)(1u << h->cfg.adc_bits);
    info->pwm_freq_hz = h->cfg.pwm_freq_hz;
    info->period_counts = h->period_counts;
    info->adc_bits = h->cfg.adc_bits;
    info->adc_current_a_per_count = 2.0 * h->cfg.i_fullscale_a / full;
    info->adc_vdc_v_per_count = h->cfg.vdc_fullscale_v / full;
    info->encoder_counts_per_rev = 4u * h->cfg.enc_lines;
    info->has_i_c = true;
    info->cycle_clock_hz = h->cfg.cycle_clock_hz;
    info->pwm_cmp_max = h->cmp_max;
}

void hal_adc_read(hal_t *h, hal_adc_raw_t *raw)
{
    if (h != NULL && raw != NULL) {
        *raw = h->adc;
    }
}

void hal_encoder_read(hal_t *h, hal_encoder_raw_t *enc)
{
    if (h != NULL && enc != NULL) {
        *enc = h->enc;
    }
}

void hal_pwm_write(hal_t *h, const hal_pwm_t *pwm)
{
    if (h != NULL && pwm != NULL) {
        h->shadow = *pwm;
    }
}

void hal_ctrl_hold(hal_t *h, bool hold)
{
    /* no interrupt: the caller runs the periods; the depth for the tests */
    if (h != NULL) {
        h->hold_depth = hold ? h->hold_depth + 1u : (h->hold_depth != 0u ? h->hold_depth - 1u : 0u);
    }
}

void hal_gate_enable(hal_t *h, bool enable)
{
    if (h == NULL) {
        return;
    }
    if (enable) {
        if (!h->gates_on) {
            h->gate_enable_pending = true;
        }
    } else {
        h->gates_on = false;
        h->gate_enable_pending = false;
    }
}

bool hal_trip_active(const hal_t *h)
{
    return h != NULL && h->trip;
}

void hal_trip_clear(hal_t *h)
{
    if (h != NULL) {
        h->trip = false;
    }
}

uint32_t hal_cycles(const hal_t *h)
{
    if (h == NULL) {
        return 0u;
    }
    /* hal_cycles takes a const handle (a read of a free-running counter); the
     * simulated counter advances per read. The handle object is never defined
     * const (hal_sim_init writes it), so dropping the qualifier is defined. */
    hal_t *m = (hal_t *)(uintptr_t)h;
    m->cycles += m->cfg.cycles_per_read;
    m->reads_this_period++;
    if (m->reads_this_period == 2u && m->overrun_pending != 0u) {
        m->cycles += m->overrun_pending;
        m->overrun_pending = 0u;
    }
    return m->cycles;
}
