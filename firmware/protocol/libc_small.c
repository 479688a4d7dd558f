/*
 * C library functions of a target image replaced by smaller ones of the
 * firmware's. Linked before libc (an OBJECT library), these definitions are
 * the ones the image uses:
 *   - snprintf and vsnprintf by the firmware's formatter (text_fmt.h):
 *     newlib-nano's printf family (3.4 KB; without _printf_float it skips %g
 *     silently, with it about 8 KB more) is not linked at all
 *     (tests/board/check_printf.py checks the image for it);
 *   - strcmp, strlen, strcpy and strncpy as byte loops: newlib's are unrolled
 *     or word-wise for speed (strcmp 0.7 KB; the other three 0.5 KB), and the
 *     image handles strings only in the command path and at start-up, never
 *     per period;
 *   - memcpy and memset word by word where both ends are word-aligned, byte
 *     by byte otherwise: newlib-nano's unrolled ones took 470 B; the running
 *     period copies no block through them (its copies are a few words, inline),
 *     the configuration and the arming period do (a copy of 1 KB: some
 *     1 300 cycles here).
 * Built with -fno-tree-loop-distribute-patterns: GCC would otherwise turn
 * these loops into calls of memset and memcpy, themselves.
 */
#include <stdarg.h>
#include <stdint.h>
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

size_t strlen(const char *s)
{
    const char *p = s;
    while (*p != '\0') {
        p++;
    }
    return (size_t)(p - s);
}

char *strcpy(char *restrict dst, const char *restrict src)
{
    char *d = dst;
    while ((*d++ = *src++) != '\0') {
    }
    return dst;
}

char *strncpy(char *restrict dst, const char *restrict src, size_t n)
{
    /* C11 7.24.2.4: at most n characters; the rest of the n filled with nulls */
    size_t i = 0;
    for (; i < n && src[i] != '\0'; i++) {
        dst[i] = src[i];
    }
    for (; i < n; i++) {
        dst[i] = '\0';
    }
    return dst;
}

/* A word that may alias any object (GCC's may_alias): the copies below read
 * and write other types' bytes through it. */
typedef uint32_t __attribute__((may_alias)) libc_word_t;

__attribute__((noinline)) void *memcpy(void *restrict dst, const void *restrict src, size_t n)
{
    unsigned char *d = dst;
    const unsigned char *s = src;
    if ((((uintptr_t)d | (uintptr_t)s) & 3u) == 0u) {
        for (; n >= 4u; n -= 4u, d += 4, s += 4) {
            *(libc_word_t *)(void *)d = *(const libc_word_t *)(const void *)s;
        }
    }
    for (; n != 0u; n--) {
        *d++ = *s++;
    }
    return dst;
}

__attribute__((noinline)) void *memset(void *dst, int c, size_t n)
{
    unsigned char *d = dst;
    const unsigned char b = (unsigned char)c;
    if (((uintptr_t)d & 3u) == 0u) {
        const uint32_t w = 0x01010101u * b;
        for (; n >= 4u; n -= 4u, d += 4) {
            *(libc_word_t *)(void *)d = w;
        }
    }
    for (; n != 0u; n--) {
        *d++ = b;
    }
    return dst;
}
