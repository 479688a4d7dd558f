/* Seeds for fuzz_settings: valid records (ECC byte 0 in front), a few with
 * a neighbouring format number. usage: seed_gen DIR */
#include <stdio.h>

#include "settings.h"
#include "settings_gen.h"

int main(int argc, char **argv)
{
    if (argc != 2) {
        return 2;
    }
    uint32_t x = 99u;
    for (int i = 0; i < 16; i++) {
        settings_t s;
        sgen_settings(&x, &s);
        unsigned char rec[1 + SETTINGS_REC_MAX];
        rec[0] = 0u;
        const size_t len = settings_encode(&s, (uint32_t)i, rec + 1, SETTINGS_REC_MAX);
        if (i % 4 == 3) {
            rec[1 + 4] = (unsigned char)(SETTINGS_FORMAT + 1u);
        }
        char path[512];
        (void)snprintf(path, sizeof path, "%s/seed%02d", argv[1], i);
        FILE *f = fopen(path, "wb");
        if (f == NULL || fwrite(rec, 1, 1 + len, f) != 1 + len) {
            return 1;
        }
        (void)fclose(f);
    }
    return 0;
}
