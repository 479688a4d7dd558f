/*
 * RAM model of the G4 flash's settings pages (settings_flash_model.h).
 */
#include "settings_flash_model.h"

#include <string.h>

static uint32_t sfm_rand(sfm_t *m)
{
    uint32_t x = m->rng; /* xorshift32 */
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    m->rng = x;
    return x;
}

void sfm_init_size(sfm_t *m, uint32_t seed, uint32_t page_size)
{
    memset(m, 0, sizeof *m);
    memset(m->mem, 0xFF, sizeof m->mem);
    m->page_size = page_size <= SFM_PAGE_MAX ? page_size & ~7u : SFM_PAGE_MAX;
    m->rng = seed != 0u ? seed : 0x9E3779B9u;
}

void sfm_init(sfm_t *m, uint32_t seed)
{
    sfm_init_size(m, seed, SFM_PAGE_SIZE);
}

void sfm_cut(sfm_t *m, uint32_t n, sfm_cut_t mode)
{
    m->cut_at = m->ops + n;
    m->cut_mode = mode;
}

void sfm_power_on(sfm_t *m)
{
    m->off = false;
    m->cut_at = 0;
}

const char *sfm_strerror(int code)
{
    switch (code) {
    case SFM_E_ECC:
        return "ECC error (ECCD)";
    case SFM_E_PROGERR:
        return "PROGERR (double word not erased)";
    case SFM_E_POWER:
        return "power off";
    case SFM_E_ADDR:
        return "address outside the settings pages";
    default:
        return "flash error";
    }
}

/* Start one operation: false when the power is off. *torn: this operation is
 * the one the power cut interrupts. */
static bool sfm_begin(sfm_t *m, bool *torn)
{
    *torn = false;
    if (m->off) {
        return false;
    }
    m->ops++;
    if (m->cut_at != 0u && m->ops == m->cut_at) {
        m->off = true;
        *torn = m->cut_mode == SFM_CUT_TORN;
    }
    return true;
}

static int sfm_read(void *ctx, unsigned page, uint32_t off, uint8_t *buf, size_t n)
{
    sfm_t *m = (sfm_t *)ctx;
    if (page > 1u || off > m->page_size || n > m->page_size - off) {
        return SFM_E_ADDR;
    }
    for (size_t i = off / 8u; i * 8u < off + n; i++) {
        if (m->ecc_bad[page][i] != 0u) {
            return SFM_E_ECC;
        }
    }
    memcpy(buf, &m->mem[page][off], n);
    return 0;
}

static int sfm_erase(void *ctx, unsigned page)
{
    sfm_t *m = (sfm_t *)ctx;
    if (page > 1u) {
        return SFM_E_ADDR;
    }
    bool torn;
    if (!sfm_begin(m, &torn)) {
        return SFM_E_POWER;
    }
    if (torn) {
        /* interrupted: each double word erased, untouched, or half-way (ECC) */
        for (unsigned i = 0; i < m->page_size / 8u; i++) {
            const uint32_t r = sfm_rand(m) % 3u;
            if (r == 0u) {
                memset(&m->mem[page][8u * i], 0xFF, 8u);
                m->ecc_bad[page][i] = 0u;
            } else if (r == 1u) {
                for (unsigned b = 0; b < 8u; b++) {
                    m->mem[page][8u * i + b] |= (uint8_t)sfm_rand(m);
                }
                m->ecc_bad[page][i] = 1u;
            }
        }
        return SFM_E_POWER;
    }
    memset(m->mem[page], 0xFF, m->page_size);
    memset(m->ecc_bad[page], 0, m->page_size / 8u);
    return m->off ? SFM_E_POWER : 0;
}

static int sfm_program(void *ctx, unsigned page, uint32_t off, const uint8_t dw[8])
{
    sfm_t *m = (sfm_t *)ctx;
    if (page > 1u || (off & 7u) != 0u || off >= m->page_size) {
        return SFM_E_ADDR;
    }
    uint8_t *at = &m->mem[page][off];
    bool erased = m->ecc_bad[page][off / 8u] == 0u;
    for (unsigned b = 0; b < 8u; b++) {
        erased = erased && at[b] == 0xFFu;
    }
    if (!erased) {
        return SFM_E_PROGERR; /* checked before the operation starts */
    }
    bool torn;
    if (!sfm_begin(m, &torn)) {
        return SFM_E_POWER;
    }
    if (torn) {
        /* some of the bits to clear are cleared, the ECC bits are not consistent */
        for (unsigned b = 0; b < 8u; b++) {
            at[b] = (uint8_t)(at[b] & (dw[b] | (uint8_t)sfm_rand(m)));
        }
        m->ecc_bad[page][off / 8u] = 1u;
        return SFM_E_POWER;
    }
    for (unsigned b = 0; b < 8u; b++) {
        at[b] &= dw[b];
    }
    return m->off ? SFM_E_POWER : 0;
}

void sfm_flash(sfm_t *m, settings_flash_t *f)
{
    memset(f, 0, sizeof *f);
    f->ctx = m;
    f->page_size = m->page_size;
    f->read = sfm_read;
    f->erase = sfm_erase;
    f->program = sfm_program;
    f->strerror = sfm_strerror;
}
