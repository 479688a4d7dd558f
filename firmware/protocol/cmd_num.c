/*
 * Strict decimal parser and a small formatter for the command interface; see
 * cmd_num.h for the grammar. Exact decimal arithmetic in integers until the
 * final conversion, so range checks are decided on the exact value.
 */
#include "cmd_num.h"

/* Powers of ten that a double represents exactly (10^22 < 2^53 * 2^22). */
static const double cmd_num_pow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                         1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                         1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

static bool cmd_num_is_digit(char c)
{
    return c >= '0' && c <= '9';
}

cmd_num_status_t cmd_num_parse(const char *s, size_t len, cmd_num_t *out)
{
    if (s == NULL || out == NULL) {
        return CMD_NUM_SYNTAX;
    }
    size_t i = 0;
    bool neg = false;
    if (i < len && (s[i] == '+' || s[i] == '-')) {
        neg = (s[i] == '-');
        i++;
    }
    uint64_t mant = 0;
    unsigned ndig = 0;   /* significant digits kept in mant */
    int64_t exp_adj = 0; /* decimal point position relative to mant */
    bool any_digit = false;
    bool too_many = false; /* a non-zero digit beyond CMD_NUM_MAX_DIGITS */
    bool frac = false;
    for (; i < len; i++) {
        const char c = s[i];
        if (c == '.' && !frac) {
            frac = true;
            continue;
        }
        if (!cmd_num_is_digit(c)) {
            break;
        }
        const unsigned d = (unsigned)(c - '0');
        any_digit = true;
        if (mant == 0 && d == 0) {
            /* a leading zero: not significant, but it moves a fraction */
            if (frac) {
                exp_adj--;
            }
        } else if (ndig < CMD_NUM_MAX_DIGITS) {
            mant = mant * 10u + d;
            ndig++;
            if (frac) {
                exp_adj--;
            }
        } else if (d != 0) {
            too_many = true;
        } else if (!frac) {
            exp_adj++; /* an integer-part zero that does not fit: exact */
        }
    }
    if (!any_digit) {
        return CMD_NUM_SYNTAX;
    }
    int64_t e = 0;
    if (i < len && (s[i] == 'e' || s[i] == 'E')) {
        i++;
        bool eneg = false;
        if (i < len && (s[i] == '+' || s[i] == '-')) {
            eneg = (s[i] == '-');
            i++;
        }
        bool edig = false;
        for (; i < len && cmd_num_is_digit(s[i]); i++) {
            edig = true;
            if (e < 1000000) { /* saturate: anything this large is a range error */
                e = e * 10 + (int64_t)(s[i] - '0');
            }
        }
        if (!edig) {
            return CMD_NUM_SYNTAX;
        }
        if (eneg) {
            e = -e;
        }
    }
    if (i != len) {
        return CMD_NUM_SYNTAX;
    }
    if (mant == 0) {
        out->mant = 0;
        out->exp10 = 0;
        return CMD_NUM_OK;
    }
    if (too_many) {
        return CMD_NUM_RANGE;
    }
    int64_t ex = exp_adj + e;
    while (mant % 10u == 0u) {
        mant /= 10u;
        ex++;
    }
    int64_t nd = 0;
    for (uint64_t t = mant; t != 0u; t /= 10u) {
        nd++;
    }
    const int64_t msd = ex + nd - 1; /* 10^msd <= |value| < 10^(msd+1) */
    if (msd < CMD_NUM_EXP_MIN || msd > CMD_NUM_EXP_MAX || (msd == CMD_NUM_EXP_MAX && mant != 1u)) {
        return CMD_NUM_RANGE;
    }
    out->mant = neg ? -(int64_t)mant : (int64_t)mant;
    out->exp10 = (int32_t)ex;
    return CMD_NUM_OK;
}

double cmd_num_to_double(const cmd_num_t *n)
{
    if (n == NULL) {
        return 0.0;
    }
    double v = (double)n->mant;
    int32_t e = n->exp10;
    if (e >= 0) {
        while (e > 22) {
            v *= cmd_num_pow10[22];
            e -= 22;
        }
        return v * cmd_num_pow10[e];
    }
    while (e < -22) {
        v /= cmd_num_pow10[22];
        e += 22;
    }
    return v / cmd_num_pow10[-e];
}

cmd_num_status_t cmd_num_parse_u32(const char *s, size_t len, uint32_t *out)
{
    if (s == NULL || out == NULL || len == 0) {
        return CMD_NUM_SYNTAX;
    }
    uint64_t v = 0;
    bool big = false;
    for (size_t i = 0; i < len; i++) {
        if (!cmd_num_is_digit(s[i])) {
            return CMD_NUM_SYNTAX;
        }
        if (!big) {
            v = v * 10u + (uint64_t)(s[i] - '0');
            big = (v > UINT32_MAX);
        }
    }
    if (big) {
        return CMD_NUM_RANGE;
    }
    *out = (uint32_t)v;
    return CMD_NUM_OK;
}

size_t cmd_num_format(char *buf, size_t cap, double x, unsigned sig)
{
    char t[48];
    size_t n = 0;
    if (buf == NULL || cap == 0) {
        return 0;
    }
    buf[0] = '\0';
    if (sig < 1u) {
        sig = 1u;
    }
    if (sig > 15u) {
        sig = 15u;
    }
    if (x != x) {
        t[n++] = 'n';
        t[n++] = 'a';
        t[n++] = 'n';
    } else if (x == 0.0) {
        t[n++] = '0';
    } else {
        double ax = x;
        if (x < 0.0) {
            t[n++] = '-';
            ax = -x;
        }
        if (ax > 1.7976931348623157e308) {
            t[n++] = 'i';
            t[n++] = 'n';
            t[n++] = 'f';
        } else {
            /* decimal exponent e10 with 10^e10 <= ax < 10^(e10+1), scaling in
             * big exact steps first so one rounding dominates */
            int e10 = 0;
            double y = ax;
            while (y >= 1e22) {
                y /= 1e22;
                e10 += 22;
            }
            while (y < 1e-22) {
                y *= 1e22;
                e10 -= 22;
            }
            while (y >= 10.0) {
                y /= 10.0;
                e10++;
            }
            while (y < 1.0) {
                y *= 10.0;
                e10--;
            }
            /* digits: m = round(ax * 10^(sig-1-e10)), from ax directly when the
             * power is exact so only one rounding happens */
            const int sh = (int)sig - 1 - e10;
            double scaled;
            if (sh >= 0 && sh <= 22) {
                scaled = ax * cmd_num_pow10[sh];
            } else if (sh < 0 && sh >= -22) {
                scaled = ax / cmd_num_pow10[-sh];
            } else {
                scaled = y * cmd_num_pow10[sig - 1u];
            }
            uint64_t m = (uint64_t)(scaled + 0.5);
            uint64_t lim = 1;
            for (unsigned k = 0; k < sig; k++) {
                lim *= 10u;
            }
            if (m >= lim) {
                m /= 10u;
                e10++;
            }
            if (m < lim / 10u) { /* scaling error put us one decade low */
                m = lim / 10u;
            }
            char d[16];
            unsigned nd = sig;
            for (unsigned k = sig; k > 0; k--) {
                d[k - 1u] = (char)('0' + (int)(m % 10u));
                m /= 10u;
            }
            while (nd > 1u && d[nd - 1u] == '0') {
                nd--;
            }
            if (e10 >= -4 && e10 < 9) {
                if (e10 < 0) {
                    t[n++] = '0';
                    t[n++] = '.';
                    for (int k = -1; k > e10; k--) {
                        t[n++] = '0';
                    }
                    for (unsigned k = 0; k < nd; k++) {
                        t[n++] = d[k];
                    }
                } else {
                    const unsigned ip = (unsigned)e10 + 1u; /* integer digits */
                    for (unsigned k = 0; k < ip; k++) {
                        t[n++] = (k < nd) ? d[k] : '0';
                    }
                    if (nd > ip) {
                        t[n++] = '.';
                        for (unsigned k = ip; k < nd; k++) {
                            t[n++] = d[k];
                        }
                    }
                }
            } else {
                t[n++] = d[0];
                if (nd > 1u) {
                    t[n++] = '.';
                    for (unsigned k = 1; k < nd; k++) {
                        t[n++] = d[k];
                    }
                }
                t[n++] = 'e';
                int ee = e10;
                if (ee < 0) {
                    t[n++] = '-';
                    ee = -ee;
                }
                char ed[4];
                unsigned ne = 0;
                do {
                    ed[ne++] = (char)('0' + ee % 10);
                    ee /= 10;
                } while (ee != 0 && ne < 4u);
                while (ne > 0u) {
                    t[n++] = ed[--ne];
                }
            }
        }
    }
    if (n + 1u > cap) {
        return 0;
    }
    for (size_t k = 0; k < n; k++) {
        buf[k] = t[k];
    }
    buf[n] = '\0';
    return n;
}
