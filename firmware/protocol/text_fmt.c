/* The firmware's text formatter (text_fmt.h). */
#include "text_fmt.h"

#include <limits.h>
#include <stdint.h>

#include "cmd_num.h"

#define TEXT_FMT_DEFAULT_SIG 6u /* C's default precision of %g */

typedef struct {
    char *buf;
    size_t cap;
    size_t n; /* length of the whole text so far (may exceed cap) */
} text_out_t;

static void text_put(text_out_t *o, char c)
{
    if (o->n + 1u < o->cap) {
        o->buf[o->n] = c;
    }
    o->n++;
}

static void text_puts(text_out_t *o, const char *s, size_t len)
{
    for (size_t k = 0; k < len; k++) {
        text_put(o, s[k]);
    }
}

static void text_put_u64(text_out_t *o, uint64_t v, unsigned base)
{
    char d[20];
    unsigned nd = 0;
    do {
        const unsigned r = (unsigned)(v % base);
        d[nd++] = (char)(r < 10u ? '0' + (int)r : 'a' + (int)r - 10);
        v /= base;
    } while (v != 0u);
    while (nd > 0u) {
        text_put(o, d[--nd]);
    }
}

int text_vformat(char *buf, size_t cap, const char *fmt, va_list ap)
{
    text_out_t o = {buf, buf != NULL ? cap : 0u, 0u};
    const char *p = fmt;
    while (*p != '\0') {
        if (*p != '%') {
            text_put(&o, *p++);
            continue;
        }
        const char *conv = p++; /* at '%' */
        unsigned prec = 0u;
        int has_prec = 0;
        if (*p == '.') {
            has_prec = 1;
            p++;
            while (*p >= '0' && *p <= '9') {
                prec = prec < 100u ? prec * 10u + (unsigned)(*p - '0') : prec;
                p++;
            }
        }
        int lng = 0; /* 0 int, 1 long, 2 long long, 3 size_t */
        if (*p == 'l') {
            lng = 1;
            p++;
            if (*p == 'l') {
                lng = 2;
                p++;
            }
        } else if (*p == 'z') {
            lng = 3;
            p++;
        }
        const char c = *p;
        if (c == '\0') {
            text_puts(&o, conv, (size_t)(p - conv)); /* a lone '%' at the end */
            break;
        }
        p++;
        switch (c) {
        case '%':
            text_put(&o, '%');
            break;
        case 'c':
            text_put(&o, (char)va_arg(ap, int));
            break;
        case 's': {
            const char *s = va_arg(ap, const char *);
            s = s != NULL ? s : "(null)";
            for (unsigned k = 0; *s != '\0' && (!has_prec || k < prec); k++) {
                text_put(&o, *s++);
            }
            break;
        }
        case 'd':
        case 'i': {
            const long long v = lng == 2   ? va_arg(ap, long long)
                                : lng == 1 ? (long long)va_arg(ap, long)
                                : lng == 3 ? (long long)va_arg(ap, size_t)
                                           : (long long)va_arg(ap, int);
            if (v < 0) {
                text_put(&o, '-');
            }
            /* |v| without negating LLONG_MIN */
            text_put_u64(&o, v < 0 ? (uint64_t)0 - (uint64_t)v : (uint64_t)v, 10u);
            break;
        }
        case 'u':
        case 'x': {
            const uint64_t v = lng == 2   ? (uint64_t)va_arg(ap, unsigned long long)
                               : lng == 1 ? (uint64_t)va_arg(ap, unsigned long)
                               : lng == 3 ? (uint64_t)va_arg(ap, size_t)
                                          : (uint64_t)va_arg(ap, unsigned);
            text_put_u64(&o, v, c == 'u' ? 10u : 16u);
            break;
        }
        case 'g':
        case 'G':
        case 'e':
        case 'E':
        case 'f':
        case 'F': {
            char t[32];
            const unsigned sig = !has_prec ? TEXT_FMT_DEFAULT_SIG : prec == 0u ? 1u : prec;
            const size_t len = cmd_num_format(t, sizeof t, va_arg(ap, double), sig);
            text_puts(&o, t, len);
            break;
        }
        default: /* unsupported: shown as written, never dropped */
            text_puts(&o, conv, (size_t)(p - conv));
            break;
        }
    }
    if (o.cap > 0u) {
        o.buf[o.n < o.cap ? o.n : o.cap - 1u] = '\0';
    }
    return o.n > (size_t)INT_MAX ? INT_MAX : (int)o.n;
}

int text_format(char *buf, size_t cap, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    const int n = text_vformat(buf, cap, fmt, ap);
    va_end(ap);
    return n;
}
