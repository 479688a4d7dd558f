/*
 * Instruction counts per control period of the chapter-6 controllers on the
 * Cortex-M4 in QEMU (cm4 build only). QEMU counts instructions, not cycles:
 * under -icount the virtual time is instructions x 2^shift ns, read here from
 * the 25 MHz Timer1 and calibrated against a block of exactly 1000 NOPs, so the
 * result does not depend on the shift (docs/architecture.md, "QEMU").
 *
 * Workload: the thesis SPMSM at 10 kHz, operating points along steady-state
 * trajectories (750 and 2250 r/min, both directions, torque -rated..+rated,
 * references stepping every few periods). Per period: estimator
 * (ctrl_estimator_update: current model, speed, k+1 prediction), the
 * controller step, and the plan -> leg duties stage. Reported: mean and worst
 * case of each and of the whole pipeline, for m2ptfc and m1 (and the others).
 *
 * Asserted (regression guard of the thesis's execution-time ranking, M2PTFC 4.6 us against M1 6.96 us): the worst-case
 * m2ptfc pipeline is at most 0.66 x the worst-case m1 pipeline.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "controller.h"
#include "ctrl_units.h"
#include "estimator.h"
#include "mpc_machines.h"
#include "plan.h"
#include "qemu_mps2.h"
#include "unity.h"

void setUp(void)
{
}
void tearDown(void)
{
}

#define N_SAMPLES 2000

static uint32_t ticks_per_1000; /* Timer1 ticks of 1000 instructions */
static uint32_t ticks_empty;    /* two back-to-back reads */

__attribute__((noinline)) static void nops_1000(void)
{
    __asm__ volatile(".rept 1000\n\tnop\n\t.endr" ::: "memory");
}

__attribute__((noinline)) static void nops_0(void)
{
    __asm__ volatile("" ::: "memory");
}

static void calibrate(void)
{
    uint32_t t0 = timer1_read();
    uint32_t t1 = timer1_read();
    ticks_empty = t1 - t0;
    t0 = timer1_read();
    nops_0();
    t1 = timer1_read();
    const uint32_t base = t1 - t0;
    t0 = timer1_read();
    nops_1000();
    t1 = timer1_read();
    ticks_per_1000 = (t1 - t0) - base; /* exactly 1000 more instructions */
}

static double instr(uint32_t ticks)
{
    const double t = (double)ticks - (double)ticks_empty;
    return t * 1000.0 / (double)ticks_per_1000;
}

typedef struct {
    double sum, max;
    unsigned n;
} stat_t;

static unsigned U(double x)
{
    return x <= 0.0 ? 0u : (unsigned)(x + 0.5);
}

static void stat_add(stat_t *s, double x)
{
    s->sum += x;
    s->max = x > s->max ? x : s->max;
    s->n++;
}

static void test_instruction_counts(void)
{
    calibrate();
    printf("  calibration: %u ticks per 1000 instructions\n", (unsigned)ticks_per_1000);
    TEST_ASSERT_TRUE(ticks_per_1000 > 100u);

    ctrl_params_t p;
    ctrl_bases_t b;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&p, &b, &ini_thesis_spmsm, 10000u));
    static const char *const names[] = {"m2ptfc", "m1", "mptfc", "m3", "m2"};
    enum { NC = 5 };
    static unsigned char state[NC][CTRL_STATE_MAX] __attribute__((aligned(8)));
    static unsigned char cfg[NC][CTRL_CFG_MAX] __attribute__((aligned(8)));
    const ctrl_desc_t *d[NC];
    ctrl_legs_t applied[NC];
    stat_t st_est = {0, 0, 0};
    stat_t st_step[NC];
    stat_t st_pipe[NC];
    memset(st_step, 0, sizeof st_step);
    memset(st_pipe, 0, sizeof st_pipe);
    for (int c = 0; c < NC; c++) {
        d[c] = ctrl_find(names[c]);
        TEST_ASSERT_NOT_NULL(d[c]);
        d[c]->cfg_default(cfg[c], &ini_thesis_spmsm);
        const ctrl_setup_t su = {&ini_thesis_spmsm, &b, &p};
        TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_init(d[c], state[c], cfg[c], &su));
        memset(&applied[c], 0, sizeof applied[c]);
    }
    ctrl_estimator_t e;
    ctrl_estimator_init(&e, &p);

    const double tb = b.torque_nm;
    double theta = 0.3;
    for (int k = 0; k < N_SAMPLES; k++) {
        /* Operating point: speed and torque change every 500 samples. */
        const int seg = k / 500;
        const double rpm = (seg & 1 ? 2250.0 : 750.0) * (seg & 2 ? -1.0 : 1.0);
        const double w_e = rpm * 2.0 * CTRL_PI / 60.0 * 4.0;
        const double t_nm = 1.8 * sin(0.37 * k);        /* -1.8 .. 1.8 N*m */
        const double iq = t_nm / (1.5 * 4.0 * 0.09427); /* SPMSM, i_d = 0 */
        theta += w_e * 1e-4;
        const double ia = -iq * sin(theta);
        const double ib = -iq * sin(theta - 2.0 * CTRL_PI / 3.0);
        ctrl_meas_t m;
        m.i_a = ctrl_q24_from_double(ia / b.i_a);
        m.i_b = ctrl_q24_from_double(ib / b.i_a);
        m.vdc = p.vdc_nom;
        m.theta_e = (fx_angle_t)(int64_t)llround(fmod(theta, 2.0 * CTRL_PI) / (2.0 * CTRL_PI) *
                                                 4294967296.0);
        ctrl_refs_t ref = {ctrl_q24_from_double((t_nm + 0.3 * sin(0.05 * k)) / tb), 0};
        ctrl_estimate_t est;
        uint32_t t0 = timer1_read();
        ctrl_estimator_update(&e, &p, &m, &applied[0], &est);
        uint32_t t1 = timer1_read();
        const double n_est = instr(t1 - t0);
        stat_add(&st_est, n_est);
        for (int c = 0; c < NC; c++) {
            const ctrl_ctx_t ctx = {&p, &est, &ref};
            ctrl_out_t out;
            t0 = timer1_read();
            d[c]->step(state[c], &ctx, &out); /* leg duties included */
            t1 = timer1_read();
            const double n_step = instr(t1 - t0);
            stat_add(&st_step[c], n_step);
            stat_add(&st_pipe[c], n_est + n_step);
            applied[c] = out.legs;
        }
    }
    /* Integer output: the target's printf has no floating point. */
    printf("  estimator        mean %6u  max %6u instructions\n", U(st_est.sum / st_est.n),
           U(st_est.max));
    for (int c = 0; c < NC; c++) {
        printf("  %-7s step     mean %6u  max %6u   pipeline mean %6u  max %6u\n", names[c],
               U(st_step[c].sum / st_step[c].n), U(st_step[c].max),
               U(st_pipe[c].sum / st_pipe[c].n), U(st_pipe[c].max));
    }
    printf("  m2ptfc / m1 worst case (x1000): step %u, pipeline %u\n",
           U(1000.0 * st_step[0].max / st_step[1].max),
           U(1000.0 * st_pipe[0].max / st_pipe[1].max));
    TEST_ASSERT_TRUE(st_pipe[0].max <= 0.66 * st_pipe[1].max);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_instruction_counts);
    return UNITY_END();
}
