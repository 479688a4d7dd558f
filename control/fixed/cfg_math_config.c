/* Elementary functions of the configuration code (ctrl_cfg_math.h). */
#include "ctrl_cfg_math.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

/* pi/2 in two parts: the first 33 bits (n CFG_PIO2_HI exact for n < 2^20)
 * and the rest, as in Cody and Waite's argument reduction. */
#define CFG_PIO2_HI 1.57079632673412561417e+00
#define CFG_PIO2_LO 6.07710050650619224932e-11
#define CFG_2_OVER_PI 6.36619772367581382433e-01
/* ln 2 in two parts: the first 32 bits (k CFG_LN2_HI exact for |k| < 2^21). */
#define CFG_LN2_HI 6.93147180369123816490e-01
#define CFG_LN2_LO 1.90821492927058770002e-10
#define CFG_1_OVER_LN2 1.44269504088896338700e+00

/* n = round(x) for |x| < 2^62, half away from zero. */
static int64_t cfg_round(double x)
{
    return (int64_t)(x >= 0.0 ? x + 0.5 : x - 0.5);
}

/* 2^n exactly, n in [-1022, 1023]: the biased exponent alone */
static double cfg_pow2(int n)
{
    const uint64_t bits = (uint64_t)(n + 1023) << 52;
    double v;
    memcpy(&v, &bits, sizeof v);
    return v;
}

/* c[0] + z (c[1] + z (... + z c[n - 1])) by Horner's rule: the nested form's
 * operations in its order (one loop instead of a call pair per term). */
static double cfg_horner(const double *c, int n, double z)
{
    double p = c[n - 1];
    for (int k = n - 2; k >= 0; k--) {
        p = c[k] + z * p;
    }
    return p;
}

/* sin r, cos r for |r| <= pi/4: Taylor to r^17 and r^18 (the next terms are
 * below 1e-19 of the result), by Horner's rule in r^2. */
static const double cfg_sin_coef[] = {
    -1.0 / 6.0,        1.0 / 120.0,        -1.0 / 5040.0,          1.0 / 362880.0,
    -1.0 / 39916800.0, 1.0 / 6227020800.0, -1.0 / 1307674368000.0, 1.0 / 355687428096000.0,
};
static const double cfg_cos_coef[] = {
    -0.5,
    1.0 / 24.0,
    -1.0 / 720.0,
    1.0 / 40320.0,
    -1.0 / 3628800.0,
    1.0 / 479001600.0,
    -1.0 / 87178291200.0,
    1.0 / 20922789888000.0,
    -1.0 / 6402373705728000.0,
};
#define CFG_N(a) ((int)(sizeof(a) / sizeof((a)[0])))

static double cfg_sin_kernel(double r)
{
    const double z = r * r;
    return r + r * z * cfg_horner(cfg_sin_coef, CFG_N(cfg_sin_coef), z);
}

static double cfg_cos_kernel(double r)
{
    const double z = r * r;
    return 1.0 + z * cfg_horner(cfg_cos_coef, CFG_N(cfg_cos_coef), z);
}

void ctrl_cfg_sincos(double x, double *s, double *c)
{
    double sv = NAN;
    double cv = NAN;
    if (x >= -CTRL_CFG_TRIG_MAX && x <= CTRL_CFG_TRIG_MAX) { /* false for NaN */
        const int64_t n = cfg_round(x * CFG_2_OVER_PI);
        const double dn = (double)n;
        const double r = (x - dn * CFG_PIO2_HI) - dn * CFG_PIO2_LO;
        const double sr = cfg_sin_kernel(r);
        const double cr = cfg_cos_kernel(r);
        switch ((unsigned)((uint64_t)n & 3u)) { /* quadrant of x */
        case 0u:
            sv = sr;
            cv = cr;
            break;
        case 1u:
            sv = cr;
            cv = -sr;
            break;
        case 2u:
            sv = -sr;
            cv = -cr;
            break;
        default:
            sv = -cr;
            cv = sr;
            break;
        }
    }
    if (s != NULL) {
        *s = sv;
    }
    if (c != NULL) {
        *c = cv;
    }
}

double ctrl_cfg_sin(double x)
{
    double s;
    ctrl_cfg_sincos(x, &s, NULL);
    return s;
}

double ctrl_cfg_cos(double x)
{
    double c;
    ctrl_cfg_sincos(x, NULL, &c);
    return c;
}

/* e^r, |r| <= ln2 / 2: Taylor to r^13 (the next term < 5e-18). */
static const double cfg_exp_coef[] = {
    1.0,
    1.0,
    1.0 / 2.0,
    1.0 / 6.0,
    1.0 / 24.0,
    1.0 / 120.0,
    1.0 / 720.0,
    1.0 / 5040.0,
    1.0 / 40320.0,
    1.0 / 362880.0,
    1.0 / 3628800.0,
    1.0 / 39916800.0,
    1.0 / 479001600.0,
    1.0 / 6227020800.0,
};

double ctrl_cfg_exp(double x)
{
    if (!(x == x)) {
        return x;
    }
    if (x > 709.0) {
        return INFINITY;
    }
    if (x < -708.0) {
        return 0.0;
    }
    /* e^x = 2^k e^r, |r| <= ln2 / 2 */
    const int64_t k = cfg_round(x * CFG_1_OVER_LN2);
    const double dk = (double)k;
    const double r = (x - dk * CFG_LN2_HI) - dk * CFG_LN2_LO;
    const double p = cfg_horner(cfg_exp_coef, CFG_N(cfg_exp_coef), r);
    return p * cfg_pow2((int)k); /* k in [-1022, 1023] */
}

double ctrl_cfg_ldexp(double x, int n)
{
    return n >= -1022 && n <= 1023 ? x * cfg_pow2(n) : NAN;
}

int ctrl_cfg_exponent(double x)
{
    if (!(x == x) || x == 0.0 || x - x != 0.0) { /* NaN, 0, +-inf */
        return 0;
    }
    uint64_t bits;
    int e = 0;
    if (x > -0x1p-1022 && x < 0x1p-1022) { /* subnormal: scale into the normal range */
        x *= 0x1p64;
        e = -64;
    }
    memcpy(&bits, &x, sizeof bits);
    return e + (int)((bits >> 52) & 0x7ffu) - 1022;
}

long long ctrl_cfg_llround(double x)
{
    if (!(x == x)) {
        return 0;
    }
    if (x >= 0x1p63) {
        return INT64_MAX;
    }
    if (x <= -0x1p63) {
        return INT64_MIN;
    }
    /* the integer part (toward zero), then the remainder, exact: x and n
     * differ by less than 1 and have the same sign (Sterbenz) */
    long long n = (long long)x;
    const double r = x - (double)n;
    if (r >= 0.5) {
        n++;
    } else if (r <= -0.5) {
        n--;
    }
    return n;
}

double ctrl_cfg_hypot(double x, double y)
{
    return sqrt(x * x + y * y);
}
