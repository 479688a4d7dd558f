/* Console on the firmware's serial link for the host tests (link_text.h). */
#include "link_text.h"

#include "unity.h"

void link_text_capture(void *ctx, const uint8_t *bytes, size_t n)
{
    link_text_t *t = ctx;
    for (size_t i = 0; i < n; i++) {
        if (bytes[i] == 0u) {
            t->zeros++;
        }
        if (t->len + 1u < sizeof t->out) {
            t->out[t->len++] = bytes[i] != 0u ? (char)bytes[i] : '.';
            t->out[t->len] = '\0';
        }
    }
}

void link_text_send(link_text_t *t, fw_link_t *link, const char *line)
{
    t->len = 0;
    t->out[0] = '\0';
    for (const char *p = line; *p != '\0'; p++) {
        fw_link_rx(link, (uint8_t)*p);
    }
    fw_link_rx(link, (uint8_t)'\n');
}

void link_text_periods(sim_run_t *run, fw_link_t *link, int n)
{
    for (int k = 0; k < n; k++) {
        TEST_ASSERT_EQUAL_INT(0, sim_run_period(run));
        fw_link_poll(link);
    }
}
