/*
 * The small motors in closed loop on the host (plant + HAL sim +
 * firmware pipeline), each controller with its default configuration for the
 * machine: the mjbots mj5208 drone outrunner on 24 V and the Rctimer GBM5208
 * gimbal motor on 12 V (sim_host/machines/{mj5208_drone,gbm5208_gimbal}.ini).
 *
 * Operating point (the small-motor acceptance point): dynamometer at 20 % of the no-load
 * speed, torque reference half the rated torque. The no-load speed follows
 * from the file's psi_pm with the line-to-line peak Kv convention the files
 * use: the back-EMF sqrt(3) p psi_pm w_m reaches Vdc (the largest line-to-line
 * voltage of the inverter) at w_m0 = Vdc / (sqrt(3) p psi_pm), i.e. Kv Vdc.
 *
 * Bound: no fault and |mean(T) - T_ref| <= 5 % of T_ref over the window
 * (plant torque on the Ts/10 grid). m2ptfc, drr and foc at 20 kHz; the
 * switching table fst at 40 kHz (switching tables are run at up to 40 kHz).
 *
 * Sensors: the files' [sensors] (a 14-bit absolute magnetic encoder, 4096
 * lines x 4 = 16384 counts per turn, as both motors are usually fitted:
 * moteus' AS5047P on the mj5208, AS5048A on gimbal motors); hal/sim's ADC
 * defaults: 12 bit, +-1.5 current_max full scale (mj5208 +-33.75 A, 16.5 mA
 * per count; GBM5208 +-1.5 A, 0.73 mA per count), 0.5 count noise; and the
 * gimbal motor once more on the B-G431B-ESC1's own current scale (its default
 * motor; board_esc1.c: 3 mOhm shunts, gain 64/7, 12-bit ADC on 3.3 V =
 * 29.4 mA per count, so its half-rated 0.146 A is 5 counts).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "board_esc1.h"
#include "fw_state.h"
#include "g4_adc.h"
#include "loop_util.h"
#include "sim_run.h"
#include "unity.h"

#define PI_D 3.14159265358979323846
#define TSSE_REL 0.05

static sim_run_t run;

void setUp(void)
{
}

void tearDown(void)
{
    sim_run_free(&run);
}

static double no_load_rpm(const sim_machine_t *m)
{
    const double w_m0 = m->vdc_v / (sqrt(3.0) * m->pole_pairs * m->psi_pm_wb);
    return w_m0 * 60.0 / (2.0 * PI_D);
}

/* Dynamometer run at 20 % of the no-load speed, half the rated torque (the
 * ADC's full scale i_fullscale_a, 0: hal/sim's default). */
static void steady_adc(const sim_machine_t *m, const char *ctrl, uint32_t fs, double duration_s,
                       double win_start_s, double i_fullscale_a)
{
    sim_run_cfg_t c;
    loop_cfg_machine(&c, m, ctrl, fs, 0.2 * no_load_rpm(m), 0.5 * m->torque_rated_nm, duration_s,
                     win_start_s);
    if (i_fullscale_a > 0.0) {
        c.hal.i_fullscale_a = i_fullscale_a;
    }
    metrics_result_t mp;
    loop_run_metrics(&run, &c, &mp);
    const double tref = c.torque_ref_nm;
    const double sse = tref - mp.torque_mean_nm;
    printf("  %-15s %-6s %2u kHz %7.1f r/min  ADC %5.1f mA/count  T_ref %.4f N*m  T_sse %+.5f N*m "
           "(%+.2f %%)  T_rip %.5f N*m (%.1f %%)  f_av %5.0f Hz  fault %s\n",
           m->name, ctrl, fs / 1000u, c.speed_rpm, 2e3 * c.hal.i_fullscale_a / 4096.0, tref, sse,
           100.0 * sse / tref, mp.torque_ripple_nm, 100.0 * mp.torque_ripple_nm / tref, mp.f_av_hz,
           fw_fault_name(fw_fault(&run.fw)));
    char msg[200];
    snprintf(msg, sizeof msg, "%s %s: fault %s", m->name, ctrl, fw_fault_name(fw_fault(&run.fw)));
    TEST_ASSERT_EQUAL_INT_MESSAGE(FW_STATE_RUNNING, fw_state(&run.fw), msg);
    snprintf(msg, sizeof msg, "%s %s: T_sse %.5f N*m beyond 5 %% of %.4f N*m", m->name, ctrl, sse,
             tref);
    TEST_ASSERT_TRUE_MESSAGE(fabs(sse) <= TSSE_REL * tref, msg);
    sim_run_free(&run);
}

/* The four controllers: m2ptfc, drr and foc at 20 kHz, fst at 40 kHz. */
static void steady_all(const sim_machine_t *m, double duration_s, double win_start_s,
                       double i_fullscale_a)
{
    static const struct {
        const char *ctrl;
        uint32_t fs;
    } k[] = {{"m2ptfc", 20000u}, {"drr", 20000u}, {"foc", 20000u}, {"fst", 40000u}};
    for (size_t j = 0; j < sizeof k / sizeof k[0]; j++) {
        steady_adc(m, k[j].ctrl, k[j].fs, duration_s, win_start_s, i_fullscale_a);
    }
}

/* mj5208: f_e = 170 Hz at 1459 r/min; window 50 ms = 8.5 electrical turns. */
static void test_mj5208_drone(void)
{
    const sim_machine_t m = loop_machine_file("mj5208_drone.ini");
    /* the file's data: Kv 304 r/min/V on 24 V, the 14-bit encoder */
    TEST_ASSERT_DOUBLE_WITHIN(1.0, 304.0 * 24.0, no_load_rpm(&m));
    TEST_ASSERT_EQUAL_INT(4096, m.encoder_lines);
    steady_all(&m, 0.08, 0.03, 0.0);
}

/* GBM5208: f_e = 11.2 Hz at 61 r/min; window 150 ms = 1.7 electrical turns,
 * 10 periods of the sixth harmonic. */
static void test_gbm5208_gimbal(void)
{
    const sim_machine_t m = loop_machine_file("gbm5208_gimbal.ini");
    /* the file's data: Kv 25.5 r/min/V on 12 V, the 14-bit encoder */
    TEST_ASSERT_DOUBLE_WITHIN(0.1, 25.5 * 12.0, no_load_rpm(&m));
    TEST_ASSERT_EQUAL_INT(4096, m.encoder_lines);
    steady_all(&m, 0.2, 0.05, 0.0);
}

/* The gimbal motor on the ESC1 board's current scale: +-(A per count) 2^11. */
static void test_gbm5208_gimbal_esc1_current_scale(void)
{
    const sim_machine_t m = loop_machine_file("gbm5208_gimbal.ini");
    const g4_board_t *b = &g4_board_esc1;
    const double a_per_count =
        b->vref / (double)G4_ADC_FULL_SCALE / (fabs(b->sense_gain) * b->shunt_ohm);
    TEST_ASSERT_DOUBLE_WITHIN(0.5e-3, 29.4e-3, a_per_count);
    const double fullscale = a_per_count * 2048.0;
    steady_all(&m, 0.2, 0.05, fullscale);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_mj5208_drone);
    RUN_TEST(test_gbm5208_gimbal);
    RUN_TEST(test_gbm5208_gimbal_esc1_current_scale);
    return UNITY_END();
}
