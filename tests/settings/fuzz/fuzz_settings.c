/*
 * libFuzzer target: arbitrary bytes against the settings loader.
 * Invariants (abort on violation):
 *  - settings_decode never reads past n bytes (ASan) and accepts a record only
 *    with its CRC, this format and every field inside its type;
 *  - an accepted record re-encodes (same sequence) to a record that decodes to
 *    the same settings (canonical form);
 *  - the same bytes as a flash page beside an erased one (first byte: which
 *    double words read as ECC errors): settings_store_load applies them only
 *    if settings_decode accepts them, and a save afterwards always succeeds
 *    and is what the next load applies.
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "settings.h"
#include "settings_flash_model.h"
#include "settings_store.h"

#define FZ_CHECK(cond)                                                                             \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            abort();                                                                               \
        }                                                                                          \
    } while (0)

static uint8_t a[SETTINGS_REC_MAX], b[SETTINGS_REC_MAX], buf[SETTINGS_REC_MAX];
static sfm_t fm;

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t n);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t n)
{
    if (n < 1u) {
        return 0;
    }
    const uint8_t ecc = data[0];
    data++;
    n--;
    settings_t s, t;
    uint32_t seq = 0, seq2 = 0;
    const settings_status_t st = settings_decode(data, n, &s, &seq, NULL);
    if (st == SETTINGS_OK) {
        const size_t len = settings_encode(&s, seq, a, sizeof a);
        FZ_CHECK(len == settings_record_size());
        FZ_CHECK(settings_decode(a, len, &t, &seq2, NULL) == SETTINGS_OK && seq2 == seq);
        FZ_CHECK(settings_encode(&t, seq2, b, sizeof b) == len && memcmp(a, b, len) == 0);
    }
    /* the bytes as page 1 of the flash */
    sfm_init(&fm, 1u);
    settings_flash_t f;
    sfm_flash(&fm, &f);
    const size_t m = n < SFM_PAGE_SIZE ? n : SFM_PAGE_SIZE;
    memcpy(fm.mem[1], data, m);
    for (unsigned k = 0; k < 8u; k++) {
        fm.ecc_bad[1][k * 2u] = (uint8_t)((ecc >> k) & 1u);
    }
    settings_scan_t scan;
    const settings_status_t ls = settings_store_load(&f, buf, sizeof buf, &t, &scan);
    FZ_CHECK(ls != SETTINGS_OK || (scan.page == 1 && scan.status[1] == SETTINGS_OK));
    if (ls == SETTINGS_OK) {
        FZ_CHECK(st == SETTINGS_OK && ecc == 0u);
    }
    /* a save now goes to page 0 and wins */
    memset(&s, 0, sizeof s);
    s.pole_pairs = 3;
    s.enc_direction = 1;
    strcpy(s.ctrl, "fst");
    FZ_CHECK(settings_store_save(&f, buf, sizeof buf, &s, &seq2) == 0);
    FZ_CHECK(settings_store_load(&f, buf, sizeof buf, &t, &scan) == SETTINGS_OK);
    FZ_CHECK(scan.page == 0 && t.pole_pairs == 3 && seq2 == scan.seq[0]);
    return 0;
}
