/*
 * Open-loop replay of a recorded switching sequence (see sim_replay.h).
 * Interval lengths are whole nanoseconds; the elapsed time is kept as an
 * integer so that long sequences accumulate no rounding.
 */
#include "sim_replay.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "sim_csv.h"

static const char k_header[] = "t_start_s,duration_s,S1,S2,S3";

int sim_replay_run(const plant_config_t *base, const sim_replay_opts_t *opts, FILE *in,
                   const char *in_name, FILE *trace, char *err, size_t errlen)
{
    char dummy[8];
    if (err == NULL || errlen == 0) {
        err = dummy;
        errlen = sizeof dummy;
    }
    err[0] = '\0';
    if (in_name == NULL) {
        in_name = "replay";
    }
    if (base == NULL || opts == NULL || in == NULL || trace == NULL) {
        snprintf(err, errlen, "sim_replay_run: NULL argument");
        return -1;
    }
    plant_config_t cfg = *base;
    cfg.mech = PLANT_MECH_IMPOSED;
    cfg.speed0_rpm = opts->speed_rpm;
    cfg.theta0_e_rad = opts->theta0_e_rad;
    cfg.id0_a = opts->id0_a;
    cfg.iq0_a = opts->iq0_a;
    plant_t p;
    if (plant_init(&p, &cfg) != PLANT_OK) {
        snprintf(err, errlen, "%s: invalid plant configuration or initial state", in_name);
        return -1;
    }
    fprintf(trace, "t,i_a,i_b,i_c,i_d,i_q,psi_alpha,psi_beta,torque\n");
    char line[1024];
    long lineno = 0;
    int header_seen = 0;
    int64_t elapsed_ns = 0;
    double t0 = 0.0;
    int first = 1;
    while (fgets(line, sizeof line, in) != NULL) {
        ++lineno;
        if (!sim_csv_line_complete(line, in)) {
            snprintf(err, errlen, "%s:%ld: line too long", in_name, lineno);
            return SIM_REPLAY_EINPUT;
        }
        const char *s = sim_csv_content(line);
        if (s == NULL) {
            continue;
        }
        if (!header_seen) {
            if (!sim_csv_is_header(s, k_header)) {
                snprintf(err, errlen, "%s:%ld: expected header %s", in_name, lineno, k_header);
                return SIM_REPLAY_EINPUT;
            }
            header_seen = 1;
            continue;
        }
        double v[5];
        if (sim_csv_numbers(s, v, 5) != 0) {
            snprintf(err, errlen, "%s:%ld: expected 5 numeric fields %s", in_name, lineno,
                     k_header);
            return SIM_REPLAY_EINPUT;
        }
        if (!(v[1] >= 0.0) || v[1] > 1e3) {
            snprintf(err, errlen, "%s:%ld: duration_s = %g must be in [0, 1000] s", in_name, lineno,
                     v[1]);
            return SIM_REPLAY_EINPUT;
        }
        const double dns = v[1] * 1e9;
        const int64_t ns = (int64_t)llround(dns);
        if (fabs(dns - (double)ns) > 1e-3 + 1e-12 * dns) {
            snprintf(err, errlen, "%s:%ld: duration_s = %.12g is not a whole number of ns", in_name,
                     lineno, v[1]);
            return SIM_REPLAY_EINPUT;
        }
        uint8_t sw[3];
        for (int x = 0; x < 3; ++x) {
            if (v[2 + x] != 0.0 && v[2 + x] != 1.0) {
                snprintf(err, errlen, "%s:%ld: S%d = %g must be 0 or 1", in_name, lineno, x + 1,
                         v[2 + x]);
                return SIM_REPLAY_EINPUT;
            }
            sw[x] = (uint8_t)(v[2 + x] != 0.0);
        }
        if (first) {
            t0 = v[0];
            first = 0;
        } else {
            const double expect = t0 + (double)elapsed_ns * 1e-9;
            if (fabs(v[0] - expect) > 1e-9 + 1e-12 * fabs(expect)) {
                snprintf(err, errlen,
                         "%s:%ld: t_start_s = %.12g, expected %.12g (end of previous interval)",
                         in_name, lineno, v[0], expect);
                return SIM_REPLAY_EINPUT;
            }
        }
        elapsed_ns += ns;
        const int rc = plant_advance(&p, (double)elapsed_ns * 1e-9 - plant_time(&p), sw);
        if (rc != PLANT_OK) {
            snprintf(err, errlen, "%s:%ld: plant integration failed (%d)", in_name, lineno, rc);
            return -1;
        }
        double iabc[3], id, iq, pa, pb;
        plant_i_abc(&p, iabc);
        plant_i_dq(&p, &id, &iq);
        plant_psi_ab(&p, &pa, &pb);
        fprintf(trace, "%.9f,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g\n",
                t0 + (double)elapsed_ns * 1e-9, iabc[0], iabc[1], iabc[2], id, iq, pa, pb,
                plant_torque(&p));
    }
    if (ferror(in)) {
        snprintf(err, errlen, "%s: read error", in_name);
        return -1;
    }
    if (!header_seen) {
        snprintf(err, errlen, "%s: empty file (expected header %s)", in_name, k_header);
        return SIM_REPLAY_EINPUT;
    }
    return 0;
}

int sim_replay_files(const plant_config_t *base, const sim_replay_opts_t *opts, const char *in_path,
                     const char *trace_path, char *err, size_t errlen)
{
    char dummy[8];
    if (err == NULL || errlen == 0) {
        err = dummy;
        errlen = sizeof dummy;
    }
    if (in_path == NULL || trace_path == NULL) {
        snprintf(err, errlen, "sim_replay_files: NULL path");
        return -1;
    }
    FILE *in = fopen(in_path, "r");
    if (in == NULL) {
        snprintf(err, errlen, "%s: cannot open: %s", in_path, strerror(errno));
        return SIM_REPLAY_EINPUT;
    }
    FILE *out = fopen(trace_path, "w");
    if (out == NULL) {
        snprintf(err, errlen, "%s: cannot create: %s", trace_path, strerror(errno));
        fclose(in);
        return SIM_REPLAY_EINPUT;
    }
    int rc = sim_replay_run(base, opts, in, in_path, out, err, errlen);
    if (fclose(out) != 0 && rc == 0) {
        snprintf(err, errlen, "%s: write error", trace_path);
        rc = -1;
    }
    fclose(in);
    return rc;
}
