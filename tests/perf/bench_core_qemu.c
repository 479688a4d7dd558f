/*
 * Instruction counts of the per-sample control core on the Cortex-M4 (QEMU
 * mps2-an386, cm4 build only; ctest label "bench", or tools/perf-core).
 *
 * QEMU counts instructions, not cycles: under -icount shift=N one instruction
 * takes 2^N ns of virtual time. Timer1 (25 MHz) is read around each call; the
 * ticks are converted with a calibration against 1000 NOPs (plus the bl/bx of
 * the extra call: 1002 instructions), so the table does not depend on N. At
 * N >= 6 one instruction spans >= 1.6 ticks and the rounded count is exact
 * (the +-1 tick phase between the two clocks is below half an instruction);
 * the ctest runs at N = 7. The overhead of the measurement (two Timer1 reads
 * and the indirect call of an empty wrapper) is subtracted. A count is what a
 * wrapper costs: the call under test including its argument set-up, call and
 * return, plus loading the inputs from an array and storing one result
 * (~6 instructions, more for functions with pointer outputs).
 *
 * Workload: thesis SPMSM (the 80 kW IPMSM for the MTPA table) at 10 kHz,
 * N_IN random operating points: currents of any direction up to current_max,
 * rotor angle anywhere, speed within +-1.2 rated, an active vector with any
 * duty followed by its zero vector, DC link 0.9-1.1 pu.
 *
 * Asserted (never a timing bound): the measurement overhead is the same twice,
 * every count is positive and below a sanity ceiling, and (at N >= 6) the same
 * input costs the same number of instructions when measured twice.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "angle_source.h"
#include "ctrl_units.h"
#include "est_fixture.h"
#include "estimator.h"
#include "flux_observer.h"
#include "flux_observer_config.h"
#include "fx.h"
#include "machines.h"
#include "mtpa.h"
#include "plan.h"
#include "qemu_mps2.h"
#include "transforms.h"
#include "unity.h"
#include "vectors.h"

void setUp(void)
{
}
void tearDown(void)
{
}

#define N_IN 256
#define CEILING 5000u /* sanity: no core call costs this much */

/* ---- inputs (filled once, outside the measurement) ---- */
typedef struct {
    q24_t ia, ib, al, be, x, y, s, c, omega, vdc, torque;
    fx_angle_t th;
    uint64_t u64;
    ctrl_plan_t plan;
    ctrl_legs_t legs; /* of plan */
    ctrl_meas_t meas;
    ctrl_mstate_t now;
} input_t;

static input_t in[N_IN];
static ctrl_params_t P;         /* thesis SPMSM, 10 kHz */
static ctrl_params_t P_ipm;     /* 80 kW IPMSM, 10 kHz (MTPA table) */
static ctrl_estimator_t E;      /* every output (CTRL_EST_ALL) */
static ctrl_estimator_t E_lean; /* no optional output */
static ctrl_fobs_t O_sl;        /* flux observer, sensorless, dead time compensated */
static ctrl_fobs_t O_enc;       /* flux observer, encoder mode */
static volatile int32_t sink;

static uint32_t rng = 12345u;
static double urand(void)
{
    rng = rng * 1664525u + 1013904223u;
    return (double)(rng >> 8) / 16777216.0;
}

static void make_inputs(void)
{
    const ctrl_machine_t spm = machine_thesis_spmsm();
    const ctrl_machine_t ipm = machine_thesis_ipmsm80();
    ctrl_bases_t b;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&P, &b, &spm, 10000u));
    ctrl_bases_t b2;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_params_init(&P_ipm, &b2, &ipm, 10000u));
    const double imax = spm.current_max_a / b.i_a;
    for (int k = 0; k < N_IN; k++) {
        input_t *t = &in[k];
        const double amp = imax * urand();
        const double gam = 2.0 * CTRL_PI * urand();
        const double th = 2.0 * CTRL_PI * urand();
        const double ia = amp * cos(gam);
        const double ib = amp * cos(gam - 2.0 * CTRL_PI / 3.0);
        t->ia = ctrl_q24_from_double(ia);
        t->ib = ctrl_q24_from_double(ib);
        ctrl_clarke(t->ia, t->ib, &t->al, &t->be);
        t->th = (fx_angle_t)(uint64_t)llround(th / (2.0 * CTRL_PI) * 4294967296.0);
        fx_sincos(t->th, &t->s, &t->c);
        /* a flux-sized vector (|psi| ~ 1 pu) for mag / sector */
        const double pa = 1.0 + 0.3 * (urand() - 0.5);
        t->x = ctrl_q24_from_double(pa * cos(gam));
        t->y = ctrl_q24_from_double(pa * sin(gam));
        t->u64 = (uint64_t)t->x * (uint64_t)t->x + ((uint64_t)rng << 20);
        const double w = (2.0 * urand() - 1.0) * 1.2 * P.speed_rated_e / (double)FX_ONE;
        t->omega = ctrl_q24_from_double(w);
        t->vdc = ctrl_q24_from_double(0.9 + 0.2 * urand());
        t->torque = ctrl_q24_from_double((2.0 * urand() - 1.0) * 0.5);
        ctrl_plan_active_zero(&t->plan, (uint8_t)(1u + (rng >> 8) % 6u),
                              ctrl_q24_from_double(urand()));
        ctrl_plan_legs(&t->plan, &t->legs);
        t->meas.i_a = t->ia;
        t->meas.i_b = t->ib;
        t->meas.vdc = t->vdc;
        t->meas.theta_e = t->th;
        fixture_state_from_current(&P, t->al, t->be, t->th, &t->now);
    }
    ctrl_estimator_init(&E, &P);
    ctrl_estimator_init(&E_lean, &P);
    ctrl_estimator_set_outputs(&E_lean, 0u);
    ctrl_fobs_config_t fc;
    ctrl_fobs_config_default(&fc, &spm);
    fc.dead_time_s = 1e-6;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_fobs_init(&O_sl, &P, &b, &fc, NULL));
    fc.mode = CTRL_FOBS_ENCODER;
    TEST_ASSERT_EQUAL_INT(CTRL_OK, ctrl_fobs_init(&O_enc, &P, &b, &fc, NULL));
    ctrl_fobs_reset(&O_sl, &P, 0u, 0, 0, 0);
    ctrl_fobs_reset(&O_enc, &P, 0u, 0, 0, 0);
}

/* ---- wrappers: one call of the function under test on input k ---- */
typedef void (*bench_fn_t)(int k);

__attribute__((noinline)) static void w_empty(int k)
{
    (void)k;
    __asm__ volatile("" ::: "memory");
}
__attribute__((noinline)) static void w_mul(int k)
{
    sink = fx_mul(in[k].x, in[k].s);
}
__attribute__((noinline)) static void w_dot(int k)
{
    sink = fx_dot(in[k].x, in[k].y, in[k].c, in[k].s);
}
__attribute__((noinline)) static void w_sincos(int k)
{
    q24_t s;
    q24_t c;
    fx_sincos(in[k].th, &s, &c);
    sink = s + c;
}
__attribute__((noinline)) static void w_isqrt(int k)
{
    sink = (int32_t)fx_isqrt64(in[k].u64);
}
__attribute__((noinline)) static void w_mag(int k)
{
    sink = fx_mag(in[k].x, in[k].y);
}
__attribute__((noinline)) static void w_clarke(int k)
{
    q24_t a;
    q24_t b;
    ctrl_clarke(in[k].ia, in[k].ib, &a, &b);
    sink = a + b;
}
__attribute__((noinline)) static void w_park(int k)
{
    q24_t d;
    q24_t q;
    ctrl_park(in[k].al, in[k].be, in[k].s, in[k].c, &d, &q);
    sink = d + q;
}
__attribute__((noinline)) static void w_sector(int k)
{
    sink = ctrl_sector(in[k].x, in[k].y);
}
__attribute__((noinline)) static void w_angle_step(int k)
{
    sink = (int32_t)(ctrl_angle_step(&P, in[k].omega) >> 1);
}
__attribute__((noinline)) static void w_legs_voltage(int k)
{
    q24_t a;
    q24_t b;
    ctrl_legs_voltage(&in[k].legs, in[k].vdc, &a, &b);
    sink = a + b;
}
__attribute__((noinline)) static void w_plan_legs(int k)
{
    ctrl_legs_t l;
    ctrl_plan_legs(&in[k].plan, &l);
    sink = l.duty[0] + l.duty[1] + l.duty[2];
}
__attribute__((noinline)) static void w_rot_q30(int k)
{
    int32_t c;
    int32_t s;
    fx_rot_q30(fx_u2i(ctrl_angle_step(&P, in[k].omega)), &c, &s);
    sink = c + s;
}
__attribute__((noinline)) static void w_rotate(int k)
{
    q24_t a;
    q24_t b;
    fx_rotate(in[k].x, in[k].y, in[k].c * 64, in[k].s * 64, &a, &b);
    sink = a + b;
}
__attribute__((noinline)) static void w_from_current(int k)
{
    ctrl_mstate_t o;
    fixture_state_from_current(&P, in[k].al, in[k].be, in[k].th, &o);
    sink = o.torque;
}
__attribute__((noinline)) static void w_from_flux(int k)
{
    ctrl_mstate_t o;
    fixture_state_from_flux(&P, in[k].x, in[k].y, in[k].th, &o);
    sink = o.torque;
}
__attribute__((noinline)) static void w_predict(int k)
{
    ctrl_mstate_t o;
    fixture_predict(&P, &in[k].now, in[k].x, in[k].y, in[k].omega, &o);
    sink = o.torque;
}
__attribute__((noinline)) static void w_mtpa_spm(int k)
{
    sink = ctrl_mtpa_psi(&P, in[k].torque);
}
__attribute__((noinline)) static void w_mtpa_ipm(int k)
{
    sink = ctrl_mtpa_psi(&P_ipm, in[k].torque);
}
__attribute__((noinline)) static void w_estimator(int k)
{
    ctrl_estimate_t est;
    ctrl_estimator_update(&E, &P, &in[k].meas, &in[k].legs, &est);
    sink = est.next.torque;
}

__attribute__((noinline)) static void w_estimator_lean(int k)
{
    ctrl_estimate_t est;
    ctrl_estimator_update(&E_lean, &P, &in[k].meas, &in[k].legs, &est);
    sink = est.next.torque;
}
__attribute__((noinline)) static void w_atan2(int k)
{
    sink = (int32_t)(fx_atan2(in[k].y, in[k].x) >> 1);
}
__attribute__((noinline)) static void w_fobs_voltage(int k)
{
    q24_t a;
    q24_t b;
    ctrl_fobs_voltage(&O_sl, &in[k].legs, in[k].vdc, in[k].ia, in[k].ib, &a, &b);
    sink = a + b;
}
__attribute__((noinline)) static void w_fobs_sl(int k)
{
    sink =
        (int32_t)(ctrl_fobs_update(&O_sl, &P, in[k].x, in[k].y, in[k].al, in[k].be, in[k].th) >> 1);
}
__attribute__((noinline)) static void w_fobs_enc(int k)
{
    sink = (int32_t)(ctrl_fobs_update(&O_enc, &P, in[k].x, in[k].y, in[k].al, in[k].be, in[k].th) >>
                     1);
}

typedef struct {
    const char *name;
    bench_fn_t fn;
} bench_t;

static const bench_t benches[] = {
    {"fx_mul", w_mul},
    {"fx_dot", w_dot},
    {"fx_sincos", w_sincos},
    {"fx_isqrt64", w_isqrt},
    {"fx_mag", w_mag},
    {"ctrl_clarke", w_clarke},
    {"ctrl_park", w_park},
    {"ctrl_sector", w_sector},
    {"ctrl_angle_step", w_angle_step},
    {"fx_rot_q30 (omega Ts)", w_rot_q30},
    {"fx_rotate", w_rotate},
    {"ctrl_legs_voltage", w_legs_voltage},
    {"ctrl_plan_legs", w_plan_legs},
    {"ctrl_mtpa_psi SPMSM", w_mtpa_spm},
    {"ctrl_mtpa_psi IPMSM", w_mtpa_ipm},
    {"ctrl_estimator_update", w_estimator},
    {"ctrl_estimator_update outputs=0", w_estimator_lean},
    {"(test fixture) state from current", w_from_current},
    {"(test fixture) state from flux", w_from_flux},
    {"(test fixture) stator-frame predict", w_predict},
    {"fx_atan2", w_atan2},
    {"ctrl_fobs_voltage (dead time)", w_fobs_voltage},
    {"ctrl_fobs_update sensorless", w_fobs_sl},
    {"ctrl_fobs_update encoder", w_fobs_enc},
};

/* ---- measurement ---- */
static uint32_t ticks_per_1002; /* Timer1 ticks of 1002 instructions (1000 NOPs, bl, bx) */
static uint32_t overhead_instr; /* two Timer1 reads and the call of an empty wrapper */

__attribute__((noinline)) static void nops_1000(void)
{
    __asm__ volatile(".rept 1000\n\tnop\n\t.endr" ::: "memory");
}

__attribute__((noinline)) static uint32_t ticks_of(bench_fn_t fn, int k)
{
    const uint32_t t0 = timer1_read();
    fn(k);
    const uint32_t t1 = timer1_read();
    return t1 - t0;
}

/* Ticks -> instructions, rounded: at shift >= 6 the +-1 tick of phase between
 * the instruction and timer clocks is below half an instruction. */
static uint32_t instr_raw(uint32_t ticks)
{
    return (uint32_t)(((uint64_t)ticks * 1002u + ticks_per_1002 / 2u) / ticks_per_1002);
}

/* Instructions of one call of fn(k), measurement overhead removed. */
static uint32_t instr_of(bench_fn_t fn, int k)
{
    const uint32_t n = instr_raw(ticks_of(fn, k));
    return n > overhead_instr ? n - overhead_instr : 0u;
}

static void calibrate(void)
{
    uint32_t t0 = timer1_read();
    nops_1000();
    uint32_t t1 = timer1_read();
    const uint32_t a = t1 - t0;
    t0 = timer1_read();
    nops_1000();
    nops_1000();
    t1 = timer1_read();
    ticks_per_1002 = (t1 - t0) - a; /* one more call: 1000 NOPs + bl + bx */
    TEST_ASSERT_TRUE(ticks_per_1002 > 0u);
    overhead_instr = instr_raw(ticks_of(w_empty, 0));
    TEST_ASSERT_EQUAL_UINT32(overhead_instr, instr_raw(ticks_of(w_empty, 1)));
}

static void test_core_counts(void)
{
    make_inputs();
    calibrate();
    const int exact = ticks_per_1002 >= 1603u; /* >= 1.6 ticks per instruction */
    printf("  calibration: %u Timer1 ticks per 1002 instructions (%s), overhead %u\n",
           (unsigned)ticks_per_1002, exact ? "exact" : "shift < 6: approximate",
           (unsigned)overhead_instr);
    printf("  %-32s %6s %6s %6s   (instructions per call, %d inputs, SPMSM 10 kHz)\n", "function",
           "min", "mean", "max", N_IN);
    for (unsigned f = 0; f < sizeof benches / sizeof benches[0]; f++) {
        uint32_t mn = UINT32_MAX;
        uint32_t mx = 0u;
        uint32_t sum = 0u;
        ctrl_estimator_reset(&E, &P);
        ctrl_estimator_reset(&E_lean, &P);
        (void)ticks_of(benches[f].fn, 0); /* prime the estimator */
        for (int k = 0; k < N_IN; k++) {
            const uint32_t n = instr_of(benches[f].fn, k);
            mn = n < mn ? n : mn;
            mx = n > mx ? n : mx;
            sum += n;
        }
        printf("  %-32s %6u %6u %6u\n", benches[f].name, (unsigned)mn,
               (unsigned)((sum + N_IN / 2) / N_IN), (unsigned)mx);
        TEST_ASSERT_TRUE(mx < CEILING);
        TEST_ASSERT_TRUE(mn > 0u);
        /* determinism: the same input costs the same (estimator: same state) */
        if (exact && benches[f].fn != w_estimator && benches[f].fn != w_estimator_lean &&
            benches[f].fn != w_fobs_sl && benches[f].fn != w_fobs_enc &&
            benches[f].fn != w_fobs_voltage) {
            TEST_ASSERT_EQUAL_UINT32(instr_of(benches[f].fn, 7), instr_of(benches[f].fn, 7));
        }
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_core_counts);
    return UNITY_END();
}
