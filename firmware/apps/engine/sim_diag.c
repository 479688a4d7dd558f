/* Warnings of a run (sim_diag.h). */
#include "sim_diag.h"

#include <stdarg.h>
#include <string.h>

void sim_warn(sim_warnings_t *w, const char *fmt, ...)
{
    char text[SIM_WARN_LEN];
    va_list ap;
    va_start(ap, fmt);
    (void)vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    if (w == NULL || !w->quiet) {
        fprintf(stderr, "sim: warning: %s\n", text);
    }
    if (w == NULL) {
        return;
    }
    if (w->n < SIM_WARN_MAX) {
        memcpy(w->msg[w->n], text, sizeof text);
        w->n++;
    } else {
        w->dropped++;
    }
}

void sim_json_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (const unsigned char *c = (const unsigned char *)s; *c != '\0'; c++) {
        if (*c == '"' || *c == '\\') {
            fputc('\\', f);
            fputc(*c, f);
        } else if (*c < 0x20u) {
            fprintf(f, "\\u%04x", (unsigned)*c);
        } else {
            fputc(*c, f);
        }
    }
    fputc('"', f);
}

void sim_warnings_json(FILE *f, const sim_warnings_t *w)
{
    fputc('[', f);
    const size_t n = w != NULL ? w->n : 0u;
    for (size_t i = 0; i < n; i++) {
        if (i > 0u) {
            fputs(", ", f);
        }
        sim_json_string(f, w->msg[i]);
    }
    if (w != NULL && w->dropped > 0u) {
        fprintf(f, "%s\"... and %zu more warnings\"", n > 0u ? ", " : "", w->dropped);
    }
    fputc(']', f);
}

void sim_appendf(char *buf, size_t len, const char *fmt, ...)
{
    const size_t used = strlen(buf);
    if (used + 1u >= len) {
        return;
    }
    va_list ap;
    va_start(ap, fmt);
    (void)vsnprintf(buf + used, len - used, fmt, ap);
    va_end(ap);
}
