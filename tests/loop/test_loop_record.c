/*
 * What is recorded does not change the result: the same closed-loop run
 * without a trace, with a full trace, and with a trace window, a trace
 * decimation and another metrics window ends in the same plant and firmware
 * state, bit for bit; with the same window the metrics JSON is the same byte
 * for byte; the rows of a windowed, decimated trace are rows of the full one.
 * (The plant's observer used to split the integration while it sampled, so
 * switching it on changed the rounding of every later period.)
 * Three drives: the thesis SPMSM on the exact linear path (m2ptfc, speed mode,
 * a load step), with 1 us dead time (the RK4 path), sensorless FOC, and the
 * 80 kW IPMSM's sensorless load step and reversal (m2ptfc at its torque limit,
 * where a wound-up sigma_T slipped poles and tripped speed_follow).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "loop_util.h"
#include "unity.h"

void setUp(void)
{
}
void tearDown(void)
{
}

static sim_run_t run;
static sim_scenario_t scn;

typedef struct {
    double t, id, iq, wm, th;
    uint32_t state, fault;
    double fault_time_s;
    char *json;
    size_t json_len;
    char *trace;
    size_t trace_len;
} rec_result_t;

/* A read-back of a temporary file (the trace, the JSON). */
static char *rec_slurp(FILE *f, size_t *len)
{
    TEST_ASSERT_EQUAL_INT(0, fflush(f));
    const long n = ftell(f);
    TEST_ASSERT_TRUE(n >= 0);
    char *buf = malloc((size_t)n + 1u);
    TEST_ASSERT_NOT_NULL(buf);
    rewind(f);
    TEST_ASSERT_EQUAL_size_t((size_t)n, fread(buf, 1u, (size_t)n, f));
    buf[n] = '\0';
    *len = (size_t)n;
    return buf;
}

static rec_result_t rec_run(const sim_run_cfg_t *base, int trace, double tr0, double tr1,
                            uint32_t dec, double w0, double w1)
{
    sim_run_cfg_t c = *base;
    FILE *tf = trace ? tmpfile() : NULL;
    c.trace = tf;
    c.trace_start_s = tr0;
    c.trace_end_s = tr1;
    c.trace_decimation = dec;
    c.win_start_s = w0;
    c.win_end_s = w1;
    loop_start(&run, &c);
    char err[256];
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, sim_run_all(&run, err, sizeof err), err);
    metrics_result_t mp, mc;
    TEST_ASSERT_EQUAL_INT(0, sim_run_metrics(&run, &mp, &mc));
    rec_result_t r;
    memset(&r, 0, sizeof r);
    r.t = plant_time(&run.plant);
    plant_i_dq(&run.plant, &r.id, &r.iq);
    r.wm = plant_omega_m(&run.plant);
    r.th = plant_theta_e(&run.plant);
    r.state = (uint32_t)fw_state(&run.fw);
    r.fault = fw_fault(&run.fw);
    r.fault_time_s = run.fault_time_s;
    FILE *jf = tmpfile();
    TEST_ASSERT_NOT_NULL(jf);
    sim_run_write_metrics_json(jf, &run, &mp, &mc);
    r.json = rec_slurp(jf, &r.json_len);
    fclose(jf);
    if (tf != NULL) {
        r.trace = rec_slurp(tf, &r.trace_len);
        fclose(tf);
    }
    sim_run_free(&run);
    return r;
}

static void rec_same_state(const rec_result_t *a, const rec_result_t *b)
{
    TEST_ASSERT_EQUAL_MEMORY(&a->t, &b->t, sizeof a->t);
    TEST_ASSERT_EQUAL_MEMORY(&a->id, &b->id, sizeof a->id);
    TEST_ASSERT_EQUAL_MEMORY(&a->iq, &b->iq, sizeof a->iq);
    TEST_ASSERT_EQUAL_MEMORY(&a->wm, &b->wm, sizeof a->wm);
    TEST_ASSERT_EQUAL_MEMORY(&a->th, &b->th, sizeof a->th);
    TEST_ASSERT_EQUAL_UINT32(a->state, b->state);
    TEST_ASSERT_EQUAL_UINT32(a->fault, b->fault);
    TEST_ASSERT_EQUAL_MEMORY(&a->fault_time_s, &b->fault_time_s, sizeof a->fault_time_s);
}

static void rec_free(rec_result_t *r)
{
    free(r->json);
    free(r->trace);
}

static void rec_check(const sim_run_cfg_t *c)
{
    const double d = c->duration_s;
    rec_result_t plain = rec_run(c, 0, 0.0, 1e9, 1u, 0.3 * d, d);
    rec_result_t full = rec_run(c, 1, 0.0, 1e9, 1u, 0.3 * d, d);
    rec_result_t part = rec_run(c, 1, 0.5 * d, 0.7 * d, 3u, 0.1 * d, 0.4 * d);
    rec_same_state(&plain, &full);
    rec_same_state(&plain, &part);
    TEST_ASSERT_EQUAL_size_t(plain.json_len, full.json_len);
    TEST_ASSERT_EQUAL_STRING(plain.json, full.json);
    /* every row of the windowed, decimated trace is a row of the full one */
    size_t rows = 0u;
    const char *nl = strchr(part.trace, '\n'); /* after the header */
    TEST_ASSERT_NOT_NULL(nl);
    for (const char *p = nl + 1; *p != '\0';) {
        const char *e = strchr(p, '\n');
        TEST_ASSERT_NOT_NULL(e);
        char row[512];
        const size_t n = (size_t)(e - p) + 1u;
        TEST_ASSERT_TRUE(n + 2u < sizeof row);
        row[0] = '\n';
        memcpy(row + 1, p, n);
        row[n + 1] = '\0';
        TEST_ASSERT_NOT_NULL_MESSAGE(strstr(full.trace, row), row);
        rows++;
        p = e + 1;
    }
    /* 20 % of the run on the Ts/10 grid, every third sample */
    const double expect = 0.2 * d * (double)c->fs_hz * 10.0 / 3.0;
    TEST_ASSERT_DOUBLE_WITHIN(0.02 * expect + 2.0, expect, (double)rows);
    printf("%s: end state, metrics and trace rows identical (%zu rows checked)\n", c->ctrl->name,
           rows);
    rec_free(&plain);
    rec_free(&full);
    rec_free(&part);
}

static void rec_scenario(sim_run_cfg_t *c)
{
    loop_scenario(&scn, "at 0 speed_ref=0\nat 0.005 speed_ref=400\nat 0.03 load=2\n", "record");
    c->scenario = &scn;
    c->free_mech = true;
    c->speed_mode = true;
    c->speed_ref_rpm = 0.0;
}

static void test_exact_path_m2ptfc(void)
{
    sim_run_cfg_t c;
    loop_cfg(&c, "m2ptfc", 0.0, 0.0, 0.06, 0.0);
    rec_scenario(&c);
    rec_check(&c);
}

static void test_dead_time_sensorless_foc(void)
{
    sim_run_cfg_t c;
    loop_cfg(&c, "foc", 600.0, 0.0, 0.05, 0.0);
    c.plant_machine.dead_time_s = 1e-6; /* RK4 sub-steps */
    c.sensorless = true;
    c.free_mech = true;
    c.speed_mode = true;
    c.speed_ref_rpm = 600.0;
    rec_check(&c);
}

/* 80 kW IPMSM, m2ptfc, sensorless, free: 0 -> 300 -> 1000 r/min, a 200 N*m
 * load step at 1000 r/min (the speed PI at the 364.5 N*m limit), then
 * -1000 r/min. Without, with a full and with a windowed, decimated trace the
 * same end state and metrics; no fault, the reversal reached within 5 %. */
static void test_ipmsm80_sensorless_load_step(void)
{
    const ctrl_desc_t *d = ctrl_find("m2ptfc");
    TEST_ASSERT_NOT_NULL(d);
    sim_run_cfg_t c;
    sim_run_config_default(&c, loop_ipmsm80(), d);
    c.fs_hz = d->fs_default_hz;
    c.sensorless = true;
    c.free_mech = true;
    c.speed_mode = true;
    c.speed_ref_rpm = 0.0;
    c.seed = 5u;
    c.duration_s = 1.0; /* the reversal is over by 0.98 s */
    loop_scenario(&scn,
                  "at 0 speed_ref=0 load=50\nat 0.05 speed_ref=300\nat 0.2 speed_ref=1000\n"
                  "at 0.6 load=200\nat 0.9 speed_ref=-1000\n",
                  "ipmsm80");
    c.scenario = &scn;
    rec_result_t plain = rec_run(&c, 0, 0.0, 1e9, 1u, 0.3, 1.0);
    rec_result_t full = rec_run(&c, 1, 0.0, 1e9, 1u, 0.3, 1.0);
    rec_result_t part = rec_run(&c, 1, 0.5, 0.8, 3u, 0.3, 1.0);
    rec_same_state(&plain, &full);
    rec_same_state(&plain, &part);
    TEST_ASSERT_EQUAL_STRING(plain.json, full.json);
    TEST_ASSERT_EQUAL_STRING(plain.json, part.json);
    TEST_ASSERT_EQUAL_UINT32(FW_FAULT_NONE, plain.fault);
    const double rpm = plain.wm * 60.0 / (2.0 * 3.14159265358979);
    printf("80 kW sensorless load step: no fault, %.1f r/min at 1 s, identical with and "
           "without a trace\n",
           rpm);
    TEST_ASSERT_DOUBLE_WITHIN(50.0, -1000.0, rpm);
    rec_free(&plain);
    rec_free(&full);
    rec_free(&part);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_exact_path_m2ptfc);
    RUN_TEST(test_dead_time_sensorless_foc);
    RUN_TEST(test_ipmsm80_sensorless_load_step);
    return UNITY_END();
}
