/*
 * Strict decimal numbers for the command interface (no strtod, no scanf, no
 * locale, no heap). A number is kept exactly as a decimal mantissa and a
 * power-of-ten exponent, value = mant * 10^exp10, and is converted to double
 * only at the boundary to the firmware (cmd_num_to_double): the command layer
 * runs in the main loop, never per sample, so a double there is acceptable.
 *
 * Grammar (whole token, nothing before or after):
 *     number   = [ "+" | "-" ] ( digits [ "." [ digits ] ] | "." digits ) [ exponent ]
 *     exponent = ( "e" | "E" ) [ "+" | "-" ] digits
 *     digits   = "0".."9" { "0".."9" }
 * Accepted: "5", "-0.25", ".5", "5.", "1e3", "2.5E-3", "+007".
 * Rejected: "", "+", "-", ".", "--1", "+-1", "1e", "1e+", "e5", "1.2.3",
 *           "0x10", "inf", "nan", "1 ", "1,5", "1_000".
 * Limits: at most CMD_NUM_MAX_DIGITS significant digits (leading zeros are not
 * significant, trailing zeros of the mantissa are dropped exactly); a non-zero
 * magnitude must lie in [1e-15, 1e15] (CMD_NUM_EXP_MIN/MAX), so "1e999" and
 * "1e-999" are range errors, not silently infinity or zero.
 */
#ifndef FIRMWARE_CMD_NUM_H
#define FIRMWARE_CMD_NUM_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define CMD_NUM_MAX_DIGITS 18 /* 10^18 < 2^63: the mantissa fits int64_t */
#define CMD_NUM_EXP_MIN (-15) /* smallest accepted non-zero magnitude 1e-15 */
#define CMD_NUM_EXP_MAX 15    /* largest accepted magnitude 1e15 */

typedef struct {
    int64_t mant;  /* |mant| < 10^18, no trailing decimal zeros (0 for zero) */
    int32_t exp10; /* value = mant * 10^exp10 */
} cmd_num_t;

typedef enum {
    CMD_NUM_OK = 0,
    CMD_NUM_SYNTAX, /* not a number by the grammar above */
    CMD_NUM_RANGE   /* well formed, but too many digits or magnitude out of limits */
} cmd_num_status_t;

/* Parse s[0..len) (not NUL-terminated necessarily). *out is written only on CMD_NUM_OK. */
cmd_num_status_t cmd_num_parse(const char *s, size_t len, cmd_num_t *out);

/* Nearest double (within a few ulp; exact for integers below 2^53). */
double cmd_num_to_double(const cmd_num_t *n);

/* Unsigned decimal integer "0".."4294967295", digits only (no sign, no
 * exponent). Returns CMD_NUM_SYNTAX or CMD_NUM_RANGE on error. */
cmd_num_status_t cmd_num_parse_u32(const char *s, size_t len, uint32_t *out);

/*
 * Format a double with up to `sig` (1..15) significant digits, shortest form:
 * plain decimal for 1e-4 <= |x| < 1e9, else d.ddde[+-]x; "0" for zero,
 * "nan"/"inf"/"-inf" for non-finite values. Always NUL-terminated. Returns the
 * length written, or 0 if cap is too small (buf then holds "").
 */
size_t cmd_num_format(char *buf, size_t cap, double x, unsigned sig);

#endif /* FIRMWARE_CMD_NUM_H */
