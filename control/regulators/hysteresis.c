/* Hysteresis regulators of Fig. 4.2; rules in hysteresis.h. */
#include "hysteresis.h"

#include <stddef.h>

void ctrl_hyst2_init(ctrl_hyst2_t *h, q24_t band)
{
    if (h == NULL) {
        return;
    }
    h->band = band < 0 ? 0 : band;
    h->out = 0;
}

void ctrl_hyst2_reset(ctrl_hyst2_t *h)
{
    if (h != NULL) {
        h->out = 0;
    }
}

int8_t ctrl_hyst2_update(ctrl_hyst2_t *h, q24_t err)
{
    if (h == NULL) {
        return err >= 0 ? (int8_t)1 : (int8_t)-1;
    }
    /* 64-bit negation: safe even for a band written directly into the struct. */
    if (err >= h->band) {
        h->out = 1;
    } else if ((int64_t)err <= -(int64_t)h->band) {
        h->out = -1;
    } else if (h->out == 0) {
        h->out = err >= 0 ? (int8_t)1 : (int8_t)-1; /* no history: follow the sign */
    }
    return h->out;
}

void ctrl_hyst2_sq_limits(ctrl_hyst2_sq_t *h, q24_t ref)
{
    const q24_t band = h->h.band;
    /* err >= band <=> |.| <= ref - band; err <= -band <=> |.| >= ref + band */
    h->inc_lim = fx_mag_le_lim((int64_t)ref - band);
    h->dec_lim = fx_mag_ge_lim((int64_t)ref + band);
    h->nonneg_lim = fx_mag_le_lim(ref);
}

void ctrl_hyst2_sq_init(ctrl_hyst2_sq_t *h, q24_t band)
{
    if (h == NULL) {
        return;
    }
    ctrl_hyst2_init(&h->h, band);
    ctrl_hyst2_sq_limits(h, 0);
}

void ctrl_hyst3_init(ctrl_hyst3_t *h, q24_t band)
{
    if (h == NULL) {
        return;
    }
    h->band = band < 0 ? 0 : band;
    h->out = 0;
}

void ctrl_hyst3_reset(ctrl_hyst3_t *h)
{
    if (h != NULL) {
        h->out = 0;
    }
}

int8_t ctrl_hyst3_update(ctrl_hyst3_t *h, q24_t err)
{
    if (h == NULL) {
        return 0;
    }
    if (err >= h->band) {
        h->out = 1;
    } else if ((int64_t)err <= -(int64_t)h->band) {
        h->out = -1;
    } else if ((h->out > 0 && err <= 0) || (h->out < 0 && err >= 0)) {
        h->out = 0; /* the estimate reached the reference from either side */
    }
    return h->out;
}
