/*
 * pi and the unit conversions of the configuration code (double): the one
 * home of each. Included by *_config.c files, the firmware's configuration
 * code and tests; never by per-sample code (control_float_free_cm0).
 *
 * Speeds: mechanical r/min (data sheets, commands), mechanical rad/s, and
 * electrical rad/s = p * mechanical rad/s (every formula of the core).
 */
#ifndef CONTROL_CTRL_UNITS_H
#define CONTROL_CTRL_UNITS_H

#define CTRL_PI 3.14159265358979323846
#define CTRL_TWO_PI 6.28318530717958647693
#define CTRL_SQRT3 1.73205080756887729353

/* Degrees -> rad. */
static inline double ctrl_deg_to_rad(double deg)
{
    return deg * (CTRL_PI / 180.0);
}

/* r/min -> mechanical rad/s, and back. */
static inline double ctrl_rpm_to_rad_s(double rpm)
{
    return rpm * (CTRL_TWO_PI / 60.0);
}

static inline double ctrl_rad_s_to_rpm(double w)
{
    return w * (60.0 / CTRL_TWO_PI);
}

/* Mechanical r/min -> electrical rad/s with p pole pairs, and back. */
static inline double ctrl_rpm_to_elec(double rpm, int pole_pairs)
{
    return ctrl_rpm_to_rad_s(rpm) * (double)pole_pairs;
}

static inline double ctrl_elec_to_rpm(double w_e, int pole_pairs)
{
    return ctrl_rad_s_to_rpm(w_e) / (double)pole_pairs;
}

#endif /* CONTROL_CTRL_UNITS_H */
