/* Scenario parser (format in sim_scenario.h). */
#define _POSIX_C_SOURCE 200809L /* strtok_r */
#include "sim_scenario.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sim_num.h"

static int sim_fail(char *err, size_t errlen, const char *name, int line, const char *msg,
                    const char *tok)
{
    if (err != NULL && errlen > 0u) {
        (void)snprintf(err, errlen, "%s:%d: %s%s%s%s", name, line, msg, tok ? " '" : "",
                       tok ? tok : "", tok ? "'" : "");
    }
    return -1;
}

int sim_scenario_parse(sim_scenario_t *s, FILE *f, const char *name, char *err, size_t errlen)
{
    if (s == NULL || f == NULL) {
        return sim_fail(err, errlen, name ? name : "?", 0, "no scenario", NULL);
    }
    memset(s, 0, sizeof *s);
    char buf[1024];
    int line = 0;
    double t_prev = -INFINITY;
    while (fgets(buf, sizeof buf, f) != NULL) {
        line++;
        if (strchr(buf, '\n') == NULL && !feof(f)) {
            return sim_fail(err, errlen, name, line, "line too long", NULL);
        }
        char *hash = strchr(buf, '#');
        if (hash != NULL) {
            *hash = '\0';
        }
        char *save = NULL;
        char *tok = strtok_r(buf, " \t\r\n", &save);
        if (tok == NULL) {
            continue;
        }
        if (s->n >= SIM_SCN_MAX_EVENTS) {
            return sim_fail(err, errlen, name, line, "too many events (max 256)", NULL);
        }
        sim_event_t *e = &s->ev[s->n];
        memset(e, 0, sizeof *e);
        e->line = line;
        if (strcmp(tok, "at") == 0) {
            tok = strtok_r(NULL, " \t\r\n", &save);
            if (tok == NULL || sim_num_parse(tok, &e->level) != 0 || e->level < 0.0) {
                return sim_fail(err, errlen, name, line, "expected a time >= 0 after 'at'", tok);
            }
            if (e->level < t_prev) {
                return sim_fail(err, errlen, name, line, "times must not decrease", tok);
            }
            t_prev = e->level;
            e->trig = SIM_TRIG_AT;
        } else if (strcmp(tok, "when") == 0) {
            tok = strtok_r(NULL, " \t\r\n", &save);
            if (tok != NULL && strncmp(tok, "speed>=", 7) == 0 &&
                sim_num_parse(tok + 7, &e->level) == 0) {
                e->trig = SIM_TRIG_SPEED_GE;
            } else if (tok != NULL && strncmp(tok, "speed<=", 7) == 0 &&
                       sim_num_parse(tok + 7, &e->level) == 0) {
                e->trig = SIM_TRIG_SPEED_LE;
            } else {
                return sim_fail(err, errlen, name, line,
                                "expected speed>=RPM or speed<=RPM after 'when'", tok);
            }
        } else {
            return sim_fail(err, errlen, name, line, "expected 'at' or 'when', got", tok);
        }
        while ((tok = strtok_r(NULL, " \t\r\n", &save)) != NULL) {
            char *eq = strchr(tok, '=');
            double v = 0.0;
            if (eq == NULL || sim_num_parse(eq + 1, &v) != 0) {
                return sim_fail(err, errlen, name, line, "expected KEY=NUMBER, got", tok);
            }
            *eq = '\0';
            unsigned bit;
            if (strcmp(tok, "torque_ref") == 0) {
                bit = SIM_SET_TORQUE_REF;
                e->torque_ref_nm = v;
            } else if (strcmp(tok, "speed_ref") == 0) {
                bit = SIM_SET_SPEED_REF;
                e->speed_ref_rpm = v;
            } else if (strcmp(tok, "load") == 0) {
                bit = SIM_SET_LOAD;
                e->load_nm = v;
            } else if (strcmp(tok, "load_passive") == 0) {
                if (v < 0.0) {
                    return sim_fail(err, errlen, name, line,
                                    "load_passive is a magnitude, allowed range [0, inf) N*m, got",
                                    eq + 1);
                }
                bit = SIM_SET_LOAD_PASSIVE;
                e->load_passive_nm = v;
            } else if (strcmp(tok, "speed") == 0) {
                bit = SIM_SET_SPEED;
                e->speed_rpm = v;
            } else {
                return sim_fail(
                    err, errlen, name, line,
                    "unknown key (torque_ref, speed_ref, load, load_passive, speed):", tok);
            }
            if (e->set & bit) {
                return sim_fail(err, errlen, name, line, "key given twice in one event:", tok);
            }
            e->set |= bit;
        }
        if (e->set == 0u) {
            return sim_fail(err, errlen, name, line, "event without an assignment", NULL);
        }
        if ((e->set & SIM_SET_TORQUE_REF) && (e->set & SIM_SET_SPEED_REF)) {
            return sim_fail(err, errlen, name, line, "torque_ref and speed_ref in one event", NULL);
        }
        s->n++;
    }
    if (ferror(f)) {
        return sim_fail(err, errlen, name, line, "read error", NULL);
    }
    return 0;
}

int sim_scenario_load(sim_scenario_t *s, const char *path, char *err, size_t errlen)
{
    FILE *f = fopen(path, "r");
    if (f == NULL) {
        if (err != NULL && errlen > 0u) {
            (void)snprintf(err, errlen, "%s: cannot open scenario file: %s", path, strerror(errno));
        }
        return -1;
    }
    const int rc = sim_scenario_parse(s, f, path, err, errlen);
    fclose(f);
    return rc;
}
