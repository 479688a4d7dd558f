/*
 * The firmware's one text formatter: snprintf's subset that the firmware's
 * and the core's messages use, with numbers through the protocol's own
 * cmd_num_format (so a board message and a protocol reply print a value the
 * same way, and no libc float printing is needed: newlib-nano without
 * _printf_float skips %g silently).
 *
 * Conversions: %% %c %s %d %i %u %x, with the length modifiers l, ll, z;
 * %g %G %e %E %f %F with an optional precision .N: the value with N
 * significant digits (6 without), in cmd_num_format's shortest form (plain
 * decimal for 1e-4 <= |x| < 1e9, else d.dde[+-]x; "nan", "inf"). Flags and
 * field widths are not supported: such a conversion, like any unknown one, is
 * copied to the output as written (visible, never silently dropped).
 *
 * Returns the length the whole text needs (as vsnprintf: not counting the
 * NUL); at most cap - 1 characters are written, always NUL-terminated when
 * cap > 0.
 */
#ifndef FIRMWARE_TEXT_FMT_H
#define FIRMWARE_TEXT_FMT_H

#include <stdarg.h>
#include <stddef.h>

int text_vformat(char *buf, size_t cap, const char *fmt, va_list ap);
int text_format(char *buf, size_t cap, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

#endif /* FIRMWARE_TEXT_FMT_H */
