/*
 * C library functions of a target image replaced by smaller ones of the
 * firmware's. Linked before libc (an OBJECT library), these definitions are
 * the ones the image uses:
 *   - snprintf and vsnprintf by the firmware's formatter (text_fmt.h):
 *     newlib-nano's printf family (3.4 KB; without _printf_float it skips %g
 *     silently, with it about 8 KB more) is not linked at all
 *     (tests/board/check_printf.py checks the image for it);
 *   - strcmp as a byte loop: newlib's is unrolled for speed (0.7 KB), and the
 *     image compares strings only in the command path, never per period.
 */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "text_fmt.h"

int vsnprintf(char *restrict buf, size_t cap, const char *restrict fmt, va_list ap)
{
    return text_vformat(buf, cap, fmt, ap);
}

int snprintf(char *restrict buf, size_t cap, const char *restrict fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    const int n = text_vformat(buf, cap, fmt, ap);
    va_end(ap);
    return n;
}

int strcmp(const char *a, const char *b)
{
    /* C11 7.24.4: the difference of the first differing characters, compared
     * as unsigned char */
    const unsigned char *p = (const unsigned char *)a;
    const unsigned char *q = (const unsigned char *)b;
    while (*p != 0u && *p == *q) {
        p++;
        q++;
    }
    return (int)*p - (int)*q;
}
