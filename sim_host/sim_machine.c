/*
 * Machine INI loader (libinih). Every key is checked for presence, syntax and
 * range; unknown sections and keys are rejected. Errors name the key and,
 * for malformed values, the line.
 */
#include "sim_machine.h"

#include <errno.h>
#include <ini.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sim_num.h"

/* K_LIST: reals (each in the range) separated by blanks or commas, their
 * count in k_lists; K_PROFILE: points x:y (load_profile). */
typedef enum { K_TEXT, K_INT, K_REAL, K_PATH, K_LIST, K_PROFILE } key_kind_t;

typedef struct {
    const char *section, *name;
    key_kind_t kind;
    int required;
    double lo, hi; /* accepted closed range (REAL / INT / LIST items) */
    int lo_open;   /* 1: lo excluded (strictly positive quantities) */
    double scale;  /* stored value = parsed * scale */
    size_t offset; /* into sim_machine_t */
} key_t_;

#define OFF(f) offsetof(sim_machine_t, f)
static const key_t_ k_keys[] = {
    {"machine", "name", K_TEXT, 1, 0, 0, 0, 1.0, OFF(name)},
    {"machine", "pole_pairs", K_INT, 1, 1, 50, 0, 1.0, OFF(pole_pairs)},
    {"machine", "rs_ohm", K_REAL, 1, 0, 100, 1, 1.0, OFF(rs_ohm)},
    {"machine", "ld_mh", K_REAL, 1, 0, 1e4, 1, 1e-3, OFF(ld_h)},
    {"machine", "lq_mh", K_REAL, 1, 0, 1e4, 1, 1e-3, OFF(lq_h)},
    {"machine", "psi_pm_wb", K_REAL, 1, 0, 10, 0, 1.0, OFF(psi_pm_wb)},
    {"rated", "torque_nm", K_REAL, 1, 0, 1e5, 1, 1.0, OFF(torque_rated_nm)},
    {"rated", "speed_rpm", K_REAL, 1, 0, 1e6, 1, 1.0, OFF(speed_rated_rpm)},
    {"rated", "current_a", K_REAL, 1, 0, 1e5, 1, 1.0, OFF(current_rated_a)},
    {"rated", "current_max_a", K_REAL, 1, 0, 1e5, 1, 1.0, OFF(current_max_a)},
    {"rated", "psi_ref_wb", K_REAL, 0, 0, 10, 0, 1.0, OFF(psi_ref_wb)},
    {"inverter", "vdc_v", K_REAL, 1, 0, 1e5, 1, 1.0, OFF(vdc_v)},
    {"inverter", "fs_hz", K_REAL, 1, 100, 1e6, 0, 1.0, OFF(fs_hz)},
    {"inverter", "dead_time_ns", K_REAL, 0, 0, 1e5, 0, 1e-9, OFF(dead_time_s)},
    {"inverter", "v_fwd_v", K_REAL, 0, 0, 100, 0, 1.0, OFF(v_fwd_v)},
    {"inverter", "dc_cap_uf", K_REAL, 0, 0, 1e9, 0, 1e-6, OFF(dc_cap_f)},
    {"inverter", "dc_src_r_ohm", K_REAL, 0, 0, 1e6, 1, 1.0, OFF(dc_src_r_ohm)},
    {"mechanics", "inertia_kgm2", K_REAL, 1, 0, 1e6, 1, 1.0, OFF(inertia_kgm2)},
    {"mechanics", "friction_nms", K_REAL, 0, 0, 1e6, 0, 1.0, OFF(friction_nms)},
    {"mechanics", "coulomb_nm", K_REAL, 0, 0, 1e5, 0, 1.0, OFF(coulomb_nm)},
    {"mechanics", "stiction_nm", K_REAL, 0, 0, 1e5, 0, 1.0, OFF(stiction_nm)},
    {"mechanics", "slots", K_INT, 0, 1, 1000, 0, 1.0, OFF(slots)},
    {"mechanics", "cogging_nm", K_REAL, 0, 0, 1e5, 0, 1.0, OFF(cogging_nm)},
    {"mechanics", "cogging_phase_deg", K_REAL, 0, -360, 360, 0, 1.0, OFF(cogging_phase_deg)},
    {"mechanics", "cogging_harmonics_nm", K_LIST, 0, 0, 1e5, 0, 1.0, OFF(cog_harm_nm)},
    {"mechanics", "cogging_harmonics_deg", K_LIST, 0, -360, 360, 0, 1.0, OFF(cog_harm_deg)},
    {"mechanics", "load_kind", K_TEXT, 0, 0, 0, 0, 1.0, OFF(load_kind_text)},
    {"mechanics", "load_nm", K_REAL, 0, -1e5, 1e5, 0, 1.0, OFF(load_nm)},
    {"mechanics", "load_profile", K_PROFILE, 0, -1e6, 1e6, 0, 1.0, OFF(load_profile)},
    {"fluxmap", "file", K_PATH, 0, 0, 0, 0, 1.0, OFF(fluxmap_path)},
    {"rated", "overspeed_rpm", K_REAL, 0, 0, 1e6, 1, 1.0, OFF(overspeed_rpm)},
    {"rated", "speed_max_rpm", K_REAL, 0, 0, 1e6, 1, 1.0, OFF(speed_max_rpm)},
    {"speed_loop", "bandwidth_hz", K_REAL, 0, 0, 1e4, 1, 1.0, OFF(speed_bw_hz)},
    {"speed_loop", "phase_margin_deg", K_REAL, 0, 20, 80, 0, 1.0, OFF(speed_pm_deg)},
    {"speed_loop", "kp_nm_s_per_rad", K_REAL, 0, 0, 1e6, 1, 1.0, OFF(speed_kp)},
    {"speed_loop", "ki_nm_per_rad", K_REAL, 0, 0, 1e8, 0, 1.0, OFF(speed_ki)},
    /* [filter]: the output filters of the book chapter (plant_filter.h) */
    {"filter", "type", K_TEXT, 0, 0, 0, 0, 1.0, OFF(filter_type)},
    {"filter", "current_sense", K_TEXT, 0, 0, 0, 0, 1.0, OFF(current_sense_text)},
    {"filter", "trap_l1_uh", K_REAL, 0, 0, 1e9, 1, 1e-6, OFF(filter.passive.l1_h)},
    {"filter", "trap_c1_uf", K_REAL, 0, 0, 1e9, 1, 1e-6, OFF(filter.passive.c1_f)},
    {"filter", "trap_r1_ohm", K_REAL, 0, 0, 1e9, 1, 1.0, OFF(filter.passive.r1_ohm)},
    {"filter", "trap_l2_mh", K_REAL, 0, 0, 1e6, 1, 1e-3, OFF(filter.passive.l2_h)},
    {"filter", "trap_c2_uf", K_REAL, 0, 0, 1e9, 1, 1e-6, OFF(filter.passive.c2_f)},
    {"filter", "trap_r2_ohm", K_REAL, 0, 0, 1e9, 0, 1.0, OFF(filter.passive.r2_ohm)},
    {"filter", "rlc_l3_mh", K_REAL, 0, 0, 1e6, 1, 1e-3, OFF(filter.passive.l3_h)},
    {"filter", "rlc_r3s_ohm", K_REAL, 0, 0, 1e9, 0, 1.0, OFF(filter.passive.r3s_ohm)},
    {"filter", "rlc_r3_ohm", K_REAL, 0, 0, 1e9, 1, 1.0, OFF(filter.passive.r3_ohm)},
    {"filter", "rlc_c3_uf", K_REAL, 0, 0, 1e9, 1, 1e-6, OFF(filter.passive.c3_f)},
    {"filter", "pri_l1_uh", K_REAL, 0, 0, 1e9, 1, 1e-6, OFF(filter.active.l1_h)},
    {"filter", "pri_c1_uf", K_REAL, 0, 0, 1e9, 1, 1e-6, OFF(filter.active.c1_f)},
    {"filter", "pri_r1_ohm", K_REAL, 0, 0, 1e9, 1, 1.0, OFF(filter.active.r1_ohm)},
    {"filter", "sec_l2_uh", K_REAL, 0, 0, 1e9, 1, 1e-6, OFF(filter.active.l2_h)},
    {"filter", "sec_c2_uf", K_REAL, 0, 0, 1e9, 1, 1e-6, OFF(filter.active.c2_f)},
    {"filter", "sec_r2_ohm", K_REAL, 0, 0, 1e9, 1, 1.0, OFF(filter.active.r2_ohm)},
    {"filter", "af_lf_mh", K_REAL, 0, 0, 1e6, 1, 1e-3, OFF(filter.active.lf_h)},
    {"filter", "af_cf_uf", K_REAL, 0, 0, 1e9, 1, 1e-6, OFF(filter.active.cf_f)},
    {"filter", "af_cf_initial_v", K_REAL, 0, 0, 1e5, 1, 1.0, OFF(filter.active.cf_v0_v)},
    {"filter", "af_sample_hz", K_REAL, 0, 1e3, 1e8, 0, 1.0, OFF(filter.active.sample_hz)},
    {"filter", "af_band_v", K_REAL, 0, 0, 1e4, 0, 1.0, OFF(filter.active.band_v)},
    {"filter", "af_ref_cutoff_hz", K_REAL, 0, 0, 1e6, 1, 1.0, OFF(filter.active.ref_cutoff_hz)},
    {"filter", "af_dc_bw_hz", K_REAL, 0, 0, 1e4, 0, 1.0, OFF(filter.active.dc_bw_hz)},
    {"filter", "af_dc_re_max_ohm", K_REAL, 0, 0, 1e6, 0, 1.0, OFF(filter.active.dc_re_max_ohm)},
    {"sensors", "encoder_lines", K_INT, 0, 1, 1e7, 0, 1.0, OFF(encoder_lines)},
    {"sensors", "encoder_offset_deg", K_REAL, 0, -360, 360, 0, 1.0, OFF(encoder_offset_deg)},
    {"sensors", "encoder_direction", K_INT, 0, -1, 1, 0, 1.0, OFF(encoder_direction)},
};
#define N_KEYS (sizeof(k_keys) / sizeof(k_keys[0]))

/* K_LIST keys: where their count goes and how many values they take. */
static const struct {
    const char *name;
    size_t offset_n;
    int max_n;
} k_lists[] = {
    {"cogging_harmonics_nm", OFF(cog_harm_n), PLANT_COG_MAX - 1},
    {"cogging_harmonics_deg", OFF(cog_harm_deg_n), PLANT_COG_MAX - 1},
};

typedef struct {
    sim_machine_t *m;
    unsigned char seen[N_KEYS];
    char msg[256];
    const char *dir; /* folder of the INI file, for relative paths */
    size_t dirlen;
} ctx_t;

/* One number of a list at *p (blanks and commas before it skipped);
 * returns 1 and advances *p, 0 at the end, -1 if malformed (the token in tok). */
static int next_number(const char **p, double *v, char *tok, size_t toklen)
{
    const char *q = *p;
    while (*q == ' ' || *q == '\t' || *q == ',') {
        q++;
    }
    if (*q == '\0') {
        return 0;
    }
    size_t n = strcspn(q, " \t,:");
    snprintf(tok, toklen, "%.*s", (int)(n < 40 ? n : 40), q);
    char *end;
    errno = 0;
    *v = strtod(q, &end);
    if (end != q + n || n == 0 || errno != 0 || !isfinite(*v)) {
        return -1;
    }
    *p = q + n;
    return 1;
}

static int parse_list(ctx_t *c, const key_t_ *K, const char *value, char *dst)
{
    double *out = (double *)(void *)dst;
    size_t li = 0;
    while (li + 1 < sizeof k_lists / sizeof k_lists[0] && strcmp(k_lists[li].name, K->name) != 0) {
        li++; /* every K_LIST key has its row */
    }
    int *count = (int *)(void *)((char *)c->m + k_lists[li].offset_n);
    const int max_n = k_lists[li].max_n;
    const char *p = value;
    int n = 0;
    char tok[48];
    for (;;) {
        double v;
        const int r = next_number(&p, &v, tok, sizeof tok);
        if (r == 0) {
            break;
        }
        if (r < 0) {
            snprintf(c->msg, sizeof c->msg, "[%s] %s value %d '%s' is not a number", K->section,
                     K->name, n + 1, tok);
            return 0;
        }
        if (n == max_n) {
            snprintf(c->msg, sizeof c->msg, "[%s] %s has more than %d values", K->section, K->name,
                     max_n);
            return 0;
        }
        if (!(v >= K->lo && v <= K->hi)) {
            snprintf(c->msg, sizeof c->msg, "[%s] %s value %d = %g out of range [%g, %g]",
                     K->section, K->name, n + 1, v, K->lo, K->hi);
            return 0;
        }
        out[n++] = v * K->scale;
    }
    if (n == 0) {
        snprintf(c->msg, sizeof c->msg, "[%s] %s is empty", K->section, K->name);
        return 0;
    }
    *count = n;
    return 1;
}

/* x:y points; the kind (time or speed) and the x range are checked after the
 * file is read (load_kind may come later), x increasing here. */
static int parse_profile(ctx_t *c, const key_t_ *K, const char *value, plant_profile_t *pr)
{
    const char *p = value;
    int n = 0;
    char tok[48];
    for (;;) {
        while (*p == ' ' || *p == '\t' || *p == ',') {
            p++;
        }
        if (*p == '\0') {
            break;
        }
        double x, y;
        const char *start = p;
        int r = next_number(&p, &x, tok, sizeof tok);
        if (r > 0 && *p == ':') {
            p++;
            r = next_number(&p, &y, tok, sizeof tok);
        } else if (r > 0) {
            r = -1;
        }
        if (r <= 0) {
            size_t k = strcspn(start, " \t,");
            snprintf(c->msg, sizeof c->msg, "[%s] %s point %d '%.*s' is not x:T (two numbers)",
                     K->section, K->name, n + 1, (int)(k < 40 ? k : 40), start);
            return 0;
        }
        if (n == PLANT_PROFILE_MAX) {
            snprintf(c->msg, sizeof c->msg, "[%s] %s has more than %d points", K->section, K->name,
                     PLANT_PROFILE_MAX);
            return 0;
        }
        if (!(x >= K->lo && x <= K->hi) || !(y >= -1e5 && y <= 1e5)) {
            snprintf(c->msg, sizeof c->msg,
                     "[%s] %s point %d = %g:%g out of range (x in [%g, %g], T in [-1e5, 1e5] N*m)",
                     K->section, K->name, n + 1, x, y, K->lo, K->hi);
            return 0;
        }
        if (n > 0 && !(x > pr->x[n - 1])) {
            snprintf(c->msg, sizeof c->msg,
                     "[%s] %s point %d: x = %g not after the previous point's %g (x must increase)",
                     K->section, K->name, n + 1, x, pr->x[n - 1]);
            return 0;
        }
        pr->x[n] = x;
        pr->y[n] = y;
        n++;
    }
    if (n < 2) {
        snprintf(c->msg, sizeof c->msg, "[%s] %s needs at least 2 points x:T (got %d)", K->section,
                 K->name, n);
        return 0;
    }
    pr->n = n;
    return 1;
}

static int handler(void *user, const char *section, const char *name, const char *value)
{
    ctx_t *c = user;
    int section_known = 0;
    for (size_t k = 0; k < N_KEYS; ++k) {
        const key_t_ *K = &k_keys[k];
        if (strcmp(section, K->section) != 0) {
            continue;
        }
        section_known = 1;
        if (strcmp(name, K->name) != 0) {
            continue;
        }
        if (c->seen[k]) {
            snprintf(c->msg, sizeof c->msg, "[%s] %s given twice", section, name);
            return 0;
        }
        c->seen[k] = 1;
        char *dst = (char *)c->m + K->offset;
        if (K->kind == K_TEXT || K->kind == K_PATH) {
            if (value[0] == '\0') {
                snprintf(c->msg, sizeof c->msg, "[%s] %s is empty", section, name);
                return 0;
            }
            size_t cap = (K->kind == K_TEXT) ? SIM_MACHINE_NAME_MAX : SIM_MACHINE_PATH_MAX;
            int n;
            if (K->kind == K_PATH && value[0] != '/' && c->dirlen > 0) {
                n = snprintf(dst, cap, "%.*s/%s", (int)c->dirlen, c->dir, value);
            } else {
                n = snprintf(dst, cap, "%s", value);
            }
            if (n < 0 || (size_t)n >= cap) {
                snprintf(c->msg, sizeof c->msg, "[%s] %s is too long", section, name);
                return 0;
            }
            return 1;
        }
        if (K->kind == K_LIST) {
            return parse_list(c, K, value, dst);
        }
        if (K->kind == K_PROFILE) {
            return parse_profile(c, K, value, (plant_profile_t *)(void *)dst);
        }
        double v;
        if (sim_num_parse(value, &v) != 0) {
            snprintf(c->msg, sizeof c->msg, "[%s] %s = '%s' is not a number", section, name, value);
            return 0;
        }
        const int below = K->lo_open ? !(v > K->lo) : !(v >= K->lo);
        if (below || !(v <= K->hi)) {
            snprintf(c->msg, sizeof c->msg, "[%s] %s = %g out of range %s%g, %g]", section, name, v,
                     K->lo_open ? "(" : "[", K->lo, K->hi);
            return 0;
        }
        if (K->kind == K_INT) {
            if (v != floor(v)) {
                snprintf(c->msg, sizeof c->msg, "[%s] %s = %g is not an integer", section, name, v);
                return 0;
            }
            *(int *)(void *)dst = (int)v;
        } else {
            *(double *)(void *)dst = v * K->scale;
        }
        return 1;
    }
    if (section[0] == '\0') {
        snprintf(c->msg, sizeof c->msg, "key %s before any [section] header", name);
    } else if (!section_known) {
        snprintf(c->msg, sizeof c->msg, "unknown section [%s] (key %s)", section, name);
    } else {
        snprintf(c->msg, sizeof c->msg, "unknown key %s in [%s]", name, section);
    }
    return 0;
}

/* A section some key of k_keys belongs to. */
static int section_known(const char *name, size_t len)
{
    for (size_t k = 0; k < N_KEYS; ++k) {
        if (strlen(k_keys[k].section) == len && strncmp(k_keys[k].section, name, len) == 0) {
            return 1;
        }
    }
    return 0;
}

/* Section headers libinih would skip silently (it reports the line but then
 * files the keys under the previous section): "[name]" with nothing but a
 * comment after it; and unknown sections, on their header's line (libinih
 * reports the line of their first key, and nothing for an empty one).
 * Returns the first bad line (0: none) and its message. */
static int header_check(FILE *f, char *bad, size_t badlen)
{
    char line[512];
    int n = 0;
    while (fgets(line, sizeof line, f) != NULL) {
        n++;
        const char *p = line;
        while (*p == ' ' || *p == '\t') {
            p++;
        }
        if (*p != '[') {
            continue;
        }
        const char *close = strchr(p, ']');
        const char *q = close != NULL ? close + 1 : NULL;
        while (q != NULL && (*q == ' ' || *q == '\t' || *q == '\r' || *q == '\n')) {
            q++;
        }
        if (close == NULL || close == p + 1 || (*q != '\0' && *q != ';' && *q != '#')) {
            size_t k = strcspn(p, "\r\n");
            snprintf(bad, badlen, "malformed section header '%.*s' (expected [name])",
                     (int)(k < 60 ? k : 60), p);
            return n;
        }
        if (!section_known(p + 1, (size_t)(close - p - 1))) {
            char known[128] = "";
            for (size_t k = 0; k < N_KEYS; ++k) {
                const char *sec = k_keys[k].section;
                size_t j = 0;
                while (j < k && strcmp(k_keys[j].section, sec) != 0) {
                    j++;
                }
                if (j == k) { /* its first key */
                    const size_t used = strlen(known);
                    snprintf(known + used, sizeof known - used, "%s%s", used ? ", " : "", sec);
                }
            }
            snprintf(bad, badlen, "unknown section [%.*s] (known: %s)",
                     (int)((size_t)(close - p - 1) < 40 ? close - p - 1 : 40), p + 1, known);
            return n;
        }
    }
    return 0;
}

/* [filter]: the type decides which keys belong (all of its keys required,
 * none of the other type's); the filter path needs the linear model. */
static int filter_check(sim_machine_t *m, const unsigned char *seen, char *err, size_t errlen)
{
    int any = 0;
    for (size_t k = 0; k < N_KEYS; ++k) {
        any |= seen[k] && strcmp(k_keys[k].section, "filter") == 0;
    }
    m->filter.type = PLANT_FILTER_NONE;
    m->current_sense = SIM_SENSE_INVERTER;
    if (!any) {
        return 0;
    }
    const char *want = NULL; /* key prefix set of the type */
    if (strcmp(m->filter_type, "passive") == 0) {
        m->filter.type = PLANT_FILTER_PASSIVE;
        want = "trap_ rlc_";
    } else if (strcmp(m->filter_type, "active") == 0) {
        m->filter.type = PLANT_FILTER_ACTIVE;
        want = "pri_ sec_ af_";
    } else {
        snprintf(err, errlen, "[filter] type = '%s': expected passive or active", m->filter_type);
        return -1;
    }
    if (m->current_sense_text[0] == '\0' || strcmp(m->current_sense_text, "inverter") == 0) {
        m->current_sense = SIM_SENSE_INVERTER;
    } else if (strcmp(m->current_sense_text, "motor") == 0) {
        m->current_sense = SIM_SENSE_MOTOR;
    } else {
        snprintf(err, errlen, "[filter] current_sense = '%s': expected inverter or motor",
                 m->current_sense_text);
        return -1;
    }
    for (size_t k = 0; k < N_KEYS; ++k) {
        const key_t_ *K = &k_keys[k];
        if (strcmp(K->section, "filter") != 0 || K->kind != K_REAL) {
            continue;
        }
        const char *us = strchr(K->name, '_');
        char prefix[8];
        snprintf(prefix, sizeof prefix, "%.*s", (int)(us - K->name + 1), K->name);
        const int mine = strstr(want, prefix) != NULL;
        /* the active filter's storage regulation is optional (not in S1; 0 = none) */
        const int optional = strncmp(K->name, "af_dc_", 6) == 0;
        if (mine && !seen[k] && !optional) {
            snprintf(err, errlen, "missing key %s in [filter] (type = %s)", K->name,
                     m->filter_type);
            return -1;
        }
        if (!mine && seen[k]) {
            snprintf(err, errlen, "[filter] %s does not belong to a filter of type %s", K->name,
                     m->filter_type);
            return -1;
        }
    }
    if (m->fluxmap_path[0] != '\0' || m->dead_time_s > 0.0 || m->v_fwd_v > 0.0 ||
        m->dc_cap_f > 0.0) {
        snprintf(err, errlen,
                 "[filter] needs the linear model: no [fluxmap], dead_time_ns = 0, "
                 "v_fwd_v = 0 and dc_cap_uf = 0 (the filter path is exact-linear)");
        return -1;
    }
    return 0;
}

/* Line of `key` in [section] of the file (0: not found), for the messages of
 * the rules that involve several keys (libinih reports no line to them). */
static int key_line(const char *path, const char *section, const char *key)
{
    FILE *f = fopen(path, "r");
    if (f == NULL) {
        return 0;
    }
    char line[512], sec[64] = "";
    int n = 0, found = 0;
    while (found == 0 && fgets(line, sizeof line, f) != NULL) {
        n++;
        const char *p = line;
        while (*p == ' ' || *p == '\t') {
            p++;
        }
        if (*p == '[') {
            const size_t k = strcspn(p + 1, "]");
            snprintf(sec, sizeof sec, "%.*s", (int)k, p + 1);
            continue;
        }
        const size_t k = strcspn(p, " \t=:");
        if (strcmp(sec, section) == 0 && k == strlen(key) && strncmp(p, key, k) == 0) {
            found = n;
        }
    }
    fclose(f);
    return found;
}

static int key_index(const char *section, const char *name)
{
    for (size_t k = 0; k < N_KEYS; ++k) {
        if (strcmp(k_keys[k].section, section) == 0 && strcmp(k_keys[k].name, name) == 0) {
            return (int)k;
        }
    }
    return -1;
}

/* [mechanics]' rules between keys; err gets "file:line: message". */
static int mech_check(const char *path, sim_machine_t *m, const unsigned char *seen, char *err,
                      size_t errlen)
{
#define SEEN(name) seen[key_index("mechanics", name)]
    char bad[256] = "";
    const char *at = NULL; /* the key whose line is reported */
    if (!SEEN("stiction_nm")) {
        m->stiction_nm = m->coulomb_nm; /* no break-away above the running friction */
    }
    static const struct {
        const char *text;
        sim_load_kind_t kind;
    } kinds[] = {{"none", SIM_LOAD_NONE},
                 {"constant", SIM_LOAD_CONSTANT},
                 {"passive", SIM_LOAD_PASSIVE},
                 {"time", SIM_LOAD_TIME},
                 {"speed", SIM_LOAD_SPEED}};
    int kind = -1;
    if (!SEEN("load_kind")) {
        kind = SIM_LOAD_NONE;
    }
    for (size_t i = 0; kind < 0 && i < sizeof kinds / sizeof kinds[0]; ++i) {
        if (strcmp(m->load_kind_text, kinds[i].text) == 0) {
            kind = (int)kinds[i].kind;
        }
    }
    m->load_kind = kind < 0 ? SIM_LOAD_NONE : (sim_load_kind_t)kind;
    const int profile = kind == SIM_LOAD_TIME || kind == SIM_LOAD_SPEED;
    if (!(m->stiction_nm >= m->coulomb_nm)) {
        at = "stiction_nm";
        snprintf(bad, sizeof bad,
                 "[mechanics] stiction_nm = %g below coulomb_nm = %g: allowed range [%g, 1e5] "
                 "(the break-away torque is at least the running friction)",
                 m->stiction_nm, m->coulomb_nm, m->coulomb_nm);
    } else if ((m->cogging_nm > 0.0 || SEEN("cogging_harmonics_nm")) && m->slots == 0) {
        at = m->cogging_nm > 0.0 ? "cogging_nm" : "cogging_harmonics_nm";
        snprintf(bad, sizeof bad,
                 "[mechanics] %s needs slots (the cogging repeats lcm(slots, 2 pole_pairs) times "
                 "per revolution)",
                 at);
    } else if (SEEN("cogging_harmonics_deg") && m->cog_harm_deg_n != m->cog_harm_n) {
        at = "cogging_harmonics_deg";
        snprintf(bad, sizeof bad,
                 "[mechanics] cogging_harmonics_deg has %d values, cogging_harmonics_nm %d: one "
                 "phase per harmonic",
                 m->cog_harm_deg_n, m->cog_harm_n);
    } else if (kind < 0) {
        at = "load_kind";
        snprintf(bad, sizeof bad,
                 "[mechanics] load_kind = '%s': expected none, constant, passive, time or speed",
                 m->load_kind_text);
    } else if ((kind == SIM_LOAD_CONSTANT || kind == SIM_LOAD_PASSIVE) && !SEEN("load_nm")) {
        at = "load_kind";
        snprintf(bad, sizeof bad, "[mechanics] load_kind = %s needs load_nm", m->load_kind_text);
    } else if (kind == SIM_LOAD_PASSIVE && !(m->load_nm >= 0.0)) {
        at = "load_nm";
        snprintf(bad, sizeof bad,
                 "[mechanics] load_nm = %g out of range [0, 1e5] for load_kind = passive (a "
                 "magnitude: it opposes the motion either way)",
                 m->load_nm);
    } else if (SEEN("load_nm") && kind != SIM_LOAD_CONSTANT && kind != SIM_LOAD_PASSIVE) {
        at = "load_nm";
        snprintf(bad, sizeof bad,
                 "[mechanics] load_nm belongs to load_kind = constant or passive (load_kind = %s)",
                 SEEN("load_kind") ? m->load_kind_text : "none");
    } else if (profile && !SEEN("load_profile")) {
        at = "load_kind";
        snprintf(bad, sizeof bad, "[mechanics] load_kind = %s needs load_profile = x:T x:T ...",
                 m->load_kind_text);
    } else if (SEEN("load_profile") && !profile) {
        at = "load_profile";
        snprintf(bad, sizeof bad,
                 "[mechanics] load_profile belongs to load_kind = time or speed (load_kind = %s)",
                 SEEN("load_kind") ? m->load_kind_text : "none");
    } else if (kind == SIM_LOAD_TIME && !(m->load_profile.x[0] >= 0.0)) {
        at = "load_profile";
        snprintf(bad, sizeof bad,
                 "[mechanics] load_profile point 1 at t = %g s: allowed range [0, 1e6] s (time "
                 "from the arm instant)",
                 m->load_profile.x[0]);
    } else if (m->filter.type != PLANT_FILTER_NONE &&
               (m->coulomb_nm > 0.0 || m->stiction_nm > 0.0 || m->cogging_nm > 0.0 ||
                m->cog_harm_n > 0 || profile)) {
        at = m->coulomb_nm > 0.0    ? "coulomb_nm"
             : m->stiction_nm > 0.0 ? "stiction_nm"
             : profile              ? "load_profile"
                                    : "cogging_nm";
        snprintf(bad, sizeof bad,
                 "[mechanics] Coulomb friction, stiction, cogging and load profiles need a "
                 "machine without [filter] (the filter path holds the speed over a PWM period)");
    }
    if (bad[0] != '\0') {
        const int line = key_line(path, "mechanics", at);
        if (line > 0) {
            snprintf(err, errlen, "%s:%d: %s", path, line, bad);
        } else {
            snprintf(err, errlen, "%s: %s", path, bad);
        }
        return -1;
    }
    if (kind == SIM_LOAD_SPEED) {
        for (int i = 0; i < m->load_profile.n; ++i) {
            m->load_profile.x[i] *= 2.0 * PLANT_PI / 60.0; /* r/min -> rad/s */
        }
    }
    m->load_profile.kind = kind == SIM_LOAD_TIME    ? PLANT_PROFILE_TIME
                           : kind == SIM_LOAD_SPEED ? PLANT_PROFILE_SPEED
                                                    : PLANT_PROFILE_NONE;
    if (!profile) {
        m->load_profile.n = 0;
    }
    return 0;
#undef SEEN
}

int sim_machine_load(const char *path, sim_machine_t *out, char *err, size_t errlen)
{
    char dummy[8];
    if (err == NULL || errlen == 0) {
        err = dummy;
        errlen = sizeof dummy;
    }
    err[0] = '\0';
    if (path == NULL || out == NULL) {
        snprintf(err, errlen, "sim_machine_load: NULL argument");
        return -1;
    }
    memset(out, 0, sizeof(*out));
    ctx_t c;
    memset(&c, 0, sizeof c);
    c.m = out;
    c.dir = path;
    const char *slash = strrchr(path, '/');
    c.dirlen = (slash != NULL) ? (size_t)(slash - path) : 0;
    if (slash == NULL) {
        c.dir = ".";
        c.dirlen = 1;
    }
    FILE *f = fopen(path, "r");
    if (f == NULL) {
        snprintf(err, errlen, "%s: cannot open: %s", path, strerror(errno));
        return -1;
    }
    char hdr[256];
    const int hdr_line = header_check(f, hdr, sizeof hdr);
    if (hdr_line != 0) {
        fclose(f);
        snprintf(err, errlen, "%s:%d: %s", path, hdr_line, hdr);
        memset(out, 0, sizeof(*out));
        return -1;
    }
    rewind(f);
    const int line = ini_parse_file(f, handler, &c);
    fclose(f);
    if (line != 0) {
        if (c.msg[0] != '\0') {
            snprintf(err, errlen, "%s:%d: %s", path, line, c.msg);
        } else {
            snprintf(err, errlen, "%s:%d: syntax error", path, line);
        }
        memset(out, 0, sizeof(*out));
        return -1;
    }
    for (size_t k = 0; k < N_KEYS; ++k) {
        if (k_keys[k].required && !c.seen[k]) {
            snprintf(err, errlen, "%s: missing key %s in [%s]", path, k_keys[k].name,
                     k_keys[k].section);
            memset(out, 0, sizeof(*out));
            return -1;
        }
    }
    /* Defaults of the optional [sensors] keys: today's aligned encoder. */
    for (size_t k = 0; k < N_KEYS; ++k) {
        if (strcmp(k_keys[k].section, "sensors") == 0 && !c.seen[k]) {
            if (strcmp(k_keys[k].name, "encoder_lines") == 0) {
                out->encoder_lines = 2500;
            } else if (strcmp(k_keys[k].name, "encoder_direction") == 0) {
                out->encoder_direction = 1;
            }
        }
    }
    /* Cross-field rules. */
    char bad[200] = "";
    if (!(out->current_max_a > out->current_rated_a)) {
        snprintf(bad, sizeof bad,
                 "[rated] current_max_a must exceed current_a (current_max_a = %g A, current_a = "
                 "%g A)",
                 out->current_max_a, out->current_rated_a);
    } else if (out->dc_cap_f > 0.0 && !(out->dc_src_r_ohm > 0.0)) {
        snprintf(bad, sizeof bad, "[inverter] dc_src_r_ohm is required (> 0) when dc_cap_uf > 0");
    } else if (out->speed_max_rpm > 0.0 && !(out->speed_max_rpm >= out->speed_rated_rpm)) {
        snprintf(
            bad, sizeof bad,
            "[rated] speed_max_rpm must be at least speed_rpm (speed_max_rpm = %g, speed_rpm = "
            "%g)",
            out->speed_max_rpm, out->speed_rated_rpm);
    } else if (out->overspeed_rpm > 0.0 && !(out->overspeed_rpm > out->speed_rated_rpm)) {
        snprintf(bad, sizeof bad,
                 "[rated] overspeed_rpm must exceed speed_rpm (overspeed_rpm = %g, speed_rpm = %g)",
                 out->overspeed_rpm, out->speed_rated_rpm);
    } else if (out->speed_ki > 0.0 && !(out->speed_kp > 0.0)) {
        snprintf(bad, sizeof bad, "[speed_loop] ki_nm_per_rad needs kp_nm_s_per_rad");
    } else if (out->speed_kp > 0.0 && (out->speed_bw_hz > 0.0 || out->speed_pm_deg > 0.0)) {
        snprintf(bad, sizeof bad,
                 "[speed_loop] give either the gains (kp_nm_s_per_rad, ki_nm_per_rad) or the "
                 "design (bandwidth_hz, phase_margin_deg), not both");
    } else if (out->encoder_direction == 0) {
        snprintf(bad, sizeof bad, "[sensors] encoder_direction must be 1 or -1 (got 0)");
    } else if (out->dead_time_s * out->fs_hz > 0.1) {
        snprintf(bad, sizeof bad,
                 "[inverter] dead_time_ns = %g exceeds 10 %% of the PWM period (<= %g ns at "
                 "fs_hz = %g)",
                 out->dead_time_s * 1e9, 0.1e9 / out->fs_hz, out->fs_hz);
    }
    if (bad[0] != '\0') {
        snprintf(err, errlen, "%s: %s", path, bad);
        memset(out, 0, sizeof(*out));
        return -1;
    }
    if (filter_check(out, c.seen, err, errlen) != 0) {
        /* err holds the key; prefix the file */
        char tmp[256];
        snprintf(tmp, sizeof tmp, "%s", err);
        snprintf(err, errlen, "%s: %s", path, tmp);
        memset(out, 0, sizeof(*out));
        return -1;
    }
    if (mech_check(path, out, c.seen, err, errlen) != 0) {
        memset(out, 0, sizeof(*out));
        return -1;
    }
    return 0;
}
